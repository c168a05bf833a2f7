#![allow(dead_code)]

use std::path::{Path, PathBuf};
use tad_diagnostics::{Diagnostic, LineIndex, Severity};

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every file under `dir` with extension `ext`, sorted.
pub fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for entry in entries.flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == ext) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

pub fn errors(diagnostics: &[Diagnostic]) -> Vec<&Diagnostic> {
    diagnostics.iter().filter(|d| d.severity == Severity::Error).collect()
}

/// `CODE@LINE` for each diagnostic (1-based line of the primary span).
pub fn located(text: &str, diagnostics: &[Diagnostic]) -> Vec<String> {
    let index = LineIndex::new(text);
    diagnostics.iter().map(|d| format!("{}@{}", d.code, index.line_col(text, d.primary.span.start).line)).collect()
}

/// Every span of every diagnostic lies in `text` on character boundaries.
pub fn assert_spans_valid(text: &str, diagnostics: &[Diagnostic]) {
    for d in diagnostics {
        let spans = std::iter::once(d.primary.span)
            .chain(d.secondary.iter().map(|l| l.span))
            .chain(d.fixes.iter().map(|f| f.span));
        for s in spans {
            assert!(s.start <= s.end && s.end <= text.len(), "{d:?} out of bounds ({})", text.len());
            assert!(text.is_char_boundary(s.start) && text.is_char_boundary(s.end), "{d:?} not on a boundary");
        }
    }
}
