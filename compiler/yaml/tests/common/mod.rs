//! Helpers shared by the YAML importer's integration tests.

#![allow(dead_code)]

use tad_diagnostics::{Diagnostic, LineIndex, Severity};

#[allow(unused_imports)]
pub use tad_test_support::{files, read, repo};

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
