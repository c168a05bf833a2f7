//! Inlay hints. TO BE WRITTEN (helper).

use crate::{Database, SourceFile, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum InlayKind {
    /// A value in other units (`20 mph` → `8.9 m/s`).
    Value,
    /// What a lane number means (`lane: -1` → `oncoming, nearest the centre`).
    Lane,
}

/// A hint shown at `offset` (after the text it explains).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InlayHint {
    pub offset: usize,
    pub label: String,
    pub kind: InlayKind,
    pub tooltip: Option<String>,
}

/// The hints inside `range`.
pub fn inlay_hints(_db: &Database, _file: SourceFile, _range: Span) -> Vec<InlayHint> {
    Vec::new()
}
