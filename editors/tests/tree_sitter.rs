//! The tree-sitter grammar (`editors/tree-sitter-tad`) checked with its own CLI, as a
//! grammar repository's CI checks it: the committed generated parser is what `grammar.js`
//! generates, the corpus and highlight tests pass, and every example and standard module
//! parses without an error node. The last one catches drift from the compiler's grammar,
//! which stays the source of truth.
//!
//! The CLI runs with a private home (it reads a config and caches compiled parsers there)
//! and its built-in JavaScript runtime, so Node is not needed; it compiles the parser with
//! the system C compiler (`cc`, or `$CC`).

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The parser ABI the committed `src/parser.c` is generated for. 14 is the newest that
/// runtimes before tree-sitter 0.25 load (Debian's Neovim 0.7 links libtree-sitter 0.20).
const ABI: &str = "14";

fn grammar() -> PathBuf {
    tad_editors::dir().join("tree-sitter-tad")
}

/// A scratch directory, removed when dropped, that is also the CLI's home.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("tad-tree-sitter-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
        Scratch(dir)
    }

    /// The CLI, run in the grammar's directory with this directory as its home.
    fn cli(&self, exe: &Path) -> Command {
        let mut cmd = Command::new(exe);
        cmd.current_dir(grammar())
            .env("HOME", self.0.join("home"))
            .env("XDG_CONFIG_HOME", self.0.join("config"))
            .env("XDG_CACHE_HOME", self.0.join("cache"))
            .env("TREE_SITTER_JS_RUNTIME", "native");
        cmd
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

fn run(cmd: &mut Command) -> Output {
    cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"))
}

fn describe(output: &Output) -> String {
    format!(
        "{}\n--- stdout\n{}\n--- stderr\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// Files under `dir`, as paths relative to it, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display())).flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(root, &path, out);
            } else if let Ok(rel) = path.strip_prefix(root) {
                out.push(rel.to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

#[test]
fn committed_parser_is_generated_from_grammar_js() {
    let Some(cli) = tad_editors::tool("tree-sitter") else { return };
    let scratch = Scratch::new("generate");
    let fresh = scratch.0.join("src");
    let output = run(scratch
        .cli(&cli)
        .args(["generate", "--abi", ABI, "--js-runtime", "native", "--output"])
        .arg(&fresh)
        .arg(grammar().join("grammar.js")));
    assert!(output.status.success(), "tree-sitter generate failed: {}", describe(&output));

    let generated = files_under(&fresh);
    assert!(generated.iter().any(|f| f.ends_with("parser.c")), "no parser.c generated: {generated:?}");
    let stale: Vec<String> = generated
        .iter()
        .filter_map(|rel| {
            let committed = grammar().join("src").join(rel);
            match (fs::read(&committed), fs::read(fresh.join(rel))) {
                (Ok(old), Ok(new)) if old == new => None,
                (Ok(_), _) => Some(format!("src/{} differs", rel.display())),
                (Err(_), _) => Some(format!("src/{} is not committed", rel.display())),
            }
        })
        .collect();
    assert!(
        stale.is_empty(),
        "the committed parser is out of date with grammar.js: {}.\nIn editors/tree-sitter-tad run \
         `tree-sitter generate --abi {ABI} --js-runtime native` and commit src/.",
        stale.join(", ")
    );
}

#[test]
fn corpus_and_highlight_tests_pass() {
    let Some(cli) = tad_editors::tool("tree-sitter") else { return };
    let scratch = Scratch::new("test");
    let output = run(scratch.cli(&cli).arg("test"));
    let report = describe(&output);
    assert!(output.status.success(), "tree-sitter test failed: {report}");
    // Every test file was run (a misplaced directory would pass silently otherwise).
    let stdout = String::from_utf8_lossy(&output.stdout);
    for dir in ["test/corpus", "test/highlight"] {
        let files = files_under(&grammar().join(dir));
        assert!(!files.is_empty(), "no tests in {dir}");
        for file in files {
            let name = if dir.ends_with("corpus") { file.with_extension("") } else { file.clone() };
            let name = name.to_string_lossy();
            assert!(stdout.contains(&*name), "{dir}/{} was not run by `tree-sitter test`: {report}", file.display());
        }
    }
}

/// `(ERROR [r, c] - …)` and `(MISSING x [r, c] - …)` nodes of a `tree-sitter parse` tree,
/// as `KIND at LINE:COLUMN` (1-based; the column counts bytes).
fn error_nodes(tree: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in tree.lines() {
        let line = line.trim_start();
        let kind = if line.starts_with("(ERROR ") {
            "ERROR"
        } else if line.starts_with("(MISSING ") {
            "MISSING"
        } else {
            continue;
        };
        // `(MISSING "}" [1, 4] - [1, 4])`: the label, then the start
        let start = line.split(" - ").next().unwrap_or(line);
        let parsed = start.rsplit_once(" [").and_then(|(label, p)| {
            let (r, c) = p.trim_end_matches(']').split_once(", ")?;
            Some((label.trim_start_matches('('), r.parse::<usize>().ok()? + 1, c.parse::<usize>().ok()? + 1))
        });
        found.push(match parsed {
            Some((label, line, column)) => format!("{label} at {line}:{column}"),
            None => format!("{kind} in `{line}`"),
        });
    }
    found
}

#[test]
fn error_nodes_are_found_with_their_positions() {
    let tree = "(source_file [0, 0] - [2, 0]\n  (ERROR [0, 19] - [0, 28]\n    (identifier [0, 19] - [0, 24]))\n  (MISSING \"}\" [1, 4] - [1, 4]))";
    assert_eq!(error_nodes(tree), ["ERROR at 1:20", "MISSING \"}\" at 2:5"]);
    assert!(error_nodes("(source_file [0, 0] - [1, 0]\n  (comment [0, 0] - [0, 5]))").is_empty());
}

#[test]
fn every_example_and_standard_module_parses_without_errors() {
    let Some(cli) = tad_editors::tool("tree-sitter") else { return };
    let scratch = Scratch::new("parse");
    let files = tad_editors::tad_files();
    assert!(!files.is_empty(), "no .tad files under examples/ and stdlib/");
    let mut problems = Vec::new();
    for file in &files {
        let shown = file.strip_prefix(tad_editors::repo()).unwrap_or(file).display().to_string();
        let output = run(scratch.cli(&cli).arg("parse").arg(file));
        let errors = error_nodes(&String::from_utf8_lossy(&output.stdout));
        if !errors.is_empty() {
            problems.extend(errors.into_iter().map(|e| format!("{shown}: {e}")));
        } else if !output.status.success() {
            problems.push(format!("{shown}: tree-sitter parse failed: {}", describe(&output)));
        }
    }
    assert!(
        problems.is_empty(),
        "the tree-sitter grammar rejects files the compiler accepts (it has drifted from \
         compiler/syntax/src/grammar.lalrpop):\n{}",
        problems.join("\n")
    );
}
