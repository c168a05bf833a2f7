//! Completion. TO BE WRITTEN (helper).

use crate::{Database, SourceFile, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CompletionKind {
    /// A section (`road`, `ego`) or the `actor`/`scenario` keyword.
    Section,
    /// A field key (`weather:`).
    Field,
    /// A vocabulary name or a word of a closed set.
    Value,
    /// An actor group (a reference).
    Group,
    Unit,
    Module,
    Keyword,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Completion {
    pub label: String,
    pub kind: CompletionKind,
    /// A short line beside the label (the declaration kind and module, the field's type).
    pub detail: Option<String>,
    /// Markdown.
    pub documentation: Option<String>,
    /// The text inserted in place of `replace` (the label when `None`).
    pub insert: Option<String>,
    /// The text the completion replaces: the word typed so far (empty at the cursor).
    pub replace: Span,
    /// Sorts before others (the best guesses of a context).
    pub preselect: bool,
}

pub fn completions(_db: &Database, _file: SourceFile, _offset: usize) -> Vec<Completion> {
    Vec::new()
}
