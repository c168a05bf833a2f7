//! The planner's diagnostics: every one with a code, words for people and a typed payload
//! for programs (`tad_diagnostics::Payload`).
//!
//! What the backend cannot express, or expresses only approximately, or chooses because the
//! scenario does not say, is [`Payload::Unsupported`] with `backend: "scenic"`, the
//! construct (`KIND NAME` for a name of the vocabulary, `SECTION.FIELD` for a field) and
//! what the program does instead. A feature the chosen map lacks is
//! [`Payload::Incompatible`] (the map cannot have it; `allowed` lists the maps that can),
//! an unknown map [`Payload::Unknown`] with the known maps as candidates.

use tad_diagnostics::{Code, Diagnostic, Payload, Span};

/// The backend's name in payloads.
pub const BACKEND: &str = "scenic";

/// `KIND NAME`: a name of the vocabulary, as a payload's construct.
pub fn named(kind: &str, name: &str) -> String {
    format!("{kind} {name}")
}

/// The payload of something the backend leaves out (`instead: None`) or replaces.
pub fn unsupported(construct: impl Into<String>, instead: Option<String>) -> Payload {
    Payload::Unsupported { backend: BACKEND.to_string(), construct: construct.into(), instead }
}

/// Collects diagnostics in the order they are found; `emit` sorts them.
#[derive(Debug, Default)]
pub struct Report {
    pub diagnostics: Vec<Diagnostic>,
}

impl Report {
    /// Push a diagnostic; notes and help go on the returned reference.
    pub fn warn(
        &mut self,
        code: Code,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
        payload: Payload,
    ) -> &mut Diagnostic {
        self.diagnostics.push(Diagnostic::new(code, message, span, label).with_payload(payload));
        self.diagnostics.last_mut().expect("just pushed")
    }

    pub fn push(&mut self, diagnostic: Diagnostic) {
        self.diagnostics.push(diagnostic);
    }
}

/// Notes and help on a diagnostic already pushed.
pub trait Annotate {
    fn note(self, note: impl Into<String>) -> Self;
    fn help(self, help: impl Into<String>) -> Self;
}

impl Annotate for &mut Diagnostic {
    fn note(self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    fn help(self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
}
