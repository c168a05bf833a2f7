//! The host side of the database: finding input files, reading them (a file that is not
//! UTF-8 is decoded lossily and reported as E0006), registering them and checking them.
//!
//! What the CLI, the benchmarks and the harness share; the queries themselves never read
//! the disk.

use std::io::Read;
use std::path::{Path, PathBuf};

use tad_check::Checked;
use tad_diagnostics::{Code, Diagnostic, Payload, Span};

use crate::{Database, Language, RealFs, SourceFile};

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

/// Every input `paths` name (see [`collect`]), in order, and why the paths that could not
/// be found or read were not (the search's errors first, then each file's).
pub fn load(paths: &[PathBuf], search: Search) -> (Vec<Input>, Vec<String>) {
    let (files, mut errors) = collect(paths, search);
    let mut inputs = Vec::with_capacity(files.len());
    for path in &files {
        match read(path) {
            Ok(input) => inputs.push(input),
            Err(e) => errors.push(e),
        }
    }
    (inputs, errors)
}

/// Every file under `dir` whose extension is `ext`, sorted (hidden directories, `target`
/// and `node_modules` skipped); an unreadable directory gives none.
pub fn with_extension(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let (mut found, mut errors) = (Vec::new(), Vec::new());
    walk(dir, &|p| p.extension().is_some_and(|e| e == ext), &mut found, &mut errors);
    found.sort();
    found
}

/// Register one input in the database, in the language its path suggests.
pub fn register(db: &mut Database, input: &Input) -> SourceFile {
    let path = input.path.clone().unwrap_or_else(|| std::path::PathBuf::from(&input.name));
    let language = Language::guess(&path, &input.text);
    db.set_source(path, input.text.clone(), language, &RealFs)
}

/// Check one input through the database: a non-UTF-8 file is reported, then checked as
/// decoded.
pub fn diagnose_in(db: &mut Database, input: &Input) -> Checked {
    let file = register(db, input);
    checked(db, file, input)
}

pub fn checked(db: &Database, file: SourceFile, input: &Input) -> Checked {
    let mut checked = crate::check(db, file).clone();
    if let Some(at) = input.invalid_utf8 {
        // The lossy text has U+FFFD (3 bytes) where the invalid sequence was.
        checked.diagnostics.insert(
            0,
            Diagnostic::new(
                Code::E0006,
                "this file is not valid UTF-8",
                Span::new(at, at + 3),
                "invalid bytes start here",
            )
            .in_file(file.id(db))
            .with_payload(Payload::WrongValue {
                field: "encoding".into(),
                expected: "UTF-8".into(),
                found: "invalid bytes".into(),
            })
            .with_help("save the file as UTF-8"),
        );
    }
    checked
}
