//! What the layout needs to know of the ego and of each group, resolved once from the IR
//! for every backend: the body, its size, how many, what it does and how fast. Values the
//! scenario leaves unsaid are chosen here by fixed rules and recorded as [`Chosen`], so
//! every target reports the same choice.

use tad_ir::{ActorType, Behavior, ClosedSet, Entry, Field, Group, Id, Motion, Named, Param, Scenario, Span};
/// The body an actor is simulated as: the road contract's (`tad-road`).
pub use tad_road::Body;

/// The most actors one group becomes.
pub use tad_ir::MAX_GROUP;

/// A value the scenario does not state, chosen by the layout.
#[derive(Clone, Debug, PartialEq)]
pub struct Chosen {
    /// `None` for the ego.
    pub group: Option<Id<Group>>,
    /// The field: `lane`, `speed`, `behavior`, `count`, `position`.
    pub field: &'static str,
    /// What was chosen, in words (`lane 2`, `30 km/h`, `` `move_forward` ``).
    pub value: String,
    /// Where it is missing (the field's value, else the group's name or the section).
    pub span: Span,
    /// Why this value.
    pub rule: &'static str,
}

/// The facts of the ego or of one group.
#[derive(Clone, Debug, PartialEq)]
pub struct Facts {
    pub body: Body,
    pub length: f64,
    pub width: f64,
    /// How many (the nominal of a range, 1 when unspecified), at most [`MAX_GROUP`].
    pub count: usize,
    /// As written, before capping.
    pub wanted: usize,
    /// `None` for a behavior that declares no motion.
    pub motion: Option<Motion>,
    /// The behavior's entry, when known.
    pub behavior: Option<Id<Behavior>>,
    /// The speed it keeps, m/s: the largest of a range (the layout keeps room for the
    /// fastest), else its type's typical speed capped by the behavior's `max_speed`.
    pub speed: f64,
}

impl Facts {
    pub fn is_static(&self) -> bool {
        self.body == Body::Object
            || self.speed <= 0.0
            || matches!(self.motion, Some(Motion::Stop | Motion::Parked | Motion::Stand))
    }
}

/// The actor type the ego vehicle is: the first `reference` that declares one.
pub fn ego_type(scenario: &Scenario) -> Option<&Entry<ActorType>> {
    let id = scenario.entries.reference_points.iter().find_map(|(_, e)| e.attrs.actor_type)?;
    scenario.entries.get(id)
}

/// The body an actor type is simulated as.
pub fn body_of(scenario: &Scenario, actor_type: Option<&Entry<ActorType>>) -> Body {
    let own = actor_type.and_then(|t| t.attrs.simulation.simulated_as);
    let kind = actor_type
        .and_then(|t| t.attrs.kind)
        .and_then(|k| scenario.entries.get(k))
        .and_then(|k| k.attrs.simulation.simulated_as);
    own.or(kind).map_or(Body::Vehicle, Body::of)
}

fn behavior_with(scenario: &Scenario, motion: Motion) -> Option<Id<Behavior>> {
    scenario.entries.behaviors.iter().find(|(_, e)| e.attrs.motion == Some(motion)).map(|(id, _)| id)
}

struct Who {
    group: Option<Id<Group>>,
    span: Span,
}

fn motion_of(
    scenario: &Scenario,
    behavior: &Field<Param<Named<Behavior>>>,
    body: Body,
    who: &Who,
    chosen: &mut Vec<Chosen>,
) -> (Option<Motion>, Option<Id<Behavior>>) {
    match behavior.given() {
        Some(param) => {
            let id = param.nominal().id();
            (id.and_then(|id| scenario.entries.get(id)).and_then(|e| e.attrs.motion), id)
        }
        None => {
            let motion = body.default_motion();
            let id = behavior_with(scenario, motion);
            let name = id.map_or(motion.as_str(), |id| scenario.entries[id].name.as_str());
            chosen.push(Chosen {
                group: who.group,
                field: "behavior",
                value: format!("`{name}`"),
                span: behavior.span().unwrap_or(who.span),
                rule: "the usual behavior of its kind of body",
            });
            (Some(motion), id)
        }
    }
}

fn speed_of(
    scenario: &Scenario,
    written: &Field<Param<tad_ir::MetresPerSecond>>,
    typical: f64,
    behavior: Option<Id<Behavior>>,
    who: &Who,
    chosen: &mut Vec<Chosen>,
) -> f64 {
    if let Some(p) = written.given() {
        return p.max().0.max(0.0);
    }
    let cap =
        behavior.and_then(|b| scenario.entries.get(b)).and_then(|b| b.attrs.max_speed).map_or(f64::INFINITY, |s| s.0);
    let speed = typical.min(cap).max(0.0);
    chosen.push(Chosen {
        group: who.group,
        field: "speed",
        value: format!("{:.0} km/h", speed * 3.6),
        span: written.span().unwrap_or(who.span),
        rule: "the actor type's typical speed, capped by the behavior's `max_speed`",
    });
    speed
}

/// The ego's facts.
pub fn ego(scenario: &Scenario, section: Span, chosen: &mut Vec<Chosen>) -> Facts {
    let kind = ego_type(scenario).map(|e| &e.attrs);
    let positive = |m: Option<tad_ir::Metres>| m.map(|m| m.0).filter(|v| *v > 0.0);
    let who = Who { group: None, span: section };
    let (motion, behavior) = motion_of(scenario, &scenario.ego.behavior, Body::Vehicle, &who, chosen);
    let typical = kind.and_then(|k| k.typical_speed).map_or(50.0 / 3.6, |s| s.0);
    let speed = speed_of(scenario, &scenario.ego.speed, typical, behavior, &who, chosen);
    Facts {
        body: Body::Vehicle,
        length: positive(kind.and_then(|k| k.length)).unwrap_or(4.5),
        width: positive(kind.and_then(|k| k.width)).unwrap_or(1.8),
        count: 1,
        wanted: 1,
        motion,
        behavior,
        speed,
    }
}

/// A group's facts.
pub fn group(scenario: &Scenario, id: Id<Group>, group: &Group, chosen: &mut Vec<Chosen>) -> Facts {
    let entry = group.actor_type.given().and_then(|t| scenario.entries.resolved(t));
    let body = body_of(scenario, entry);
    let (default_length, default_width) = body.default_size();
    let positive = |m: Option<tad_ir::Metres>| m.map(|m| m.0).filter(|v| *v > 0.0);
    let who = Who { group: Some(id), span: group.name_span };
    let wanted = match group.count_param() {
        Some(p) => usize::try_from(p.nominal().max(1)).unwrap_or(usize::MAX),
        None => {
            chosen.push(Chosen {
                group: Some(id),
                field: "count",
                value: "1".into(),
                span: group.count.span().unwrap_or(group.name_span),
                rule: "one actor when the number is not known",
            });
            1
        }
    };
    let (motion, behavior) = motion_of(scenario, &group.behavior, body, &who, chosen);
    let typical = entry.and_then(|e| e.attrs.typical_speed).map_or(0.0, |s| s.0);
    let speed =
        if body == Body::Object { 0.0 } else { speed_of(scenario, &group.speed, typical, behavior, &who, chosen) };
    Facts {
        body,
        length: positive(entry.and_then(|e| e.attrs.length)).unwrap_or(default_length),
        width: positive(entry.and_then(|e| e.attrs.width)).unwrap_or(default_width),
        count: wanted.min(MAX_GROUP),
        wanted,
        motion: if body == Body::Object { Some(Motion::Parked) } else { motion },
        behavior,
        speed,
    }
}
