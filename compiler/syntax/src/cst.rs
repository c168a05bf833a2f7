//! The concrete syntax tree the grammar builds: every construct in source order, with
//! spans, and error nodes where the parser recovered.
//!
//! It is deliberately generic (sections and fields are names, not fixed variants): which
//! sections and fields exist is the schema's business ([`crate::schema`]), so a misspelt
//! section is a located "unknown section" with a suggestion, not a parse error. The
//! formatter works on this tree; the checker works on the model lowered from it.

use tad_diagnostics::Span;

/// An identifier as written.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Name {
    pub text: String,
    pub span: Span,
}

impl Name {
    pub(crate) fn new(src: &str, start: usize, end: usize) -> Self {
        Name { text: src[start..end].to_string(), span: Span::new(start, end) }
    }

    /// A name from a `Key` token (`name :`): the colon and spaces are not part of it.
    pub(crate) fn from_key(src: &str, start: usize, end: usize) -> Self {
        let text = src[start..end].trim_end_matches(':').trim_end();
        Name { text: text.to_string(), span: Span::new(start, start + text.len()) }
    }
}

#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct File {
    pub items: Vec<Item>,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Item {
    Use(Use),
    Scenario(Scenario),
    Declaration(Declaration),
    Error(Span),
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Use(u) => u.span,
            Item::Scenario(s) => s.span,
            Item::Declaration(d) => d.span,
            Item::Error(span) => *span,
        }
    }
}

/// `use a.b.c`
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Use {
    pub span: Span,
    pub path: Vec<Name>,
}

/// A vocabulary declaration: `KIND NAME` or `KIND NAME { FIELD* }`,
/// e.g. `weather clear { aliases: [sunny] }`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Declaration {
    pub span: Span,
    pub kind: Name,
    pub name: Name,
    pub body: Option<Body<Entry>>,
}

/// `scenario NAME { MEMBER* }`
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Scenario {
    pub span: Span,
    pub keyword: Span,
    pub name: Option<Name>,
    pub body: Body<Member>,
}

/// `{ ITEM* }`. A `close` span that is empty was supplied by the parser at the end of
/// the file for a brace that was never closed (already reported).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Body<T> {
    pub open: Span,
    pub items: Vec<T>,
    pub close: Span,
}

impl<T> Body<T> {
    pub fn span(&self) -> Span {
        self.open.to(self.close)
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Member {
    Section(Section),
    Actor(Box<Actor>),
    Error(Span),
}

impl Member {
    pub fn span(&self) -> Span {
        match self {
            Member::Section(s) => s.span,
            Member::Actor(a) => a.span,
            Member::Error(span) => *span,
        }
    }
}

/// `NAME { FIELD* }`, e.g. `environment { weather: clear }`
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Section {
    pub span: Span,
    pub name: Name,
    pub body: Body<Entry>,
}

/// `actor NAME: [COUNT] TYPE { FIELD* }`
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Actor {
    pub span: Span,
    pub keyword: Span,
    pub name: Name,
    pub count: Option<Value>,
    pub kind: Value,
    pub body: Body<Entry>,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Entry {
    Field(Field),
    Error(Span),
}

impl Entry {
    pub fn span(&self) -> Span {
        match self {
            Entry::Field(f) => f.span,
            Entry::Error(span) => *span,
        }
    }
}

/// `KEY: VALUE`
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Field {
    pub span: Span,
    pub key: Name,
    pub value: Value,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Value {
    /// `unspecified`: explicitly unknown.
    Unspecified(Span),
    /// `38` or `38 km/h`
    Number { span: Span, number: Span, unit: Option<Span> },
    /// `LOW..HIGH UNIT` (`30..40 km/h`, `3..5`); each end may carry a unit, checked
    /// when lowered.
    Range { span: Span, low: Bound, high: Bound },
    /// `NAME | NAME ...` (`clear | cloudy`): one of the names; at least two.
    Choice { span: Span, options: Vec<Vec<Name>> },
    /// `"..."`, escapes not yet decoded.
    String(Span),
    /// `"""..."""`
    TextBlock(Span),
    /// One or more names: `move_forward`, or `go forward` (reported when lowered).
    Words(Vec<Name>),
    /// `RELATION of REFERENCE`, e.g. `left_front of ego`
    Position { span: Span, relation: Vec<Name>, of: Span, reference: Vec<Name> },
    /// `[VALUE, ...]`
    List { span: Span, items: Vec<Value> },
    /// A lexical error in value position (already reported).
    Error(Span),
}

impl Value {
    pub fn span(&self) -> Span {
        match self {
            Value::Unspecified(span)
            | Value::String(span)
            | Value::TextBlock(span)
            | Value::Error(span)
            | Value::Number { span, .. }
            | Value::Range { span, .. }
            | Value::Choice { span, .. }
            | Value::Position { span, .. }
            | Value::List { span, .. } => *span,
            Value::Words(words) => words_span(words),
        }
    }

    /// A short description for messages: "a name", "a number", ...
    pub fn describe(&self) -> &'static str {
        match self {
            Value::Unspecified(_) => "`unspecified`",
            Value::Number { unit: Some(_), .. } => "a quantity",
            Value::Number { .. } => "a number",
            Value::Range { .. } => "a range",
            Value::Choice { .. } => "a choice of names",
            Value::String(_) => "a string",
            Value::TextBlock(_) => "a text block",
            Value::Words(w) if w.len() > 1 => "several words",
            Value::Words(_) => "a name",
            Value::Position { .. } => "a position",
            Value::List { .. } => "a list",
            Value::Error(_) => "invalid text",
        }
    }
}

/// One end of a range: `30` or `30 km/h`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Bound {
    pub number: Span,
    pub unit: Option<Span>,
}

impl Bound {
    pub fn span(&self) -> Span {
        self.unit.map_or(self.number, |u| self.number.to(u))
    }
}

pub fn words_span(words: &[Name]) -> Span {
    match (words.first(), words.last()) {
        (Some(first), Some(last)) => first.span.to(last.span),
        _ => Span::default(),
    }
}
