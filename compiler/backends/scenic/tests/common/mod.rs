//! Helpers shared by the Scenic backend's integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

use tad_scenic::{EmitOptions, Emitted};

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../..").canonicalize().expect("repository root")
}

/// Every `*.tad` file under `examples/`, sorted.
pub fn examples() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![repo().join("examples")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "tad") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

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

/// The Scenic venv's python: `TADSL_SCENIC_PYTHON`, else `/work/.venv-scenic`, else
/// `.venv-scenic` in the repository root.
pub fn scenic_python() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("TADSL_SCENIC_PYTHON").map(PathBuf::from),
        Some(PathBuf::from("/work/.venv-scenic/bin/python")),
        Some(repo().join(".venv-scenic/bin/python")),
    ];
    candidates.into_iter().flatten().find(|p| {
        p.is_file() && Command::new(p).args(["-c", "import scenic"]).output().is_ok_and(|o| o.status.success())
    })
}

/// The oracle script: `TADSL_SCENIC_CHECK`, else `../shared/scenic/scenic_check.py` beside
/// the repository.
pub fn scenic_check() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("TADSL_SCENIC_CHECK").map(PathBuf::from),
        Some(repo().join("../shared/scenic/scenic_check.py")),
        Some(PathBuf::from("/work/shared/scenic/scenic_check.py")),
    ];
    candidates.into_iter().flatten().find(|p| p.is_file())
}

/// The CARLA maps: `TADSL_SCENIC_MAPS`, else `../shared/maps/CARLA` beside the repository.
pub fn shared_maps() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("TADSL_SCENIC_MAPS").map(PathBuf::from),
        Some(repo().join("../shared/maps/CARLA")),
        Some(PathBuf::from("/work/shared/maps/CARLA")),
    ];
    candidates.into_iter().flatten().find(|p| p.join("Town10HD.xodr").is_file())
}

/// A writable directory of links to the maps, so Scenic's map cache (`.snet`) lands there
/// and is reused across runs.
pub fn map_dir() -> Option<PathBuf> {
    let shared = shared_maps()?;
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-maps");
    std::fs::create_dir_all(&dir).ok()?;
    for entry in std::fs::read_dir(&shared).ok()?.flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|e| e == "xodr") {
            let link = dir.join(entry.file_name());
            if !link.exists() {
                #[cfg(unix)]
                let made = std::os::unix::fs::symlink(&path, &link);
                #[cfg(not(unix))]
                let made = std::fs::copy(&path, &link).map(|_| ());
                // another test may have made it meanwhile
                if made.is_err() && !link.exists() {
                    return None;
                }
            }
        }
    }
    Some(dir)
}

/// Skip (loudly) when Scenic is not installed, unless `TAD_REQUIRE_SCENIC=1`.
pub fn oracle() -> Option<(PathBuf, PathBuf, PathBuf)> {
    let found = (|| Some((scenic_python()?, scenic_check()?, map_dir()?)))();
    if found.is_none() {
        let why = "the Scenic oracle is not available (set TADSL_SCENIC_PYTHON to a python with scenic 3.1.1, \
                   and make ../shared/scenic/scenic_check.py and ../shared/maps/CARLA available)";
        if std::env::var_os("TAD_REQUIRE_SCENIC").is_some_and(|v| v == "1") {
            panic!("{why}");
        }
        eprintln!("SKIPPED: {why}");
    }
    found
}

/// Run the oracle on `files` in one process; one JSON object per file.
pub fn run_oracle(python: &Path, check: &Path, args: &[&str], files: &[PathBuf]) -> Vec<serde_json::Value> {
    // One Scenic process at a time: they share the map cache (`.snet`), which the first
    // compile of a map writes.
    static ORACLE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ORACLE.lock().unwrap_or_else(|e| e.into_inner());
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
