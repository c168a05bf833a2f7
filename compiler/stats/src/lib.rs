//! Statistics of scenario corpora and distances between them.
//!
//! ```text
//! ir::Scenario ──features──▶ Features (attribute → values, actor count, a sentence)
//! [Features] ──Stats::of──▶ histograms, the corpus table ──table/csv/json, plot::bars (SVG)
//! A, B ──compare (bootstrap, seeded)──▶ JSD per attribute, actor-count Wasserstein,
//!          + embeddings of each scenario's sentence ──▶ MMD², Fréchet; plot::scatter (PCA)
//! ```
//!
//! Scenarios are typed programs, so their attributes are counted exactly; the attributes
//! are one table ([`features::ATTRIBUTES`]). Embeddings come from the caller (the
//! `tad-embed` models, or [`features::one_hot`]), so this crate needs no model.

pub mod compare;
pub mod distance;
pub mod features;
pub mod plot;
pub mod stats;

pub use compare::{Comparison, Interval, Options, compare};
pub use features::{ATTRIBUTES, Attribute, Features};
pub use stats::Stats;
