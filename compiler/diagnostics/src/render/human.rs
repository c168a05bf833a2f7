//! Terminal rendering through codespan-reporting, with or without colour.

use super::FileReport;
use crate::{Diagnostic, Severity};
use codespan_reporting::diagnostic::{
    Diagnostic as CsDiagnostic, Label as CsLabel, LabelStyle, Severity as CsSeverity,
};
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term::{self, Config, termcolor};

/// Render every diagnostic of one file. `color` chooses ANSI escapes.
pub fn render(report: &FileReport<'_>, color: bool) -> String {
    let file = SimpleFile::new(report.name, report.text);
    let config = Config::default();
    let mut buffer = if color { termcolor::Buffer::ansi() } else { termcolor::Buffer::no_color() };
    for diagnostic in report.diagnostics {
        let converted = convert(diagnostic, report.text.len());
        if term::emit_to_write_style(&mut buffer, &config, &file, &converted).is_err() {
            // A span outside the text would be a bug upstream; fall back to a plain line.
            let line = format!("{}[{}]: {}\n", diagnostic.severity.as_str(), diagnostic.code, diagnostic.message);
            buffer.as_mut_slice_fallback(line.as_bytes());
        }
    }
    String::from_utf8_lossy(buffer.as_slice()).into_owned()
}

trait BufferExt {
    fn as_mut_slice_fallback(&mut self, bytes: &[u8]);
}

impl BufferExt for termcolor::Buffer {
    fn as_mut_slice_fallback(&mut self, bytes: &[u8]) {
        use std::io::Write;
        let _ = self.write_all(bytes);
    }
}

fn clamp(span: crate::Span, len: usize) -> std::ops::Range<usize> {
    let end = span.end.min(len);
    span.start.min(end)..end
}

fn convert(d: &Diagnostic, len: usize) -> CsDiagnostic<()> {
    let severity = match d.severity {
        Severity::Error => CsSeverity::Error,
        Severity::Warning => CsSeverity::Warning,
    };
    let mut labels =
        vec![CsLabel::new(LabelStyle::Primary, (), clamp(d.primary.span, len)).with_message(&d.primary.message)];
    labels.extend(
        d.secondary
            .iter()
            .map(|l| CsLabel::new(LabelStyle::Secondary, (), clamp(l.span, len)).with_message(&l.message)),
    );
    let mut notes = d.notes.clone();
    if let Some(help) = &d.help {
        notes.push(format!("help: {help}"));
    }
    CsDiagnostic::new(severity)
        .with_code(d.code.as_str())
        .with_message(&d.message)
        .with_labels(labels)
        .with_notes(notes)
}
