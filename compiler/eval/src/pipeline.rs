//! One path from a scenario to a scene the runtime runs:
//!
//! ```text
//! text ──tad-db: check, resolve──▶ ir::Scenario ──tad-layout──▶ Layout ──tad-bytecode: lower──▶ Program ──Scene::new──▶ Scene
//! ```
//!
//! `tadslc build --target bytecode`, `run`, `search`, `train-ego` and `eval` all go through
//! [`program`]; the layout is decided here once and every later stage reads it.

use std::path::PathBuf;

use tad_db::host::Input;
use tad_db::{Database, Language, RealFs, SourceFile};
use tad_diagnostics::Diagnostic;
use tad_runtime::{Scene, SetupError};

/// The bytecode program of a resolved scenario: laid out, then lowered.
pub fn program(scenario: &tad_ir::Scenario, name: &str) -> tad_bytecode::Program {
    let layout = tad_layout::lay_out(scenario);
    tad_bytecode::lower(scenario, &layout, name)
}

/// Why an input has no program.
#[derive(Debug)]
pub enum Refusal {
    /// The input has errors (these).
    Errors(Vec<Diagnostic>),
    /// The input checks but holds no scenario (E0700).
    NoScenario(Box<Diagnostic>),
}

impl Refusal {
    /// The refusal as people read it: the diagnostics, then `NAME: not VERB` (and why).
    pub fn render(&self, input: &Input, verb: &str, color: bool) -> String {
        use tad_diagnostics::render::{FileReport, human};
        let (diagnostics, why) = match self {
            Refusal::Errors(errors) => (errors.as_slice(), ": it has errors"),
            Refusal::NoScenario(d) => (std::slice::from_ref(d.as_ref()), ""),
        };
        let shown = human::render(&FileReport::new(&input.name, &input.text, diagnostics), color);
        format!("{shown}{}: not {verb}{why}\n", input.name)
    }
}

/// An input's program: checked (a file with errors is refused), resolved, laid out and
/// lowered. What `build --target bytecode` writes and `run` and `search` run.
pub fn compile(db: &mut Database, input: &Input) -> Result<tad_bytecode::Program, Refusal> {
    resolved(db, input).map(|scenario| program(&scenario, &input.name))
}

/// An input's resolved scenario: checked (a file with errors is refused), then resolved.
/// What every backend is given.
pub fn resolved(db: &mut Database, input: &Input) -> Result<tad_ir::Scenario, Refusal> {
    let checked = tad_db::host::diagnose_in(db, input);
    if checked.diagnostics.iter().any(Diagnostic::is_error) {
        return Err(Refusal::Errors(checked.diagnostics.into_iter().filter(Diagnostic::is_error).collect()));
    }
    let file = tad_db::host::register(db, input);
    match tad_db::resolve(db, file) {
        Some(scenario) => Ok(scenario.clone()),
        None => Err(Refusal::NoScenario(Box::new(tad_check::no_scenario(&tad_db::analyze(db, file).module)))),
    }
}

/// The warnings that say a scene will differ from its file (a group capped, a group
/// beyond the scene's road): what `build` and `run` print beside what they make.
pub const SCENE_WARNINGS: [tad_diagnostics::Code; 2] = [tad_diagnostics::Code::W0512, tad_diagnostics::Code::W0513];

/// An input's [`SCENE_WARNINGS`] (its check is the database's, done once).
pub fn scene_warnings(db: &mut Database, input: &Input) -> Vec<Diagnostic> {
    let checked = tad_db::host::diagnose_in(db, input);
    checked.diagnostics.into_iter().filter(|d| SCENE_WARNINGS.contains(&d.code)).collect()
}

/// The scene of a file the database holds; `None` when it holds no scenario.
pub fn scene(db: &Database, file: SourceFile, name: &str) -> Option<Result<Scene, SetupError>> {
    let scenario = tad_db::resolve(db, file).as_ref()?;
    Some(Scene::new(&program(scenario, name)))
}

/// The scene of a TAD text, registered in `db` as `path`.
pub fn scene_of_text(db: &mut Database, path: PathBuf, text: String, name: &str) -> Option<Result<Scene, SetupError>> {
    let file = db.set_source(path, text, Language::Tad, &RealFs);
    scene(db, file, name)
}
