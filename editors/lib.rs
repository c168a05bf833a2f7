//! What the editor packages' tests share: where things are, and finding an external tool.
//!
//! The tests run each package's own tools (`tree-sitter`, `vscode-tmgrammar-test`, `nvim`)
//! as a user of that editor would. A tool that is not installed skips its test loudly,
//! unless `TAD_REQUIRE_EDITORS=1` (set by CI after installing them), which makes it fail.

use std::path::{Path, PathBuf};

/// `editors/`.
pub fn dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The repository's root.
pub fn repo() -> &'static Path {
    dir().parent().unwrap_or(dir())
}

/// Whether a missing tool fails the test instead of skipping it.
pub fn required() -> bool {
    std::env::var_os("TAD_REQUIRE_EDITORS").is_some_and(|v| v == "1")
}

/// `name` on `PATH` (or `~/.cargo/bin`), or `None` after saying why the test skips;
/// panics when tools are required.
pub fn tool(name: &str) -> Option<PathBuf> {
    let mut dirs: Vec<PathBuf> =
        std::env::var_os("PATH").map(|p| std::env::split_paths(&p).collect()).unwrap_or_default();
    if let Some(home) = std::env::var_os("HOME") {
        dirs.push(Path::new(&home).join(".cargo/bin"));
    }
    let found = dirs.iter().map(|d| d.join(name)).find(|p| p.is_file());
    if found.is_none() {
        assert!(!required(), "`{name}` is not installed and TAD_REQUIRE_EDITORS=1");
        eprintln!("SKIPPED: `{name}` is not installed (TAD_REQUIRE_EDITORS=1 makes this a failure)");
    }
    found
}

/// Every `.tad` file under `examples/` and `stdlib/`, sorted.
pub fn tad_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "tad") {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    walk(&repo().join("examples"), &mut out);
    walk(&repo().join("stdlib"), &mut out);
    out.sort();
    out
}
