//! Document symbols and folding ranges. TO BE WRITTEN (helper).

use crate::{Database, SourceFile, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SymbolKind {
    Scenario,
    Section,
    Group,
    Field,
    Declaration,
    Module,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Symbol {
    pub name: String,
    pub detail: Option<String>,
    pub kind: SymbolKind,
    /// The whole construct.
    pub span: Span,
    /// Its name.
    pub selection: Span,
    pub children: Vec<Symbol>,
}

pub fn symbols(_db: &Database, _file: SourceFile) -> Vec<Symbol> {
    Vec::new()
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FoldKind {
    Block,
    Comment,
    Text,
}

/// A foldable region, from the line of `span.start` to the line of `span.end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Fold {
    pub span: Span,
    pub kind: FoldKind,
}

pub fn folding(_db: &Database, _file: SourceFile) -> Vec<Fold> {
    Vec::new()
}
