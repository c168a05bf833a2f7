//! Hover. TO BE WRITTEN (helper).

use crate::{Database, SourceFile, Span};

/// Markdown about the thing at an offset, and the span it covers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Hover {
    pub span: Span,
    pub markdown: String,
}

pub fn hover(_db: &Database, _file: SourceFile, _offset: usize) -> Option<Hover> {
    None
}
