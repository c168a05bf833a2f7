//! Scenario semantics: what the vocabulary's attributes say about a scenario.
//!
//! Lanes against the road (TrafficAlign's convention: 1..n in the ego's direction, -1..-n
//! opposite), behaviors against the kinds that can perform them, speeds against behavior,
//! actor type and road context, relations against lane indexes, position reference cycles,
//! lights against the road and signs against lights, counts, and the dash-cam profile.

use crate::names::{Resolved, Target, format_number, quoted};
use crate::vocab::{Entry, Vocabulary};
use tad_diagnostics::{Applicability, Code, Diagnostic, Payload, Span};
use tad_syntax::schema::{Lateral, Longitudinal};

/// The fields of a relation declaration.
const LATERAL: &str = "lateral";
const LONGITUDINAL: &str = "longitudinal";
use tad_syntax::model::{Attr, Known, Scenario, Val};

/// The ego vehicle's actor kind.
/// The actor kind of the ego vehicle.
pub const EGO_KIND: &str = "vehicle";

/// Whether an actor of `kind` can perform `behavior` (a behavior that names no performers
/// is open to all).
pub fn performs(behavior: &Entry, kind: &str) -> bool {
    behavior.symbols("performers").is_none_or(|performers| performers.contains(&kind))
}

fn entry<'v>(vocabulary: &'v Vocabulary, kind: &str, attr: Option<&Attr>) -> Option<&'v Entry> {
    vocabulary.get(kind, &attr?.symbol()?.name)
}

/// The entry of every name a name field states: its one name, or each name of a choice.
fn entries<'v>(vocabulary: &'v Vocabulary, kind: &str, attr: Option<&Attr>) -> Vec<&'v Entry> {
    attr.map(Attr::names).unwrap_or_default().into_iter().filter_map(|s| vocabulary.get(kind, &s.name)).collect()
}

fn speed_text(si: f64) -> String {
    format!("{} km/h", format_number(si * 3.6))
}

pub fn check(
    scenario: &Scenario,
    vocabulary: &Vocabulary,
    resolved: &Resolved,
    dashcam: bool,
    out: &mut Vec<Diagnostic>,
) {
    let road = scenario.section("road");
    let road_attr = |name: &str| road.and_then(|r| r.attr(name));
    let lanes = road_attr("lanes").and_then(Attr::integer);
    let direction = entry(vocabulary, "direction", road_attr("direction"));
    let opposite_lanes = direction.and_then(|d| d.flag("opposite_lanes"));
    let context = entry(vocabulary, "road_context", road_attr("context"));
    let road_type = entry(vocabulary, "road_type", road_attr("type"));

    lanes_check(scenario, road_attr("lanes"), lanes, opposite_lanes, direction, out);
    lights_and_signs(vocabulary, road_attr("light"), road_attr("signs"), road_type, context, out);

    // the ego vehicle
    let ego = scenario.section("ego");
    let ego_lane = ego.and_then(|e| e.attr("lane")).and_then(Attr::integer);
    if let Some(ego) = ego {
        let behaviors = entries(vocabulary, "behavior", ego.attr("behavior"));
        for behavior in &behaviors {
            performers(vocabulary, Some(behavior), ego.attr("behavior"), EGO_KIND, "the ego vehicle", out);
        }
        let kind = vocabulary.get("actor_kind", EGO_KIND);
        speeds(ego.attr("speed"), &behaviors, kind, None, context, "the ego vehicle", out);
    }

    for (index, group) in scenario.actors.iter().enumerate() {
        let what = format!("group `{}`", group.name.text);
        if let Some(count) = &group.count
            && let Known::Given(n) = count.value
            && let (n, _) = n.bounds()
            && n < 1
        {
            out.push(
                Diagnostic::new(
                    Code::E0509,
                    format!("{what} has {n} actors"),
                    count.span,
                    "a group has at least one actor",
                )
                .with_payload(range("count", n as f64, Some(1.0), None, None))
                .with_help("remove the group if nothing is there"),
            );
        }
        scene_limits(group, &what, out);
        let actor_type = match &group.kind.value {
            Known::Given(kind) => vocabulary.get("actor_type", &kind.name),
            Known::Unspecified => None,
        };
        let actor_kind = actor_type.and_then(|t| t.symbol("kind"));
        let behavior_attr = group.attr("behavior");
        let behaviors = entries(vocabulary, "behavior", behavior_attr);
        if let Some(kind) = actor_kind {
            for behavior in &behaviors {
                performers(vocabulary, Some(behavior), behavior_attr, kind, &what, out);
            }
        }
        let kind = actor_kind.and_then(|k| vocabulary.get("actor_kind", k));
        speeds(group.attr("speed"), &behaviors, kind, actor_type, context, &what, out);

        let Some(position_attr) = group.attr("position") else { continue };
        let Known::Given(Val::Position(position)) = &position_attr.value else { continue };
        let relation = vocabulary.get("relation", &position.relation.name);
        if let Some(relation) = relation
            && relation.choice(LATERAL) == Some(Lateral::Opposite)
            && opposite_lanes == Some(false)
        {
            let mut d = Diagnostic::new(
                Code::E0501,
                format!(
                    "{what} is `{} of {}`, but the road is {}",
                    relation.name,
                    position.reference.name,
                    direction.map_or("one-way", |d| d.name.as_str())
                ),
                position.relation.span,
                "no opposite direction",
            )
            .with_payload(Payload::Incompatible {
                subject: direction.map_or("one_way", |d| d.name.as_str()).to_string(),
                value: relation.name.clone(),
                allowed: Vec::new(),
            })
            .with_help("a one-way road has no oncoming lanes: correct the relation or the road's direction");
            if let Some(d_attr) = road_attr("direction") {
                d = d.with_secondary(d_attr.value_span, "the road's direction");
            }
            out.push(d);
        }
        if resolved.targets.get(&index) == Some(&Target::Ego)
            && let Some(relation) = relation
        {
            if dashcam && relation.choice(LONGITUDINAL) == Some(Longitudinal::Behind) {
                out.push(
                        Diagnostic::new(
                            Code::E0510,
                            format!("{what} is `{} of ego`, where a dash-cam cannot see", relation.name),
                            position.relation.span,
                            "behind the camera",
                        )
                        .with_payload(Payload::Incompatible {
                            subject: "dashcam".into(),
                            value: relation.name.clone(),
                            allowed: Vec::new(),
                        })
                        .with_note("the `dashcam` profile describes forward-facing camera frames: only what is ahead or beside the ego vehicle"),
                    );
            }
            let lane = group.attr("lane").and_then(Attr::integer);
            if let (Some(lane), Some(ego_lane)) = (lane, ego_lane) {
                relation_vs_lanes(vocabulary, relation, position.relation.span, lane, ego_lane, &what, out);
            }
        }
    }
    cycles(scenario, resolved, out);
}

/// Whether a scenario's lane indexes (the ego's and every group's) are counted from 0:
/// one is 0, none is negative and all are below the road's `lanes`. They then mean one
/// more each (W0403).
pub fn lanes_counted_from_zero(indexes: &[i64], lanes: Option<i64>) -> bool {
    indexes.contains(&0) && indexes.iter().all(|n| *n >= 0) && lanes.is_none_or(|l| indexes.iter().all(|n| *n < l))
}

fn lanes_check(
    scenario: &Scenario,
    lanes_attr: Option<&Attr>,
    lanes: Option<i64>,
    opposite_lanes: Option<bool>,
    direction: Option<&Entry>,
    out: &mut Vec<Diagnostic>,
) {
    let mut indexed: Vec<(&Attr, i64, String)> = Vec::new();
    if let Some(a) = scenario.section("ego").and_then(|e| e.attr("lane")) {
        indexed.extend(a.integer().map(|n| (a, n, "the ego vehicle".to_string())));
    }
    for group in &scenario.actors {
        if let Some(a) = group.attr("lane") {
            indexed.extend(a.integer().map(|n| (a, n, format!("group `{}`", group.name.text))));
        }
    }
    if let Some(n) = lanes.filter(|n| *n < 1) {
        if let Some(a) = lanes_attr {
            out.push(
                Diagnostic::new(
                    Code::E0500,
                    format!("a road has at least one lane, not {n}"),
                    a.value_span,
                    "not a lane count",
                )
                .with_payload(range("lanes", n as f64, Some(1.0), None, None)),
            );
        }
        return;
    }
    // Lane indexes counted from 0 (another tool's convention) are shifted, not rejected.
    let indexes: Vec<i64> = indexed.iter().map(|(_, n, _)| *n).collect();
    if lanes_counted_from_zero(&indexes, lanes) {
        let first = indexed.iter().find(|(_, n, _)| *n == 0).map(|(a, ..)| a.value_span).unwrap_or_default();
        let mut d =
            Diagnostic::new(Code::W0403, "lane indexes look counted from 0", first, "lane 0 does not exist in TAD")
                .with_help(
                    "TAD counts lanes from 1 (the leftmost lane in the ego's direction); add 1 to every lane index",
                )
                .with_payload(Payload::WrongValue {
                    field: "lane".into(),
                    expected: "lane indexes counted from 1".into(),
                    found: "0".into(),
                });
        for (a, n, _) in &indexed {
            d = d.with_fix(a.value_span, (n + 1).to_string(), Applicability::MachineApplicable);
        }
        out.push(d);
        return;
    }
    for (a, n, who) in &indexed {
        let n = *n;
        if n == 0 {
            out.push(
                Diagnostic::new(
                    Code::E0500,
                    format!("{who} is in lane 0, which does not exist"),
                    a.value_span,
                    "lanes are numbered from 1",
                )
                .with_payload(range("lane", 0.0, lanes.map(|l| -(l as f64)), lanes.map(|l| l as f64), None))
                .with_help(
                    "1 is the leftmost lane in the ego's direction; -1 the leftmost lane of the opposite direction",
                ),
            );
        } else if let Some(lanes) = lanes.filter(|l| n.abs() > *l) {
            let mut d = Diagnostic::new(
                Code::E0500,
                format!(
                    "{who} is in lane {n}, but the road has {lanes} lane{} per direction",
                    if lanes == 1 { "" } else { "s" }
                ),
                a.value_span,
                "beyond the road",
            )
            .with_payload(range("lane", n as f64, Some(-(lanes as f64)), Some(lanes as f64), None))
            .with_help(if n > 0 {
                format!("use a lane from 1 to {lanes}")
            } else {
                format!("use a lane from -1 to -{lanes}")
            });
            if let Some(l) = lanes_attr {
                d = d.with_secondary(l.value_span, "lanes per direction");
            }
            out.push(d);
        } else if n < 0 && opposite_lanes == Some(false) {
            let mut d = Diagnostic::new(
                Code::E0501,
                format!(
                    "{who} is in lane {n} of the opposite direction, but the road is {}",
                    direction.map_or("one-way", |d| d.name.as_str())
                ),
                a.value_span,
                "no opposite direction",
            )
            .with_payload(Payload::Incompatible {
                subject: direction.map_or("one_way", |d| d.name.as_str()).to_string(),
                value: format!("lane {n}"),
                allowed: Vec::new(),
            })
            .with_help("negative lane indexes are the opposite direction's lanes; a one-way road has none");
            if let Some(d_attr) = scenario.section("road").and_then(|r| r.attr("direction")) {
                d = d.with_secondary(d_attr.value_span, "the road's direction");
            }
            out.push(d);
        }
    }
}

/// E0502: a behavior its actor kind does not perform. The help names the kind's own
/// behaviors of the same sort (keeping still when the rejected one has a `max_speed`, else
/// moving), in declaration order; the fix takes the first when the field holds one name.
fn performers(
    vocabulary: &Vocabulary,
    behavior: Option<&Entry>,
    attr: Option<&Attr>,
    kind: &str,
    what: &str,
    out: &mut Vec<Diagnostic>,
) {
    let (Some(behavior), Some(attr)) = (behavior, attr) else { return };
    let Some(performers) = behavior.symbols("performers") else { return };
    if performs(behavior, kind) {
        return;
    }
    let still = behavior.speed("max_speed").is_some();
    let instead: Vec<&str> = vocabulary
        .entries("behavior")
        .into_iter()
        .filter(|b| performs(b, kind) && b.speed("max_speed").is_some() == still)
        .map(|b| b.name.as_str())
        .collect();
    let mut d = Diagnostic::new(
        Code::E0502,
        format!("{what} cannot `{}`: it is a {kind}", behavior.name),
        attr.value_span,
        format!("not something a {kind} does"),
    )
    .with_payload(Payload::Incompatible {
        subject: kind.to_string(),
        value: behavior.name.clone(),
        allowed: performers.iter().map(|p| p.to_string()).collect(),
    })
    .with_note(format!("`{}` is done by {}", behavior.name, quoted(&performers)));
    if let Some(first) = instead.first() {
        let sort = if still { "keeps still" } else { "moves" };
        d = d.with_help(format!("a {kind} {sort} with {}", quoted(&instead)));
        if attr.symbol().is_some() {
            d = d.with_fix(attr.value_span, *first, Applicability::MaybeIncorrect);
        }
    }
    out.push(d);
}

/// A speed, or a range of speeds, judged by its bounds, in order: its upper bound against
/// the behaviors' limits (each of a choice; error), its lower bound against 0 (error), the
/// actor kind's physical limit (error: impossible), the type's plausible maximum and the
/// road context's (warnings: implausible). The first that applies is reported.
fn speeds(
    attr: Option<&Attr>,
    behaviors: &[&Entry],
    kind: Option<&Entry>,
    actor_type: Option<&Entry>,
    context: Option<&Entry>,
    what: &str,
    out: &mut Vec<Diagnostic>,
) {
    let Some(attr) = attr else { return };
    let Some((low, speed)) = attr.bounds() else { return };
    let ranged = low != speed;
    let moves_at = if ranged { "up to " } else { "" };
    const EPSILON: f64 = 1e-9;
    if let Some((behavior, max)) =
        behaviors.iter().find_map(|b| b.speed("max_speed").filter(|m| speed > m + EPSILON).map(|m| (b, m)))
    {
        // a range keeps what of it the behavior allows
        let fixed = if ranged && low < max - EPSILON {
            format!("{}..{} km/h", format_number(low * 3.6), format_number(max * 3.6))
        } else {
            speed_text(max)
        };
        out.push(
            Diagnostic::new(
                Code::E0503,
                format!("{what} is `{}` but moves at {moves_at}{}", behavior.name, speed_text(speed)),
                attr.value_span,
                format!("`{}` allows at most {}", behavior.name, speed_text(max)),
            )
            .with_payload(speed_range(speed, None, Some(max)))
            .with_help(format!("write `{fixed}`, or a behavior that moves"))
            .with_fix(attr.value_span, fixed, Applicability::MaybeIncorrect),
        );
        return;
    }
    if low < 0.0 {
        let speed = low;
        out.push(
            Diagnostic::new(
                Code::E0503,
                format!("{what} has a negative speed"),
                attr.value_span,
                "speeds are not negative",
            )
            .with_payload(speed_range(speed, Some(0.0), None)),
        );
        return;
    }
    if let Some((k, max)) = kind.and_then(|k| k.speed("max_speed").map(|m| (k, m)))
        && speed > max + EPSILON
    {
        let kind_name = k.name.replace('_', " ");
        out.push(
            Diagnostic::new(
                Code::E0511,
                format!("{what} moves at {}, impossibly fast for a {kind_name}", speed_text(speed)),
                attr.value_span,
                format!("no {kind_name} is faster than {}", speed_text(max)),
            )
            .with_payload(speed_range(speed, None, Some(max)))
            .with_help("check the unit and the number; a speed this high is a misreading"),
        );
        return;
    }
    if let Some((t, max)) = actor_type.and_then(|t| t.speed("max_speed").map(|m| (t, m)))
        && speed > max + EPSILON
    {
        out.push(
            Diagnostic::new(
                Code::W0504,
                format!(
                    "{what} moves at {moves_at}{}, implausibly fast for {}",
                    speed_text(speed),
                    tad_base::a(&t.name)
                ),
                attr.value_span,
                format!("{} reaches about {}", tad_base::a(&t.name), speed_text(max)),
            )
            .with_payload(speed_range(speed, None, Some(max))),
        );
        return;
    }
    if let Some((c, max)) = context.and_then(|c| c.speed("max_speed").map(|m| (c, m)))
        && speed > max + EPSILON
    {
        out.push(
            Diagnostic::new(
                Code::W0504,
                format!(
                    "{what} moves at {moves_at}{}, implausibly fast on {} road",
                    speed_text(speed),
                    tad_base::a(&c.name.replace('_', " "))
                ),
                attr.value_span,
                format!("more than {} there", speed_text(max)),
            )
            .with_payload(speed_range(speed, None, Some(max))),
        );
    }
}

/// `front of ego` in another lane, `left` in a lane to the right, ...: same direction only
/// (the paper writes oncoming traffic as `front`).
fn relation_vs_lanes(
    vocabulary: &Vocabulary,
    relation: &Entry,
    span: Span,
    lane: i64,
    ego_lane: i64,
    what: &str,
    out: &mut Vec<Diagnostic>,
) {
    if lane < 0 || ego_lane < 0 {
        return;
    }
    // an unstated part of a relation means the reference's own lane or place
    let lateral = relation.choice(LATERAL).unwrap_or(Lateral::Same);
    let actual = match lane.cmp(&ego_lane) {
        std::cmp::Ordering::Less => Lateral::Left,
        std::cmp::Ordering::Greater => Lateral::Right,
        std::cmp::Ordering::Equal => Lateral::Same,
    };
    let consistent = match lateral {
        Lateral::Same => actual == Lateral::Same,
        Lateral::Left | Lateral::Right => actual == lateral || actual == Lateral::Same,
        Lateral::Opposite => true,
    };
    if consistent {
        return;
    }
    let longitudinal = relation.choice(LONGITUDINAL).unwrap_or(Longitudinal::Same);
    let better = vocabulary.entries("relation").into_iter().find(|r| {
        r.choice(LATERAL) == Some(actual) && r.choice(LONGITUDINAL).unwrap_or(Longitudinal::Same) == longitudinal
    });
    let mut d = Diagnostic::new(
        Code::W0505,
        format!(
            "{what} is `{} of ego`, but its lane {lane} is {} the ego's lane {ego_lane}",
            relation.name,
            match actual {
                Lateral::Left => "to the left of",
                Lateral::Right => "to the right of",
                _ => "the same as",
            }
        ),
        span,
        "disagrees with the lanes",
    )
    .with_payload(Payload::Incompatible {
        subject: format!("lane {lane} beside ego lane {ego_lane}"),
        value: relation.name.clone(),
        allowed: better.iter().map(|b| b.name.clone()).collect(),
    });
    if let Some(better) = better {
        d = d.with_help(format!("write `{}`, or correct the lane", better.name)).with_fix(
            span,
            better.name.clone(),
            Applicability::MaybeIncorrect,
        );
    }
    out.push(d);
}

fn lights_and_signs(
    vocabulary: &Vocabulary,
    light_attr: Option<&Attr>,
    signs: Option<&Attr>,
    road_type: Option<&Entry>,
    context: Option<&Entry>,
    out: &mut Vec<Diagnostic>,
) {
    let light_entry = entry(vocabulary, "light_state", light_attr);
    if let (Some(light), Some(light_attr)) = (light_entry, light_attr)
        && light.flag("present") != Some(false)
    {
        let unsignalised = [road_type, context].into_iter().flatten().find(|e| e.flag("signalised") == Some(false));
        if let Some(place) = unsignalised {
            out.push(
                Diagnostic::new(
                    Code::W0507,
                    format!("a `{}` traffic light on {}", light.name, tad_base::a(&place.name.replace('_', " "))),
                    light_attr.value_span,
                    format!("{} has no traffic lights", tad_base::a(&place.name.replace('_', " "))),
                )
                .with_payload(Payload::Incompatible {
                    subject: place.name.clone(),
                    value: light.name.clone(),
                    allowed: vec!["none".into()],
                })
                .with_help("write `light: none`, or correct the road"),
            );
        }
    }
    let (Some(signs), Some(light)) = (signs, light_entry) else { return };
    for sign in signs.symbols().unwrap_or(&[]) {
        let Some(sign_entry) = vocabulary.get("traffic_sign", &sign.name) else { continue };
        if sign_entry.symbols("conflicts_with").is_some_and(|c| c.contains(&light.name.as_str())) {
            let mut d = Diagnostic::new(
                Code::W0508,
                format!(
                    "{} together with {} light",
                    tad_base::a(&sign_entry.name.replace('_', " ")),
                    tad_base::a(&light.name)
                ),
                sign.span,
                format!("contradicts the `{}` light", light.name),
            )
            .with_payload(Payload::Incompatible {
                subject: sign_entry.name.clone(),
                value: light.name.clone(),
                allowed: Vec::new(),
            });
            if let Some(l) = light_attr {
                d = d.with_secondary(l.value_span, "the light");
            }
            out.push(d.with_help("a scenario states what governs the ego vehicle: keep the sign or the light"));
        }
    }
}

/// A quantity outside its bounds.
fn range(quantity: &str, value: f64, min: Option<f64>, max: Option<f64>, unit: Option<&str>) -> Payload {
    Payload::OutOfRange { quantity: quantity.into(), value, min, max, unit: unit.map(str::to_string) }
}

/// A speed outside its bounds, in km/h (rounded like the messages).
fn speed_range(speed: f64, min: Option<f64>, max: Option<f64>) -> Payload {
    let kmh = |v: f64| (v * 36.0).round() / 10.0;
    range("speed", kmh(speed), min.map(kmh), max.map(kmh), Some("km/h"))
}

/// What a scene cannot hold as written, so that it would differ from the file without a
/// word: more actors than a group becomes (W0512), a group farther from its reference
/// than the scene's road reaches (W0513).
fn scene_limits(group: &tad_syntax::model::ActorGroup, what: &str, out: &mut Vec<Diagnostic>) {
    use tad_syntax::schema::{MAX_GROUP, SCENE_REACH};
    if let Some(count) = &group.count
        && let Known::Given(n) = count.value
        && let (_, most) = n.bounds()
        && most > MAX_GROUP as i64
    {
        out.push(
            Diagnostic::new(
                Code::W0512,
                format!("{what} is capped at {MAX_GROUP} actors"),
                count.span,
                format!("{} placed of {most}", MAX_GROUP),
            )
            .with_payload(range("count", most as f64, Some(1.0), Some(MAX_GROUP as f64), None))
            .with_note(format!("a group becomes at most {MAX_GROUP} actors in every target (`run`, `build`)"))
            .with_help("for a crowd, write several groups, or the nearest ones"),
        );
    }
    let Some(attr) = group.attr("distance") else { return };
    let far = match &attr.value {
        Known::Given(Val::Quantity(q)) => q.value,
        Known::Given(Val::Range(_, high)) => high.value,
        _ => return,
    };
    if far > SCENE_REACH {
        out.push(
            Diagnostic::new(
                Code::W0513,
                format!("{what} is {} m from its reference, beyond the scene's road", format_number(far)),
                attr.value_span,
                format!("the road reaches {} m", format_number(SCENE_REACH)),
            )
            .with_payload(range("distance", far, Some(0.0), Some(SCENE_REACH), Some("m")))
            .with_note("the group starts off the road the scene models, and never meets the ego vehicle"),
        );
    }
}

/// Groups positioned relative to each other in a circle have no anchor.
fn cycles(scenario: &Scenario, resolved: &Resolved, out: &mut Vec<Diagnostic>) {
    let next = |i: usize| match resolved.targets.get(&i) {
        Some(Target::Group(j)) => Some(*j),
        _ => None,
    };
    let mut reported = vec![false; scenario.actors.len()];
    for start in 0..scenario.actors.len() {
        // walk at most n steps; a revisit of `start` is a cycle through it
        let mut path = vec![start];
        let mut current = start;
        while let Some(j) = next(current) {
            if j == start {
                if path.iter().any(|&p| reported[p]) {
                    break;
                }
                for &p in &path {
                    reported[p] = true;
                }
                let position_span = |i: usize| {
                    scenario.actors[i].attr("position").map_or(scenario.actors[i].name.span, |a| a.value_span)
                };
                let names: Vec<&str> = path.iter().map(|&p| scenario.actors[p].name.text.as_str()).collect();
                let mut d = Diagnostic::new(
                    Code::E0506,
                    if path.len() == 1 {
                        format!("group `{}` is positioned relative to itself", names[0])
                    } else {
                        format!("groups {} are positioned relative to each other in a cycle", quoted(&names))
                    },
                    position_span(start),
                    "this position",
                )
                .with_payload(Payload::Cycle { groups: names.iter().map(|n| n.to_string()).collect() })
                .with_help("place one of them relative to `ego` or a road element");
                for &p in &path[1..] {
                    d = d.with_secondary(position_span(p), "relative to the next");
                }
                out.push(d);
                break;
            }
            if path.contains(&j) || path.len() > scenario.actors.len() {
                break;
            }
            path.push(j);
            current = j;
        }
    }
}
