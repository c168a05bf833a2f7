//! The objects of the program: the ego vehicle and one object per actor of every group,
//! each with a safe identifier (`crate::python::Names`), its class, blueprint, size, and
//! where the layout (`tad_layout`) put it: arm, lane, station, place in the lane or on the
//! sidewalk, facing, speeds and timing.

use tad_ir::Scenario;
use tad_layout::{Arm, Facing, Layout, Place, Side};

use super::ego::EgoPlan;
use super::groups::Resolved;
use super::{Actor, Group, MeetPlan, OnTime, Sampled};
use crate::mapping::{self, Class};
use crate::python::Names;

/// The program's objects.
#[derive(Clone, Debug, PartialEq)]
pub struct Actors {
    pub ego: Actor,
    pub ego_summary: String,
    pub groups: Vec<Group>,
}

/// `junction`: the map choice kept the junction (else actors of other arms stand on the
/// ego's road beyond where the junction would be).
pub fn build(
    scenario: &Scenario,
    ego: &EgoPlan,
    groups: &[Resolved],
    laid: &Layout,
    kept: &[usize],
    junction: bool,
) -> Actors {
    let mut names = Names::default();
    names.reserve("ego");
    let ego_actor = Actor {
        ident: "ego".into(),
        class: Class::Car,
        blueprint: mapping::EGO_BLUEPRINT.to_string(),
        is_ego: true,
        adversary: false,
        length: ego.length,
        width: ego.width,
        lane: ego.lane,
        arm: Arm::Ego,
        offset: 0.0,
        place: Place::Lane,
        cross: None,
        motion: ego.motion,
        target_speed: ego.speed,
        initial_speed: if laid.ego.moving { ego.speed } else { 0.0 },
        params: Sampled {
            tag: "Ego".into(),
            speed: ego.speed_range,
            motions: ego.motions.clone(),
            ..Sampled::default()
        },
    };
    let mut out = Vec::new();
    for (i, g) in groups.iter().enumerate() {
        let Some(gl) = laid.groups.iter().find(|l| l.group.index() == i) else {
            out.push(Group { summary: g.summary.clone(), actors: Vec::new() });
            continue;
        };
        let class = g.mapping.class;
        let conflict = laid.conflict(gl.group);
        let first = gl.agents.first();
        // the way the group extends from its reference, to sample it nearer
        let reference_along =
            match scenario.group(gl.group).and_then(|s| s.position.given()).map(|p| &p.reference.value) {
                Some(tad_ir::Reference::Group(r)) => laid
                    .group(*r)
                    .and_then(|r| r.agents.first())
                    .filter(|r| first.is_some_and(|f| f.station.arm == r.station.arm))
                    .map_or(0.0, |r| r.station.along),
                _ => 0.0,
            };
        let away = first.map_or(1.0, |f| if f.station.along >= reference_along { 1.0 } else { -1.0 });
        let (meet, on_time) = first.map_or((None, None), |f| timing(f, g, laid, ego, conflict.is_some(), junction));
        let params = Sampled {
            tag: (i + 1).to_string(),
            speed: g.speed_range,
            motions: g.motions.clone(),
            shift: if g.offset.is_some() {
                None
            } else if let Some((low, high)) = g.distance.filter(|(low, high)| low < high) {
                Some((high - low, -away))
            } else if conflict.is_none() {
                Some((gl.shift_room(), -away)).filter(|(s, _)| *s >= 0.5)
            } else {
                None
            },
            delay: g.delay.or_else(|| {
                // a meeting TadMeet cannot find on this map: the wait at the ego's stated speed
                let waits = first.and_then(|f| f.start.meet).zip(conflict).map(|(m, c)| c.time - m.travel);
                let waits = waits.filter(|_| meet.is_none());
                first.map(|f| f.start.delay).filter(|d| *d > 0.05).or(waits.filter(|d| *d > 0.05)).map(|d| (d, d))
            }),
            trigger: g.trigger,
            jitter: first.map(|f| laid.conflict_spread(f)).filter(|j| *j >= 0.3 && g.offset.is_none()),
            offset: g.offset.filter(|(low, high)| low < high),
            meet,
            on_time,
        };
        // a single written offset moves the group's place
        let moved_by = g.offset.filter(|(low, high)| low >= high).map_or(0.0, |(low, _)| low);
        let row_start = first.map_or(0.0, |f| f.lateral);
        let mut actors = Vec::new();
        let n = kept.get(i).copied().unwrap_or(gl.agents.len());
        for (k, a) in gl.agents.iter().take(n).enumerate() {
            let ident = if n == 1 && g.count == 1 {
                names.fresh(&g.name)
            } else {
                names.fresh(&format!("{}_{}", g.name, k + 1))
            };
            let (arm, offset) = if junction || a.station.arm == Arm::Ego {
                // on another arm a spot is never inside the junction (a walker's may be)
                let inside = a.station.arm != Arm::Ego && a.facing == Facing::Along;
                let along = a.station.along + moved_by;
                (a.station.arm, if inside { along.max(0.0) } else { along })
            } else {
                // no junction on the map: beyond where it would be, on the ego's road
                (Arm::Ego, laid.road.approach + a.station.along + moved_by + 10.0)
            };
            let cross = match a.facing {
                Facing::Across { from } => Some((from == Side::Right, (a.lateral - row_start).abs())),
                Facing::Along => None,
            };
            actors.push(Actor {
                ident,
                class,
                blueprint: g.mapping.blueprint.clone(),
                is_ego: false,
                adversary: conflict.is_some(),
                length: g.length,
                width: g.width,
                lane: a.lane,
                arm,
                offset,
                place: a.place,
                cross,
                motion: g.motion,
                target_speed: g.speed,
                initial_speed: if a.moving && class == Class::Car && !params.waits() { g.speed } else { 0.0 },
                params: params.clone(),
            });
        }
        out.push(Group { summary: g.summary.clone(), actors });
    }
    Actors { ego: ego_actor, ego_summary: ego_summary(scenario, ego.lane), groups: out }
}

/// How an adversary of group `g` (`first` its first actor) is timed on the map: waiting for
/// the ego (`TadMeet`), or started moving from where the map's junction puts it on time
/// (`tadOnTime`); neither for the rest.
fn timing(
    first: &tad_layout::Agent,
    g: &Resolved,
    laid: &Layout,
    ego: &EgoPlan,
    conflict: bool,
    junction: bool,
) -> (Option<MeetPlan>, Option<OnTime>) {
    let vehicle = first.body == tad_layout::Body::Vehicle && first.facing == Facing::Along;
    // an adversary waiting for the ego meets it on the map's own ways: its maneuver (a
    // crosser goes straight across) and the ego's, through the junction the map kept;
    // without the junction the ego's way is its lane onward: a walker's crossing of the
    // road still meets it, a vehicle's way from another arm may not
    let meet = (first.start.meet.is_some() && g.delay.is_none())
        .then_some(first)
        .filter(|f| junction || laid.ego.turn == tad_layout::Turn::Straight || f.facing != Facing::Along)
        .map(|f| MeetPlan {
            own: vehicle.then(|| letter(f.turn)).filter(|_| junction),
            ego: Some(letter(laid.ego.turn)).filter(|_| junction),
        });
    // an adversary on another arm started moving, on time on the layout's junction: on the
    // map's junction the same rule places it again
    let on_time = (first.start.meet.is_none() && first.moving && conflict && vehicle)
        .then_some(first)
        .filter(|f| junction && laid.ego.moving && f.station.arm != Arm::Ego && f.lane > 0)
        .filter(|_| g.delay.is_none() && g.trigger.is_none() && g.offset.is_none())
        .map(|f| OnTime {
            arm: f.station.arm,
            lane: f.lane,
            own: letter(f.turn),
            ego: letter(laid.ego.turn),
            reach: (ego.width + f.width) / 2.0 + tad_layout::MEET_MARGIN,
            before: f.station.along,
        });
    (meet, on_time)
}

/// `ego vehicle: BEHAVIOR, SPEED, lane N`, for a comment.
fn ego_summary(scenario: &Scenario, lane: i64) -> String {
    let mut parts = Vec::new();
    if let Some(b) = scenario.ego.behavior.given() {
        let names: Vec<&str> = b.values().into_iter().map(|n| scenario.entries.name(n)).collect();
        parts.push(names.join(" | "));
    }
    if let Some(speed) = scenario.ego.speed.given() {
        parts.push(super::groups::speed_text(speed));
    }
    parts.push(format!("lane {lane}"));
    format!("ego vehicle: {}", parts.join(", "))
}

/// A turn as the map table's maneuver letter (`mapping::maneuver`).
fn letter(turn: tad_layout::Turn) -> char {
    match turn {
        tad_layout::Turn::Straight => 'S',
        tad_layout::Turn::Left => 'L',
        tad_layout::Turn::Right => 'R',
        tad_layout::Turn::UTurn => 'U',
    }
}
