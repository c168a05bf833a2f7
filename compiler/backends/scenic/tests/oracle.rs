//! Every example, built for Scenic, compiles, samples and simulates with the real Scenic
//! 3.1.1 (its Newtonian simulator, headless); the CARLA programs compile and sample with the
//! CARLA model. Needs the Scenic venv; skipped (loudly) without it unless
//! `TAD_REQUIRE_SCENIC=1`. Prints one JSON line per file, and the backend's emission time
//! per scenario against Scenic's own compile time for the same program.

mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use tad_scenic::{EmitOptions, Simulator};

const STEPS: u64 = 100;
const EMIT_RUNS: u32 = 200;

/// Emit every example into `dir`; the second value is each one's mean emission time in
/// seconds (the backend alone, over `EMIT_RUNS` runs).
fn emit_all(simulator: Simulator, dir: &Path, maps: &Path) -> (Vec<PathBuf>, Vec<f64>) {
    std::fs::create_dir_all(dir).unwrap();
    let options =
        EmitOptions { simulator, map_dir: Some(maps.to_string_lossy().into_owned()), ..EmitOptions::default() };
    let mut files = Vec::new();
    let mut times = Vec::new();
    for example in common::examples() {
        let text = std::fs::read_to_string(&example).unwrap();
        let (_, scenario) = common::checked(&example, &text);
        let scenario = scenario.expect("an example has a scenario");
        let start = Instant::now();
        let mut emitted = tad_scenic::emit(&scenario, &options);
        for _ in 1..EMIT_RUNS {
            emitted = tad_scenic::emit(&scenario, &options);
        }
        times.push(start.elapsed().as_secs_f64() / f64::from(EMIT_RUNS));
        let path = dir.join(format!("{}.scenic", common::stem(&example)));
        std::fs::write(&path, &emitted.text).unwrap();
        files.push(path);
    }
    (files, times)
}

fn figures(files: &[PathBuf], times: &[f64], records: &[serde_json::Value]) {
    let profile = if cfg!(debug_assertions) { "debug" } else { "release" };
    println!("emission ({profile} build, mean of {EMIT_RUNS}) vs Scenic 3.1.1 compile of the same program:");
    println!("{:<40} {:>12} {:>12} {:>10} {:>10}", "scenario", "emit (µs)", "compile (s)", "ratio", "steps");
    let (mut emit_total, mut compile_total) = (0.0, 0.0);
    for ((file, emit), record) in files.iter().zip(times).zip(records) {
        let compile = record["compile_s"].as_f64().unwrap_or(f64::NAN);
        emit_total += emit;
        compile_total += compile;
        println!(
            "{:<40} {:>12.1} {:>12.3} {:>10.0} {:>10}",
            file.file_stem().unwrap().to_string_lossy(),
            emit * 1e6,
            compile,
            compile / emit,
            record["sim_steps"]
        );
    }
    let n = files.len() as f64;
    println!(
        "{:<40} {:>12.1} {:>12.3} {:>10.0}",
        "mean",
        emit_total / n * 1e6,
        compile_total / n,
        compile_total / emit_total
    );
}

#[test]
fn every_example_compiles_samples_and_simulates_in_scenic() {
    let Some((python, check, maps)) = common::oracle() else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-newtonian");
    let (files, times) = emit_all(Simulator::Newtonian, &dir, &maps);
    let steps = STEPS.to_string();
    let records = common::run_oracle(&python, &check, &["--sim", &steps, "--max-iters", "500"], &files);
    figures(&files, &times, &records);
    let failures = common::failures(&records, STEPS);
    assert!(failures.is_empty(), "{} of {} examples failed:\n{}", failures.len(), records.len(), failures.join("\n"));
}

#[test]
fn every_example_compiles_and_samples_with_the_carla_model() {
    let Some((python, check, maps)) = common::oracle() else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-carla");
    let (files, _) = emit_all(Simulator::Carla, &dir, &maps);
    let records = common::run_oracle(&python, &check, &["--max-iters", "500"], &files);
    let failures: Vec<String> = records
        .iter()
        .filter(|r| !(r["compiled"] == true && r["sampled"] == true && r["error"].is_null()))
        .map(|r| r.to_string())
        .collect();
    assert!(failures.is_empty(), "{} of {} examples failed:\n{}", failures.len(), records.len(), failures.join("\n"));
}
