//! The steps from a resolved scenario to a [`Layout`] (`spec/layout.md` §3–§6):
//!
//! 1. facts of the ego and every group (`crate::facts`);
//! 2. arms: which road of the junction each group is on, from its relation and lane (a side
//!    relation in the reference's own lane is the crossing arm on that side at a junction and
//!    the adjacent lane elsewhere; an opposite lane ahead is the opposite arm);
//! 3. the road: shape, lanes, the junction's arms (a three-way junction keeps the arms the
//!    scenario uses), sidewalks and crosswalks;
//! 4. stations on the ego's road, in placement order, each group beyond its reference with a
//!    gap that grows with speed, never overlapping what is already there; crossing groups on
//!    the sidewalk, spread along it; then the ego's approach to the junction (a queue ahead
//!    ends at the stop line; a moving ego is about three seconds away);
//! 5. stations on the other arms, from their stop lines;
//! 6. paths: through the junction by each vehicle's turn, lane changes, overtaking, walking
//!    across;
//! 7. timing: every moving group whose path meets the ego's ahead starts where it reaches
//!    that point when the ego does at its stated speed (crossing walkers wait instead), kept
//!    on the side of its reference that its relation says.

use std::collections::HashMap;

use tad_ir::{GroupId, Lane, Lateral, Longitudinal, Motion, Reference, Scenario, Span};

use crate::facts::{self, Body, Chosen, Facts};
use crate::geom::{Path, Pose, Vec2};
use crate::road::{self, Arm, CROSSWALK, Junction, Road, Shape, Side, Station, Turn};
use crate::{Agent, Conflict, Facing, Finding, GroupLayout, Layout, Place, Start};

/// The farthest from the ego anything is put by timing or a late walker, m.
const MAX_REACH: f64 = 150.0;
/// How long a moving ego takes to reach its stop line, s.
const APPROACH_TIME: f64 = 2.0;
/// The farthest a timed adversary starts from its arm's stop line, m; one that would need
/// more waits there and starts late.
const MAX_ARM_START: f64 = 150.0;
/// Spacing of walkers standing side by side.
const WALKER_SPACING: f64 = 0.9;

/// What a group's position resolves to.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Ego,
    Group(usize),
}

#[derive(Clone, Debug)]
struct Decision {
    arm: Arm,
    lane: i64,
    place: Place,
    facing: Facing,
    target: Target,
    longitudinal: Longitudinal,
    crosser: bool,
    /// At the curb on the road's left (past its leftmost lane) rather than its right.
    curb_left: bool,
    /// A written `distance`: (low, high).
    distance: Option<(f64, f64)>,
    span: Span,
}

fn turn_of(motion: Option<Motion>) -> Turn {
    match motion {
        Some(Motion::TurnLeft) => Turn::Left,
        Some(Motion::TurnRight) => Turn::Right,
        Some(Motion::UTurn) => Turn::UTurn,
        _ => Turn::Straight,
    }
}

/// The layout of a resolved scenario.
pub fn lay_out(scenario: &Scenario) -> Layout {
    let mut chosen: Vec<Chosen> = Vec::new();
    let mut findings: Vec<Finding> = Vec::new();
    let scenario_span = scenario.name.as_ref().map_or(scenario.span, |n| n.span);
    let ego_section = scenario.ego.span.unwrap_or(scenario_span);
    let ego_facts = facts::ego(scenario, ego_section, &mut chosen);
    let group_facts: Vec<Facts> = scenario.groups().map(|(id, g)| facts::group(scenario, id, g, &mut chosen)).collect();
    for (id, g) in scenario.groups() {
        let f = &group_facts[id.index()];
        if f.wanted > f.count {
            findings.push(Finding::Capped {
                group: id,
                wanted: f.wanted,
                placed: f.count,
                span: g.count.span().unwrap_or(g.name_span),
            });
        }
    }

    // --- the ego's lane and the road's lanes
    let written_lanes = scenario.road.lanes.get().filter(|n| *n >= 1).map(|n| n.min(12) as u32);
    let ego_lane = match scenario.ego.lane.get() {
        Some(l) if l.index() > 0 => l.index().min(12),
        Some(_) => 1,
        None => {
            let lane = written_lanes.map_or(1, |n| i64::from(n.div_ceil(2)));
            chosen.push(Chosen {
                group: None,
                field: "lane",
                value: format!("lane {lane}"),
                span: scenario.ego.lane.span().unwrap_or(ego_section),
                rule: "the middle lane (the left one of the two middle lanes)",
            });
            lane
        }
    };
    let one_way =
        scenario.road.direction.given().and_then(|d| scenario.entries.resolved(d)).and_then(|e| e.attrs.opposite_lanes)
            == Some(false);
    let used = |positive: bool| {
        scenario
            .groups
            .iter()
            .filter_map(|g| g.lane.get().map(Lane::index))
            .chain([ego_lane])
            .filter(|l| (*l > 0) == positive)
            .map(|l| l.unsigned_abs().min(12) as u32)
            .max()
            .unwrap_or(0)
    };
    let lanes = written_lanes.unwrap_or_else(|| used(true).max(1)).max(ego_lane as u32);
    let opposite = if one_way { 0 } else { lanes.max(used(false)) };

    // --- the road's kind
    let road_type = scenario.road.road_type.given().and_then(|t| scenario.entries.resolved(t)).map(|e| e.attrs);
    let at_junction = scenario.groups.iter().any(|g| {
        g.position.given().is_some_and(|p| match &p.reference.value {
            Reference::RoadElement(id) => scenario.entries.get(*id).is_some_and(|e| e.attrs.at_junction),
            _ => false,
        })
    });
    let shape = match road_type {
        Some(t) if t.shape == Some(tad_ir::RoadShape::Roundabout) => Shape::Junction { arms: 4, roundabout: true },
        Some(t) if t.junction => Shape::Junction { arms: if t.arms == Some(3) { 3 } else { 4 }, roundabout: false },
        Some(t) if t.shape == Some(tad_ir::RoadShape::Curved) => Shape::Curve { left: true },
        _ if at_junction => Shape::Junction { arms: 4, roundabout: false },
        _ => Shape::Straight,
    };
    // a light that shows something stands at a junction ahead, whatever the road's shape
    let lit = scenario
        .road
        .light
        .given()
        .and_then(|l| scenario.entries.resolved(l))
        .is_some_and(|e| e.attrs.present && e.attrs.signal.is_some());
    // so do signs that belong to a junction, and the ego's turn
    let junction_sign = scenario.road.signs.given().is_some_and(|signs| {
        signs.iter().any(|s| scenario.entries.resolved(&s.value).is_some_and(|e| e.attrs.opendrive_type.is_some()))
    });
    let turning = matches!(ego_facts.motion, Some(Motion::TurnLeft | Motion::TurnRight | Motion::UTurn));
    let junction_road = matches!(shape, Shape::Junction { .. }) || lit || junction_sign || turning;

    // --- decisions: arm, lane, place, facing, in placement order
    let ids: Vec<GroupId> = scenario.groups().map(|(id, _)| id).collect();
    let order: Vec<usize> = scenario.placement_order.iter().map(|id| id.index()).collect();
    let mut decisions: Vec<Option<Decision>> = vec![None; scenario.groups.len()];
    for &i in &order {
        let group = &scenario.groups[i];
        let id = ids[i];
        let f = &group_facts[i];
        let crosser = f.motion == Some(Motion::Cross) && f.body != Body::Object;
        let (target, lateral, longitudinal) = match group.position.given() {
            None => {
                chosen.push(Chosen {
                    group: Some(id),
                    field: "position",
                    value: "`front of ego`".into(),
                    span: group.position.span().unwrap_or(group.name_span),
                    rule: "in front of the ego vehicle when the position is not known",
                });
                (Target::Ego, Lateral::Same, Longitudinal::Front)
            }
            Some(p) => {
                let relation = scenario.entries.resolved(&p.relation.value).map(|r| r.attrs);
                let target = match &p.reference.value {
                    Reference::Group(j) if j.index() != i && decisions[j.index()].is_some() => Target::Group(j.index()),
                    _ => Target::Ego,
                };
                (
                    target,
                    relation.and_then(|r| r.lateral).unwrap_or(Lateral::Same),
                    relation.and_then(|r| r.longitudinal).unwrap_or(Longitudinal::Same),
                )
            }
        };
        let (ref_arm, ref_lane) = match target {
            Target::Ego => (Arm::Ego, ego_lane),
            Target::Group(j) => decisions[j].as_ref().map_or((Arm::Ego, ego_lane), |d| (d.arm, d.lane)),
        };
        let written = group.lane.get().map(Lane::index);
        let moving_vehicle = f.body == Body::Vehicle && !f.is_static();
        let side_arm = match lateral {
            Lateral::Left => Some(Arm::Left),
            Lateral::Right => Some(Arm::Right),
            _ => None,
        };
        let mut arm = ref_arm;
        let mut lane;
        let mut place = Place::Lane;
        let mut curb_left = false;
        if junction_road
            && ref_arm == Arm::Ego
            && side_arm.is_some()
            && written.is_none_or(|l| l == ref_lane)
            && (moving_vehicle || crosser)
            && longitudinal != Longitudinal::Behind
        {
            // from the left or the right: the crossing arm on that side
            arm = side_arm.unwrap_or(Arm::Left);
            lane = written.map_or(1, i64::abs).min(i64::from(lanes));
        } else if junction_road
            && ref_arm == Arm::Ego
            && moving_vehicle
            && longitudinal == Longitudinal::Front
            && (lateral == Lateral::Opposite || written.is_some_and(|l| l < 0))
        {
            // oncoming: the opposite arm, coming into the junction
            arm = Arm::Opposite;
            lane = written.map_or(1, i64::abs);
        } else {
            // a lane written for a group on the opposite arm counts on the ego's road
            let written = if arm == Arm::Opposite { written.map(|l| -l) } else { written };
            let ref_lane = Lane::new(ref_lane).unwrap_or(Lane::new(1).expect("1 is a lane"));
            lane = match written {
                Some(l) if l != ref_lane.index() || lateral == Lateral::Same || lateral == Lateral::Opposite => l,
                _ => match lateral {
                    Lateral::Left => ref_lane.shift(-1).index(),
                    Lateral::Right => ref_lane.shift(1).index(),
                    Lateral::Opposite => -ref_lane.index(),
                    Lateral::Same => ref_lane.index(),
                },
            };
            let (incoming, outgoing) = match arm {
                Arm::Ego => (lanes, opposite),
                Arm::Opposite => (opposite.max(1), lanes),
                _ => (lanes, lanes),
            };
            if lane > i64::from(incoming) {
                lane = i64::from(incoming);
                place = Place::Shoulder;
            } else if lane < 0 && lane < -i64::from(outgoing) {
                curb_left = outgoing == 0;
                lane = if outgoing == 0 { 1 } else { -i64::from(outgoing) };
                place = Place::Shoulder;
            }
            if one_way && arm == Arm::Ego && lane < 0 {
                lane = 1;
                place = Place::Shoulder;
                curb_left = true;
            }
        }
        if written.is_none() {
            chosen.push(Chosen {
                group: Some(id),
                field: "lane",
                value: format!("lane {lane}"),
                span: group.lane.span().unwrap_or(group.name_span),
                rule: "from the position's relation and the lane of its reference",
            });
        }
        let outermost = |arm: Arm, lane: i64| {
            let (incoming, outgoing) = if arm == Arm::Ego { (lanes, opposite) } else { (lanes, lanes) };
            lane == i64::from(incoming) || lane == -i64::from(outgoing) || (outgoing == 0 && lane == 1)
        };
        match f.motion {
            Some(Motion::Parked) if f.body != Body::Object && outermost(arm, lane) => {
                place = Place::Curb;
                // lane 1 of a one-way road of several lanes has its curb on the left
                curb_left |= one_way && arm == Arm::Ego && lane == 1 && lanes > 1;
            }
            Some(Motion::Walk) if f.body == Body::Walker => place = Place::Sidewalk,
            Some(Motion::Graze) if outermost(arm, lane) => place = Place::Curb,
            _ => {}
        }
        let facing = if crosser {
            place = Place::Sidewalk;
            // at a junction arm, from the side its outgoing lanes are on; on the ego's road,
            // from the side of the lane written
            let from = if arm != Arm::Ego || lane < 0 { Side::Left } else { Side::Right };
            Facing::Across { from }
        } else {
            Facing::Along
        };
        let distance = group.distance.given().map(|p| (p.min().0.max(0.0), p.max().0.max(0.0)));
        decisions[i] = Some(Decision {
            arm,
            lane,
            place,
            facing,
            target,
            longitudinal,
            crosser,
            curb_left,
            distance,
            span: group.position.given().map_or(group.name_span, |p| p.relation.span),
        });
    }

    // --- the junction's arms
    let ego_turn = turn_of(ego_facts.motion);
    let junction_shape = match shape {
        Shape::Junction { arms, roundabout } => Some((arms, roundabout)),
        _ if junction_road => Some((4, false)),
        _ => None,
    };
    let junction = match junction_shape {
        Some((arms, roundabout)) => {
            let mut needed: Vec<Arm> = decisions.iter().flatten().map(|d| d.arm).collect();
            needed.push(ego_turn.exit(Arm::Ego));
            let arms_of = if arms == 3 {
                let missing = [Arm::Opposite, Arm::Left, Arm::Right]
                    .into_iter()
                    .find(|a| !needed.contains(a))
                    .unwrap_or(Arm::Opposite);
                Arm::ALL.into_iter().filter(|a| *a != missing).collect()
            } else {
                Arm::ALL.to_vec()
            };
            let widest = lanes.max(opposite).max(1);
            let signal = scenario.road.light.given().and_then(|l| scenario.entries.resolved(l)).map(|e| e.attrs);
            Some(Junction {
                arms: arms_of,
                roundabout,
                half: widest as f64 * road::LANE_WIDTH + 1.0 + 3.5,
                signalised: signal.is_some_and(|s| s.present),
                stop_signs: scenario.road.signs.given().is_some_and(|signs| {
                    signs.iter().any(|s| {
                        scenario.entries.resolved(&s.value).and_then(|e| e.attrs.opendrive_type) == Some(STOP_SIGN)
                    })
                }),
            })
        }
        None => None,
    };
    for (i, d) in decisions.iter_mut().enumerate() {
        let Some(d) = d else { continue };
        if junction.as_ref().is_some_and(|j| !j.arms.contains(&d.arm)) {
            findings.push(Finding::NoArm { group: ids[i], arm: d.arm, span: d.span });
            d.arm = Arm::Ego;
            d.lane = d.lane.abs().min(i64::from(lanes)).max(1);
        }
    }
    let walkway = scenario.road.roadside.given().is_some_and(|r| {
        r.iter().any(|s| s.value.id().and_then(|id| scenario.entries.get(id)).is_some_and(|e| e.attrs.walkway))
    });
    let walkers = group_facts.iter().any(|f| f.body == Body::Walker);
    let mut road = Road {
        shape,
        lanes,
        opposite,
        cross_lanes: lanes,
        lane_width: road::LANE_WIDTH,
        sidewalks: walkway || walkers,
        crosswalks: junction.is_some() || decisions.iter().flatten().any(|d| d.crosser),
        signal: scenario.road.light.given().and_then(|l| scenario.entries.resolved(l)).and_then(|e| e.attrs.signal),
        junction,
        approach: 0.0,
    };

    // --- stations on the ego's road, then the approach, then the other arms
    let mut occupied: Occupied = HashMap::new();
    let ego_len = ego_facts.length;
    occupied.entry((Arm::Ego, Key::Lane(ego_lane))).or_default().push((-ego_len / 2.0, ego_len / 2.0, ego_facts.speed));
    let mut stations: Vec<Vec<(Station, f64)>> = vec![Vec::new(); scenario.groups.len()];
    let mut slack = vec![0.0; scenario.groups.len()];
    let ego_extent = Extent {
        lane: ego_lane,
        stop_line: false,
        low: -ego_len / 2.0,
        high: ego_len / 2.0,
        forward: 1.0,
        speed: ego_facts.speed,
    };
    let place_arm = |on_ego: bool,
                     road: &Road,
                     stations: &mut Vec<Vec<(Station, f64)>>,
                     slack: &mut Vec<f64>,
                     occupied: &mut Occupied| {
        for &i in &order {
            let Some(d) = decisions[i].as_ref() else { continue };
            if (d.arm == Arm::Ego) != on_ego {
                continue;
            }
            let f = &group_facts[i];
            let reference = match d.target {
                Target::Group(j)
                    if decisions[j].as_ref().is_some_and(|r| r.arm == d.arm) && !stations[j].is_empty() =>
                {
                    let r = decisions[j].as_ref();
                    let across = r.is_some_and(|r| r.crosser);
                    let rf = &group_facts[j];
                    let half = if across { rf.width.max(0.5) / 2.0 } else { rf.length / 2.0 };
                    extent_of(&stations[j], half, rf.speed, r.map_or(1, |r| r.lane), d.arm)
                }
                _ if d.arm == Arm::Ego => ego_extent,
                _ => Extent::stop_line(),
            };
            // a crossing ahead of a moving ego, on a road without a junction, is where the
            // walkers reach the ego's lane when the ego does
            let mut min_first = f64::NEG_INFINITY;
            if d.crosser
                && d.arm == Arm::Ego
                && road.junction.is_none()
                && d.target == Target::Ego
                && d.distance.is_none()
                && f.speed > 0.0
                && !ego_facts.is_static()
            {
                let start = road.curb(match d.facing {
                    Facing::Across { from } => from,
                    _ => Side::Right,
                });
                let walk = ((start - road.lateral(ego_lane)).abs() + 1.0) / f.speed;
                min_first = (ego_facts.speed * walk + ego_len / 2.0).min(MAX_REACH);
            }
            let (placed, room) = place_group(road, d, f, reference, min_first, occupied);
            stations[i] = placed;
            slack[i] = room;
        }
    };
    place_arm(true, &road, &mut stations, &mut slack, &mut occupied);
    if road.junction.is_some() {
        // a queue ahead waits at the stop line; a moving ego is a few seconds away
        let ahead: Vec<(f64, bool, bool)> = decisions
            .iter()
            .enumerate()
            .filter(|(_, d)| d.as_ref().is_some_and(|d| d.arm == Arm::Ego && !d.crosser))
            .flat_map(|(i, d)| {
                let f = &group_facts[i];
                // moving traffic in the opposite lanes comes from the opposite arm; what stands
                // there is before the junction too
                let incoming = d.as_ref().is_some_and(|d| d.lane > 0);
                if !incoming && !f.is_static() {
                    return Vec::new();
                }
                let queued = incoming && f.is_static() && f.motion != Some(Motion::Parked) && f.body == Body::Vehicle;
                // what turns at the junction is before it too (only straight traffic moves across)
                let before = f.is_static() || turn_of(f.motion) != Turn::Straight || road.opposite == 0;
                stations[i].iter().map(|(s, _)| (s.along + f.length / 2.0, before, queued)).collect()
            })
            .filter(|(front, _, _)| *front > 0.0)
            .collect();
        // moving traffic ahead drives on through the junction; what stands waits before it
        // a queue of stopped vehicles ends at the stop line; what stands elsewhere stays
        // before it
        let front = |which: fn(&(f64, bool, bool)) -> bool| {
            ahead.iter().filter(|a| which(a)).map(|a| a.0).fold(ego_len / 2.0, f64::max)
        };
        let queue = ahead.iter().any(|a| a.2);
        // on a one-way road the road across the junction may not go on: all of it waits
        let standing = if road.opposite == 0 { front(|_| true) + 1.0 } else { 0.0 };
        let standing = standing.max(front(|a| a.1) + 1.0);
        let base = (ego_facts.speed * APPROACH_TIME).clamp(6.0, 40.0) + ego_len / 2.0;
        road.approach = if queue { front(|a| a.2) + 1.0 } else { base }.max(standing).max(6.0);
        // crossers on the ego's road near the junction use its crosswalk
        for (i, d) in decisions.iter().enumerate() {
            let Some(d) = d.as_ref().filter(|d| d.arm == Arm::Ego && d.crosser) else { continue };
            let Some(first) = stations[i].first().map(|(s, _)| s.along) else { continue };
            if first > road.approach - 8.0 || d.target == Target::Ego {
                let shift = road.approach + CROSSWALK - first;
                for (s, _) in &mut stations[i] {
                    s.along += shift;
                }
            }
        }
    }
    if let Some(half) =
        road.junction.as_ref().filter(|j| j.arms.contains(&Arm::Opposite) && road.opposite > 0).map(|j| j.half)
    {
        // moving traffic ahead past the stop line is already across the junction: all of it
        // moves on by the same distance, so that none is inside the junction and their
        // relations hold
        let beyond = |i: usize| {
            let f = &group_facts[i];
            decisions[i].as_ref().is_some_and(|d| d.arm == Arm::Ego && d.lane > 0 && !d.crosser)
                && !f.is_static()
                && f.body == Body::Vehicle
                && turn_of(f.motion) == Turn::Straight
        };
        let exit = road.approach + 2.0 * half;
        let mut push: f64 = 0.0;
        for i in (0..stations.len()).filter(|&i| beyond(i)) {
            let len = group_facts[i].length;
            for (s, _) in stations[i].iter().filter(|(s, _)| s.along + len / 2.0 > road.approach - 0.5) {
                push = push.max(exit + len / 2.0 + 0.5 - s.along);
            }
        }
        for i in (0..stations.len()).filter(|&i| beyond(i)) {
            let f = &group_facts[i];
            let lane = decisions[i].as_ref().map_or(1, |d| d.lane);
            for (s, _) in stations[i].iter_mut().filter(|(s, _)| s.along + f.length / 2.0 > road.approach - 0.5) {
                let along = s.along + push - exit;
                *s = Station { arm: Arm::Opposite, along };
                occupied.entry((Arm::Opposite, Key::Lane(-lane))).or_default().push((
                    along - f.length / 2.0,
                    along + f.length / 2.0,
                    f.speed,
                ));
            }
        }
    }
    place_arm(false, &road, &mut stations, &mut slack, &mut occupied);
    // --- agents, paths and timing; a walker that cannot reach a junction's crossing in
    // time moves the ego's start back
    let mut built = build(scenario, &road, &decisions, &group_facts, &stations, &slack, &ids, ego_lane, &ego_facts);
    for _ in 0..3 {
        if road.junction.is_none() || built.late <= 0.05 {
            break;
        }
        let delta = (built.late * ego_facts.speed + 1.0).min(MAX_REACH - road.approach);
        if delta <= 0.0 {
            break;
        }
        road.approach += delta;
        // walkers at the ego's crosswalk stay at it
        for (i, d) in decisions.iter().enumerate() {
            if d.as_ref().is_some_and(|d| d.arm == Arm::Ego && d.crosser) {
                for (s, _) in &mut stations[i] {
                    s.along += delta;
                }
            }
        }
        built = build(scenario, &road, &decisions, &group_facts, &stations, &slack, &ids, ego_lane, &ego_facts);
    }
    let Built { ego, groups, conflicts, .. } = built;

    findings.extend(chosen.into_iter().map(Finding::Chosen));
    Layout { road, ego, ego_facts, groups, conflicts, findings }
}

struct Built {
    ego: Agent,
    groups: Vec<GroupLayout>,
    conflicts: Vec<Conflict>,
    /// How late the latest crossing walker is for its conflict, s.
    late: f64,
}

#[allow(clippy::too_many_arguments)]
fn build(
    scenario: &Scenario,
    road: &Road,
    decisions: &[Option<Decision>],
    group_facts: &[Facts],
    stations: &[Vec<(Station, f64)>],
    slack: &[f64],
    ids: &[GroupId],
    ego_lane: i64,
    ego_facts: &Facts,
) -> Built {
    let ego_len = ego_facts.length;
    let ego_turn = turn_of(ego_facts.motion);
    let ego_station = Station { arm: Arm::Ego, along: 0.0 };
    let mut ego = Agent {
        group: None,
        index: 0,
        body: Body::Vehicle,
        length: ego_len,
        width: ego_facts.width,
        station: ego_station,
        lane: ego_lane,
        place: Place::Lane,
        lateral: road.lateral(ego_lane),
        facing: Facing::Along,
        motion: ego_facts.motion,
        turn: ego_turn,
        speed: if ego_facts.is_static() { 0.0 } else { ego_facts.speed },
        moving: !ego_facts.is_static(),
        start: Start::default(),
        pose: road.lane_pose(ego_station, ego_lane),
        path: Path::default(),
        path_start: 0.0,
    };
    let mut groups: Vec<GroupLayout> = Vec::new();
    for (i, group) in scenario.groups.iter().enumerate() {
        let f = group_facts[i].clone();
        let Some(d) = decisions[i].as_ref() else { continue };
        let delay = group.delay.given().map_or(0.0, |p| p.nominal().0.max(0.0));
        let trigger = group.trigger.given().map(|p| p.nominal().0.max(0.0));
        let waits = delay > 0.0 || trigger.is_some();
        let agents = stations[i]
            .iter()
            .enumerate()
            .map(|(k, &(station, lateral))| {
                // moved across the junction: an outgoing lane of the opposite arm
                let moved = station.arm != d.arm;
                let lane = if moved { -d.lane } else { d.lane };
                let lateral = if moved { road.lateral(lane) } else { lateral };
                let yaw_of = |pose: Pose| match d.facing {
                    Facing::Along => pose.yaw,
                    Facing::Across { from } => {
                        let base = if station.arm == Arm::Ego { road.lane_pose(station, 1).yaw } else { pose.yaw };
                        let base = if station.arm != Arm::Ego && lane < 0 { base + std::f64::consts::PI } else { base };
                        match from {
                            Side::Right => base + std::f64::consts::FRAC_PI_2,
                            Side::Left => base - std::f64::consts::FRAC_PI_2,
                        }
                    }
                };
                let pose = road.pose_at(station, if d.crosser { 1 } else { lane }, lateral);
                let pose = Pose { yaw: yaw_of(pose), ..pose };
                Agent {
                    group: Some(ids[i]),
                    index: k,
                    body: f.body,
                    length: f.length,
                    width: f.width,
                    station,
                    lane,
                    place: d.place,
                    lateral,
                    facing: d.facing,
                    motion: f.motion,
                    turn: turn_of(f.motion),
                    speed: if f.is_static() { 0.0 } else { f.speed },
                    moving: !f.is_static() && !waits && f.body == Body::Vehicle,
                    start: Start { delay, trigger },
                    pose,
                    path: Path::default(),
                    path_start: 0.0,
                }
            })
            .collect();
        groups.push(GroupLayout { group: ids[i], facts: f, agents, slack: slack[i] });
    }
    let obstacles: Vec<(i64, f64, f64)> = groups
        .iter()
        .flat_map(|g| &g.agents)
        .filter(|a| {
            a.is_static() && a.station.arm == Arm::Ego && a.place != Place::Sidewalk && a.facing == Facing::Along
        })
        .map(|a| (a.lane, a.station.along - a.length / 2.0, a.station.along + a.length / 2.0))
        .collect();
    paths(road, &mut ego, &obstacles);
    for g in &mut groups {
        for a in &mut g.agents {
            paths(road, a, &obstacles);
        }
    }

    // --- timing
    let mut conflicts = Vec::new();
    let mut late: f64 = 0.0;
    if ego.moving && ego.speed > 0.5 {
        for (i, g) in groups.iter_mut().enumerate() {
            let Some(d) = decisions[i].as_ref() else { continue };
            let written_timing =
                d.distance.is_some() || scenario.groups[i].delay.is_given() || scenario.groups[i].trigger.is_given();
            if written_timing || g.facts.is_static() || g.agents.is_empty() {
                continue;
            }
            if let Some((conflict, lateness)) = time_group(road, &ego, d, g) {
                conflicts.push(conflict);
                late = late.max(lateness);
            }
        }
    }

    Built { ego, groups, conflicts, late }
}

/// What is taken along each arm and lane: (from, to, speed of what is there).
type Occupied = HashMap<(Arm, Key), Vec<(f64, f64, f64)>>;

/// OpenDRIVE's signal type of a stop sign.
const STOP_SIGN: i64 = 206;

/// What is occupied along an arm: a lane (centre or curb), or a sidewalk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    Lane(i64),
    Sidewalk(Side),
}

/// What a group is placed relative to: an interval of stations on an arm.
#[derive(Clone, Copy, Debug)]
struct Extent {
    /// The lane it is in (what stands in another lane needs no room to brake for it).
    lane: i64,
    /// It is an arm's stop line: groups extend from it away from the junction.
    stop_line: bool,
    low: f64,
    high: f64,
    /// The way its front faces, in stations (+1 or -1).
    forward: f64,
    speed: f64,
}

impl Extent {
    /// An arm's stop line: its incoming traffic's front is towards smaller stations.
    fn stop_line() -> Extent {
        Extent { lane: 0, stop_line: true, low: 0.0, high: 0.0, forward: 1.0, speed: 0.0 }
    }
}

/// The way a lane's traffic drives, in stations.
fn forward_of(arm: Arm, lane: i64) -> f64 {
    if (arm == Arm::Ego) == (lane > 0) { 1.0 } else { -1.0 }
}

fn extent_of(stations: &[(Station, f64)], half: f64, speed: f64, lane: i64, arm: Arm) -> Extent {
    let low = stations.iter().map(|(s, _)| s.along).fold(f64::INFINITY, f64::min);
    let high = stations.iter().map(|(s, _)| s.along).fold(f64::NEG_INFINITY, f64::max);
    Extent { lane, stop_line: false, low: low - half, high: high + half, forward: forward_of(arm, lane), speed }
}

/// The gap kept in front of a vehicle moving at `speed` (IDM's jam distance and one second
/// of headway), or between standing actors.
fn gap(f: &Facts, other_speed: f64) -> f64 {
    if other_speed > 0.0 && f.is_static() {
        // standing in front of something moving: room to see it and brake
        return (2.0 + 1.5 * other_speed).min(40.0);
    }
    match f.body {
        Body::Walker => WALKER_SPACING - f.length.min(0.5),
        Body::Object => 1.0,
        Body::Vehicle if f.motion == Some(Motion::Parked) => 1.0,
        Body::Vehicle if f.is_static() && other_speed <= 0.0 => 1.5,
        Body::Vehicle => (2.0 + f.speed.max(other_speed)).min(30.0),
    }
}

/// Place a group's actors (stations and lateral offsets) beyond its reference; returns them
/// and the free room kept between the group and its reference.
fn place_group(
    road: &Road,
    d: &Decision,
    f: &Facts,
    reference: Extent,
    min_first: f64,
    occupied: &mut Occupied,
) -> (Vec<(Station, f64)>, f64) {
    let forward = reference.forward;
    // the way the group extends from its reference, in stations
    let step = match d.longitudinal {
        _ if reference.stop_line => 1.0,
        Longitudinal::Behind => -forward,
        _ => forward,
    };
    let across = matches!(d.facing, Facing::Across { .. });
    let extent = if across { f.width.max(0.5) } else { f.length };
    let spacing = if across { WALKER_SPACING.max(f.width + 0.3) } else { f.length + gap(f, f.speed) };
    let lead = match d.distance {
        Some((_, high)) => high,
        None if (reference.speed <= 0.0 || reference.lane != d.lane) && f.is_static() => gap(f, 0.0),
        None if across => 1.0,
        None if reference.stop_line && !f.is_static() => 1.0 + 0.5 * f.speed,
        None if reference.stop_line => 1.0,
        None => gap(f, reference.speed),
    };
    let room = match d.distance {
        Some((low, high)) => high - low,
        None => (lead * 0.25).min(5.0),
    };
    let lead = if d.distance.is_some() { lead } else { lead + room };
    let edge = if step > 0.0 { reference.high } else { reference.low };
    let first = match d.longitudinal {
        _ if reference.stop_line && across => -CROSSWALK,
        Longitudinal::Same if !reference.stop_line => (reference.low + reference.high) / 2.0,
        _ => edge + step * (lead + extent / 2.0),
    };
    // on another arm nothing stands inside the junction: what would, goes behind its reference
    let (first, step) = if d.arm != Arm::Ego && !across && first - extent / 2.0 < 0.5 {
        (reference.high.max(0.0) + lead + extent / 2.0, 1.0)
    } else {
        (first, step)
    };
    // walkers across stand in rows of four along the sidewalk, further back row by row
    let side_lateral = |side: Side, row: usize| {
        let curb = match (d.arm, side) {
            (Arm::Ego, s) => road.curb(s),
            (arm, Side::Right) => -(road.arm_lanes(arm).0 as f64) * road.lane_width,
            (arm, Side::Left) => road.arm_lanes(arm).1 as f64 * road.lane_width,
        };
        let out = if road.sidewalks { 0.6 + road::SIDEWALK_WIDTH * 0.3 } else { 0.6 }
            + f.length / 2.0
            + row as f64 * (f.length + 0.3);
        if side == Side::Right { curb - out } else { curb + out }
    };
    let lane_lateral = |place: Place| {
        let centre = road.lateral(d.lane);
        match place {
            Place::Lane => centre,
            Place::Curb | Place::Shoulder => {
                let shift = if place == Place::Shoulder {
                    road.lane_width / 2.0 + f.width / 2.0 + 0.2
                } else {
                    (road.lane_width / 2.0 - f.width / 2.0 - 0.2).max(0.0)
                };
                // the curb is to the right of a lane's own traffic
                let outward = if d.lane > 0 && !d.curb_left { -1.0 } else { 1.0 };
                centre + outward * shift
            }
            Place::Sidewalk => side_lateral(if d.lane > 0 { Side::Right } else { Side::Left }, 0),
        }
    };
    let key = match (d.facing, d.place) {
        (Facing::Across { from }, _) => Key::Sidewalk(from),
        (_, Place::Sidewalk) => Key::Sidewalk(if d.lane > 0 { Side::Right } else { Side::Left }),
        _ => Key::Lane(d.lane),
    };
    if across {
        // the strip the walkers cross is clear in every lane of the arm: move it on until it is
        let columns = f.count.min(4) as f64;
        let strip = |first: f64| {
            let ends =
                [first - step * (extent / 2.0 + 0.3), first + step * ((columns - 1.0) * spacing + extent / 2.0 + 0.3)];
            (ends[0].min(ends[1]), ends[0].max(ends[1]))
        };
        let mut first_at = if step > 0.0 { first.max(min_first) } else { first };
        for _ in 0..200 {
            let (lo, hi) = strip(first_at);
            let blocking = occupied
                .iter()
                .filter(|((arm, key), _)| *arm == d.arm && matches!(key, Key::Lane(_)))
                .flat_map(|(_, list)| list.iter())
                .filter(|(a, b, _)| lo < *b && *a < hi)
                .map(|(a, b, _)| if step > 0.0 { *b } else { *a })
                .fold(None::<f64>, |m, e| Some(m.map_or(e, |m| if step > 0.0 { m.max(e) } else { m.min(e) })));
            match blocking {
                Some(edge) => first_at = edge + step * (extent / 2.0 + 0.6),
                None => break,
            }
        }
        let (lo, hi) = strip(first_at);
        let (incoming, outgoing) = road.arm_lanes(d.arm);
        for lane in (-i64::from(outgoing)..=i64::from(incoming)).filter(|l| *l != 0) {
            occupied.entry((d.arm, Key::Lane(lane))).or_default().push((lo, hi, 0.0));
        }
        return place_walkers(d, f, first_at, step, spacing, occupied, key, side_lateral);
    }
    let list = occupied.entry((d.arm, key)).or_default();
    let mut out = Vec::new();
    let mut centre = first;
    for k in 0..f.count {
        let (row, column) = if across { (k / 4, k % 4) } else { (0, k) };
        let along = if across { first + step * column as f64 * spacing } else { centre };
        // never on top of what is already there: move on, away from the reference (beside
        // it, whichever way is nearer)
        let free = |start: f64, way: f64| {
            let mut along = start;
            for _ in 0..200 {
                // a vehicle keeps its headway to what it shares the lane with, moving or not
                let keep = |speed: f64| {
                    if f.body == Body::Vehicle && (speed > 0.0 || f.speed > 0.0) {
                        2.0 + speed.max(f.speed)
                    } else {
                        0.5
                    }
                };
                let (lo, hi) = (along - extent / 2.0, along + extent / 2.0);
                match list.iter().find(|(a, b, speed)| lo - keep(*speed) + 0.25 < *b && *a < hi + keep(*speed) - 0.25) {
                    Some(&(a, b, speed)) if !across || row == 0 => {
                        let keep = keep(speed);
                        along = if way > 0.0 { b + extent / 2.0 + keep } else { a - extent / 2.0 - keep };
                    }
                    _ => break,
                }
            }
            along
        };
        let mut along = free(along, step);
        if d.longitudinal == Longitudinal::Same && k == 0 {
            let back = free(first, -step);
            if (back - first).abs() < (along - first).abs() {
                along = back;
            }
        }
        let lateral = match d.facing {
            Facing::Across { from } => side_lateral(from, row),
            Facing::Along => lane_lateral(d.place),
        };
        if !across || row == 0 {
            list.push((along - extent / 2.0, along + extent / 2.0, if f.is_static() { 0.0 } else { f.speed }));
        }
        out.push((Station { arm: d.arm, along }, lateral));
        centre = along + step * spacing;
    }
    (out, if d.longitudinal == Longitudinal::Same { 0.0 } else { room })
}

/// The agent's path and its start on it.
fn paths(road: &Road, a: &mut Agent, obstacles: &[(i64, f64, f64)]) {
    let heading = Vec2::from_yaw(a.pose.yaw);
    match (a.body, a.facing) {
        (_, Facing::Across { .. }) => {
            let width = (road.lanes + road.opposite.max(road.cross_lanes)) as f64 * road.lane_width + 12.0;
            a.path = Path::new([a.pose.position, a.pose.position + heading * width]);
            a.path_start = 0.0;
        }
        (Body::Vehicle, Facing::Along) if a.speed > 0.0 => {
            let lane_change = match a.motion {
                Some(Motion::ChangeLaneLeft) => Some(-1),
                Some(Motion::ChangeLaneRight) => Some(1),
                _ => None,
            };
            if a.station.arm == Arm::Ego && (lane_change.is_some() || a.motion == Some(Motion::Overtake)) && a.lane > 0
            {
                a.path = ego_road_path(road, a, lane_change, obstacles);
                a.path_start = road::RUN;
            } else {
                let (path, start) = road.vehicle_path(a.station, a.lane, a.turn);
                // a curb-side rider keeps its offset from the lane's centre
                a.path = path;
                a.path_start = start;
                if a.place != Place::Lane {
                    let offset = a.lateral - road.lateral(a.lane);
                    a.path = a.path.offset(if a.lane < 0 { -offset } else { offset });
                }
            }
        }
        _ => {
            let speed_dir = if a.speed > 0.0 { 200.0 } else { 1.0 };
            a.path = Path::new([a.pose.position, a.pose.position + heading * speed_dir]);
            a.path_start = 0.0;
        }
    }
    if let Some(start) = Some(a.path.project(a.pose.position).0).filter(|_| a.path.length() > 0.0) {
        a.path_start = start;
    }
}

/// A path along the ego's road for a lane change (−1 left, +1 right) after a second and a
/// half, or an overtake of the first obstacle ahead in its lane through the lane to its left.
fn ego_road_path(road: &Road, a: &Agent, lane_change: Option<i64>, obstacles: &[(i64, f64, f64)]) -> Path {
    let x0 = a.station.along;
    let v = a.speed.max(1.0);
    let from = road.lateral(a.lane);
    let width = road.lane_width;
    let profile: Box<dyn Fn(f64) -> f64> = match lane_change {
        Some(dir) => {
            let target = road.lateral(Lane::new(a.lane).map_or(a.lane, |l| l.shift(dir).index()));
            let (x1, x2) = (x0 + 1.5 * v, x0 + 1.5 * v + (3.0 * v).max(12.0));
            Box::new(move |x| blend(from, target, x1, x2, x))
        }
        None => {
            let obstacle = obstacles
                .iter()
                .filter(|(lane, low, _)| *lane == a.lane && *low > x0)
                .min_by(|p, q| p.1.total_cmp(&q.1))
                .copied();
            match obstacle {
                Some((_, low, high)) => {
                    let target = from + width;
                    let (x1, x2) = (low - 6.0 - v * 1.5, low - 3.0);
                    let (x3, x4) = (high + 3.0, high + 6.0 + v * 1.5);
                    Box::new(
                        move |x| if x < x3 { blend(from, target, x1, x2, x) } else { blend(target, from, x3, x4, x) },
                    )
                }
                None => Box::new(move |_| from),
            }
        }
    };
    let n = (2.0 * road::RUN) as usize;
    Path::new((0..=n).map(|k| {
        let x = x0 - road::RUN + k as f64;
        road.ego_road(x, profile(x)).position
    }))
}

/// A smooth step from `a` (before `x1`) to `b` (after `x2`).
fn blend(a: f64, b: f64, x1: f64, x2: f64, x: f64) -> f64 {
    if x <= x1 {
        a
    } else if x >= x2 {
        b
    } else {
        let t = (x - x1) / (x2 - x1);
        a + (b - a) * (1.0 - (std::f64::consts::PI * t).cos()) / 2.0
    }
}

/// Start a group where its first actor reaches its path's first meeting with the ego's
/// path when the ego does; `None` when their paths do not meet ahead of both.
fn time_group(road: &Road, ego: &Agent, d: &Decision, g: &mut GroupLayout) -> Option<(Conflict, f64)> {
    let first = g.agents.first()?;
    let reach = (ego.width + first.width) / 2.0 + 0.3;
    // the ego's path ahead of it
    let ego_ahead = Path::new(sample_path(&ego.path, ego.path_start, ego.path.length()));
    let own_ahead = Path::new(sample_path(&first.path, first.path_start, first.path.length()));
    let (s_own, s_ego) = own_ahead.first_within(&ego_ahead, reach, 0.5)?;
    // on the ego's path from the start and going its way (a leader or a follower), or
    // meeting it where the ego already is: not a conflict; head-on on its path is one
    let same_way = Vec2::from_yaw(own_ahead.pose(s_own).yaw).dot(Vec2::from_yaw(ego_ahead.pose(s_ego).yaw)) > 0.7;
    if (s_own < 1.0 && same_way) || s_ego < ego.length / 2.0 {
        return None;
    }
    let time = s_ego / ego.speed;
    let v = first.speed.max(0.1);
    let point = own_ahead.pose(s_own).position;
    if d.crosser {
        // walkers wait on the sidewalk, then cross in time
        let wait = time - s_own / v;
        for a in &mut g.agents {
            a.start.delay = wait.max(0.0);
            a.moving = false;
        }
        return Some((Conflict { group: g.group, point, time, spread: 1.0 }, -wait));
    }
    // move the whole group along its path by the difference, keeping its relation
    let mut shift = s_own - v * time; // > 0: start nearer the conflict point
    // not inside the junction; not past the ego when in front of it, nor ahead when behind
    let room = first.station.along.abs() - first.length / 2.0 - ego.length / 2.0 - 0.5;
    let (floor, limit) = match d.arm {
        Arm::Ego if d.target == Target::Ego && d.longitudinal != Longitudinal::Same => {
            let room = room.max(0.0);
            match (d.longitudinal == Longitudinal::Front, first.lane > 0) {
                // in front, driving with the ego: moving back at most `room`
                (true, true) => (-room, f64::INFINITY),
                (true, false) => (f64::NEG_INFINITY, room),
                (false, true) => (f64::NEG_INFINITY, room),
                (false, false) => (-room, f64::INFINITY),
            }
        }
        // never farther than MAX_REACH from the ego
        Arm::Ego if first.lane > 0 => (-MAX_REACH - first.station.along, MAX_REACH - first.station.along),
        Arm::Ego => (first.station.along - MAX_REACH, first.station.along + MAX_REACH),
        // never past the junction; never farther out than MAX_ARM_START (it waits instead)
        _ => (first.station.along - MAX_ARM_START, first.station.along - first.length / 2.0 - 0.5),
    };
    shift = shift.clamp(floor.min(limit), limit);
    // clamped: it reaches the point early (it waits, on another arm) or late (the ego must
    // start further back)
    let arrival = (s_own - shift) / v;
    let early = time - arrival;
    for a in &mut g.agents {
        let along = match (a.station.arm, a.lane < 0) {
            (Arm::Ego, false) => a.station.along + shift,
            (Arm::Ego, true) => a.station.along - shift,
            (_, false) => a.station.along - shift,
            (_, true) => a.station.along + shift,
        };
        let station = Station { along, ..a.station };
        let pose = road.pose_at(station, a.lane, a.lateral);
        a.station = station;
        a.pose = Pose { yaw: a.pose.yaw, ..pose };
        a.path_start = a.path.project(a.pose.position).0;
        if early > 0.05 && d.arm != Arm::Ego {
            a.start.delay = early;
            a.moving = false;
        }
    }
    Some((Conflict { group: g.group, point, time, spread: v }, (-early).max(0.0)))
}

fn sample_path(path: &Path, from: f64, to: f64) -> Vec<Vec2> {
    let n = ((to - from).max(0.0).ceil() as usize).clamp(1, 4000);
    (0..=n).map(|k| path.pose(from + (to - from) * k as f64 / n as f64).position).collect()
}

/// Walkers about to cross: in rows of four along the sidewalk, row after row further back.
#[allow(clippy::too_many_arguments)]
fn place_walkers(
    d: &Decision,
    f: &Facts,
    first: f64,
    step: f64,
    spacing: f64,
    occupied: &mut Occupied,
    key: Key,
    side_lateral: impl Fn(Side, usize) -> f64,
) -> (Vec<(Station, f64)>, f64) {
    let Facing::Across { from } = d.facing else { return (Vec::new(), 0.0) };
    let list = occupied.entry((d.arm, key)).or_default();
    let out: Vec<(Station, f64)> = (0..f.count)
        .map(|k| {
            let along = first + step * (k % 4) as f64 * spacing;
            (Station { arm: d.arm, along }, side_lateral(from, k / 4))
        })
        .collect();
    for (s, _) in &out {
        list.push((s.along - f.width / 2.0, s.along + f.width / 2.0, 0.0));
    }
    (out, 0.0)
}
