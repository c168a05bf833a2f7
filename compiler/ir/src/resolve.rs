//! From the checked model to the IR: names to ids, quantities to SI, lanes to [`Lane`]s,
//! references to groups, and the placement order.
//!
//! Total, like every stage: any model lowering produced resolves, whatever the checker
//! said of it. A name that resolves to nothing is [`Named::Unknown`], a value whose field
//! took another kind or that has no meaning (lane 0 in 1-based lanes) is absent, and
//! nothing is reported: the checker does that. Resolution rules that the checker also
//! applies (a reference's lookup order, lanes counted from 0) are the checker's functions.

use crate::entries::*;
use crate::lane::Lane;
use crate::param::Param;
use crate::quantity::{Metres, MetresPerSecond, Seconds};
use crate::scenario::*;
use tad_check::{Target, Vocabulary};
use tad_syntax::model::{self, Attr, Known, Module, Spanned, Val};
use tad_syntax::schema::ValueType;

/// The scenario of `module` resolved against `vocabulary` (what its file sees); `None`
/// for a module without a scenario.
pub fn resolve(module: &Module, vocabulary: &Vocabulary) -> Option<Scenario> {
    let model = module.scenario.as_ref()?;
    let r = Resolver { vocabulary, groups: tad_check::Groups::new(model) };
    let section = |name: &str| model.section(name);
    let attr = |s: &str, f: &str| model.attr(s, f);

    let lanes = r.field(attr("road", "lanes"), integer);
    let written_lanes: Vec<i64> = std::iter::once(attr("ego", "lane"))
        .chain(model.actors.iter().map(|g| g.attr("lane")))
        .filter_map(|a| a.and_then(Attr::integer))
        .collect();
    let lanes_from_zero = tad_check::lanes_counted_from_zero(&written_lanes, lanes.get());
    let lane = |a: Option<&Attr>| r.field(a, |v| Lane::new(integer(v)? + i64::from(lanes_from_zero)));

    let source = Source {
        span: section("source").map(|s| s.span),
        video: r.field(attr("source", "video"), text),
        time: r.field(attr("source", "time"), |v| quantity(v, ValueType::Duration).map(Seconds)),
        frame: r.field(attr("source", "frame"), integer),
        region: r.named(attr("source", "region")),
        description: r.field(attr("source", "description"), text),
    };
    let environment = Environment {
        span: section("environment").map(|s| s.span),
        weather: r.named_param(attr("environment", "weather")),
        time: r.named_param(attr("environment", "time")),
    };
    let road = Road {
        span: section("road").map(|s| s.span),
        road_type: r.named(attr("road", "type")),
        context: r.named(attr("road", "context")),
        lanes,
        direction: r.named(attr("road", "direction")),
        special_lanes: r.names(attr("road", "special_lanes")),
        signs: r.names(attr("road", "signs")),
        light: r.named(attr("road", "light")),
        traffic: r.named(attr("road", "traffic")),
        hazards: r.names(attr("road", "hazards")),
        roadworks: r.names(attr("road", "roadworks")),
        emergency_vehicles: r.names(attr("road", "emergency_vehicles")),
        roadside: r.names(attr("road", "roadside")),
    };
    let ego = Ego {
        span: section("ego").map(|s| s.span),
        behavior: r.named_param(attr("ego", "behavior")),
        speed: r.field(attr("ego", "speed"), |v| quantity_param(v, ValueType::Speed, MetresPerSecond)),
        lane: lane(attr("ego", "lane")),
    };
    let groups: Vec<Group> = model
        .actors
        .iter()
        .map(|g| Group {
            name: g.name.text.clone(),
            name_span: g.name.span,
            span: g.span,
            count: match &g.count {
                None => Field::Absent,
                Some(Spanned { value: Known::Unspecified, span }) => Field::Unspecified(*span),
                Some(Spanned { value: Known::Given(n), span }) => Field::Given(
                    match *n {
                        model::Count::Exactly(n) => Param::Fixed(n),
                        model::Count::Between(min, max) => Param::Range { min, max },
                    },
                    *span,
                ),
            },
            actor_type: match &g.kind.value {
                Known::Unspecified => Field::Unspecified(g.kind.span),
                Known::Given(symbol) => Field::Given(r.name(&symbol.name), g.kind.span),
            },
            behavior: r.named_param(g.attr("behavior")),
            speed: r.field(g.attr("speed"), |v| quantity_param(v, ValueType::Speed, MetresPerSecond)),
            position: r.field(g.attr("position"), |v| match v {
                Val::Position(p) => Some(r.position(p)),
                _ => None,
            }),
            lane: lane(g.attr("lane")),
            distance: r.field(g.attr("distance"), |v| quantity_param(v, ValueType::Length, Metres)),
            delay: r.field(g.attr("delay"), |v| quantity_param(v, ValueType::Duration, Seconds)),
            trigger: r.field(g.attr("trigger"), |v| quantity_param(v, ValueType::Length, Metres)),
            offset: r.field(g.attr("offset"), |v| quantity_param(v, ValueType::Length, Metres)),
        })
        .collect();
    Some(Scenario {
        name: model.name.as_ref().map(|n| Spanned { value: n.text.clone(), span: n.span }),
        span: model.span,
        entries: entries(vocabulary),
        source,
        environment,
        road,
        ego,
        placement_order: placement_order(&groups),
        groups,
        lanes_from_zero,
    })
}

struct Resolver<'a> {
    vocabulary: &'a Vocabulary,
    groups: tad_check::Groups<'a>,
}

impl Resolver<'_> {
    fn field<T>(&self, attr: Option<&Attr>, read: impl FnOnce(&Val) -> Option<T>) -> Field<T> {
        let Some(attr) = attr else { return Field::Absent };
        match &attr.value {
            Known::Unspecified => Field::Unspecified(attr.value_span),
            Known::Given(value) => read(value).map_or(Field::Absent, |v| Field::Given(v, attr.value_span)),
        }
    }

    fn name<K: Kind>(&self, name: &str) -> Named<K> {
        id(self.vocabulary, name).map_or_else(|| Named::Unknown(name.to_string()), Named::Known)
    }

    fn named<K: Kind>(&self, attr: Option<&Attr>) -> Field<Named<K>> {
        self.field(attr, |v| match v {
            Val::Symbol(s) => Some(self.name(&s.name)),
            _ => None,
        })
    }

    /// A name, or a choice of names.
    fn named_param<K: Kind>(&self, attr: Option<&Attr>) -> Field<Param<Named<K>>> {
        self.field(attr, |v| match v {
            Val::Symbol(s) => Some(Param::Fixed(self.name(&s.name))),
            Val::Choice(options) => Some(Param::Choice(options.iter().map(|s| self.name(&s.name)).collect())),
            _ => None,
        })
    }

    fn names<K: Kind>(&self, attr: Option<&Attr>) -> Field<Names<K>> {
        self.field(attr, |v| match v {
            Val::Symbols(symbols) => {
                Some(symbols.iter().map(|s| Spanned { value: self.name(&s.name), span: s.span }).collect())
            }
            _ => None,
        })
    }

    fn position(&self, p: &model::Position) -> Position {
        let name = &p.reference.name;
        let reference = match tad_check::target(&self.groups, self.vocabulary, name) {
            Some(Target::Ego) => Reference::Ego,
            Some(Target::Group(i)) => Reference::Group(Id::new(i)),
            Some(Target::RoadElement(element)) => {
                id(self.vocabulary, &element).map_or_else(|| Reference::Unknown(name.clone()), Reference::RoadElement)
            }
            None => Reference::Unknown(name.clone()),
        };
        Position {
            relation: Spanned { value: self.name(&p.relation.name), span: p.relation.span },
            reference: Spanned { value: reference, span: p.reference.span },
        }
    }
}

/// The id of the entry `name` (or an alias of it) names in kind `K`.
fn id<K: Kind>(vocabulary: &Vocabulary, name: &str) -> Option<Id<K>> {
    let entry = vocabulary.get(K::KIND, name)?;
    vocabulary.entries(K::KIND).into_iter().position(|e| std::ptr::eq(e, entry)).map(Id::new)
}

fn integer(v: &Val) -> Option<i64> {
    match v {
        Val::Integer(n) => Some(*n),
        _ => None,
    }
}

fn text(v: &Val) -> Option<String> {
    match v {
        Val::Text(t) => Some(t.clone()),
        _ => None,
    }
}

/// A quantity in SI, if it measures `what`.
fn quantity(v: &Val, what: ValueType) -> Option<f64> {
    match v {
        Val::Quantity(q) if q.unit.measures() == what => Some(q.si()),
        _ => None,
    }
}

/// A quantity or a range of quantities in SI, if it measures `what`.
fn quantity_param<T>(v: &Val, what: ValueType, si: impl Fn(f64) -> T) -> Option<Param<T>> {
    match v {
        Val::Quantity(q) if q.unit.measures() == what => Some(Param::Fixed(si(q.si()))),
        Val::Range(low, high) if low.unit.measures() == what => {
            Some(Param::Range { min: si(low.si()), max: si(high.si()) })
        }
        _ => None,
    }
}

fn speed(v: &Val) -> Option<MetresPerSecond> {
    quantity(v, ValueType::Speed).map(MetresPerSecond)
}

fn declared<T>(entry: &tad_check::Entry, field: &str, read: impl FnOnce(&Val) -> Option<T>) -> Option<T> {
    match &entry.declaration.attr(field)?.value {
        Known::Given(v) => read(v),
        Known::Unspecified => None,
    }
}

fn ids<K: Kind>(vocabulary: &Vocabulary, entry: &tad_check::Entry, field: &str) -> Option<Vec<Id<K>>> {
    let names = entry.declaration.attr(field)?.symbols()?;
    Some(names.iter().filter_map(|s| id(vocabulary, &s.name)).collect())
}

fn table<K: Kind>(vocabulary: &Vocabulary, read: impl Fn(&tad_check::Entry) -> K) -> Table<K> {
    let entries = vocabulary
        .entries(K::KIND)
        .iter()
        .map(|e| Entry {
            name: e.name.clone(),
            module: e.module.clone(),
            span: e.declaration.span,
            file: e.file,
            attrs: read(e),
        })
        .collect();
    Table { entries }
}

fn simulation(e: &tad_check::Entry) -> Simulation {
    Simulation {
        simulated_as: e.declaration.attr("simulated_as").and_then(Attr::choice),
        carla_blueprint: declared(e, "carla_blueprint", text),
        carla_note: declared(e, "carla_note", text),
    }
}

fn entries(v: &Vocabulary) -> Entries {
    let flag = |e: &tad_check::Entry, f: &str, default: bool| e.flag(f).unwrap_or(default);
    let length = |e: &tad_check::Entry, f: &str| declared(e, f, |v| quantity(v, ValueType::Length)).map(Metres);
    let int = |e: &tad_check::Entry, f: &str| declared(e, f, integer);
    let max_speed = |e: &tad_check::Entry| declared(e, "max_speed", speed);
    Entries {
        weather: table(v, |e| Weather {
            cloudiness: int(e, "cloudiness"),
            precipitation: int(e, "precipitation"),
            precipitation_deposits: int(e, "precipitation_deposits"),
            wetness: int(e, "wetness"),
            wind_intensity: int(e, "wind_intensity"),
            fog_density: int(e, "fog_density"),
            fog_distance: length(e, "fog_distance"),
        }),
        times_of_day: table(v, |e| TimeOfDay {
            sun_altitude: int(e, "sun_altitude"),
            sun_azimuth: int(e, "sun_azimuth"),
        }),
        road_types: table(v, |e| RoadType {
            junction: flag(e, "junction", false),
            signalised: flag(e, "signalised", true),
            arms: int(e, "arms"),
            shape: e.declaration.attr("shape").and_then(Attr::choice),
        }),
        road_contexts: table(v, |e| RoadContext {
            max_speed: max_speed(e),
            signalised: flag(e, "signalised", true),
            carla_towns: e.symbols("carla_towns").unwrap_or_default().into_iter().map(str::to_string).collect(),
            carla_note: declared(e, "carla_note", text),
        }),
        directions: table(v, |e| Direction { opposite_lanes: e.flag("opposite_lanes") }),
        special_lanes: table(v, |_| SpecialLane),
        traffic_signs: table(v, |e| TrafficSign {
            conflicts_with: ids(v, e, "conflicts_with").unwrap_or_default(),
            opendrive_type: int(e, "opendrive_type"),
        }),
        light_states: table(v, |e| LightState {
            present: flag(e, "present", true),
            signal: e.declaration.attr("signal").and_then(Attr::choice),
        }),
        traffic_densities: table(v, |_| TrafficDensity),
        hazards: table(v, |_| Hazard),
        roadworks: table(v, |_| Roadwork),
        emergency_vehicles: table(v, |_| EmergencyVehicle),
        roadsides: table(v, |e| Roadside { walkway: flag(e, "walkway", false) }),
        regions: table(v, |e| Region { style: e.symbol("style").map(str::to_string) }),
        actor_kinds: table(v, |e| ActorKind { simulation: simulation(e) }),
        actor_types: table(v, |e| ActorType {
            kind: e.symbol("kind").and_then(|k| id(v, k)),
            length: length(e, "length"),
            width: length(e, "width"),
            height: length(e, "height"),
            typical_speed: declared(e, "typical_speed", speed),
            max_speed: max_speed(e),
            simulation: simulation(e),
        }),
        behaviors: table(v, |e| Behavior {
            performers: ids(v, e, "performers"),
            max_speed: max_speed(e),
            motion: e.declaration.attr("motion").and_then(Attr::choice),
        }),
        relations: table(v, |e| Relation {
            lateral: e.declaration.attr("lateral").and_then(Attr::choice),
            longitudinal: e.declaration.attr("longitudinal").and_then(Attr::choice),
        }),
        road_elements: table(v, |e| RoadElement { at_junction: flag(e, "at_junction", false) }),
        reference_points: table(v, |e| ReferencePoint { actor_type: e.symbol("actor_type").and_then(|t| id(v, t)) }),
    }
}

/// Groups in source order, each moved after the group it refers to; what a cycle leaves
/// unplaced follows in source order.
fn placement_order(groups: &[Group]) -> Vec<GroupId> {
    let parent = |i: usize| match groups[i].position.given().map(|p| &p.reference.value) {
        Some(Reference::Group(j)) if j.index() != i && j.index() < groups.len() => Some(j.index()),
        _ => None,
    };
    let mut placed = vec![false; groups.len()];
    let mut order = Vec::with_capacity(groups.len());
    loop {
        let before = order.len();
        for i in 0..groups.len() {
            if !placed[i] && parent(i).is_none_or(|j| placed[j]) {
                placed[i] = true;
                order.push(Id::new(i));
            }
        }
        if order.len() == before {
            break;
        }
    }
    order.extend((0..groups.len()).filter(|&i| !placed[i]).map(Id::new));
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_declaration_kind_has_a_table() {
        let kinds: Vec<&str> = tad_syntax::schema::DECLARATIONS.iter().map(|d| d.name).collect();
        assert_eq!(Entries::KINDS, kinds.as_slice());
    }

    #[test]
    fn closed_sets_parse_their_words() {
        use tad_syntax::schema::{ClosedSet, Lateral, Longitudinal, Motion};
        for (word, motion) in Motion::NAMES.iter().zip(Motion::ALL) {
            assert_eq!(Motion::parse(word), Some(*motion));
            assert_eq!(motion.as_str(), *word);
        }
        assert_eq!(Lateral::parse("opposite"), Some(Lateral::Opposite));
        assert_eq!(Longitudinal::parse("up"), None);
    }
}
