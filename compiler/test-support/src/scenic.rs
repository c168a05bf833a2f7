//! The Scenic oracle: `shared/scenic/scenic_check.py` run by a Python with Scenic 3.1.1,
//! on the CARLA maps of `shared/maps/CARLA` (found by `tad-scenic-run`, re-exported here).
//!
//! Found through `TADSL_SCENIC_PYTHON` (else `.venv-scenic` in the repository, which
//! `.ci/run` creates), `TADSL_SCENIC_CHECK` and `TADSL_SCENIC_MAPS` (else `../shared`).
//! Without it a test skips with a message on standard error and a line in its output,
//! unless `TAD_REQUIRE_SCENIC=1`, which makes the absence a failure.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::shared;
pub use tad_scenic_run::{imports_scenic, map_dir, python, shared_maps, turn};

/// The oracle script.
pub fn check_script() -> Option<PathBuf> {
    let candidates =
        [std::env::var_os("TADSL_SCENIC_CHECK").map(PathBuf::from), shared().map(|s| s.join("scenic/scenic_check.py"))];
    candidates.into_iter().flatten().find(|p| p.is_file())
}

/// The oracle's python, script and map directory; `None` (after saying so where a user
/// sees it) when it is not installed, a panic when `TAD_REQUIRE_SCENIC=1`.
pub fn oracle(base: &Path) -> Option<(PathBuf, PathBuf, PathBuf)> {
    let found = (|| Some((python()?, check_script()?, map_dir(base)?)))();
    if found.is_none() {
        unavailable(
            "the Scenic oracle is not available (set TADSL_SCENIC_PYTHON to a python with scenic 3.1.1, \
             or run `bash ../shared/scenic/setup.sh .venv-scenic`; ../shared/scenic/scenic_check.py and \
             ../shared/maps/CARLA must exist)",
        );
    }
    found
}

/// Say `why` Scenic is missing where a user sees it (a skip), or panic with it when
/// `TAD_REQUIRE_SCENIC=1`.
pub fn unavailable(why: &str) {
    if std::env::var_os("TAD_REQUIRE_SCENIC").is_some_and(|v| v == "1") {
        panic!("{why}");
    }
    // `cargo test` shows what a passing test prints with `println!`/`eprintln!` only
    // with --nocapture; a direct write to the process's stderr always reaches the
    // terminal, so the skip is seen
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "warning: SKIPPED: {why}");
}

/// Run the oracle on `files` in one process; one JSON object per file.
pub fn run(python: &Path, check: &Path, args: &[&str], files: &[PathBuf]) -> Vec<serde_json::Value> {
    let _turn = turn();
    let output = Command::new(python)
        .arg(check)
        .args(args)
        .args(files)
        .env("SCENIC_MAP_CACHE", "none")
        .output()
        .expect("the oracle runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let records: Vec<serde_json::Value> =
        stdout.lines().filter(|l| l.starts_with('{')).filter_map(|l| serde_json::from_str(l).ok()).collect();
    for line in stdout.lines() {
        println!("{line}");
    }
    if records.len() != files.len() {
        panic!(
            "the oracle printed {} records for {} files\n--- stdout\n{stdout}\n--- stderr\n{}",
            records.len(),
            files.len(),
            String::from_utf8_lossy(&output.stderr)
        );
    }
    records
}

/// The oracle records of programs that did not compile, sample, or simulate at least
/// `steps` steps without an error, as JSON lines.
pub fn failures(records: &[serde_json::Value], steps: u64) -> Vec<String> {
    records
        .iter()
        .filter(|r| {
            !(r["compiled"] == true
                && r["sampled"] == true
                && r["error"].is_null()
                && r["sim_steps"].as_u64().is_some_and(|s| s >= steps))
        })
        .map(|r| r.to_string())
        .collect()
}
