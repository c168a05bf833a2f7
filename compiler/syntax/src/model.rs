//! The scenario model: what a file means once its structure is known.
//!
//! Lowered from the concrete tree by [`crate::lower`]. Every attribute keeps the spans of
//! its key and value, so later phases (vocabulary checks, completeness, backends) can
//! point at the source. An attribute is absent (not written), [`Known::Unspecified`]
//! (written as `unspecified`: explicitly unknown) or given.

use crate::cst::Name;
use crate::schema::{FieldDef, SectionDef, Unit};
use tad_diagnostics::Span;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Module {
    pub uses: Vec<crate::cst::Use>,
    pub declarations: Vec<Declaration>,
    pub scenario: Option<Scenario>,
}

/// `KIND NAME { FIELD* }`: one name of a vocabulary.
#[derive(Clone, Debug, PartialEq)]
pub struct Declaration {
    pub def: &'static SectionDef,
    pub span: Span,
    pub name: Name,
    pub attrs: Vec<Attr>,
}

impl Declaration {
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.def.name == name)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    pub span: Span,
    pub name: Option<Name>,
    pub sections: Vec<Section>,
    pub actors: Vec<ActorGroup>,
}

impl Scenario {
    pub fn section(&self, name: &str) -> Option<&Section> {
        self.sections.iter().find(|s| s.def.name == name)
    }

    /// The attribute `field` of section `section`, if written.
    pub fn attr(&self, section: &str, field: &str) -> Option<&Attr> {
        self.section(section)?.attr(field)
    }

    pub fn actor(&self, name: &str) -> Option<&ActorGroup> {
        self.actors.iter().find(|a| a.name.text == name)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    pub def: &'static SectionDef,
    pub span: Span,
    pub name_span: Span,
    pub attrs: Vec<Attr>,
}

impl Section {
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.def.name == name)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ActorGroup {
    pub span: Span,
    pub name: Name,
    /// `None` when the header gives no count: the group is one actor.
    pub count: Option<Spanned<Known<Count>>>,
    pub kind: Spanned<Known<Symbol>>,
    pub attrs: Vec<Attr>,
}

impl ActorGroup {
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.def.name == name)
    }

    /// The number of actors, when known as one number (1 when the header gives none);
    /// `None` for `unspecified` and for a range (see [`ActorGroup::count_bounds`]).
    pub fn count(&self) -> Option<i64> {
        self.count_bounds().filter(|(low, high)| low == high).map(|(n, _)| n)
    }

    /// The least and the most actors, when known: `(n, n)` for a single count.
    pub fn count_bounds(&self) -> Option<(i64, i64)> {
        match &self.count {
            None => Some((1, 1)),
            Some(Spanned { value: Known::Given(count), .. }) => Some(count.bounds()),
            Some(_) => None,
        }
    }
}

/// The count in an actor group's header: `3`, or a range `3..5` (`low <= high` once
/// lowered).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Count {
    Exactly(i64),
    Between(i64, i64),
}

impl std::fmt::Display for Count {
    /// As TAD writes it: `3`, `3..5`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Count::Exactly(n) => write!(f, "{n}"),
            Count::Between(low, high) => write!(f, "{low}..{high}"),
        }
    }
}

impl Count {
    /// The single count, `None` for a range.
    pub fn single(self) -> Option<i64> {
        match self {
            Count::Exactly(n) => Some(n),
            Count::Between(..) => None,
        }
    }

    /// `(low, high)`; `(n, n)` for a single count.
    pub fn bounds(self) -> (i64, i64) {
        match self {
            Count::Exactly(n) => (n, n),
            Count::Between(low, high) => (low, high),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Spanned<T> {
    pub value: T,
    pub span: Span,
}

/// A written value: given, or explicitly `unspecified`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Known<T> {
    Given(T),
    Unspecified,
}

impl<T> Known<T> {
    pub fn given(&self) -> Option<&T> {
        match self {
            Known::Given(v) => Some(v),
            Known::Unspecified => None,
        }
    }
}

/// One `field: value` of a section or actor block.
#[derive(Clone, Debug, PartialEq)]
pub struct Attr {
    pub def: &'static FieldDef,
    pub key_span: Span,
    pub value_span: Span,
    pub value: Known<Val>,
}

impl Attr {
    pub fn symbol(&self) -> Option<&Symbol> {
        match &self.value {
            Known::Given(Val::Symbol(s)) => Some(s),
            _ => None,
        }
    }

    pub fn integer(&self) -> Option<i64> {
        match &self.value {
            Known::Given(Val::Integer(n)) => Some(*n),
            _ => None,
        }
    }

    pub fn flag(&self) -> Option<bool> {
        match &self.value {
            Known::Given(Val::Flag(b)) => Some(*b),
            _ => None,
        }
    }

    pub fn symbols(&self) -> Option<&[Symbol]> {
        match &self.value {
            Known::Given(Val::Symbols(s)) => Some(s),
            _ => None,
        }
    }

    /// The word of a [`crate::schema::ValueType::Choice`] field as its enum.
    pub fn choice<T: crate::schema::ClosedSet>(&self) -> Option<T> {
        self.symbol().and_then(|s| T::parse(&s.name))
    }

    /// A single quantity (not a range).
    pub fn quantity(&self) -> Option<Quantity> {
        match &self.value {
            Known::Given(Val::Quantity(q)) => Some(*q),
            _ => None,
        }
    }

    /// The given value, when it is a single one: `None` for a range or a choice (and
    /// when not given).
    pub fn single(&self) -> Option<&Val> {
        self.value.given().and_then(Val::single)
    }

    /// A quantity's bounds in SI: `(v, v)` for a single value, `(low, high)` for a range.
    pub fn bounds(&self) -> Option<(f64, f64)> {
        self.value.given().and_then(Val::bounds)
    }

    /// Every name a name field states: its one name, or each name of a choice.
    pub fn names(&self) -> Vec<&Symbol> {
        self.value.given().map(Val::names).unwrap_or_default()
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    /// A name, or a word of a field's closed set (lowering checked it is one).
    Symbol(Symbol),
    Symbols(Vec<Symbol>),
    Integer(i64),
    Quantity(Quantity),
    Text(String),
    Position(Position),
    Flag(bool),
    /// `LOW..HIGH UNIT`: a quantity between two bounds, both in one unit, `low <= high`.
    /// Only fields that take a parameter (`FieldDef::param`) have one.
    Range(Quantity, Quantity),
    /// `a | b | c`: one of these names (at least two, no name twice). Only name fields
    /// that take a parameter have one. (Not to be confused with
    /// [`crate::schema::ValueType::Choice`], a word of a closed set.)
    Choice(Vec<Symbol>),
}

impl Val {
    /// Whether it is a parameter: a range or a choice.
    pub fn is_param(&self) -> bool {
        matches!(self, Val::Range(..) | Val::Choice(_))
    }

    /// The value itself when it is a single one; `None` for a range or a choice, so a
    /// consumer that understands single values only sees no value rather than a wrong one.
    pub fn single(&self) -> Option<&Val> {
        if self.is_param() { None } else { Some(self) }
    }

    /// A quantity's bounds in SI: `(v, v)` for a single quantity, `(low, high)` for a
    /// range; `None` for anything else.
    pub fn bounds(&self) -> Option<(f64, f64)> {
        match self {
            Val::Quantity(q) => Some((q.si(), q.si())),
            Val::Range(low, high) => Some((low.si(), high.si())),
            _ => None,
        }
    }

    /// The names a name value states: its one name, or each name of a choice.
    pub fn names(&self) -> Vec<&Symbol> {
        match self {
            Val::Symbol(s) => vec![s],
            Val::Choice(options) => options.iter().collect(),
            _ => Vec::new(),
        }
    }
}

/// A name from a vocabulary, as written (`clear`, `move_forward`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Symbol {
    pub name: String,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantity {
    pub value: f64,
    pub unit: Unit,
}

impl Quantity {
    /// The value in SI units (m/s, m, s).
    pub fn si(self) -> f64 {
        self.value * self.unit.to_si()
    }
}

/// `RELATION of REFERENCE`
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Position {
    pub relation: Symbol,
    pub reference: Symbol,
}
