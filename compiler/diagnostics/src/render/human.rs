//! Terminal rendering through codespan-reporting, with or without colour.
//!
//! Text from the input (source lines, file names, messages quoting it) reaches the
//! terminal through [`shown`]: a control character or a bidirectional override would
//! otherwise act on the terminal instead of being read. Each is replaced by a character
//! of the same UTF-8 length, so spans still point where they did. A line longer than
//! [`window::LONG_LINE`](super::window::LONG_LINE) is shown as a window around each
//! diagnostic's labels on it, so a one-megabyte line is not echoed once per diagnostic.

use super::FileReport;
use super::window::{Shown, Sources, has_long_lines};
use crate::{Diagnostic, Severity};
use codespan_reporting::diagnostic::{
    Diagnostic as CsDiagnostic, Label as CsLabel, LabelStyle, Severity as CsSeverity,
};
use codespan_reporting::term::{self, Config, termcolor};

/// Render every diagnostic of one file. `color` chooses ANSI escapes.
pub fn render(report: &FileReport<'_>, color: bool) -> String {
    let own = shown(report.text);
    let related: Vec<(crate::FileId, std::borrow::Cow<'_, str>)> =
        report.related.iter().map(|s| (s.file, shown(s.text))).collect();
    let long = has_long_lines(&own) || related.iter().any(|(_, text)| has_long_lines(text));
    // without a long line, the files are shown whole, the same for every diagnostic
    let whole = (!long).then(|| sources(None, report, &own, &related));
    let config = Config::default();
    let mut buffer = if color { termcolor::Buffer::ansi() } else { termcolor::Buffer::no_color() };
    for diagnostic in report.diagnostics {
        let cut;
        let files = match &whole {
            Some(files) => files,
            None => {
                cut = sources(Some(diagnostic), report, &own, &related);
                &cut
            }
        };
        let converted = convert(diagnostic, report, files);
        if term::emit_to_write_style(&mut buffer, &config, files, &converted).is_err() {
            // A span outside the text would be a bug upstream; fall back to a plain line.
            let line = format!("{}[{}]: {}\n", diagnostic.severity.as_str(), diagnostic.code, diagnostic.message);
            buffer.as_mut_slice_fallback(line.as_bytes());
        }
    }
    String::from_utf8_lossy(buffer.as_slice()).into_owned()
}

/// The report's files as shown for `diagnostic` (its own file first, then the related
/// ones in order), long lines cut around its labels.
fn sources(
    diagnostic: Option<&Diagnostic>,
    report: &FileReport<'_>,
    own: &str,
    related: &[(crate::FileId, std::borrow::Cow<'_, str>)],
) -> Sources {
    let spans = |file: Option<crate::FileId>| -> Vec<std::ops::Range<usize>> {
        let Some(d) = diagnostic else { return Vec::new() };
        let here = |f: Option<crate::FileId>| if f == Some(report.file) { None } else { f };
        let mut spans = Vec::new();
        if file.is_none() {
            spans.push(d.primary.span.start..d.primary.span.end);
        }
        spans.extend(d.secondary.iter().filter(|l| here(l.file) == file).map(|l| l.span.start..l.span.end));
        spans
    };
    let mut sources = Sources::default();
    sources.add(Shown::new(shown(report.name).into_owned(), own, &spans(None)));
    for ((id, text), source) in related.iter().zip(&report.related) {
        sources.add(Shown::new(shown(source.name).into_owned(), text, &spans(Some(*id))));
    }
    sources
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

/// `span` of file `index` (0: the report's own) as shown in `sources`.
fn place(sources: &Sources, index: usize, span: crate::Span, len: usize) -> std::ops::Range<usize> {
    let end = span.end.min(len);
    let file = &sources.0[index];
    file.map(span.start.min(end))..file.map(end).min(file.len())
}

fn convert(d: &Diagnostic, report: &FileReport<'_>, sources: &Sources) -> CsDiagnostic<usize> {
    let severity = match d.severity {
        Severity::Error => CsSeverity::Error,
        Severity::Warning => CsSeverity::Warning,
        Severity::Hint => CsSeverity::Help,
    };
    let len = report.text.len();
    let primary = place(sources, 0, d.primary.span, len);
    let mut labels = vec![CsLabel::new(LabelStyle::Primary, 0, primary).with_message(shown(&d.primary.message))];
    let mut notes = Vec::new();
    for l in &d.secondary {
        let file = match l.file {
            None => Some((0, len)),
            Some(f) if f == report.file => Some((0, len)),
            Some(f) => report.related.iter().position(|s| s.file == f).map(|i| (i + 1, report.related[i].text.len())),
        };
        match file {
            Some((index, len)) => labels.push(
                CsLabel::new(LabelStyle::Secondary, index, place(sources, index, l.span, len))
                    .with_message(shown(&l.message)),
            ),
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
