//! The resolved scenario: its sections and actor groups, every field typed.
//!
//! Each field is a [`Field`]: absent (not written, or written with a value that has no
//! meaning, which the checker reports), `unspecified`, or given with the span of its value
//! in the scenario's file. Names are [`Named`] ids into the scenario's [`Entries`]; speeds,
//! lengths and times are SI; lanes are [`Lane`]s. Groups keep source order, so a
//! [`GroupId`] is the group's index, and [`Scenario::placement_order`] lists them so that
//! every group comes after the group its position refers to.

use crate::entries::*;
use crate::lane::Lane;
use crate::param::Param;
use crate::quantity::{Metres, MetresPerSecond, Seconds};
use tad_diagnostics::Span;
use tad_syntax::model::Spanned;

/// One field's state (`spec/language.md` §4.2). The span is the value's.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Field<T> {
    #[default]
    Absent,
    Unspecified(Span),
    Given(T, Span),
}

impl<T> Field<T> {
    pub fn given(&self) -> Option<&T> {
        match self {
            Field::Given(value, _) => Some(value),
            _ => None,
        }
    }

    /// The value's span, when written.
    pub fn span(&self) -> Option<Span> {
        match self {
            Field::Absent => None,
            Field::Unspecified(span) | Field::Given(_, span) => Some(*span),
        }
    }

    pub fn is_given(&self) -> bool {
        matches!(self, Field::Given(..))
    }

    /// Absent or `unspecified`: missing, for completeness.
    pub fn is_missing(&self) -> bool {
        !self.is_given()
    }

    pub fn map<U>(self, f: impl FnOnce(T) -> U) -> Field<U> {
        match self {
            Field::Absent => Field::Absent,
            Field::Unspecified(span) => Field::Unspecified(span),
            Field::Given(value, span) => Field::Given(f(value), span),
        }
    }
}

impl<T: Copy> Field<T> {
    pub fn get(&self) -> Option<T> {
        self.given().copied()
    }
}

impl<T> Field<Param<T>> {
    /// The value when given as a single one (not a range or a choice).
    pub fn fixed(&self) -> Option<&T> {
        self.given().and_then(Param::fixed)
    }
}

/// A list of names (`[stop_sign, school_zone]`); each name keeps its span.
pub type Names<K> = Vec<Spanned<Named<K>>>;

pub type GroupId = Id<Group>;

#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// `None` for `scenario { ... }` without a name (E0210).
    pub name: Option<Spanned<String>>,
    pub span: Span,
    /// The vocabulary the scenario's file sees.
    pub entries: Entries,
    pub source: Source,
    pub environment: Environment,
    pub road: Road,
    pub ego: Ego,
    /// In source order: a [`GroupId`] is an index here.
    pub groups: Vec<Group>,
    /// Every group once, each after the group it is positioned relative to; groups in a
    /// cycle of references (E0506) come last, in source order.
    pub placement_order: Vec<GroupId>,
    /// The lane indexes were written counted from 0 (W0403); the [`Lane`]s here are one
    /// more, in TAD's convention.
    pub lanes_from_zero: bool,
}

impl Scenario {
    pub fn group(&self, id: GroupId) -> Option<&Group> {
        self.groups.get(id.index())
    }

    pub fn group_named(&self, name: &str) -> Option<GroupId> {
        self.groups.iter().position(|g| g.name == name).map(Id::new)
    }

    pub fn groups(&self) -> impl Iterator<Item = (GroupId, &Group)> {
        self.groups.iter().enumerate().map(|(i, g)| (Id::new(i), g))
    }

    /// The groups in [`Scenario::placement_order`].
    pub fn order(&self) -> impl Iterator<Item = (GroupId, &Group)> {
        self.placement_order.iter().filter_map(|&id| Some((id, self.group(id)?)))
    }
}

/// `source { ... }`; `span` is `None` when the section is not written.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Source {
    pub span: Option<Span>,
    pub video: Field<String>,
    pub time: Field<Seconds>,
    pub frame: Field<i64>,
    pub region: Field<Named<Region>>,
    pub description: Field<String>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Environment {
    pub span: Option<Span>,
    /// A name, or a choice of names (`clear | cloudy`).
    pub weather: Field<Param<Named<Weather>>>,
    pub time: Field<Param<Named<TimeOfDay>>>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Road {
    pub span: Option<Span>,
    /// `type:`
    pub road_type: Field<Named<RoadType>>,
    pub context: Field<Named<RoadContext>>,
    /// Lanes per direction, as written (at least 1 in a valid scenario).
    pub lanes: Field<i64>,
    pub direction: Field<Named<Direction>>,
    pub special_lanes: Field<Names<SpecialLane>>,
    pub signs: Field<Names<TrafficSign>>,
    pub light: Field<Named<LightState>>,
    pub traffic: Field<Named<TrafficDensity>>,
    pub hazards: Field<Names<Hazard>>,
    pub roadworks: Field<Names<Roadwork>>,
    pub emergency_vehicles: Field<Names<EmergencyVehicle>>,
    pub roadside: Field<Names<Roadside>>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ego {
    pub span: Option<Span>,
    pub behavior: Field<Param<Named<Behavior>>>,
    pub speed: Field<Param<MetresPerSecond>>,
    pub lane: Field<Lane>,
}

/// `actor NAME: [COUNT] TYPE { ... }`
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    pub name: String,
    pub name_span: Span,
    pub span: Span,
    /// The header's count, one or a range (`3..5`): absent means one actor.
    pub count: Field<Param<i64>>,
    /// The header's type: given or `unspecified`, never absent.
    pub actor_type: Field<Named<ActorType>>,
    pub behavior: Field<Param<Named<Behavior>>>,
    pub speed: Field<Param<MetresPerSecond>>,
    pub position: Field<Position>,
    pub lane: Field<Lane>,
    /// The gap along the road from the position's reference to the nearest actor.
    pub distance: Field<Param<Metres>>,
    /// The time before the group starts its behavior.
    pub delay: Field<Param<Seconds>>,
    /// The group starts its behavior when the ego vehicle is within this distance.
    pub trigger: Field<Param<Metres>>,
    /// A move of the whole group along its lane from where the layout puts it, in the
    /// direction its arm's stations grow; a range is a search parameter.
    pub offset: Field<Param<Metres>>,
}

impl Group {
    /// The number of actors when known as one number: 1 without a count in the header;
    /// `None` when `unspecified` or a range (see [`Group::count_param`]).
    pub fn count(&self) -> Option<i64> {
        self.count_param().and_then(|p| p.fixed().copied())
    }

    /// The number of actors, one or a range, when known: `Fixed(1)` without a count.
    pub fn count_param(&self) -> Option<Param<i64>> {
        match &self.count {
            Field::Absent => Some(Param::Fixed(1)),
            Field::Unspecified(_) => None,
            Field::Given(n, _) => Some(n.clone()),
        }
    }
}

/// `RELATION of REFERENCE`
#[derive(Clone, Debug, PartialEq)]
pub struct Position {
    pub relation: Spanned<Named<Relation>>,
    pub reference: Spanned<Reference>,
}

/// What a position is relative to, resolved as the checker does: a group of the scenario
/// first, then a `reference` (`ego` and its aliases), then a road element.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Reference {
    Ego,
    Group(GroupId),
    RoadElement(Id<RoadElement>),
    /// Nothing of that name (E0402), as written.
    Unknown(String),
}
