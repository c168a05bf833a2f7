//! `tadslc build --target scenic`: a Scenic 3 program per scenario.
//!
//! Each file is checked first: a file with errors is refused (its errors are printed and
//! the status is 1); the others are resolved (`tad_db::resolve`, the typed IR) and emitted
//! by `tad-scenic`, whose warnings (W07xx) are printed. One file without `-o` goes to standard output; otherwise `NAME.scenic` is
//! written into the `-o` directory.

use std::path::{Path, PathBuf};

use crate::Status;
use crate::files;
use tad_check::Options;
use tad_db::Database;
use tad_diagnostics::render::{FileReport, human};
use tad_scenic::{EmitOptions, Simulator};

/// Targets `build` knows.
pub const TARGETS: &[&str] = &["scenic"];

pub fn run(
    paths: &[PathBuf],
    target: &str,
    out: Option<&Path>,
    map_dir: Option<&Path>,
    map: Option<&str>,
    simulator: &str,
    color: bool,
) -> Status {
    if !target.eq_ignore_ascii_case("scenic") {
        eprintln!("error: unknown target `{target}` (targets: {})", TARGETS.join(", "));
        return Status::Usage;
    }
    let Some(simulator) = Simulator::parse(simulator) else {
        eprintln!("error: unknown simulator `{simulator}` (simulators: carla, newtonian)");
        return Status::Usage;
    };
    let (inputs, mut status) = files::load(paths);
    if out.is_none() && inputs.len() > 1 {
        eprintln!("error: {} files to build: give an output directory with -o", inputs.len());
        return Status::Usage;
    }
    if let Some(dir) = out
        && let Err(e) = std::fs::create_dir_all(dir)
    {
        eprintln!("error: cannot create `{}`: {e}", dir.display());
        return Status::Usage;
    }
    // The program names its map by path: make a relative map directory absolute, so the
    // program finds it wherever it is written.
    let map_dir = map_dir.map(|d| std::path::absolute(d).unwrap_or_else(|_| d.to_path_buf()));
    let mut written: Vec<PathBuf> = Vec::new();
    let mut db = Database::new(Options::default());
    for input in &inputs {
        let checked = crate::check::diagnose_in(&mut db, input);
        if checked.diagnostics.iter().any(|d| d.is_error()) {
            let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).cloned().collect();
            let report = FileReport::new(&input.name, &input.text, &errors);
            eprint!("{}", human::render(&report, color));
            eprintln!("{}: not built: it has errors", input.name);
            status = status.max(Status::Failed);
            continue;
        }
        let file = crate::check::register(&mut db, input);
        let module = &tad_db::analyze(&db, file).module;
        let scenario = tad_db::resolve(&db, file);
        let options = EmitOptions {
            simulator,
            map: map.map(str::to_string),
            map_dir: map_dir.as_ref().map(|d| d.to_string_lossy().into_owned()),
            source: Some(input.name.clone()),
        };
        let emitted = tad_scenic::build(module, scenario.as_ref(), &options);
        let report = FileReport::new(&input.name, &input.text, &emitted.diagnostics);
        eprint!("{}", human::render(&report, color));
        if emitted.diagnostics.iter().any(|d| d.is_error()) {
            eprintln!("{}: not built", input.name);
            status = status.max(Status::Failed);
            continue;
        }
        if let Some(dir) = &map_dir {
            let file = dir.join(format!("{}.xodr", emitted.map));
            if !file.is_file() {
                eprintln!("{}: note: the program loads `{}`, which does not exist yet", input.name, file.display());
            }
        }
        let warnings = emitted.diagnostics.len();
        match out {
            None => print!("{}", emitted.text),
            Some(dir) => {
                let stem = input
                    .path
                    .as_deref()
                    .and_then(Path::file_stem)
                    .map_or_else(|| "stdin".to_string(), |s| s.to_string_lossy().into_owned());
                let target = dir.join(format!("{stem}.scenic"));
                if written.contains(&target) {
                    eprintln!(
                        "error: {} would overwrite `{}`, written for an earlier file",
                        input.name,
                        target.display()
                    );
                    status = status.max(Status::Usage);
                    continue;
                }
                if let Err(e) = std::fs::write(&target, &emitted.text) {
                    eprintln!("error: cannot write `{}`: {e}", target.display());
                    status = status.max(Status::Usage);
                    continue;
                }
                eprintln!(
                    "{}: wrote {} ({}, {}, {})",
                    input.name,
                    target.display(),
                    emitted.map,
                    simulator.as_str(),
                    match warnings {
                        0 => "no warnings".to_string(),
                        1 => "1 warning".to_string(),
                        n => format!("{n} warnings"),
                    }
                );
                written.push(target);
            }
        }
    }
    status
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tadslc-build-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn example(path: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
    }

    #[test]
    fn builds_a_scenic_file_per_input() {
        let out = scratch("ok");
        let inputs =
            [example("examples/safety/right_turn.tad"), example("examples/regions/yosemite_deer_on_curve.tad")];
        let status = run(&inputs, "scenic", Some(&out), Some(Path::new("maps")), None, "newtonian", false);
        assert_eq!(status, Status::Ok);
        let text = std::fs::read_to_string(out.join("right_turn.scenic")).unwrap();
        assert!(text.contains("model scenic.simulators.newtonian.driving_model"));
        let maps = std::path::absolute("maps").unwrap().join("Town10HD.xodr");
        assert!(text.contains(&format!("param map = '{}'", maps.display())), "{text}");
        assert!(out.join("yosemite_deer_on_curve.scenic").is_file());
    }

    #[test]
    fn refuses_files_with_errors_and_bad_options() {
        let dir = scratch("errors");
        let bad = dir.join("bad.tad");
        std::fs::write(&bad, "scenario bad {\n  environment {\n    weather: sunnyy\n  }\n}\n").unwrap();
        assert_eq!(run(std::slice::from_ref(&bad), "scenic", Some(&dir), None, None, "carla", false), Status::Failed);
        assert!(!dir.join("bad.scenic").exists());
        let good = example("examples/safety/right_turn.tad");
        assert_eq!(run(std::slice::from_ref(&good), "python", None, None, None, "carla", false), Status::Usage);
        assert_eq!(run(std::slice::from_ref(&good), "scenic", None, None, None, "lgsvl", false), Status::Usage);
        assert_eq!(run(&[good.clone(), good], "scenic", None, None, None, "carla", false), Status::Usage);
    }
}
