//! The prelude's junction placement and driving behaviors hold up in the real Scenic 3.1.1:
//! every `tests/scenic/prelude/*.scenic` program, assembled with the prelude, sampled with
//! seeds 0..4 and simulated in Scenic's Newtonian simulator by `tools/prelude_check.py`, keeps
//! the facts its objects ask for (arm headings and sides, crossings, following gaps, turns).
//! Needs the Scenic venv; skipped (loudly) without it unless `TAD_REQUIRE_SCENIC=1`.

mod common;

use std::path::Path;
use std::process::Command;

#[test]
fn prelude_programs_keep_their_facts() {
    let Some((python, _, maps)) = common::oracle() else { return };
    let tool = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/prelude_check.py");
    let output = Command::new(&python)
        .arg(&tool)
        .arg("--map-dir")
        .arg(&maps)
        .arg("--map-cache")
        .arg(&maps)
        .output()
        .expect("the Scenic python runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    // one JSON line per program and seed, with the measured numbers
    println!("{stdout}");
    let failed: Vec<&str> = stdout.lines().filter(|l| l.contains("\"ok\": false")).collect();
    assert!(output.status.success() && failed.is_empty(), "{stderr}\n{}", failed.join("\n"));
    assert!(stdout.lines().count() >= 20, "too few runs:\n{stdout}");
}

/// `TadMeet` measures the ego's time to its meeting as the runtime does (`tad_road::time_to`):
/// a standing ego counts as creeping at `tad_road::CREEP`.
#[test]
fn the_meeting_time_creeps_as_the_runtimes() {
    let rule = format!("return (arc - here) / max(car.speed or 0.0, {})", tad_road::CREEP);
    assert!(tad_scenic::PRELUDE_PLACEMENT.contains(&rule), "the prelude's tadTimeTo is not `{rule}`");
}

/// Where two ways meet is the layout's rule (`tad_layout::MEET_MARGIN`), in `TadMeet` and,
/// through the reach the program passes, in `tadOnTime`.
#[test]
fn ways_meet_within_the_layouts_margin() {
    let rule = format!("TAD_MEET_MARGIN = {}", tad_layout::MEET_MARGIN);
    assert!(tad_scenic::PRELUDE_PLACEMENT.contains(&rule), "the prelude's margin is not `{rule}`");
    assert!(tad_scenic::PRELUDE_PARAMS.contains("(self.width + ego.width) / 2 + TAD_MEET_MARGIN"));
}
