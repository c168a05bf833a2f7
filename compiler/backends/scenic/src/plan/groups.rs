//! Every actor group resolved but for its place: the Scenic class and CARLA blueprint its
//! actor type declares (`simulated_as`, `carla_blueprint`, `carla_note`; else its kind's),
//! what its position refers to, and the layout's facts of it (size, count, motion, speed,
//! lane and arm: `tad_layout::GroupLayout`), with where Scenic renders them only
//! approximately (W0703, W0707).

use tad_diagnostics::{Code, Span};
use tad_ir::{ActorType, Entry, Field, Lane, Lateral, Longitudinal, Reference, Scenario};

use super::report::{Annotate, Report, named, unsupported};
use super::{ends, kmh, motion};
use crate::mapping::{self, Class};

/// Where a group's position points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    Ego,
    /// The group of that index.
    Group(usize),
    /// The stop line of the junction ahead of the ego.
    Junction,
}

/// What stands for an actor type in the program.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapping {
    pub class: Class,
    pub blueprint: String,
    /// Why the blueprint only approximates the type (W0703).
    pub approximation: Option<String>,
}

/// An actor group with everything resolved but its place.
#[derive(Clone, Debug, PartialEq)]
pub struct Resolved {
    /// The group's name in the scenario.
    pub name: String,
    pub summary: String,
    pub mapping: Mapping,
    pub length: f64,
    pub width: f64,
    /// The layout's (at most `tad_layout::MAX_GROUP`).
    pub count: usize,
    pub motion: Option<tad_ir::Motion>,
    /// m/s.
    pub speed: f64,
    /// TAD lane index (on its arm), the layout's.
    pub lane: i64,
    /// The junction arm its first actor stands on (`Ego` without a junction).
    pub arm: tad_layout::Arm,
    pub target: Target,
    pub longitudinal: Longitudinal,
    pub lateral: Option<Lateral>,
    pub span: Span,
    /// A speed range (m/s) Scenic samples; `speed` is then its upper end, for the layout.
    pub speed_range: Option<(f64, f64)>,
    /// The motions of a choice of behaviors (empty: no choice).
    pub motions: Vec<Option<tad_ir::Motion>>,
    /// The written gap to the reference, m: `(low, high)`.
    pub distance: Option<(f64, f64)>,
    /// Time before the group starts its behavior, s.
    pub delay: Option<(f64, f64)>,
    /// The ego's distance at which the group starts its behavior, m.
    pub trigger: Option<(f64, f64)>,
    /// The written move along the lane from the layout's place, m: `(low, high)`.
    pub offset: Option<(f64, f64)>,
}

/// What stands for an actor type: its own declared simulation, else its kind's (W0703 with
/// the kind's `carla_note`), else a default of its class.
pub fn mapping(scenario: &Scenario, actor_type: Option<&Entry<ActorType>>) -> Mapping {
    let own = actor_type.map(|t| &t.attrs.simulation);
    let kind = actor_type.and_then(|t| t.attrs.kind).and_then(|k| scenario.entries.get(k)).map(|k| &k.attrs.simulation);
    let class = own.and_then(|s| s.simulated_as).or(kind.and_then(|k| k.simulated_as)).map_or(Class::Car, Class::of);
    if let Some(blueprint) = own.and_then(|s| s.carla_blueprint.clone()) {
        return Mapping { class, blueprint, approximation: own.and_then(|s| s.carla_note.clone()) };
    }
    match kind.filter(|k| k.carla_blueprint.is_some() && k.simulated_as.map_or(Class::Car, Class::of) == class) {
        Some(k) => Mapping {
            class,
            blueprint: k.carla_blueprint.clone().unwrap_or_default(),
            approximation: Some(k.carla_note.clone().unwrap_or_else(|| mapping::FALLBACK_NOTE.to_string())),
        },
        None => Mapping {
            class,
            blueprint: class.default_blueprint().to_string(),
            approximation: Some(match class {
                Class::Car => mapping::FALLBACK_NOTE.to_string(),
                _ => format!("no CARLA blueprint is declared for it: `{}` stands in", class.default_blueprint()),
            }),
        },
    }
}

/// The text of a position's reference.
pub fn reference_name<'s>(scenario: &'s Scenario, reference: &'s Reference) -> &'s str {
    match reference {
        Reference::Ego => "ego",
        Reference::Group(id) => scenario.group(*id).map_or("", |g| g.name.as_str()),
        Reference::RoadElement(id) => scenario.entries.get(*id).map_or("", |e| e.name.as_str()),
        Reference::Unknown(name) => name,
    }
}

/// Every group of `scenario`, in source order.
pub fn resolve(scenario: &Scenario, laid: &tad_layout::Layout, report: &mut Report) -> Vec<Resolved> {
    let entries = &scenario.entries;
    let mut out = Vec::new();
    for (group, layout) in scenario.groups.iter().zip(&laid.groups) {
        let facts = &layout.facts;
        let who = format!("group `{}`", group.name);
        let (type_name, entry) = match &group.actor_type {
            Field::Given(written, _) => (entries.name(written).to_string(), entries.resolved(written)),
            _ => ("unspecified".to_string(), None),
        };
        let type_span = group.actor_type.span().unwrap_or(group.name_span);
        let mapping = mapping(scenario, entry);
        if let Some(why) = &mapping.approximation {
            report
                .warn(
                    Code::W0703,
                    format!("actor type `{type_name}` has no exact Scenic counterpart"),
                    type_span,
                    "approximated",
                    unsupported(named("actor_type", &type_name), Some(format!("`{}`", mapping.blueprint))),
                )
                .note(why.clone());
        }
        let count_span = group.count.span().unwrap_or(group.name_span);
        let count_param = group.count_param();
        if let Some(tad_ir::Param::Range { min, max }) = &count_param {
            let chosen = count_param.as_ref().map_or(1, tad_ir::Param::nominal);
            report
                .warn(
                    Code::W0707,
                    format!("Scenic cannot sample the number of actors of {who}"),
                    count_span,
                    format!("{chosen} in every scene"),
                    unsupported("actor.count", Some(format!("{chosen} actors, the midpoint of {min}..{max}"))),
                )
                .note("a Scenic program creates a fixed set of objects: how many cannot depend on a sampled value");
        }
        motion::approximate(scenario, &group.behavior, mapping.class, report);
        let debris = mapping.class == Class::Debris;
        let motions = motion::choices(scenario, &group.behavior, mapping.class, report);
        let speed_range = ends(&group.speed, |s| s.0.max(0.0)).filter(|(low, high)| low < high && !debris);
        let (target, longitudinal, lateral) = match group.position.given() {
            // the layout's choice (W0706 from its findings)
            None => (Target::Ego, Longitudinal::Front, None),
            Some(p) => {
                let relation = entries.resolved(&p.relation.value).map(|r| r.attrs);
                let longitudinal = match relation.and_then(|r| r.longitudinal) {
                    Some(Longitudinal::Front) => Longitudinal::Front,
                    Some(Longitudinal::Behind) => Longitudinal::Behind,
                    _ => Longitudinal::Same,
                };
                let target = match &p.reference.value {
                    Reference::Group(id) => Target::Group(id.index()),
                    Reference::Ego => Target::Ego,
                    Reference::RoadElement(id) if entries.get(*id).is_some_and(|e| e.attrs.at_junction) => {
                        Target::Junction
                    }
                    other => {
                        let element = reference_name(scenario, other);
                        report.warn(
                            Code::W0700,
                            format!("road element `{element}` has no Scenic mapping"),
                            p.reference.span,
                            "placed relative to the ego vehicle instead",
                            unsupported(named("road_element", element), Some("relative to the ego vehicle".into())),
                        )
                        .note("the CARLA maps as Scenic reads them have junctions, lanes and sidewalks, but no bus stops or parking lots");
                        Target::Ego
                    }
                };
                (target, longitudinal, relation.and_then(|r| r.lateral))
            }
        };
        let summary = summary(scenario, group, &type_name, facts.count);
        let first = layout.agents.first();
        out.push(Resolved {
            name: group.name.clone(),
            summary,
            mapping,
            length: facts.length,
            width: facts.width,
            count: facts.count,
            motion: facts.motion,
            speed: facts.speed,
            lane: first.map_or_else(|| group.lane.get().map_or(0, Lane::index), |a| a.lane),
            arm: first.map_or(tad_layout::Arm::Ego, |a| a.station.arm),
            target,
            longitudinal,
            lateral,
            span: group.span,
            speed_range,
            motions: if debris { Vec::new() } else { motions },
            distance: ends(&group.distance, |m| m.0.max(0.0)),
            delay: ends(&group.delay, |s| s.0.max(0.0)).filter(|_| !debris),
            trigger: ends(&group.trigger, |m| m.0.max(0.0)).filter(|_| !debris),
            offset: ends(&group.offset, |m| m.0).filter(|(low, high)| low.is_finite() && high.is_finite()),
        });
    }
    out
}

/// `group `NAME`: COUNT TYPE, BEHAVIOR, SPEED, RELATION of REFERENCE, lane N`: what the
/// source says, for a comment.
fn summary(scenario: &Scenario, group: &tad_ir::Group, type_name: &str, count: usize) -> String {
    let mut parts = vec![format!("{count} {type_name}")];
    if let Some(b) = group.behavior.given() {
        let names: Vec<&str> = b.values().into_iter().map(|n| scenario.entries.name(n)).collect();
        parts.push(names.join(" | "));
    }
    if let Some(speed) = group.speed.given() {
        parts.push(speed_text(speed));
    }
    if let Some(p) = group.position.given() {
        let relation = scenario.entries.name(&p.relation.value);
        parts.push(format!("{relation} of {}", reference_name(scenario, &p.reference.value)));
    }
    if let Some(lane) = group.lane.get() {
        parts.push(format!("lane {}", lane.index()));
    }
    format!("group `{}`: {}", group.name, parts.join(", "))
}

/// `30 km/h`, or a range `30..40 km/h`, for a comment.
pub fn speed_text(speed: &tad_ir::Param<tad_ir::MetresPerSecond>) -> String {
    match speed {
        tad_ir::Param::Range { min, max } => {
            format!("{:.0}..{}", min.km_per_hour(), kmh(max.0))
        }
        other => kmh(other.nominal().0),
    }
}
