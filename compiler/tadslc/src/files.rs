//! Finding and reading input files.

use std::io::Read;
use std::path::{Path, PathBuf};

/// One input: a display name and its text.
#[derive(Clone, Debug)]
pub struct Input {
    pub name: String,
    pub path: Option<PathBuf>,
    pub text: String,
    /// Byte offset of the first invalid UTF-8 sequence, if the file was not UTF-8
    /// (the text then holds a lossy decoding).
    pub invalid_utf8: Option<usize>,
}

/// Expand paths into the files to process: files as given, directories searched
/// recursively for `*.tad` (hidden directories and `target` skipped), sorted; `-` is
/// standard input. Unreadable paths are returned as errors, the rest still processed.
pub fn collect(paths: &[PathBuf]) -> (Vec<PathBuf>, Vec<String>) {
    let mut files = Vec::new();
    let mut errors = Vec::new();
    for path in paths {
        if path.as_os_str() == "-" {
            files.push(path.clone());
        } else if path.is_dir() {
            let mut found = Vec::new();
            walk(path, &mut found, &mut errors);
            found.sort();
            files.extend(found);
        } else if path.exists() {
            files.push(path.clone());
        } else {
            errors.push(format!("cannot read `{}`: no such file or directory", path.display()));
        }
    }
    (files, errors)
}

fn walk(dir: &Path, found: &mut Vec<PathBuf>, errors: &mut Vec<String>) {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) => {
            errors.push(format!("cannot read directory `{}`: {e}", dir.display()));
            return;
        }
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        let name = entry.file_name();
        let hidden = name.to_string_lossy().starts_with('.');
        if kind.is_dir() && !hidden && name != "target" && name != "node_modules" {
            walk(&path, found, errors);
        } else if (kind.is_file() || kind.is_symlink())
            && path.extension().is_some_and(|e| e == "tad")
            && path.is_file()
        {
            found.push(path);
        }
    }
}

pub fn read(path: &Path) -> Result<Input, String> {
    let (name, bytes) = if path.as_os_str() == "-" {
        let mut bytes = Vec::new();
        std::io::stdin().read_to_end(&mut bytes).map_err(|e| format!("cannot read standard input: {e}"))?;
        ("<stdin>".to_string(), bytes)
    } else {
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
        (path.display().to_string(), bytes)
    };
    let (text, invalid_utf8) = match String::from_utf8(bytes) {
        Ok(text) => (text, None),
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            (String::from_utf8_lossy(e.as_bytes()).into_owned(), Some(at))
        }
    };
    let path = (path.as_os_str() != "-").then(|| path.to_path_buf());
    Ok(Input { name, path, text, invalid_utf8 })
}

/// Every input `paths` name (see [`collect`]), in order. Paths that cannot be read are
/// reported on standard error; the status is then [`Status::Usage`](crate::Status), and
/// the other inputs are still returned.
pub fn load(paths: &[PathBuf]) -> (Vec<Input>, crate::Status) {
    let (files, errors) = collect(paths);
    let mut status = crate::Status::Ok;
    for error in &errors {
        eprintln!("error: {error}");
        status = crate::Status::Usage;
    }
    let mut inputs = Vec::with_capacity(files.len());
    for path in &files {
        match read(path) {
            Ok(input) => inputs.push(input),
            Err(e) => {
                eprintln!("error: {e}");
                status = crate::Status::Usage;
            }
        }
    }
    (inputs, status)
}
