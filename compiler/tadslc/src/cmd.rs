//! One module per subcommand: each has its arguments (`Args`, parsed by clap) and a `run`
//! that calls the libraries, prints through [`crate::output`] and returns
//! `Result<Status, CliError>`; `main` turns that into the exit status.

pub mod bench;
pub mod build;
pub mod check;
pub mod compare;
pub mod completions;
pub mod disasm;
pub mod eval;
pub mod explain;
pub mod export;
pub mod finetune;
pub mod fit;
pub mod fmt;
pub mod generate;
pub mod grammar;
pub mod import;
pub mod lsp;
pub mod man;
pub mod merge;
pub mod model;
pub mod run;
pub mod search;
pub mod sft_export;
pub mod stats;
pub mod synth;
pub mod train_ego;
pub mod translate;
