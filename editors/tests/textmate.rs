//! The VS Code extension's TextMate grammar (`editors/vscode/syntaxes/tad.tmLanguage.json`),
//! checked with vscode-tmgrammar-test from the extension's own `node_modules` (`npm ci` in
//! `editors/vscode`): the assertion files in `test/grammar/` pass; every example and
//! standard module tokenises without an `invalid` scope; and every keyword and unit the
//! compiler's lexer knows (`KEYWORDS`, `UNITS`) gets its own scope, so the grammar cannot
//! drift from the language.

use std::path::{Path, PathBuf};
use std::process::Command;

fn extension() -> PathBuf {
    tad_editors::dir().join("vscode")
}

/// The extension's installed test tool, or `None` (skipped loudly; a failure when
/// `TAD_REQUIRE_EDITORS=1`).
fn tool(name: &str) -> Option<PathBuf> {
    let path = extension().join("node_modules/.bin").join(name);
    if path.is_file() {
        return Some(path);
    }
    assert!(!tad_editors::required(), "{} is missing: run `npm ci` in editors/vscode", path.display());
    eprintln!("SKIPPED: {} is missing (npm ci in editors/vscode)", path.display());
    None
}

/// One source line of a snapshot and the scopes of its pieces: `(start, end, scopes)`.
struct Line {
    text: String,
    pieces: Vec<(usize, usize, String)>,
}

/// Tokenise `files` (copied into a scratch directory) with vscode-tmgrammar-snap.
fn snapshots(files: &[(String, String)]) -> Vec<(String, Vec<Line>)> {
    let Some(snap) = tool("vscode-tmgrammar-snap") else { return Vec::new() };
    let dir = std::env::temp_dir().join(format!("tad-textmate-{}-{}", std::process::id(), files.len()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let output = Command::new(snap)
        .current_dir(extension())
        .args(["-u", "-g", "syntaxes/tad.tmLanguage.json", "--config", "package.json"])
        .arg(format!("{}/*.tad", dir.display()))
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let out = files
        .iter()
        .map(|(name, _)| {
            let snap = std::fs::read_to_string(dir.join(format!("{name}.snap"))).unwrap();
            let mut lines: Vec<Line> = Vec::new();
            for line in snap.lines() {
                if let Some(source) = line.strip_prefix('>') {
                    lines.push(Line { text: source.to_string(), pieces: Vec::new() });
                } else if let Some(marks) = line.strip_prefix('#')
                    && let Some(last) = lines.last_mut()
                {
                    let start = marks.find('^').unwrap_or(0);
                    let end = start + marks[start..].chars().take_while(|c| *c == '^').count();
                    last.pieces.push((start, end, marks[end..].trim().to_string()));
                }
            }
            (name.clone(), lines)
        })
        .collect();
    let _ = std::fs::remove_dir_all(&dir);
    out
}

#[test]
fn the_assertion_files_pass() {
    let Some(test) = tool("vscode-tmgrammar-test") else { return };
    let output = Command::new(test)
        .current_dir(extension())
        .args(["-g", "syntaxes/tad.tmLanguage.json", "test/grammar/*.tad"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}{}", String::from_utf8_lossy(&output.stderr));
    let files = std::fs::read_dir(extension().join("test/grammar")).unwrap().count();
    assert!(files >= 2 && stdout.matches("successfuly").count() == files, "{stdout}");
}

#[test]
fn every_example_tokenises_without_invalid_scopes() {
    let files: Vec<(String, String)> = tad_editors::tad_files()
        .iter()
        .enumerate()
        .map(|(i, path)| (format!("{i:02}_{}", file_name(path)), std::fs::read_to_string(path).unwrap()))
        .collect();
    let mut bad = Vec::new();
    for (name, lines) in snapshots(&files) {
        for (n, line) in lines.iter().enumerate() {
            for (start, end, scopes) in &line.pieces {
                if scopes.contains("invalid") {
                    bad.push(format!("{name}:{}: `{}` is {scopes}", n + 1, line.text.get(*start..*end).unwrap_or("")));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

fn file_name(path: &Path) -> String {
    path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

#[test]
fn keywords_and_units_of_the_lexer_have_their_scopes() {
    use tad_syntax::lexer::{KEYWORDS, UNITS};
    let mut text = String::from(
        "use national_park\nscenario demo {\n  actor g: 2 car {\n    position: front of ego\n    time: unspecified\n",
    );
    for unit in UNITS {
        text.push_str(&format!("    x: 3 {unit}\n"));
    }
    text.push_str("  }\n}\n");
    let snaps = snapshots(&[("keywords.tad".to_string(), text)]);
    let Some((_, lines)) = snaps.first() else { return };
    let scope_of = |word: &str| -> Option<String> {
        lines.iter().find_map(|line| {
            line.pieces
                .iter()
                .find(|(s, e, _)| line.text.get(*s..*e) == Some(word))
                .map(|(_, _, scopes)| scopes.clone())
        })
    };
    for (keyword, _) in KEYWORDS {
        let scopes = scope_of(keyword).unwrap_or_else(|| panic!("`{keyword}` is not one token"));
        assert!(
            scopes.contains("keyword") || scopes.contains("constant.language"),
            "`{keyword}` is {scopes}: the grammar does not know the keyword"
        );
    }
    for unit in UNITS {
        let scopes = scope_of(unit).unwrap_or_else(|| panic!("`{unit}` is not one token"));
        assert!(scopes.contains("keyword.other.unit"), "`{unit}` is {scopes}: the grammar does not know the unit");
    }
}
