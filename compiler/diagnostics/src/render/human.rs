//! Terminal rendering through codespan-reporting, with or without colour.
//!
//! Text from the input (source lines, file names, messages quoting it) reaches the
//! terminal through [`shown`]: a control character or a bidirectional override would
//! otherwise act on the terminal instead of being read. Each is replaced by a character
//! of the same UTF-8 length, so spans still point where they did.

use super::FileReport;
use crate::{Diagnostic, Severity};
use codespan_reporting::diagnostic::{
    Diagnostic as CsDiagnostic, Label as CsLabel, LabelStyle, Severity as CsSeverity,
};
use codespan_reporting::files::SimpleFiles;
use codespan_reporting::term::{self, Config, termcolor};

/// Render every diagnostic of one file. `color` chooses ANSI escapes.
pub fn render(report: &FileReport<'_>, color: bool) -> String {
    let mut files = SimpleFiles::new();
    let own = files.add(shown(report.name), shown(report.text));
    let related: Vec<(crate::FileId, usize, usize)> =
        report.related.iter().map(|s| (s.file, files.add(shown(s.name), shown(s.text)), s.text.len())).collect();
    let config = Config::default();
    let mut buffer = if color { termcolor::Buffer::ansi() } else { termcolor::Buffer::no_color() };
    for diagnostic in report.diagnostics {
        let converted = convert(diagnostic, report, own, &related);
        if term::emit_to_write_style(&mut buffer, &config, &files, &converted).is_err() {
            // A span outside the text would be a bug upstream; fall back to a plain line.
            let line = format!("{}[{}]: {}\n", diagnostic.severity.as_str(), diagnostic.code, diagnostic.message);
            buffer.as_mut_slice_fallback(line.as_bytes());
        }
    }
    String::from_utf8_lossy(buffer.as_slice()).into_owned()
}

/// `text` with every control character (but tab and line breaks) and bidirectional
/// control replaced by one of the same UTF-8 length: `?` for one byte, `¿` for two,
/// U+FFFD for three.
pub fn shown(text: &str) -> std::borrow::Cow<'_, str> {
    let hidden = |c: char| {
        (c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
            || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
    };
    if !text.chars().any(hidden) {
        return std::borrow::Cow::Borrowed(text);
    }
    let shown = text
        .chars()
        .map(|c| match (hidden(c), c.len_utf8()) {
            (false, _) => c,
            (true, 1) => '?',
            (true, 2) => '¿',
            (true, _) => '\u{fffd}',
        })
        .collect();
    std::borrow::Cow::Owned(shown)
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

fn convert(
    d: &Diagnostic,
    report: &FileReport<'_>,
    own: usize,
    related: &[(crate::FileId, usize, usize)],
) -> CsDiagnostic<usize> {
    let severity = match d.severity {
        Severity::Error => CsSeverity::Error,
        Severity::Warning => CsSeverity::Warning,
        Severity::Hint => CsSeverity::Help,
    };
    let len = report.text.len();
    let mut labels = vec![
        CsLabel::new(LabelStyle::Primary, own, clamp(d.primary.span, len)).with_message(shown(&d.primary.message)),
    ];
    let mut notes = Vec::new();
    for l in &d.secondary {
        let place = match l.file {
            None => Some((own, len)),
            Some(f) if f == report.file => Some((own, len)),
            Some(f) => related.iter().find(|(id, ..)| *id == f).map(|(_, index, len)| (*index, *len)),
        };
        match place {
            Some((file, len)) => labels
                .push(CsLabel::new(LabelStyle::Secondary, file, clamp(l.span, len)).with_message(shown(&l.message))),
            None => notes.push(shown(&l.message).into_owned()),
        }
    }
    notes.extend(d.notes.iter().map(|n| shown(n).into_owned()));
    if let Some(help) = &d.help {
        notes.push(format!("help: {}", shown(help)));
    }
    CsDiagnostic::new(severity)
        .with_code(d.code.as_str())
        .with_message(shown(&d.message))
        .with_labels(labels)
        .with_notes(notes)
}
