//! Backend fixtures (`tests/scenic/fixtures`, `tests/openscenario/fixtures`): a `.tad` file
//! whose diagnostics are written in it, one comment each in the UI tests' format
//! (`// warning[W0700]: 17:13-17:22`: severity, code, 1-based start and end line:column),
//! and its rendered human output in `NAME.stderr` beside it. Every diagnostic carries a typed
//! payload. `TAD_BLESS=1` rewrites the annotations and the `.stderr` files; never when `CI`
//! is set.

use std::path::Path;

use tad_diagnostics::render::{FileReport, human};
use tad_diagnostics::{Diagnostic, LineIndex};

fn bless() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

fn is_annotation(line: &str) -> bool {
    let line = line.trim();
    line.starts_with("// warning[") || line.starts_with("// error[")
}

/// The fixture at `path` (its `text`) against what a backend reported for it: `Err` says
/// every difference. Blessing rewrites the fixture and its `.stderr` instead.
pub fn judge(path: &Path, text: &str, diagnostics: &[Diagnostic]) -> Result<(), String> {
    let index = LineIndex::new(text);
    let mut actual: Vec<String> = diagnostics
        .iter()
        .map(|d| {
            let (s, e) = index.span_range(text, d.primary.span);
            format!("// {}[{}]: {}:{}-{}:{}", d.severity.as_str(), d.code, s.line, s.column, e.line, e.column)
        })
        .collect();
    actual.sort();
    let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
    let rendered = human::render(&FileReport::new(&name, text, diagnostics), false);
    let stderr = path.with_extension("stderr");
    if bless() {
        let mut rewritten: String = text.lines().filter(|l| !is_annotation(l)).map(|l| format!("{l}\n")).collect();
        rewritten.extend(actual.iter().map(|a| format!("{a}\n")));
        std::fs::write(path, rewritten).map_err(|e| e.to_string())?;
        std::fs::write(&stderr, &rendered).map_err(|e| e.to_string())?;
        return Ok(());
    }
    let mut wanted: Vec<String> = text.lines().filter(|l| is_annotation(l)).map(|l| l.trim().to_string()).collect();
    wanted.sort();
    let mut problems: Vec<String> = diagnostics
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

/// The first ```` ```tad ```` block of a text (a spec section's example), with a final newline.
pub fn tad_block(text: &str) -> Option<String> {
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim_end() == "```tad" {
            let block: Vec<&str> = lines.by_ref().take_while(|l| l.trim_end() != "```").collect();
            return Some(block.join("\n") + "\n");
        }
    }
    None
}
