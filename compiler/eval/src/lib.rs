//! The evaluation harness, beside the CLI: what `tadslc eval`, `run`, `search`, `merge`,
//! `train-ego` and `bench --align` do, as a library.
//!
//! ```text
//! corpus ─▶ regions ─▶ generators (fitted, baseline, llm… by the host, directories) ─▶ counted
//!   ─▶ units ─pipeline─▶ scenes ─▶ search against the surrogate ─▶ every ego on the kept scenes
//!   ─▶ rows (journal as they finish) ─▶ results file ─merge─▶ region × generator × ego table
//! kept scenes ─split 3/5 per behaviour─▶ SAC (train) ─▶ the held-out 2/5: "after fine-tuning"
//! ```
//!
//! [`pipeline`] is the one path from a scenario to a scene; [`corpus::counts`] the one
//! predicate for which scenarios count; [`results`] the one results format; [`record`] what `run` leaves of its episodes, [`searched`] what
//! `search` writes. Hosts read
//! files, print and choose exit statuses; nothing here writes to a terminal.

pub mod baseline;
pub mod chatscene;
pub mod corpus;
pub mod examples;
pub mod finetune;
pub mod generator;
pub mod harness;
pub mod interval;
pub mod journal;
pub mod pipeline;
pub mod pretrain;
pub mod record;
pub mod recovery;
pub mod results;
pub mod searched;
pub mod synthetic;
pub mod train;

pub use corpus::{Corpus, Item, counts};
pub use generator::{ATTEMPTS, Generator, Prompt};
pub use harness::{Kept, Plan, Unit};
pub use journal::{Entry, Journal, KeptScene};
pub use results::{FORMAT, Results, Row, Setup, TableFormat};
