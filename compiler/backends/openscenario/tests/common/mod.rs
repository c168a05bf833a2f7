//! What the backend's integration tests share: the scenarios they build, and building one.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The examples and the backend's own scenarios (`tests/openscenario/`: a roundabout, a
/// T-junction with stop signs, a U-turn at lights, a bend with a crossing; its fixtures).
pub fn scenarios() -> Vec<PathBuf> {
    let mut files = tad_test_support::examples();
    files.extend(tad_test_support::files(&tad_test_support::repo().join("tests/openscenario"), "tad"));
    files
}

/// `text`, checked as the file at `path` (it must have no errors), resolved and emitted
/// with the files named `stem`.
pub fn emit(path: &Path, text: &str, stem: &str) -> (tad_ir::Scenario, tad_openscenario::Emitted) {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(path.to_path_buf(), text.to_string());
    let checked = tad_db::check(&db, file);
    assert!(!checked.diagnostics.iter().any(|d| d.is_error()), "{}: {:#?}", path.display(), checked.diagnostics);
    let scenario = tad_db::resolve(&db, file).clone().expect("a scenario");
    let options = tad_openscenario::EmitOptions { stem: stem.to_string(), source: path.display().to_string() };
    let emitted = tad_openscenario::emit(&scenario, &options);
    (scenario, emitted)
}

/// A scenario file emitted, its stem naming the files.
pub fn emit_file(path: &Path) -> (String, tad_ir::Scenario, tad_openscenario::Emitted) {
    let text = std::fs::read_to_string(path).unwrap();
    let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
    let (scenario, emitted) = emit(path, &text, &stem);
    (stem, scenario, emitted)
}
