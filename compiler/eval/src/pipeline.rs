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
    resolved_warned(db, input).map(|(scenario, _)| scenario)
}

/// The warnings that say a scene will differ from its file (a group capped, a group
/// beyond the scene's road): what `build` and `run` print beside what they make.
pub const SCENE_WARNINGS: [tad_diagnostics::Code; 2] = [tad_diagnostics::Code::W0512, tad_diagnostics::Code::W0513];

/// [`resolved`], with the input's [`SCENE_WARNINGS`] from the same check.
pub fn resolved_warned(db: &mut Database, input: &Input) -> Result<(tad_ir::Scenario, Vec<Diagnostic>), Refusal> {
    let file = tad_db::host::register(db, input);
    let checked = tad_db::host::checked(db, file, input);
    if checked.diagnostics.iter().any(Diagnostic::is_error) {
        return Err(Refusal::Errors(checked.diagnostics.into_iter().filter(Diagnostic::is_error).collect()));
    }
    let warnings = checked.diagnostics.into_iter().filter(|d| SCENE_WARNINGS.contains(&d.code)).collect();
    match tad_db::resolve(db, file) {
        Some(scenario) => Ok((scenario.clone(), warnings)),
        None => Err(Refusal::NoScenario(Box::new(tad_check::no_scenario(&tad_db::analyze(db, file).module)))),
    }
}

/// What a scenario states that the runtime does not model (W0720): a weather with rain,
/// wet roads or fog (its road keeps dry grip and its view clear), a time with the sun
/// below the horizon (its egos sense as by day). The Scenic and OpenSCENARIO targets carry
/// both; the note says so where the runtime runs the scene.
pub fn runtime_notes(scenario: &tad_ir::Scenario) -> Vec<Diagnostic> {
    use tad_diagnostics::{Code, Payload};
    let environment = &scenario.environment;
    let entries = &scenario.entries;
    let note = |field: &str, name: &str, span, label: &str| {
        Diagnostic::new(Code::W0720, format!("{field} `{name}` does not act in the runtime"), span, label)
            .with_payload(Payload::Unsupported {
                backend: "runtime".into(),
                construct: format!("{field} `{name}`"),
                instead: Some(label.into()),
            })
            .with_note("`build --target openscenario` and `--target scenic` carry it to a simulator that models it")
    };
    let mut out = Vec::new();
    if let (Some(p), Some(span)) = (environment.weather.given(), environment.weather.span()) {
        let named = p.nominal();
        let acts = entries.resolved(&named).map(|e| e.attrs).is_some_and(|w| {
            [w.precipitation, w.precipitation_deposits, w.wetness, w.fog_density]
                .iter()
                .any(|v| v.is_some_and(|v| v > 0))
        });
        if acts {
            out.push(note("weather", entries.name(&named), span, "dry grip and a clear view there"));
        }
    }
    if let (Some(p), Some(span)) = (environment.time.given(), environment.time.span()) {
        let named = p.nominal();
        let dark = entries.resolved(&named).and_then(|e| e.attrs.sun_altitude).is_some_and(|a| a < 0);
        if dark {
            out.push(note("time", entries.name(&named), span, "the egos sense as by day there"));
        }
    }
    out
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
