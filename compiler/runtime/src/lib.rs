//! The scenario runtime: runs a bytecode program (`spec/runtime.md`).
//!
//! ```text
//! Program ──Scene::new──▶ Scene (world: the layout's road, lights; the ego's route; actors
//!                          with their scripts) ──episode::run(seed, policy)──▶ Episode
//!                          (records scored by tad-metrics, events, frames)
//! ```
//!
//! Modules: `world` (lanes, stop lines, phase
//! programs), `models` (kinematic bicycle, pure pursuit, IDM), `physics` (rapier3d contacts),
//! `detect` (SafeBench's criteria), `scene` (set-up), `episode` (the loop, scripts, MOBIL,
//! the ego's view), `sample` (seeded parameters).

pub mod detect;
pub mod episode;
pub mod models;
pub mod physics;
pub mod sample;
pub mod scene;
pub mod world;

pub use episode::{Episode, Event, EventKind, Frame, Options, Sim, run};
pub use scene::{Scene, SetupError};
pub use tad_metrics::{Mode, StopReason};
