//! The real tools on every example (`spec/backends/openscenario.md` §5), through
//! `tools/openscenario_check.py`: ASAM's Quality Checker bundles for OpenSCENARIO XML and
//! OpenDRIVE report no issue, SUMO's `netconvert` imports every road with the lanes of the
//! `.xodr` and one connection per connecting road, and `scenariogeneration` reads every
//! `.xosc` back. Needs the Python of `tools/openscenario_setup.sh` in
//! `TADSL_OPENSCENARIO_PYTHON` and `netconvert` on the path; skipped (loudly) without
//! them unless `TAD_REQUIRE_OPENSCENARIO=1`.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn python() -> Option<PathBuf> {
    let python = std::env::var_os("TADSL_OPENSCENARIO_PYTHON").map(PathBuf::from);
    if python.is_none() {
        let why = "TADSL_OPENSCENARIO_PYTHON is not set (run tools/openscenario_setup.sh)";
        assert!(std::env::var("TAD_REQUIRE_OPENSCENARIO").as_deref() != Ok("1"), "{why}");
        eprintln!("SKIPPED: the OpenSCENARIO tools test: {why}");
    }
    python
}

/// Every example built into `dir`, on the generated road or on `town` (the town and the path
/// its `.xosc` names it by); returns the stems.
fn build_examples(dir: &Path, town: Option<(&tad_openscenario::town::Town, &str)>) -> Vec<String> {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    let mut stems = Vec::new();
    for path in common::scenarios() {
        let (stem, scenario, emitted) = common::emit_file(&path);
        let emitted = match town {
            None => emitted,
            Some((town, file)) => common::on_town(&scenario, &stem, town, file).expect("a site"),
        };
        for (ext, text) in emitted.files() {
            std::fs::write(dir.join(format!("{stem}.{ext}")), text).unwrap();
        }
        stems.push(stem);
    }
    stems
}

/// `tools/openscenario_check.py DIR --json`: its report's files, the problems it found in
/// them (the bundles' issues, failed read-backs), and whether it exited 0.
fn check_dir(python: &Path, dir: &Path) -> (Vec<serde_json::Value>, Vec<String>, bool) {
    let script = tad_test_support::repo().join("tools/openscenario_check.py");
    let out = Command::new(python).arg(&script).arg(dir).arg("--json").output().expect("the checker runs");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
    });
    let files = report["files"].as_array().expect("files").clone();
    let mut problems = Vec::new();
    for f in &files {
        let name = f["file"].as_str().unwrap();
        for issue in f["issues"].as_array().unwrap() {
            problems.push(format!("{name}: {issue}"));
        }
        if let Some(rb) = f["readback"].as_object().filter(|rb| rb["ok"] != true) {
            problems.push(format!("{name}: read-back failed: {}", rb["error"]));
        }
    }
    (files, problems, out.status.success())
}

/// The lanes of a type on the roads outside the junction, and the junction's connections.
fn xodr_counts(text: &str) -> (usize, usize, usize) {
    let doc = roxmltree::Document::parse(text).unwrap();
    let roads = doc.descendants().filter(|n| n.has_tag_name("road") && n.attribute("junction") == Some("-1"));
    let lanes: Vec<&str> = roads
        .flat_map(|r| r.descendants().filter(|n| n.has_tag_name("lane")))
        .filter_map(|l| l.attribute("type"))
        .collect();
    let count = |t: &str| lanes.iter().filter(|l| **l == t).count();
    let connections = doc.descendants().filter(|n| n.has_tag_name("connection")).count();
    (count("driving"), count("sidewalk"), connections)
}

#[test]
fn asam_checkers_netconvert_and_scenariogeneration_pass_every_example() {
    let Some(python) = python() else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("openscenario-tools");
    let stems = build_examples(&dir, None);
    let (files, mut problems, success) = check_dir(&python, &dir);
    println!("| example | edges | driving lanes | sidewalks | connections (xodr / SUMO) |\n|---|---|---|---|---|");
    for f in &files {
        let name = f["file"].as_str().unwrap();
        let Some(nc) = f["netconvert"].as_object() else { continue };
        if nc["ok"] != true {
            problems.push(format!("{name}: netconvert failed: {:?}", nc.get("errors")));
            continue;
        }
        let text = std::fs::read_to_string(name).unwrap();
        let (driving, sidewalks, connections) = xodr_counts(&text);
        let net = &nc["net"];
        let count = |v: &serde_json::Value| v.as_u64().unwrap_or(0) as usize;
        let sumo_driving = count(&net["lanes_by_type"]["driving"]);
        let sumo_sidewalks = count(&net["lanes_by_type"]["sidewalk"]);
        let sumo_connections = count(&net["connections"]);
        println!(
            "| {} | {} | {driving} / {sumo_driving} | {sidewalks} / {sumo_sidewalks} | {connections} / {sumo_connections} |",
            Path::new(name).file_stem().unwrap().to_string_lossy(),
            net["edges"]
        );
        if (driving, sidewalks) != (sumo_driving, sumo_sidewalks) {
            problems.push(format!("{name}: SUMO has {sumo_driving} driving lanes and {sumo_sidewalks} sidewalks"));
        }
        if connections != sumo_connections {
            problems.push(format!("{name}: {connections} connections, SUMO {sumo_connections}"));
        }
    }
    let xosc = files.iter().filter(|f| f["kind"] == "xosc").count();
    let xodr = files.iter().filter(|f| f["kind"] == "xodr").count();
    assert_eq!(xodr, stems.len(), "one .xodr per example");
    assert!(xosc >= stems.len(), "{xosc} .xosc files");
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
    assert!(success, "the checker's status is not 0");
}

/// `--map Town10HD`: every example placed on the town, which its `.xosc` names by absolute
/// path. The `.xosc` bundle and the read-back pass; the town's own `.xodr` is CARLA's, not
/// checked here.
#[test]
fn asam_checker_and_scenariogeneration_pass_every_example_on_a_town() {
    let Some(python) = python() else { return };
    let Some((town, path)) = common::town("Town10HD") else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("openscenario-town");
    let stems = build_examples(&dir, Some((&town, &path.to_string_lossy()))).len();
    let (files, problems, success) = check_dir(&python, &dir);
    assert!(files.iter().filter(|f| f["kind"] == "xosc").count() >= stems, "every .xosc checked");
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
    assert!(success, "the checker's status is not 0");
}
