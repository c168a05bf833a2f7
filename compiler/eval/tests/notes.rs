//! The runtime's notes (`tad_eval::pipeline::runtime_notes`, W0720) on the fixtures of
//! `tests/runtime/fixtures`, judged by `tad_test_support::fixtures` (the annotations in each,
//! `NAME.stderr` beside it, a typed payload on each).
//!
//! `TAD_BLESS=1 cargo test -p tad-eval --test notes` rewrites the annotations and the
//! `.stderr` files; never when `CI` is set.

use std::path::Path;

use tad_db::Database;
use tad_db::host::Input;

fn run(path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).unwrap();
    let input =
        Input { name: "fixture".into(), path: Some(path.to_path_buf()), text: text.clone(), invalid_utf8: None };
    let mut db = Database::new(tad_check::Options::default());
    let scenario =
        tad_eval::pipeline::resolved(&mut db, &input).map_err(|_| format!("{}: does not resolve", path.display()))?;
    tad_test_support::fixtures::judge(path, &text, &tad_eval::pipeline::runtime_notes(&scenario))
}

#[test]
fn fixtures_report_what_they_expect() {
    let dir = tad_test_support::repo().join("tests/runtime/fixtures");
    let fixtures = tad_test_support::files(&dir, "tad");
    assert!(!fixtures.is_empty());
    let failures: Vec<String> = fixtures.iter().filter_map(|p| run(p).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
