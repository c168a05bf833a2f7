//! The resolved scenario IR: what a scenario means, typed, for every stage after the
//! checker (backends, layout, a runtime, the language server). Specified in `spec/ir.md`.
//!
//! ```text
//! model::Module + Vocabulary ──resolve──▶ Scenario { entries, source, environment, road, ego, groups, placement_order }
//! ```
//!
//! The model keeps names as strings and values as written; [`resolve`] does once what every
//! consumer would otherwise redo: names become [`Id`]s into typed [`Entries`] tables
//! (aliases resolved to their canonical entry), quantities SI, lanes [`Lane`]s, positions
//! a [`Relation`] and a [`Reference`] (the ego, a group, a road element), and groups get a
//! [`Scenario::placement_order`]. Closed sets ([`Lateral`], [`Longitudinal`], [`Motion`],
//! [`SimulatedAs`], [`Signal`], [`RoadShape`])
//! are the schema's enums. It is pure and total, and reports nothing: the checker has.
//!
//! Modules: [`entries`](crate::Entries) (vocabulary tables and ids), `scenario` (the
//! scenario's parts and field states), `lane`, `quantity` (SI newtypes), `param` (ranges
//! and choices: [`Param`], with seeded sampling), `resolve`.

mod entries;
mod lane;
mod param;
mod quantity;
mod resolve;
mod scenario;

pub use entries::*;
pub use lane::Lane;
pub use param::{Param, ParamValue, Rng, SplitMix64};
pub use quantity::{Metres, MetresPerSecond, Seconds};
pub use resolve::resolve;
pub use scenario::*;
pub use tad_diagnostics::Span;
pub use tad_syntax::model::Spanned;
pub use tad_syntax::schema::{
    ClosedSet, Lateral, Longitudinal, MAX_GROUP, Motion, RoadShape, SCENE_REACH, Signal, SimulatedAs,
};
