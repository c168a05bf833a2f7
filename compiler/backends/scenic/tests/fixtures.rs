//! Backend fixtures: every `tests/scenic/fixtures/*.tad` is built for Scenic and its
//! diagnostics compared with the annotations in it, one comment per diagnostic in the format
//! of the UI tests: `// warning[W0700]: 17:13-17:22` (severity, code, 1-based start and end
//! line:column). The rendered human output is compared with `NAME.stderr` beside it. A line
//! `// simulator: newtonian` or `// map: TOWN` sets that option. The files must check without
//! errors.
//!
//! `TAD_BLESS=1 cargo test -p tad-scenic --test fixtures` rewrites the annotations and the
//! `.stderr` files; never when `CI` is set.

mod common;

use std::path::{Path, PathBuf};

use tad_diagnostics::LineIndex;
use tad_diagnostics::render::{FileReport, human};
use tad_scenic::{EmitOptions, Simulator};

fn bless() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

fn annotations(text: &str) -> Vec<String> {
    let mut out: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("// warning[") || l.starts_with("// error["))
        .map(str::to_string)
        .collect();
    out.sort();
    out
}

fn option(text: &str, key: &str) -> Option<String> {
    text.lines().find_map(|l| l.trim().strip_prefix(&format!("// {key}: ")).map(|v| v.trim().to_string()))
}

fn fixtures() -> Vec<PathBuf> {
    let dir = common::repo().join("tests/scenic/fixtures");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/scenic/fixtures")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "tad"))
        .collect();
    out.sort();
    out
}

fn run(path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).unwrap();
    let options = EmitOptions {
        simulator: if option(&text, "simulator").as_deref() == Some("newtonian") {
            Simulator::Newtonian
        } else {
            Simulator::Carla
        },
        map: option(&text, "map"),
        ..EmitOptions::default()
    };
    let emitted = common::build_text(path, &text, &options);
    let index = LineIndex::new(&text);
    let mut actual: Vec<String> = emitted
        .diagnostics
        .iter()
        .map(|d| {
            let (s, e) = index.span_range(&text, d.primary.span);
            format!("// {}[{}]: {}:{}-{}:{}", d.severity.as_str(), d.code, s.line, s.column, e.line, e.column)
        })
        .collect();
    actual.sort();
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let report = FileReport::new(&name, &text, &emitted.diagnostics);
    let rendered = human::render(&report, false);
    let stderr = path.with_extension("stderr");
    if bless() {
        let kept: Vec<&str> = text
            .lines()
            .filter(|l| !(l.trim().starts_with("// warning[") || l.trim().starts_with("// error[")))
            .collect();
        let mut rewritten = kept.join("\n");
        rewritten.push('\n');
        for a in &actual {
            rewritten.push_str(a);
            rewritten.push('\n');
        }
        std::fs::write(path, rewritten).unwrap();
        std::fs::write(&stderr, &rendered).unwrap();
        return Ok(());
    }
    let wanted = annotations(&text);
    let mut problems = Vec::new();
    for d in emitted.diagnostics.iter().filter(|d| d.payload.is_none()) {
        problems.push(format!("{name}: {} `{}` has no payload", d.code, d.message));
    }
    if wanted != actual {
        problems.push(format!(
            "{name}: expected\n  {}\nbut the backend reports\n  {}",
            wanted.join("\n  "),
            actual.join("\n  ")
        ));
    }
    match std::fs::read_to_string(&stderr) {
        Ok(expected) if expected == rendered => {}
        Ok(expected) => {
            problems.push(format!("{} differs\n--- expected\n{expected}\n--- actual\n{rendered}", stderr.display()))
        }
        Err(_) => problems.push(format!("{} is missing (TAD_BLESS=1 to create it)", stderr.display())),
    }
    if problems.is_empty() { Ok(()) } else { Err(problems.join("\n")) }
}

#[test]
fn fixtures_report_what_they_expect() {
    let failures: Vec<String> = fixtures().iter().filter_map(|p| run(p).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn every_scenic_code_has_a_fixture() {
    let all: String = fixtures().iter().map(|p| std::fs::read_to_string(p).unwrap()).collect();
    // W071x are the OpenSCENARIO backend's
    for code in tad_diagnostics::Code::ALL.iter().filter(|c| c.as_str()[1..].starts_with("070")) {
        assert!(all.contains(&format!("[{code}]:")), "no fixture in tests/scenic/fixtures expects {code}");
    }
}
