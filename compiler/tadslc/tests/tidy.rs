//! Tidy: rules of the code base that no compiler checks, held by reading the sources (in
//! the spirit of rust-analyzer's `tidy`).
//!
//! - every Rust source file opens with a `//!` header saying what it is and why (generated
//!   files excepted);
//! - only `tadslc`'s output module writes to the terminal: no `print!`/`println!`/`eprint!`/
//!   `eprintln!` in production code elsewhere (test helpers and `#[cfg(test)]` modules may);
//! - `tad-test-support` is never a production dependency (an exception would be listed with
//!   its reason);
//! - every subcommand is in `tadslc --help`, README.md's table and spec/output.md;
//! - no function is longer than 150 lines, but for the ones listed in [`LONG`], which only
//!   shrinks: a listed function that got shorter must leave the list;
//! - no `too_many_arguments` allowance (each is a missing struct), but for [`MANY_ARGUMENTS`],
//!   which only shrinks too;
//! - a path inside a message is quoted in backticks (a single-placeholder line's
//!   `X.display()`; a path that starts the message is a location, and bare);
//! - subcommands return `Result<Status, CliError>`: no status raised by side effect
//!   (`*status = …`), but in the files of [`STATUS_BY_SIDE_EFFECT`], which only shrinks.

mod common;

use std::path::{Path, PathBuf};

use common::{repo, stdout, tadslc};

/// Functions over [`MAX_LINES`] lines, as `path::name` (the debt being paid off).
const LONG: &[&str] = &[];

const MAX_LINES: usize = 150;

/// tadslc's files that still raise a `&mut Status` (and how often): the subcommands not yet
/// returning `Result<Status, CliError>`.
const STATUS_BY_SIDE_EFFECT: &[(&str, usize)] = &[];

/// Files that still allow `clippy::too_many_arguments`, with how many times (the debt).
const MANY_ARGUMENTS: &[(&str, usize)] = &[];

/// Every tracked-looking Rust file of the workspace (sources, tests, build scripts), relative
/// to the repository root; `target` and hidden directories skipped.
fn rust_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for entry in entries.flatten() {
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') || name == "target" || name == "node_modules" {
                continue;
            }
            if path.is_dir() {
                walk(&path, out);
            } else if name.ends_with(".rs") {
                out.push(path);
            }
        }
    }
    let root = repo();
    let mut out = Vec::new();
    for top in ["compiler", "lsp", "editors", "python"] {
        walk(&root.join(top), &mut out);
    }
    out.sort();
    out.into_iter().map(|p| p.strip_prefix(&root).unwrap().to_path_buf()).collect()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(repo().join(path)).unwrap()
}

/// Whether a file is production code: under a crate's `src/`, not a test module, not the
/// test-support crate.
fn production(path: &Path) -> bool {
    let text = path.to_string_lossy();
    text.contains("/src/")
        && !text.starts_with("compiler/test-support/")
        && !text.ends_with("/tests.rs")
        && !text.contains("/tests/")
}

#[test]
fn every_source_file_has_a_header() {
    let missing: Vec<String> = rust_files()
        .into_iter()
        .filter(|p| {
            let text = read(p);
            !text.starts_with("//!") && !text.starts_with("// @generated")
        })
        .map(|p| p.display().to_string())
        .collect();
    assert!(missing.is_empty(), "files without a `//!` header: {missing:#?}");
}

#[test]
fn only_the_output_module_prints() {
    let mut found = Vec::new();
    for path in rust_files().into_iter().filter(|p| production(p)) {
        if path.ends_with("compiler/tadslc/src/output.rs") {
            continue;
        }
        let text = read(&path);
        // a file's own tests may print
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for (i, line) in code.lines().enumerate() {
            let line = line.trim_start();
            if line.starts_with("//") {
                continue;
            }
            if ["println!(", "print!(", "eprintln!(", "eprint!("].iter().any(|m| {
                line.match_indices(m)
                    .any(|(at, _)| at == 0 || !line[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_'))
            }) {
                found.push(format!("{}:{}: {line}", path.display(), i + 1));
            }
        }
    }
    assert!(found.is_empty(), "printing outside tadslc's output module (use outln!/errln!): {found:#?}");
}

/// A message's one placeholder for a path (`X.display()`, the line's last argument) inside
/// a sentence, not quoted: `cannot write {}: …` where `cannot write `{}`: …` is the rule
/// (spec/output.md, Paths). A path that starts the text (`{}: not formatted`) is a
/// location, and a listing's field (`cache: {}`) a value: both bare.
fn unquoted_path(line: &str) -> bool {
    let Some(start) = line.find('"') else { return false };
    let Some(end) = line[start + 1..].find('"').map(|e| start + 1 + e) else { return false };
    let literal = &line[start + 1..end];
    let rest = &line[end..];
    let last = rest.rfind(".display()").map(|at| &rest[at + ".display()".len()..]);
    let holders: Vec<usize> = literal.match_indices("{}").map(|(at, _)| at).collect();
    let [at] = holders[..] else { return false };
    // `cache: {}`: a listing's field, its value bare
    let field = literal[..at].strip_suffix(": ").is_some_and(|k| k.chars().all(|c| c.is_ascii_lowercase() || c == ' '));
    at > 0
        && !field
        && !literal[..at].ends_with(['`', '\'', '/', ':', '('])
        && last.is_some_and(|after| after.chars().all(|c| ")?;, ".contains(c)))
        && rest.matches(',').count() == 1
}

#[test]
fn paths_in_messages_are_quoted() {
    let mut found = Vec::new();
    for path in rust_files().into_iter().filter(|p| production(p)) {
        let text = read(&path);
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for (i, line) in code.lines().enumerate() {
            if !line.trim_start().starts_with("//") && unquoted_path(line) {
                found.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "a path inside a message is written `{{}}` (in backticks): {found:#?}");
    assert!(unquoted_path(r#"    errln!("rows in {}", path.display())?;"#));
    assert!(!unquoted_path(r#"    errln!("rows in `{}`", path.display())?;"#));
    assert!(!unquoted_path(r#"    errln!("{}: not formatted", path.display())?;"#));
}

/// Production dependencies on `tad-test-support` still to remove, with why they remain.
const TEST_SUPPORT_USERS: &[&str] = &[];

#[test]
fn test_support_is_a_dev_dependency_only() {
    let mut found = Vec::new();
    for path in rust_files().into_iter().filter(|p| p.ends_with("src/lib.rs") || p.ends_with("src/main.rs")) {
        let manifest = repo().join(path.parent().unwrap().parent().unwrap()).join("Cargo.toml");
        let Ok(text) = std::fs::read_to_string(&manifest) else { continue };
        let mut section = String::new();
        for line in text.lines() {
            if line.starts_with('[') {
                section = line.to_string();
            } else if section == "[dependencies]" && line.starts_with("tad-test-support") {
                let shown = manifest.strip_prefix(repo()).unwrap_or(&manifest).display().to_string();
                if !TEST_SUPPORT_USERS.contains(&shown.as_str()) {
                    found.push(shown);
                }
            }
        }
    }
    found.dedup();
    assert!(found.is_empty(), "tad-test-support as a production dependency: {found:?}");
}

#[test]
fn every_subcommand_is_documented() {
    let help = stdout(&tadslc(&["--help"], ""));
    let commands: Vec<String> = help
        .split("Commands:")
        .nth(1)
        .unwrap()
        .lines()
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|c| c != "help")
        .collect();
    assert!(commands.len() > 20, "{help}");
    let readme = read(Path::new("README.md"));
    let spec = read(Path::new("spec/output.md"));
    let mut missing = Vec::new();
    for command in &commands {
        let named = format!("tadslc {command}");
        if !readme.contains(&format!("| `{named}")) {
            missing.push(format!("README.md's table: {command}"));
        }
        if !spec.contains(&named) {
            missing.push(format!("spec/output.md: {command}"));
        }
    }
    assert!(missing.is_empty(), "subcommands not documented: {missing:#?}");
}

/// `(path::name, lines)` of every function longer than [`MAX_LINES`]: a line whose code
/// starts with `fn` (after `pub`, `async`, `const` and the like) opens one, and the first
/// line at the same indentation that starts with `}` closes it (rustfmt's layout).
fn long_functions() -> Vec<(String, usize)> {
    let mut out = Vec::new();
    for path in rust_files() {
        let text = read(&path);
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let code = line.trim_start();
            let indent = line.len() - code.len();
            let mut words = code.split_whitespace().peekable();
            while let Some(w) = words.peek() {
                if ["pub", "pub(crate)", "pub(super)", "async", "const", "unsafe", "extern"].contains(w)
                    || w.starts_with("pub(")
                {
                    words.next();
                } else {
                    break;
                }
            }
            if words.next() != Some("fn") || code.ends_with(';') {
                continue;
            }
            let Some(name) = words.next().map(|n| n.split(['(', '<']).next().unwrap_or(n).to_string()) else {
                continue;
            };
            let end = lines[i + 1..].iter().position(|l| {
                let c = l.trim_start();
                l.len() - c.len() == indent && c.starts_with('}')
            });
            if let Some(end) = end
                && end + 2 > MAX_LINES
            {
                out.push((format!("{}::{name}", path.display()), end + 2));
            }
        }
    }
    out
}

#[test]
fn functions_read_as_their_steps() {
    let long = long_functions();
    let new: Vec<String> =
        long.iter().filter(|(f, _)| !LONG.contains(&f.as_str())).map(|(f, n)| format!("{f} ({n} lines)")).collect();
    assert!(new.is_empty(), "functions over {MAX_LINES} lines (split them into their steps): {new:#?}");
    let paid: Vec<&str> = LONG.iter().copied().filter(|f| !long.iter().any(|(g, _)| g == f)).collect();
    assert!(paid.is_empty(), "no longer over {MAX_LINES} lines: remove them from LONG: {paid:?}");
}

#[test]
fn a_function_with_many_arguments_is_a_missing_struct() {
    let mut found: Vec<(String, usize)> = Vec::new();
    for path in rust_files() {
        // written in two parts, so that this file does not count itself
        let count = read(&path).matches(concat!("allow(clippy::", "too_many_arguments)")).count();
        if count > 0 {
            found.push((path.display().to_string(), count));
        }
    }
    let listed: Vec<(String, usize)> = MANY_ARGUMENTS.iter().map(|&(p, n)| (p.to_string(), n)).collect();
    assert_eq!(
        found, listed,
        "`too_many_arguments` allowances: give the function a struct (or, when one goes, shrink MANY_ARGUMENTS)"
    );
}

#[test]
fn subcommands_return_their_status() {
    let mut found: Vec<(String, usize)> = Vec::new();
    for path in rust_files().into_iter().filter(|p| p.starts_with("compiler/tadslc/src")) {
        // written in two parts, so that this file does not count itself
        let count = read(&path).matches(concat!("*status", " = ")).count();
        if count > 0 {
            found.push((path.display().to_string(), count));
        }
    }
    let mut listed: Vec<(String, usize)> = STATUS_BY_SIDE_EFFECT.iter().map(|&(p, n)| (p.to_string(), n)).collect();
    listed.sort();
    found.sort();
    assert_eq!(
        found, listed,
        "a status raised by side effect: return Result<Status, CliError> (when one goes, shrink the list)"
    );
}
