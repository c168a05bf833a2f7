//! Finding and reading input files.

use crate::errln;
use crate::output::Closed;
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

/// Which files a directory is searched for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Search {
    /// Scenarios in either language: `*.tad`, and `*.yaml`/`*.yml` (read as answers).
    Scenarios,
    /// TAD only: `*.tad` (what `fmt`, `build` and `bench` take from a directory).
    Tad,
}

impl Search {
    fn wants(self, path: &Path) -> bool {
        let Some(ext) = path.extension().and_then(|e| e.to_str()) else {
            return false;
        };
        match self {
            Search::Scenarios => ["tad", "yaml", "yml"].iter().any(|x| ext.eq_ignore_ascii_case(x)),
            Search::Tad => ext == "tad",
        }
    }

    /// The files searched for, in words: `.tad or .yaml files`.
    pub fn describe(self) -> &'static str {
        match self {
            Search::Scenarios => ".tad or .yaml files",
            Search::Tad => ".tad files",
        }
    }
}

/// Expand paths into the files to process: files as given, directories searched
/// recursively for the files `search` wants (hidden directories, `target` and
/// `node_modules` skipped), sorted; `-` is standard input. Unreadable paths, and
/// directories with no file to process, are returned as errors; the rest are still
/// processed.
pub fn collect(paths: &[PathBuf], search: Search) -> (Vec<PathBuf>, Vec<String>) {
    let mut files = Vec::new();
    let mut errors = Vec::new();
    for path in paths {
        if path.as_os_str() == "-" {
            files.push(path.clone());
        } else if path.is_dir() {
            let mut found = Vec::new();
            walk(path, &|p| search.wants(p), &mut found, &mut errors);
            if found.is_empty() {
                errors.push(format!("no {} in `{}`", search.describe(), path.display()));
            }
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

fn walk(dir: &Path, wants: &dyn Fn(&Path) -> bool, found: &mut Vec<PathBuf>, errors: &mut Vec<String>) {
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
            walk(&path, wants, found, errors);
        } else if (kind.is_file() || kind.is_symlink()) && wants(&path) && path.is_file() {
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
/// reported on standard error and raise `status` to [`Status::Usage`](crate::Status);
/// the other inputs are still returned.
pub fn load(paths: &[PathBuf], search: Search, status: &mut crate::Status) -> Result<Vec<Input>, Closed> {
    let (files, errors) = collect(paths, search);
    for error in &errors {
        *status = crate::Status::Usage;
        errln!("error: {error}")?;
    }
    let mut inputs = Vec::with_capacity(files.len());
    for path in &files {
        match read(path) {
            Ok(input) => inputs.push(input),
            Err(e) => {
                *status = crate::Status::Usage;
                errln!("error: {e}")?;
            }
        }
    }
    Ok(inputs)
}

/// Every file under `dir` whose extension is `ext`, sorted (hidden directories, `target`
/// and `node_modules` skipped); an unreadable directory gives none.
pub fn with_extension(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let (mut found, mut errors) = (Vec::new(), Vec::new());
    walk(dir, &|p| p.extension().is_some_and(|e| e == ext), &mut found, &mut errors);
    found.sort();
    found
}
