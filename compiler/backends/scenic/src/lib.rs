//! The Scenic backend: a checked TAD scenario as a Scenic 3 program.
//!
//! [`emit`] is pure: a resolved scenario ([`tad_ir::Scenario`], from `tad_ir::resolve` or
//! the database's `tad_db::resolve`) and the [`EmitOptions`] in, the program text and the
//! backend's diagnostics out; [`no_scenario`] is the answer for a module without one
//! (E0700). Only scenarios without errors should be emitted (the command line refuses the
//! others).
//!
//! The program targets Scenic 3.1.1 with either the CARLA world model or Scenic's built-in
//! Newtonian simulator. It has four parts:
//!
//! 1. a header of comments: where it comes from, the source's description, and everything
//!    the backend left out or approximated (each also a coded warning);
//! 2. `param map` (and `param carla_map`), `param weather` and the `model`;
//! 3. a fixed prelude (`src/prelude/`): Python helpers that find where the ego vehicle can
//!    be on the map's road network and where every actor goes relative to it, and
//!    behaviors for what actors do;
//! 4. the scenario: the road requirements as data, the ego and every actor placed at its
//!    lane and offset, and (CARLA) a monitor holding the traffic light's state.
//!
//! Modules: `plan` (the steps from the scenario to a typed plan: road, ego, groups, map
//! choice, layout, actors, environment), `print` (the plan as Scenic text), `mapping`
//! (Scenic's and CARLA's names for what the vocabulary declares), `maps` (the CARLA towns'
//! features), `python` (safe identifiers, strings and comments).
//!
//! The mapping from vocabulary to Scenic is declared with the vocabulary, in TAD (an actor
//! type's `carla_blueprint`, a weather's `cloudiness`, ...), and documented in
//! `spec/backends/scenic.md`; the backend reads it through the IR's typed entries.

pub mod mapping;
pub mod maps;
pub mod plan;
pub mod print;
pub mod python;

use tad_diagnostics::Diagnostic;
use tad_ir::Scenario;
use tad_syntax::model::Module;

/// The prelude's Python helpers, verbatim in every program.
pub const PRELUDE_PLACEMENT: &str = include_str!("prelude/placement.py");
/// The prelude's behaviors, verbatim in every program.
pub const PRELUDE_BEHAVIORS: &str = include_str!("prelude/behaviors.scenic");

/// The behaviors of parameters (a choice of behaviors, a delay, a trigger), added after the
/// prelude only in programs that use them.
pub const PRELUDE_PARAMS: &str = include_str!("prelude/params.scenic");

/// The simulator a program is written for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Simulator {
    /// `model scenic.simulators.carla.model`: CARLA blueprints, weather, traffic lights.
    #[default]
    Carla,
    /// `model scenic.simulators.newtonian.driving_model`: runs headless in Scenic itself.
    Newtonian,
}

impl Simulator {
    pub fn parse(name: &str) -> Option<Simulator> {
        match name.to_ascii_lowercase().as_str() {
            "carla" => Some(Simulator::Carla),
            "newtonian" => Some(Simulator::Newtonian),
            _ => None,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Simulator::Carla => "carla",
            Simulator::Newtonian => "newtonian",
        }
    }

    pub fn model(self) -> &'static str {
        match self {
            Simulator::Carla => "scenic.simulators.carla.model",
            Simulator::Newtonian => "scenic.simulators.newtonian.driving_model",
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EmitOptions {
    pub simulator: Simulator,
    /// The map (a CARLA town such as `Town10HD`); `None` chooses the known map that has
    /// most of what the scenario needs.
    pub map: Option<String>,
    /// The directory holding `TOWN.xodr`. Absolute: written as is. Relative: resolved by
    /// Scenic from the `.scenic` file's directory (`localPath`). `None`: the map is expected
    /// next to the `.scenic` file. Scenic writes its parsed-map cache (`TOWN.snet`) into this
    /// directory, so it must be writable.
    pub map_dir: Option<String>,
    /// The name of the source file, for the header.
    pub source: Option<String>,
}

/// A generated program and what the backend has to say about it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Emitted {
    pub text: String,
    pub diagnostics: Vec<Diagnostic>,
    /// The map the program uses.
    pub map: String,
}

/// The Scenic program for a resolved scenario.
pub fn emit(scenario: &Scenario, options: &EmitOptions) -> Emitted {
    let (plan, mut diagnostics) = plan::plan(scenario, options);
    tad_diagnostics::sort(&mut diagnostics);
    let text = print::program(scenario, &plan, &diagnostics, options);
    Emitted { text, diagnostics, map: plan.map }
}

/// What building a module without a scenario gives: nothing, and E0700 at its first
/// declaration.
pub fn no_scenario(module: &Module) -> Emitted {
    Emitted { text: String::new(), diagnostics: vec![tad_check::no_scenario(module)], map: String::new() }
}

/// The program for `module` resolved as `scenario` (`tad_db::resolve`): [`emit`], or
/// [`no_scenario`] when it has none.
pub fn build(module: &Module, scenario: Option<&Scenario>, options: &EmitOptions) -> Emitted {
    match scenario {
        Some(scenario) => emit(scenario, options),
        None => no_scenario(module),
    }
}
