//! Semantic tokens. TO BE WRITTEN (helper).

use crate::{Database, SourceFile, Span};

/// What a piece of text is, for highlighting. The language server's legend lists these
/// in the order of [`TokenKind::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TokenKind {
    Keyword,
    /// A section name or a declaration kind.
    Namespace,
    /// A field key.
    Property,
    /// An actor group's name or a reference to one (`ego` too).
    Variable,
    /// An actor type in a group's header.
    Type,
    /// A vocabulary name or a closed-set word in a value.
    EnumMember,
    /// A declaration's name.
    Declaration,
    Number,
    /// A unit (`km/h`).
    Unit,
    String,
    Comment,
    Operator,
}

impl TokenKind {
    pub const ALL: &'static [TokenKind] = &[
        TokenKind::Keyword,
        TokenKind::Namespace,
        TokenKind::Property,
        TokenKind::Variable,
        TokenKind::Type,
        TokenKind::EnumMember,
        TokenKind::Declaration,
        TokenKind::Number,
        TokenKind::Unit,
        TokenKind::String,
        TokenKind::Comment,
        TokenKind::Operator,
    ];
}

/// Modifiers, as bits; the legend lists them in the order of [`Modifier::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Modifier {
    /// Where a name is declared (a group's header, a declaration).
    Declaration,
    /// An alias of a vocabulary name (deprecated spelling).
    Deprecated,
    /// From the embedded standard library.
    DefaultLibrary,
}

impl Modifier {
    pub const ALL: &'static [Modifier] = &[Modifier::Declaration, Modifier::Deprecated, Modifier::DefaultLibrary];

    pub fn bit(self) -> u32 {
        1 << Modifier::ALL.iter().position(|m| *m == self).unwrap_or(0)
    }
}

/// One token: its span (on one line; a multi-line string or comment is split per line by
/// the producer), kind and modifier bits. Sorted by position, not overlapping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Token {
    pub span: Span,
    pub kind: TokenKind,
    pub modifiers: u32,
}

pub fn tokens(_db: &Database, _file: SourceFile) -> Vec<Token> {
    Vec::new()
}
