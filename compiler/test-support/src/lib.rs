//! What TADSL's tests share: where the repository and `../shared` are, the files of a
//! directory, the examples, a scratch directory, seeded mutations of TAD texts, the
//! backends' fixtures judged against what a backend reported (`fixtures`), and the
//! Scenic oracle (the real Scenic 3.1.1 in a Python venv), traces of programs in Scenic's
//! Newtonian simulator, and the footprint geometry to judge them by.
//!
//! No machine paths: everything is found from this crate's own location, or from an
//! environment variable a user or CI sets (`TADSL_SHARED`, `TADSL_SCENIC_PYTHON`,
//! `TADSL_SCENIC_CHECK`, `TADSL_SCENIC_MAPS`, `TADSL_SCENIC_TRACE`).

pub mod fake_llm;
pub mod fixtures;
pub mod mutate;
pub mod scenic;
pub mod trace;

use std::path::{Path, PathBuf};

/// The repository's root.
pub fn repo() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    root.canonicalize().unwrap_or(root)
}

/// The shared material beside the repository: `TADSL_SHARED`, else `../shared`.
pub fn shared() -> Option<PathBuf> {
    let candidates = [std::env::var_os("TADSL_SHARED").map(PathBuf::from), Some(repo().join("../shared"))];
    candidates.into_iter().flatten().find(|p| p.is_dir())
}

/// Every file under `dir` whose name ends with `.EXT`, sorted; hidden directories skipped.
pub fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let path = entry.path();
            let hidden = entry.file_name().to_string_lossy().starts_with('.');
            if path.is_dir() {
                if !hidden {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|e| e == ext) {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// Every `*.tad` file under `examples/`, sorted.
pub fn examples() -> Vec<PathBuf> {
    files(&repo().join("examples"), "tad")
}

/// A file's text, or a panic that names it.
pub fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A path relative to the repository, with `/` separators, for messages and snapshots.
pub fn relative(path: &Path) -> String {
    path.strip_prefix(repo()).unwrap_or(path).to_string_lossy().replace('\\', "/")
}

/// A fresh, empty directory named `name` under `base` (a test's `CARGO_TARGET_TMPDIR`).
pub fn scratch(base: &Path, name: &str) -> PathBuf {
    let dir = base.join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("scratch directory {}: {e}", dir.display()));
    dir
}
