//! Running the real Scenic 3.1.1, for the fidelity suite and `tadslc bench --runtime`'s peer:
//! a Python that imports Scenic, the CARLA maps, one run at a time (Scenic processes share
//! the maps' cache), and traces of programs in Scenic's Newtonian simulator ([`trace`]).
//!
//! Found through `TADSL_SCENIC_PYTHON` (else `.venv-scenic` in the repository, which
//! `.ci/run` creates), `TADSL_SCENIC_MAPS` (else `../shared/maps/CARLA` beside the
//! repository, or `TADSL_SHARED`) and `TADSL_SCENIC_TRACE` (else the script embedded here).
//! The only I/O of the Scenic backend's family: `tad-scenic` itself stays pure.

pub mod trace;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository this crate was built in (where `.venv-scenic` may be).
fn repo() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../..");
    root.canonicalize().unwrap_or(root)
}

/// The shared material beside the repository: `TADSL_SHARED`, else `../shared`.
pub fn shared() -> Option<PathBuf> {
    let candidates = [std::env::var_os("TADSL_SHARED").map(PathBuf::from), Some(repo().join("../shared"))];
    candidates.into_iter().flatten().find(|p| p.is_dir())
}

/// A Python that imports `scenic`.
pub fn python() -> Option<PathBuf> {
    let candidates =
        [std::env::var_os("TADSL_SCENIC_PYTHON").map(PathBuf::from), Some(repo().join(".venv-scenic/bin/python"))];
    candidates.into_iter().flatten().find(|p| imports_scenic(p))
}

/// Whether `python` is a Python that imports `scenic`.
pub fn imports_scenic(python: &Path) -> bool {
    python.is_file() && Command::new(python).args(["-c", "import scenic"]).output().is_ok_and(|o| o.status.success())
}

/// The CARLA maps.
pub fn shared_maps() -> Option<PathBuf> {
    let candidates = [std::env::var_os("TADSL_SCENIC_MAPS").map(PathBuf::from), shared().map(|s| s.join("maps/CARLA"))];
    candidates.into_iter().flatten().find(|p| p.join("Town10HD.xodr").is_file())
}

/// A writable directory (under `base`) of links to the maps, so Scenic's map cache
/// (`.snet`) lands there and is reused across runs.
pub fn map_dir(base: &Path) -> Option<PathBuf> {
    let shared = shared_maps()?;
    let dir = base.join("scenic-maps");
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

/// This process's turn to run Scenic: one run at a time, as Scenic processes share
/// the map cache (`.snet`), which the first compile of a map writes.
pub fn turn() -> std::sync::MutexGuard<'static, ()> {
    static SCENIC: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SCENIC.lock().unwrap_or_else(|e| e.into_inner())
}
