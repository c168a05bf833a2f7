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

/// The programs of `tests/scenic/fixtures/ranges.tad` (ranges and choices) for `simulator`.
fn emit_ranges(simulator: Simulator, dir: &Path, maps: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = common::repo().join("tests/scenic/fixtures/ranges.tad");
    let options =
        EmitOptions { simulator, map_dir: Some(maps.to_string_lossy().into_owned()), ..EmitOptions::default() };
    let emitted = common::build(&path, &options);
    let out = dir.join("ranges.scenic");
    std::fs::write(&out, &emitted.text).unwrap();
    out
}

#[test]
fn ranges_and_choices_compile_sample_and_simulate_in_scenic() {
    let Some((python, check, maps)) = common::oracle() else { return };
    let base = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let newtonian = emit_ranges(Simulator::Newtonian, &base.join("scenic-ranges-newtonian"), &maps);
    let steps = STEPS.to_string();
    let records = common::run_oracle(&python, &check, &["--sim", &steps, "--max-iters", "500"], &[newtonian]);
    let failures = common::failures(&records, STEPS);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let carla = emit_ranges(Simulator::Carla, &base.join("scenic-ranges-carla"), &maps);
    let records = common::run_oracle(&python, &check, &["--max-iters", "500"], &[carla]);
    assert!(records[0]["compiled"] == true && records[0]["sampled"] == true, "{}", records[0]);
}

/// Two seeds sample two speeds: the program's `Range` is Scenic's, sampled per scene.
#[test]
fn two_scenic_seeds_sample_different_speeds() {
    let Some((python, _, maps)) = common::oracle() else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-ranges-seeds");
    let program = emit_ranges(Simulator::Newtonian, &dir, &maps);
    let text = std::fs::read_to_string(&program).unwrap();
    assert!(text.contains("tadSpeedEgo = Range(6.944, 9.722)"), "{text}");
    assert!(text.contains("with speed tadSpeedEgo"), "{text}");
    const SAMPLE: &str = r#"
import random, sys, warnings
warnings.simplefilter("ignore")
import numpy, scenic
speeds = []
for seed in (1, 2):
    random.seed(seed)
    numpy.random.seed(seed)
    scenario = scenic.scenarioFromFile(sys.argv[1], mode2D=True, model="scenic.simulators.newtonian.driving_model")
    scene, _ = scenario.generate(maxIterations=500)
    speeds.append(scene.egoObject.speed)
print(" ".join(repr(s) for s in speeds))
"#;
    let output = std::process::Command::new(&python)
        .arg("-c")
        .arg(SAMPLE)
        .arg(&program)
        .env("SCENIC_MAP_CACHE", "none")
        .output()
        .expect("python runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let speeds: Vec<f64> = stdout.split_whitespace().filter_map(|s| s.parse().ok()).collect();
    assert_eq!(speeds.len(), 2, "{stdout}\n{}", String::from_utf8_lossy(&output.stderr));
    println!("ego speeds sampled with seeds 1 and 2: {speeds:?} m/s");
    assert!(speeds.iter().all(|s| (25.0 / 3.6 - 1e-3..=35.0 / 3.6 + 1e-3).contains(s)), "{speeds:?}");
    assert!((speeds[0] - speeds[1]).abs() > 1e-6, "the same speed for two seeds: {speeds:?}");
}
