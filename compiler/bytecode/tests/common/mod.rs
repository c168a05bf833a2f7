//! Loading scenarios for the tests, as `tadslc` does: through the database.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use tad_bytecode::Program;

/// The resolved scenario of a file, if it has one.
pub fn resolved(path: &Path) -> Option<tad_ir::Scenario> {
    let text = std::fs::read_to_string(path).ok()?;
    resolved_text(path, text)
}

pub fn resolved_text(path: &Path, text: String) -> Option<tad_ir::Scenario> {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(path.to_path_buf(), text);
    tad_db::resolve(&db, file).clone()
}

/// A file's program, lowered from its layout.
pub fn program(path: &Path) -> Program {
    let scenario = resolved(path).unwrap_or_else(|| panic!("{}: no scenario", path.display()));
    let layout = tad_layout::lay_out(&scenario);
    tad_bytecode::lower(&scenario, &layout, &tad_test_support::relative(path))
}

pub fn examples() -> Vec<PathBuf> {
    tad_test_support::examples()
}

/// Every scenario file of the test fixtures.
pub fn fixtures() -> Vec<PathBuf> {
    tad_test_support::files(&tad_test_support::repo().join("tests"), "tad")
}

pub fn example(name: &str) -> PathBuf {
    examples()
        .into_iter()
        .find(|p| p.file_stem().is_some_and(|s| s == name))
        .unwrap_or_else(|| panic!("no example `{name}`"))
}
