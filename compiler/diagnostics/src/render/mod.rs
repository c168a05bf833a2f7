//! Renderers: adapters from [`Diagnostic`](crate::Diagnostic) to a terminal, JSON and SARIF.
//!
//! Each renderer takes the file's name and text alongside the diagnostics, and the other
//! files a label may point into; nothing here reads files or decides exit codes.

pub mod human;
pub mod json;
pub mod sarif;
mod window;

use crate::{FileId, Label};

/// A file's name and text.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    pub file: FileId,
    pub name: &'a str,
    pub text: &'a str,
}

/// A file's name, text and diagnostics, as the renderers need them, and the other files
/// their labels point into.
pub struct FileReport<'a> {
    pub file: FileId,
    pub name: &'a str,
    pub text: &'a str,
    pub diagnostics: &'a [crate::Diagnostic],
    pub related: Vec<Source<'a>>,
}

impl<'a> FileReport<'a> {
    /// A report on one file whose labels point into no other.
    pub fn new(name: &'a str, text: &'a str, diagnostics: &'a [crate::Diagnostic]) -> Self {
        let file = diagnostics.first().map_or(FileId::UNSET, |d| d.file);
        FileReport { file, name, text, diagnostics, related: Vec::new() }
    }

    pub fn with_related(mut self, related: Vec<Source<'a>>) -> Self {
        self.related = related;
        self
    }

    /// The file a label is in: the report's own, or a related one (`None` when unknown).
    pub fn source_of(&self, label: &Label) -> Option<Source<'a>> {
        match label.file {
            None => Some(self.own()),
            Some(file) if file == self.file => Some(self.own()),
            Some(file) => self.related.iter().find(|s| s.file == file).copied(),
        }
    }

    pub fn own(&self) -> Source<'a> {
        Source { file: self.file, name: self.name, text: self.text }
    }
}
