//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

pub use tad_test_support::{files, repo};

/// Run `tadslc` from the repository root, with `stdin` as standard input.
pub fn tadslc(args: &[&str], stdin: &str) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_tadslc"))
        .args(args)
        .current_dir(repo())
        .env_remove("NO_COLOR")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("tadslc runs");
    if let Some(mut input) = child.stdin.take() {
        let _ = input.write_all(stdin.as_bytes());
    }
    child.wait_with_output().expect("tadslc finishes")
}

pub fn code(output: &Output) -> i32 {
    output.status.code().expect("exited normally")
}

pub fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A fresh, empty directory under the target directory.
pub fn scratch(name: &str) -> PathBuf {
    tad_test_support::scratch(Path::new(env!("CARGO_TARGET_TMPDIR")), name)
}

/// Every `*.tad` file under `dir`, sorted.
pub fn tad_files(dir: &Path) -> Vec<PathBuf> {
    files(dir, "tad")
}

/// Run `tadslc` from the repository root and press Ctrl-C (SIGINT) once `file` has
/// `lines` lines (a journal's head and its first finished unit); its output once it has
/// stopped.
pub fn interrupted_once(args: &[&str], file: &Path, lines: usize) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_tadslc"))
        .args(args)
        .current_dir(repo())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("tadslc runs");
    let count = || std::fs::read_to_string(file).map_or(0, |t| t.lines().count());
    for _ in 0..1200 {
        if count() >= lines {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(25));
    }
    assert!(count() >= lines, "{} never had {lines} lines", file.display());
    let _ = Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    child.wait_with_output().expect("tadslc finishes")
}
