//! Backend fixtures: every `tests/openscenario/fixtures/*.tad` is built and its diagnostics
//! compared with the annotations in it, one comment per diagnostic in the UI tests' format
//! (`// warning[W0710]: 17:9-17:16`); the rendered human output is compared with
//! `NAME.stderr` beside it. Every diagnostic carries a typed payload.
//!
//! `TAD_BLESS=1 cargo test -p tad-openscenario --test fixtures` rewrites the annotations and
//! the `.stderr` files; never when `CI` is set.

use std::path::Path;

use tad_diagnostics::LineIndex;
use tad_diagnostics::render::{FileReport, human};

fn bless() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

fn is_annotation(line: &str) -> bool {
    let line = line.trim();
    line.starts_with("// warning[") || line.starts_with("// error[")
}

fn run(path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(path.to_path_buf(), text.clone());
    let scenario = tad_db::resolve(&db, file).clone().ok_or("no scenario")?;
    let options = tad_openscenario::EmitOptions { stem: "fixture".into(), source: "fixture.tad".into() };
    let emitted = tad_openscenario::emit(&scenario, &options);
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
    let rendered = human::render(&FileReport::new(&name, &text, &emitted.diagnostics), false);
    let stderr = path.with_extension("stderr");
    if bless() {
        let mut rewritten: String = text.lines().filter(|l| !is_annotation(l)).map(|l| format!("{l}\n")).collect();
        rewritten.extend(actual.iter().map(|a| format!("{a}\n")));
        std::fs::write(path, rewritten).unwrap();
        std::fs::write(&stderr, &rendered).unwrap();
        return Ok(());
    }
    let mut wanted: Vec<String> = text.lines().filter(|l| is_annotation(l)).map(|l| l.trim().to_string()).collect();
    wanted.sort();
    let mut problems: Vec<String> = emitted
        .diagnostics
        .iter()
        .filter(|d| d.payload.is_none())
        .map(|d| format!("{name}: {} `{}` has no payload", d.code, d.message))
        .collect();
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
    let dir = tad_test_support::repo().join("tests/openscenario/fixtures");
    let fixtures = tad_test_support::files(&dir, "tad");
    assert!(fixtures.len() >= 2);
    let failures: Vec<String> = fixtures.iter().filter_map(|p| run(p).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
