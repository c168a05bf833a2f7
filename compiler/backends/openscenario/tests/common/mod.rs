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

/// CARLA's maps (`../shared/maps/CARLA`); `None`, said on standard error, when they are not
/// there, which fails the test instead when `TAD_REQUIRE_MAPS=1`.
pub fn maps() -> Option<PathBuf> {
    let dir = tad_test_support::shared().map(|s| s.join("maps/CARLA")).filter(|d| d.is_dir());
    if dir.is_none() {
        assert!(std::env::var("TAD_REQUIRE_MAPS").as_deref() != Ok("1"), "../shared/maps/CARLA is not there");
        eprintln!("SKIPPED: a test on CARLA's towns: ../shared/maps/CARLA is not there");
    }
    dir
}

/// The town `name` read from CARLA's maps, and the absolute path of its file.
pub fn town(name: &str) -> Option<(tad_openscenario::town::Town, PathBuf)> {
    let path = std::path::absolute(maps()?.join(format!("{name}.xodr"))).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    Some((tad_openscenario::town::Town::parse(name, &text).unwrap(), path))
}

/// `scenario` emitted on `town`, whose file it names `file`, with the files named `stem`.
pub fn on_town(
    scenario: &tad_ir::Scenario,
    stem: &str,
    town: &tad_openscenario::town::Town,
    file: &str,
) -> Result<tad_openscenario::Emitted, String> {
    let options = tad_openscenario::EmitOptions { stem: stem.to_string(), source: stem.to_string() };
    tad_openscenario::emit_on_town(scenario, &options, town, file)
}
