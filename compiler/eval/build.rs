//! Embed every scenario under `examples/` (`*.tad`, `*.yaml`, `*.yml`), so `tadslc eval` and
//! `gen` have their default corpus wherever `tadslc` is installed.
use std::path::{Path, PathBuf};

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        let hidden = entry.file_name().to_string_lossy().starts_with('.');
        if path.is_dir() && !hidden {
            walk(&path, out);
        } else if path.extension().is_some_and(|e| e == "tad" || e == "yaml" || e == "yml") {
            out.push(path);
        }
    }
}

fn main() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let repo = repo.canonicalize().expect("the repository exists");
    let examples = repo.join("examples");
    println!("cargo:rerun-if-changed={}", examples.display());
    let mut files = Vec::new();
    walk(&examples, &mut files);
    // the order `tadslc` reads a directory in: sorted paths
    let mut files: Vec<(PathBuf, PathBuf)> =
        files.into_iter().map(|p| (p.strip_prefix(&repo).expect("under the repository").to_path_buf(), p)).collect();
    files.sort();
    let mut code = String::from("/// `(path from the repository, text)` of every example scenario, sorted by path.\n");
    code.push_str("pub const EXAMPLES: &[(&str, &str)] = &[\n");
    for (relative, path) in &files {
        println!("cargo:rerun-if-changed={}", path.display());
        let shown = relative.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/");
        code.push_str(&format!("    ({shown:?}, include_str!({:?})),\n", path.display().to_string()));
    }
    code.push_str("];\n");
    let out = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("examples.rs");
    std::fs::write(out, code).expect("write examples.rs");
}
