//! Raw LLM answers: every `tests/yaml/answers/*.yaml` is imported and must give exactly
//! the diagnostics its annotations state, at the stated places, never panic, and import
//! to a model whose TAD (`NAME.tad`) checks without errors.
//!
//! Annotations are lines `# error[E0303]: 7:16-7:20` (severity, code, 1-based
//! `line:column-line:column` of the primary span, columns in characters), outside the
//! YAML block or as YAML comments. `NAME.stderr` is the rendered human output and
//! `NAME.tad` the imported scenario; `TAD_BLESS=1 cargo test -p tad-yaml --test answers`
//! rewrites both (never when `CI` is set).

mod common;
use common::*;
use std::path::Path;
use tad_diagnostics::LineIndex;
use tad_diagnostics::render::{FileReport, human};

fn expected(text: &str) -> Vec<String> {
    let mut out: Vec<String> = text
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("# "))
        .filter(|l| l.starts_with("error[") || l.starts_with("warning["))
        .map(|l| l.trim().to_string())
        .collect();
    out.sort();
    out
}

fn blessing() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

fn compare(path: &Path, actual: &str, problems: &mut Vec<String>) {
    let expected = std::fs::read_to_string(path).unwrap_or_default();
    if expected == actual {
        return;
    }
    if blessing() {
        std::fs::write(path, actual).unwrap();
        return;
    }
    problems.push(format!(
        "{} differs (TAD_BLESS=1 to accept)\n--- expected\n{expected}\n--- actual\n{actual}",
        path.display()
    ));
}

#[test]
fn answers() {
    let dir = repo().join("tests/yaml/answers");
    let fixtures = files(&dir, "yaml");
    assert!(fixtures.len() >= 10);
    let mut problems = Vec::new();
    for path in &fixtures {
        let text = read(path);
        let name = format!("tests/yaml/answers/{}", path.file_name().unwrap().to_string_lossy());
        let (model, diagnostics) = tad_yaml::lower(&text);
        assert_spans_valid(&text, &diagnostics);
        let index = LineIndex::new(&text);
        let mut actual: Vec<String> = diagnostics
            .iter()
            .map(|d| {
                let (s, e) = index.span_range(&text, d.primary.span);
                format!("{}[{}]: {}:{}-{}:{}", d.severity.as_str(), d.code, s.line, s.column, e.line, e.column)
            })
            .collect();
        actual.sort();
        let wanted = expected(&text);
        if actual != wanted {
            problems.push(format!(
                "{name}: diagnostics differ\n--- expected\n{}\n--- actual\n{}",
                wanted.join("\n"),
                actual.join("\n")
            ));
        }
        let rendered = human::render(&FileReport::new(&name, &text, &diagnostics), false);
        compare(&path.with_extension("stderr"), &rendered, &mut problems);
        let tad = if model.scenario.is_some() { tad_yaml::to_tad(&model) } else { "(no scenario)\n".to_string() };
        if model.scenario.is_some() {
            let (_, again) = tad_syntax::analyze(&tad);
            assert!(errors(&again).is_empty(), "{name}: imported TAD does not check: {again:?}\n{tad}");
        }
        compare(&path.with_extension("tad"), &tad, &mut problems);
    }
    // every YAML import code is expected by at least one fixture
    let all: Vec<String> = fixtures.iter().flat_map(|p| expected(&read(p))).collect();
    for code in tad_diagnostics::Code::ALL.iter().filter(|c| c.as_str()[1..].starts_with("03")) {
        if !all.iter().any(|a| a.contains(&format!("[{code}]"))) {
            problems.push(format!("no answer fixture expects {code}"));
        }
    }
    // every expected file has its fixture
    for ext in ["stderr", "tad"] {
        for p in files(&dir, ext) {
            if !p.with_extension("yaml").exists() {
                problems.push(format!("orphaned {}", p.display()));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n\n"));
}
