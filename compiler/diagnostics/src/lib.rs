//! The diagnostic type every TADSL phase reports with, and its renderers.
//!
//! Analysis code (lexer, parser, checker) builds [`Diagnostic`] values and never touches
//! a terminal or a serialisation format: rendering is an adapter at the edge
//! ([`render`]). Every diagnostic carries a stable [`Code`]; codes are never renumbered or
//! reused, and each one is documented in `spec/diagnostics.md`, which is compiled into
//! this crate so `tadslc explain` and the documentation cannot drift apart.
//!
//! A diagnostic states a fact twice: in words for people (message, labels, help) and as a
//! typed [`Payload`] for programs (the LLM front-end, the language server, JSON and SARIF
//! consumers), so nothing downstream ever parses a message. Fixes carry an
//! [`Applicability`] in rustc's sense, so a tool applies only the certain ones.
//!
//! Every diagnostic belongs to one file ([`FileId`]); a label may point into another file
//! (a conflicting declaration in a used module). Pure phases analyse one text and leave the
//! file [`FileId::UNSET`]; the database stamps the file it analysed ([`Diagnostic::in_file`]).

mod code;
mod line_index;
mod payload;
pub mod render;

pub use code::Code;
pub use line_index::{LineCol, LineIndex};
pub use payload::{Element, Payload};

/// A source file of one run or session, numbered by the database that registered it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct FileId(pub u32);

impl FileId {
    /// The file being analysed, before the database says which one it is.
    pub const UNSET: FileId = FileId(u32::MAX);
}

impl Default for FileId {
    fn default() -> Self {
        FileId::UNSET
    }
}

/// A span in a known file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct FileSpan {
    pub file: FileId,
    pub span: Span,
}

use serde::Serialize;

/// A byte range `start..end` in one source text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct Span {
    pub start: usize,
    pub end: usize,
}

impl Span {
    pub const fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }

    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span::new(self.start.min(other.start), self.end.max(other.end))
    }

    pub fn len(self) -> usize {
        self.end - self.start
    }

    pub fn is_empty(self) -> bool {
        self.start == self.end
    }

    pub fn contains(self, other: Span) -> bool {
        self.start <= other.start && other.end <= self.end
    }
}

impl From<std::ops::Range<usize>> for Span {
    fn from(r: std::ops::Range<usize>) -> Self {
        Span::new(r.start, r.end)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
    /// Only a different way of writing the same thing (an alias): shown, with a
    /// machine-applicable fix, but not a warning.
    Hint,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Hint => "hint",
        }
    }
}

/// A span with a short message shown under it. `file` is `None` for the diagnostic's own
/// file.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Label {
    pub file: Option<FileId>,
    pub span: Span,
    pub message: String,
}

impl Label {
    pub fn new(span: Span, message: impl Into<String>) -> Self {
        Label { file: None, span, message: message.into() }
    }
}

/// How sure a fix is, as rustc says it; from the surest, in order ([`fixes_at_least`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Applicability {
    /// Certainly what was meant: a tool may apply it without asking (an alias, a unit).
    MachineApplicable,
    /// Probably what was meant, to be confirmed by a person (a "did you mean" guess).
    MaybeIncorrect,
    /// The replacement has parts a person must fill in.
    HasPlaceholders,
}

impl Applicability {
    pub fn as_str(self) -> &'static str {
        match self {
            Applicability::MachineApplicable => "machine-applicable",
            Applicability::MaybeIncorrect => "maybe-incorrect",
            Applicability::HasPlaceholders => "has-placeholders",
        }
    }
}

/// An edit to the diagnostic's file: replace the text at `span` with `replacement`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Fix {
    pub span: Span,
    pub replacement: String,
    pub applicability: Applicability,
}

/// One problem found in one source text.
///
/// The message is lowercase without a final period and states the problem; the primary
/// label points at the offending text; `help` gives a concrete fix in words and `fixes`
/// the same fix as edits a tool can apply.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: Code,
    /// The file the primary label and the fixes are in.
    pub file: FileId,
    pub message: String,
    /// The fact, typed.
    pub payload: Payload,
    pub primary: Label,
    pub secondary: Vec<Label>,
    pub notes: Vec<String>,
    pub help: Option<String>,
    pub fixes: Vec<Fix>,
}

impl Diagnostic {
    /// A diagnostic with the code's default severity.
    pub fn new(code: Code, message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        Diagnostic {
            severity: code.severity(),
            code,
            file: FileId::UNSET,
            message: message.into(),
            payload: Payload::None,
            primary: Label::new(span, label),
            secondary: Vec::new(),
            notes: Vec::new(),
            help: None,
            fixes: Vec::new(),
        }
    }

    pub fn with_secondary(mut self, span: Span, message: impl Into<String>) -> Self {
        self.secondary.push(Label::new(span, message));
        self
    }

    /// A secondary label in another file.
    pub fn with_secondary_in(mut self, at: FileSpan, message: impl Into<String>) -> Self {
        self.secondary.push(Label { file: Some(at.file), span: at.span, message: message.into() });
        self
    }

    pub fn with_payload(mut self, payload: Payload) -> Self {
        self.payload = payload;
        self
    }

    /// Place the diagnostic in `file`, if no file is set yet; labels in the same file
    /// stay relative to it.
    pub fn in_file(mut self, file: FileId) -> Self {
        if self.file == FileId::UNSET {
            self.file = file;
        }
        self
    }

    /// Every file a label of this diagnostic is in.
    pub fn files(&self) -> impl Iterator<Item = FileId> + '_ {
        std::iter::once(self.file).chain(self.secondary.iter().filter_map(|l| l.file))
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn with_fix(mut self, span: Span, replacement: impl Into<String>, applicability: Applicability) -> Self {
        self.fixes.push(Fix { span, replacement: replacement.into(), applicability });
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    pub fn span(&self) -> Span {
        self.primary.span
    }
}

/// Sort diagnostics by position, then code, so output and snapshots are stable.
pub fn sort(diagnostics: &mut [Diagnostic]) {
    diagnostics.sort_by(|a, b| {
        (a.file, a.primary.span.start, a.primary.span.end, a.code).cmp(&(
            b.file,
            b.primary.span.start,
            b.primary.span.end,
            b.code,
        ))
    });
}

/// The machine-applicable fixes of `diagnostics` that can be applied together to a text
/// of `len` bytes ([`fixes_at_least`]).
pub fn machine_fixes<'a>(diagnostics: impl IntoIterator<Item = &'a Diagnostic>, len: usize) -> Vec<&'a Fix> {
    fixes_at_least(diagnostics, len, Applicability::MachineApplicable)
}

/// The fixes of `diagnostics` at least as sure as `sure` that can be applied together to
/// a text of `len` bytes: in order, each once (several diagnostics may ask for the same
/// edit, such as one `use` line), none overlapping an earlier one or past the end.
pub fn fixes_at_least<'a>(
    diagnostics: impl IntoIterator<Item = &'a Diagnostic>,
    len: usize,
    sure: Applicability,
) -> Vec<&'a Fix> {
    let mut fixes: Vec<&Fix> = diagnostics
        .into_iter()
        .flat_map(|d| &d.fixes)
        .filter(|f| f.applicability <= sure && f.span.end <= len)
        .collect();
    fixes.sort_by_key(|f| (f.span.start, f.span.end));
    fixes.dedup_by(|a, b| a.span == b.span && a.replacement == b.replacement);
    let mut cursor = 0;
    fixes.retain(|f| {
        let keep = f.span.start >= cursor;
        if keep {
            cursor = f.span.end;
        }
        keep
    });
    fixes
}

/// Apply every machine-applicable fix of `diagnostics` to `text` ([`machine_fixes`]).
/// Returns the new text and how many fixes were applied.
pub fn apply_fixes<'a>(text: &str, diagnostics: impl IntoIterator<Item = &'a Diagnostic>) -> (String, usize) {
    let fixes = machine_fixes(diagnostics, text.len());
    (apply(text, &fixes), fixes.len())
}

/// `text` with `fixes`, in order and not overlapping ([`fixes_at_least`]), applied.
pub fn apply(text: &str, fixes: &[&Fix]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut cursor = 0;
    for fix in fixes {
        out.push_str(&text[cursor..fix.span.start]);
        out.push_str(&fix.replacement);
        cursor = fix.span.end;
    }
    out.push_str(&text[cursor..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixes_at_least_as_sure_apply_in_order_and_never_a_placeholder() {
        let text = "speed: 30 kmh; lane: too; type: bsu";
        let fix = |d: Diagnostic, at: (usize, usize), to: &str, sure| d.with_fix(Span::new(at.0, at.1), to, sure);
        let d = |start| Diagnostic::new(Code::E0402, "x", Span::new(start, start + 1), "x");
        let diagnostics = [
            fix(d(32), (32, 35), "bus", Applicability::MaybeIncorrect),
            fix(d(10), (10, 13), "km/h", Applicability::MachineApplicable),
            fix(d(21), (21, 24), "LANE", Applicability::HasPlaceholders),
        ];
        let machine = machine_fixes(&diagnostics, text.len());
        assert_eq!(apply(text, &machine), "speed: 30 km/h; lane: too; type: bsu");
        let guesses = fixes_at_least(&diagnostics, text.len(), Applicability::MaybeIncorrect);
        assert_eq!(apply(text, &guesses), "speed: 30 km/h; lane: too; type: bus");
    }
}
