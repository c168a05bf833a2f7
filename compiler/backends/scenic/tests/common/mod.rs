//! Helpers shared by the Scenic backend's integration tests.
#![allow(dead_code, unused_imports)]

use std::path::{Path, PathBuf};

use tad_scenic::{EmitOptions, Emitted};

pub use tad_test_support::{examples, repo};

/// Check `text` as the file at `path` (with the standard library) and emit it. Panics when
/// the file has errors: only checked scenarios are built.
pub fn build_text(path: &Path, text: &str, options: &EmitOptions) -> Emitted {
    let (module, scenario) = checked(path, text);
    tad_scenic::build(&module, scenario.as_ref(), options)
}

/// The lowered module of `text` (as the file at `path`) and its resolved scenario
/// (`tad_db::resolve`). Panics when the file has errors: only checked scenarios are built.
pub fn checked(path: &Path, text: &str) -> (tad_syntax::model::Module, Option<tad_ir::Scenario>) {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(path.to_path_buf(), text.to_string());
    let checked = tad_db::check(&db, file);
    let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).collect();
    assert!(errors.is_empty(), "{} has errors: {errors:#?}", path.display());
    (tad_db::analyze(&db, file).module.clone(), tad_db::resolve(&db, file).clone())
}

pub fn build(path: &Path, options: &EmitOptions) -> Emitted {
    let text = std::fs::read_to_string(path).expect("example readable");
    build_text(path, &text, options)
}

/// The stem of an example, unique across `examples/`.
pub fn stem(path: &Path) -> String {
    path.file_stem().unwrap().to_string_lossy().into_owned()
}

/// The oracle (python, script, map directory), or `None` after saying so where a user sees
/// it; a failure when `TAD_REQUIRE_SCENIC=1`.
pub fn oracle() -> Option<(PathBuf, PathBuf, PathBuf)> {
    tad_test_support::scenic::oracle(Path::new(env!("CARGO_TARGET_TMPDIR")))
}

pub use tad_test_support::scenic::{failures, run as run_oracle};
