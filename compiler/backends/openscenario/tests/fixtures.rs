//! Backend fixtures: every `tests/openscenario/fixtures/*.tad` is built and its diagnostics
//! judged by `tad_test_support::fixtures` (the annotations in it, `NAME.stderr` beside it,
//! a typed payload on each). A fixture whose first line is `// map: TownNN` is built on that
//! CARLA town (`--map`).
//!
//! `TAD_BLESS=1 cargo test -p tad-openscenario --test fixtures` rewrites the annotations and
//! the `.stderr` files; never when `CI` is set.

mod common;

use std::path::Path;

fn run(path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).unwrap();
    let (scenario, mut emitted) = common::emit(path, &text, "fixture");
    // `// map: TownNN`: built on that CARLA town (`--map`)
    if let Some(name) = text.lines().find_map(|l| l.strip_prefix("// map: ")) {
        let Some((town, _)) = common::town(name) else { return Ok(()) };
        emitted = common::on_town(&scenario, "fixture", &town, "town.xodr")?;
    }
    tad_test_support::fixtures::judge(path, &text, &emitted.diagnostics)
}

#[test]
fn fixtures_report_what_they_expect() {
    let dir = tad_test_support::repo().join("tests/openscenario/fixtures");
    let fixtures = tad_test_support::files(&dir, "tad");
    assert!(fixtures.len() >= 2);
    let failures: Vec<String> = fixtures.iter().filter_map(|p| run(p).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
