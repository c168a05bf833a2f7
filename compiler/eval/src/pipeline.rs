//! One path from a scenario to a scene the runtime runs:
//!
//! ```text
//! text ──tad-db: check, resolve──▶ ir::Scenario ──tad-layout──▶ Layout ──tad-bytecode: lower──▶ Program ──Scene::new──▶ Scene
//! ```
//!
//! `tadslc build --target bytecode`, `run`, `search`, `train-ego` and `eval` all go through
//! [`program`]; the layout is decided here once and every later stage reads it.

use std::path::PathBuf;

use tad_db::{Database, Language, RealFs, SourceFile};
use tad_runtime::{Scene, SetupError};

/// The bytecode program of a resolved scenario: laid out, then lowered.
pub fn program(scenario: &tad_ir::Scenario, name: &str) -> tad_bytecode::Program {
    let layout = tad_layout::lay_out(scenario);
    tad_bytecode::lower(scenario, &layout, name)
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
