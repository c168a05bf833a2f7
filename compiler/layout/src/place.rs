//! The steps from a resolved scenario to a [`Layout`] (`spec/layout.md` §3–§6). [`lay_out`]
//! makes a `Planner`, which holds what the steps share, and calls its methods in order:
//!
//! 1. `facts`: facts of the ego and every group (`crate::facts`), the ego's lane, the road's
//!    lanes and whether it leads to a junction;
//! 2. `arms`: which road of the junction each group is on, from its relation and lane (a side
//!    relation in the reference's own lane is the crossing arm on that side at a junction and
//!    the adjacent lane elsewhere; an opposite lane ahead is the opposite arm);
//! 3. `road`: shape, lanes, the junction's arms (a three-way junction keeps the arms the
//!    scenario uses), sidewalks and crosswalks;
//! 4. `ego_road`: stations on the ego's road, in placement order, each group beyond its
//!    reference with a gap that grows with speed, never overlapping what is already there;
//!    crossing groups on the sidewalk, spread along it; then the ego's approach to the
//!    junction (a queue ahead ends at the stop line; a moving ego is about two seconds away,
//!    [`APPROACH_TIME`]); then moving traffic past the stop line moves on across the junction;
//! 5. `other_arms`: stations on the other arms, from their stop lines;
//! 6. `paths`: every agent's path, through the junction by each vehicle's turn, lane changes,
//!    overtaking, walking across;
//! 7. `timing`: every moving group whose path meets the ego's ahead starts where it reaches
//!    that point when the ego does at its stated speed, kept on the side of its reference
//!    that its relation says; one that cannot start far enough out, and crossing walkers,
//!    wait until the ego's time to the point falls to their own (`Start::meet`).
//!
//! `build` makes the agents and runs steps 6 and 7; while a walker cannot reach a junction's
//! crossing in time, `wait_for_walkers` moves the ego's start back and they run again.

use std::collections::HashMap;

use tad_ir::{GroupId, Lane, Lateral, Longitudinal, Motion, Position, Reference, Scenario, Span};

use crate::Limits;
use crate::facts::{self, Body, Chosen, Facts};
use crate::geom::{Path, Pose, Vec2};
use crate::road::{self, Arm, CROSSWALK, Junction, Road, Shape, Side, Station, Turn};
use crate::{Agent, Conflict, Facing, Finding, GroupLayout, Layout, Meet, Place, Start};

/// The farthest from the ego anything is put by timing or a late walker, m.
const MAX_REACH: f64 = 150.0;
/// How long a moving ego takes to reach its stop line, s.
const APPROACH_TIME: f64 = 2.0;
/// The farthest a timed adversary starts from its arm's stop line, m; one that would need
/// more waits there and starts late.
const MAX_ARM_START: f64 = 150.0;
/// Two paths meet where they come within this much (m) of touching: half of each one's
/// width, plus this margin.
pub const MEET_MARGIN: f64 = 0.3;
/// Spacing of walkers standing side by side.
const WALKER_SPACING: f64 = 0.9;

/// What a group's position resolves to.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Ego,
    Group(usize),
}

/// A group's position: what it is relative to, and on which sides.
#[derive(Clone, Copy, Debug)]
struct Relation {
    target: Target,
    lateral: Lateral,
    longitudinal: Longitudinal,
}

/// Where a group goes: its arm, its lane, its place there and which curb it keeps to.
#[derive(Clone, Copy, Debug)]
struct Slot {
    arm: Arm,
    lane: i64,
    place: Place,
    /// At the curb on the road's left (past its leftmost lane) rather than its right.
    curb_left: bool,
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

/// Whether a group walks across the road.
fn crosses(f: &Facts) -> bool {
    f.motion == Some(Motion::Cross) && f.body != Body::Object
}

/// The layout of a resolved scenario.
pub fn lay_out(scenario: &Scenario) -> Layout {
    lay_out_within(scenario, None)
}

/// The layout of a resolved scenario on a road with at most `limits`' lanes (a target's
/// map): the road is that narrow, and a written lane on the ego's road that it lacks moves
/// to the nearest one it has ([`Finding::Moved`]).
pub fn lay_out_within(scenario: &Scenario, limits: Option<Limits>) -> Layout {
    let mut planner = Planner::facts(scenario, limits);
    planner.arms();
    let mut road = planner.road();
    planner.ego_road(&mut road);
    planner.other_arms(&road);
    let mut built = planner.build(&road);
    for _ in 0..3 {
        if !planner.wait_for_walkers(&mut road, built.late) {
            break;
        }
        built = planner.build(&road);
    }
    planner.finish(road, built)
}

/// What the steps of [`lay_out`] share: the scenario and its facts, and what the steps decide
/// for each group (indexed by group) as they go.
struct Planner<'a> {
    scenario: &'a Scenario,
    ids: Vec<GroupId>,
    /// The groups' indices in placement order.
    order: Vec<usize>,
    ego_facts: Facts,
    group_facts: Vec<Facts>,
    ego_lane: i64,
    /// The lanes a target's road has, when it has fewer than the scenario uses.
    limits: Option<Limits>,
    /// The ego's road's lanes in its direction and in the other (none on a one-way road).
    lanes: u32,
    opposite: u32,
    one_way: bool,
    shape: Shape,
    /// The ego's road leads to a junction (its shape, a light, a junction's sign, a turn).
    junction_road: bool,
    decisions: Vec<Option<Decision>>,
    stations: Vec<Vec<(Station, f64)>>,
    slack: Vec<f64>,
    occupied: Occupied,
    chosen: Vec<Chosen>,
    findings: Vec<Finding>,
}

impl<'a> Planner<'a> {
    /// Step 1: the facts of the ego, of every group and of the road.
    fn facts(scenario: &'a Scenario, limits: Option<Limits>) -> Planner<'a> {
        let mut chosen: Vec<Chosen> = Vec::new();
        let mut findings: Vec<Finding> = Vec::new();
        let scenario_span = scenario.name.as_ref().map_or(scenario.span, |n| n.span);
        // the `ego` keyword, where what the ego section leaves unsaid is reported
        let ego_section = scenario.ego.span.map_or(scenario_span, |s| Span::new(s.start, s.start + "ego".len()));
        let ego_facts = facts::ego(scenario, ego_section, &mut chosen);
        let group_facts: Vec<Facts> =
            scenario.groups().map(|(id, g)| facts::group(scenario, id, g, &mut chosen)).collect();
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
        let written_lanes = scenario.road.lanes.get().filter(|n| *n >= 1).map(|n| n.min(12) as u32);
        let written_lanes = written_lanes.map(|n| limits.map_or(n, |l| n.min(l.same.max(1))));
        let ego_lane = ego_lane(scenario, written_lanes, ego_section, &mut chosen);
        let fitted = limits.map_or(ego_lane, |l| l.fit(ego_lane));
        if fitted != ego_lane {
            let span = scenario.ego.lane.span().unwrap_or(ego_section);
            findings.push(Finding::Moved { group: None, from: ego_lane, to: fitted, span });
        }
        let ego_lane = fitted;
        let (lanes, opposite, one_way) = road_lanes(scenario, written_lanes, ego_lane, limits);
        let (shape, junction_road) = road_kind(scenario, &ego_facts);
        let n = scenario.groups.len();
        Planner {
            scenario,
            ids: scenario.groups().map(|(id, _)| id).collect(),
            order: scenario.placement_order.iter().map(|id| id.index()).collect(),
            ego_facts,
            group_facts,
            ego_lane,
            limits,
            lanes,
            opposite,
            one_way,
            shape,
            junction_road,
            decisions: vec![None; n],
            stations: vec![Vec::new(); n],
            slack: vec![0.0; n],
            occupied: HashMap::new(),
            chosen,
            findings,
        }
    }

    /// Step 2: each group's arm, lane, place and facing, in placement order.
    fn arms(&mut self) {
        for i in self.order.clone() {
            let decision = self.decide(i);
            self.decisions[i] = Some(decision);
        }
    }

    /// A group's decision: its relation, then its arm and lane, its place and its facing.
    fn decide(&mut self, i: usize) -> Decision {
        let scenario = self.scenario;
        let group = &scenario.groups[i];
        let f = &self.group_facts[i];
        let crosser = crosses(f);
        let relation = match group.position.given() {
            None => {
                self.chosen.push(Chosen {
                    group: Some(self.ids[i]),
                    field: "position",
                    value: "`front of ego`".into(),
                    span: group.position.span().unwrap_or(group.name_span),
                    rule: "in front of the ego vehicle when the position is not known",
                });
                Relation { target: Target::Ego, lateral: Lateral::Same, longitudinal: Longitudinal::Front }
            }
            Some(p) => self.relation(i, p),
        };
        let written = group.lane.get().map(Lane::index);
        let mut slot = self.slot(relation, written, f);
        // a written lane of the ego's road that the target's road lacks: the nearest it has
        if let (Some(lane), Some(limits)) = (written, self.limits)
            && slot.arm == Arm::Ego
            && limits.fit(lane) != lane
        {
            let to = limits.fit(lane);
            let span = group.lane.span().unwrap_or(group.name_span);
            self.findings.push(Finding::Moved { group: Some(self.ids[i]), from: lane, to, span });
            slot = self.slot(relation, Some(to), f);
        }
        if written.is_none() {
            self.chosen.push(Chosen {
                group: Some(self.ids[i]),
                field: "lane",
                value: format!("lane {}", slot.lane),
                span: group.lane.span().unwrap_or(group.name_span),
                rule: "from the position's relation and the lane of its reference",
            });
        }
        self.place_by_motion(f, &mut slot);
        let facing = if crosser {
            slot.place = Place::Sidewalk;
            // at a junction arm, from the side its outgoing lanes are on; on the ego's road,
            // from the side of the lane written
            let from = if slot.arm != Arm::Ego || slot.lane < 0 { Side::Left } else { Side::Right };
            Facing::Across { from }
        } else {
            Facing::Along
        };
        Decision {
            arm: slot.arm,
            lane: slot.lane,
            place: slot.place,
            facing,
            target: relation.target,
            longitudinal: relation.longitudinal,
            crosser,
            curb_left: slot.curb_left,
            distance: group.distance.given().map(|p| (p.min().0.max(0.0), p.max().0.max(0.0))),
            span: group.position.given().map_or(group.name_span, |p| p.relation.span),
        }
    }

    /// What group `i`'s written position says: its reference (a group placed already, else
    /// the ego) and its relation's sides.
    fn relation(&self, i: usize, p: &Position) -> Relation {
        let relation = self.scenario.entries.resolved(&p.relation.value).map(|r| r.attrs);
        let target = match &p.reference.value {
            Reference::Group(j) if j.index() != i && self.decisions[j.index()].is_some() => Target::Group(j.index()),
            _ => Target::Ego,
        };
        Relation {
            target,
            lateral: relation.and_then(|r| r.lateral).unwrap_or(Lateral::Same),
            longitudinal: relation.and_then(|r| r.longitudinal).unwrap_or(Longitudinal::Same),
        }
    }

    /// A group's arm and lane: on a road to a junction, a moving group beside the ego in its
    /// lane comes along the crossing arm on that side, and a vehicle oncoming ahead along the
    /// opposite arm; anything else is on its reference's arm ([`Planner::beside`]).
    fn slot(&self, relation: Relation, written: Option<i64>, f: &Facts) -> Slot {
        let (ref_arm, ref_lane) = match relation.target {
            Target::Ego => (Arm::Ego, self.ego_lane),
            Target::Group(j) => self.decisions[j].as_ref().map_or((Arm::Ego, self.ego_lane), |d| (d.arm, d.lane)),
        };
        let Relation { lateral, longitudinal, .. } = relation;
        let moving_vehicle = f.body == Body::Vehicle && !f.is_static();
        let side_arm = match lateral {
            Lateral::Left => Some(Arm::Left),
            Lateral::Right => Some(Arm::Right),
            _ => None,
        };
        let in_lane = |arm: Arm, lane: i64| Slot { arm, lane, place: Place::Lane, curb_left: false };
        if self.junction_road
            && ref_arm == Arm::Ego
            && side_arm.is_some()
            && written.is_none_or(|l| l == ref_lane)
            && (moving_vehicle || crosses(f))
            && longitudinal != Longitudinal::Behind
        {
            // from the left or the right: the crossing arm on that side
            in_lane(side_arm.unwrap_or(Arm::Left), written.map_or(1, i64::abs).min(i64::from(self.lanes)))
        } else if self.junction_road
            && ref_arm == Arm::Ego
            && moving_vehicle
            && longitudinal == Longitudinal::Front
            && (lateral == Lateral::Opposite || written.is_some_and(|l| l < 0))
        {
            // oncoming: the opposite arm, coming into the junction
            in_lane(Arm::Opposite, written.map_or(1, i64::abs))
        } else {
            self.beside(ref_arm, ref_lane, lateral, written)
        }
    }

    /// A group's lane on its reference's arm: the one written, else the one beside the
    /// reference's lane on its relation's side; past the road's last lane, its shoulder.
    fn beside(&self, arm: Arm, ref_lane: i64, lateral: Lateral, written: Option<i64>) -> Slot {
        let (lanes, opposite) = (self.lanes, self.opposite);
        // a lane written for a group on the opposite arm counts on the ego's road
        let written = if arm == Arm::Opposite { written.map(|l| -l) } else { written };
        let ref_lane = Lane::new(ref_lane).unwrap_or(Lane::new(1).expect("1 is a lane"));
        let mut lane = match written {
            Some(l) if l != ref_lane.index() || lateral == Lateral::Same || lateral == Lateral::Opposite => l,
            _ => match lateral {
                Lateral::Left => ref_lane.shift(-1).index(),
                Lateral::Right => ref_lane.shift(1).index(),
                Lateral::Opposite => -ref_lane.index(),
                Lateral::Same => ref_lane.index(),
            },
        };
        let mut place = Place::Lane;
        let mut curb_left = false;
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
        if self.one_way && arm == Arm::Ego && lane < 0 {
            lane = 1;
            place = Place::Shoulder;
            curb_left = true;
        }
        Slot { arm, lane, place, curb_left }
    }

    /// The place its motion gives a group: parked or grazing in an outermost lane, at its
    /// curb; a walker walking, on the sidewalk.
    fn place_by_motion(&self, f: &Facts, slot: &mut Slot) {
        let (lanes, opposite) = (self.lanes, self.opposite);
        let outermost = |arm: Arm, lane: i64| {
            let (incoming, outgoing) = if arm == Arm::Ego { (lanes, opposite) } else { (lanes, lanes) };
            lane == i64::from(incoming) || lane == -i64::from(outgoing) || (outgoing == 0 && lane == 1)
        };
        match f.motion {
            Some(Motion::Parked) if f.body != Body::Object && outermost(slot.arm, slot.lane) => {
                slot.place = Place::Curb;
                // lane 1 of a one-way road of several lanes has its curb on the left
                slot.curb_left |= self.one_way && slot.arm == Arm::Ego && slot.lane == 1 && lanes > 1;
            }
            Some(Motion::Walk) if f.body == Body::Walker => slot.place = Place::Sidewalk,
            Some(Motion::Graze) if outermost(slot.arm, slot.lane) => slot.place = Place::Curb,
            _ => {}
        }
    }

    /// Step 3: the road: its shape and lanes, the junction's arms (a group on an arm the
    /// junction lacks moves to the ego's road), sidewalks and crosswalks.
    fn road(&mut self) -> Road {
        let scenario = self.scenario;
        let junction = self.junction();
        for (i, d) in self.decisions.iter_mut().enumerate() {
            let Some(d) = d else { continue };
            if junction.as_ref().is_some_and(|j| !j.arms.contains(&d.arm)) {
                self.findings.push(Finding::NoArm { group: self.ids[i], arm: d.arm, span: d.span });
                d.arm = Arm::Ego;
                d.lane = d.lane.abs().min(i64::from(self.lanes)).max(1);
            }
        }
        let walkway = scenario.road.roadside.given().is_some_and(|r| {
            r.iter().any(|s| s.value.id().and_then(|id| scenario.entries.get(id)).is_some_and(|e| e.attrs.walkway))
        });
        let walkers = self.group_facts.iter().any(|f| f.body == Body::Walker);
        Road {
            shape: self.shape,
            lanes: self.lanes,
            opposite: self.opposite,
            cross_lanes: self.lanes,
            lane_width: road::LANE_WIDTH,
            sidewalks: walkway || walkers,
            crosswalks: junction.is_some() || self.decisions.iter().flatten().any(|d| d.crosser),
            signal: scenario.road.light.given().and_then(|l| scenario.entries.resolved(l)).and_then(|e| e.attrs.signal),
            junction,
            approach: 0.0,
        }
    }

    /// The junction the ego's road leads to, if any: its arms (a three-way one keeps those
    /// the groups and the ego's exit use), its size, its light and its stop signs.
    fn junction(&self) -> Option<Junction> {
        let scenario = self.scenario;
        let (arms, roundabout) = match self.shape {
            Shape::Junction { arms, roundabout } => (arms, roundabout),
            _ if self.junction_road => (4, false),
            _ => return None,
        };
        let mut needed: Vec<Arm> = self.decisions.iter().flatten().map(|d| d.arm).collect();
        needed.push(turn_of(self.ego_facts.motion).exit(Arm::Ego));
        let arms_of = if arms == 3 {
            let missing = [Arm::Opposite, Arm::Left, Arm::Right]
                .into_iter()
                .find(|a| !needed.contains(a))
                .unwrap_or(Arm::Opposite);
            Arm::ALL.into_iter().filter(|a| *a != missing).collect()
        } else {
            Arm::ALL.to_vec()
        };
        let widest = self.lanes.max(self.opposite).max(1);
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

    /// Step 4: stations on the ego's road (where the ego is taken first), then the ego's
    /// approach to the junction, then what drives on across it.
    fn ego_road(&mut self, road: &mut Road) {
        let ego_len = self.ego_facts.length;
        self.occupied.entry((Arm::Ego, Key::Lane(self.ego_lane))).or_default().push((
            -ego_len / 2.0,
            ego_len / 2.0,
            self.ego_facts.speed,
        ));
        self.place_arm(true, road);
        if road.junction.is_some() {
            road.approach = self.approach(road);
            self.move_to_crosswalk(road.approach);
        }
        self.across_junction(road);
    }

    /// Step 5: stations on the other arms, from their stop lines.
    fn other_arms(&mut self, road: &Road) {
        self.place_arm(false, road);
    }

    /// Places the groups on the ego's road (`on_ego`) or those on the other arms, in
    /// placement order.
    fn place_arm(&mut self, on_ego: bool, road: &Road) {
        for &i in &self.order {
            let Some(d) = self.decisions[i].as_ref() else { continue };
            if (d.arm == Arm::Ego) != on_ego {
                continue;
            }
            let f = &self.group_facts[i];
            let reference = self.reference(d);
            let min_first = self.min_first(road, d, f);
            let (placed, room) = place_group(road, d, f, reference, min_first, &mut self.occupied);
            self.stations[i] = placed;
            self.slack[i] = room;
        }
    }

    /// What a group is placed from: its reference group when that is placed on the same
    /// arm, else the ego on its road, else the arm's stop line.
    fn reference(&self, d: &Decision) -> Extent {
        match d.target {
            Target::Group(j)
                if self.decisions[j].as_ref().is_some_and(|r| r.arm == d.arm) && !self.stations[j].is_empty() =>
            {
                let r = self.decisions[j].as_ref();
                let across = r.is_some_and(|r| r.crosser);
                let rf = &self.group_facts[j];
                let half = if across { rf.width.max(0.5) / 2.0 } else { rf.length / 2.0 };
                extent_of(&self.stations[j], half, rf.speed, r.map_or(1, |r| r.lane), d.arm)
            }
            _ if d.arm == Arm::Ego => {
                let half = self.ego_facts.length / 2.0;
                Extent {
                    lane: self.ego_lane,
                    stop_line: false,
                    low: -half,
                    high: half,
                    forward: 1.0,
                    speed: self.ego_facts.speed,
                }
            }
            _ => Extent::stop_line(),
        }
    }

    /// The nearest station a group's first actor may take: a crossing ahead of a moving ego,
    /// on a road without a junction, is where the walkers reach the ego's lane when the ego
    /// does.
    fn min_first(&self, road: &Road, d: &Decision, f: &Facts) -> f64 {
        let ego = &self.ego_facts;
        if !(d.crosser
            && d.arm == Arm::Ego
            && road.junction.is_none()
            && d.target == Target::Ego
            && d.distance.is_none()
            && f.speed > 0.0
            && !ego.is_static())
        {
            return f64::NEG_INFINITY;
        }
        let start = road.curb(match d.facing {
            Facing::Across { from } => from,
            _ => Side::Right,
        });
        let walk = ((start - road.lateral(self.ego_lane)).abs() + 1.0) / f.speed;
        (ego.speed * walk + ego.length / 2.0).min(MAX_REACH)
    }

    /// The ego's distance to its stop line: a queue of stopped vehicles ahead ends at it;
    /// moving traffic ahead drives on through the junction; what stands elsewhere, or turns
    /// there, stays before it; a moving ego is [`APPROACH_TIME`] away.
    fn approach(&self, road: &Road) -> f64 {
        let ego_len = self.ego_facts.length;
        let ahead: Vec<(f64, bool, bool)> = self
            .decisions
            .iter()
            .enumerate()
            .filter(|(_, d)| d.as_ref().is_some_and(|d| d.arm == Arm::Ego && !d.crosser))
            .flat_map(|(i, d)| {
                let f = &self.group_facts[i];
                // moving traffic in the opposite lanes comes from the opposite arm; what stands
                // there is before the junction too
                let incoming = d.as_ref().is_some_and(|d| d.lane > 0);
                if !incoming && !f.is_static() {
                    return Vec::new();
                }
                let queued = incoming && f.is_static() && f.motion != Some(Motion::Parked) && f.body == Body::Vehicle;
                // what turns at the junction is before it too (only straight traffic moves across)
                let before = f.is_static() || turn_of(f.motion) != Turn::Straight || road.opposite == 0;
                self.stations[i].iter().map(|(s, _)| (s.along + f.length / 2.0, before, queued)).collect()
            })
            .filter(|(front, _, _)| *front > 0.0)
            .collect();
        let front = |which: fn(&(f64, bool, bool)) -> bool| {
            ahead.iter().filter(|a| which(a)).map(|a| a.0).fold(ego_len / 2.0, f64::max)
        };
        let queue = ahead.iter().any(|a| a.2);
        // on a one-way road the road across the junction may not go on: all of it waits
        let standing = if road.opposite == 0 { front(|_| true) + 1.0 } else { 0.0 };
        let standing = standing.max(front(|a| a.1) + 1.0);
        let base = (self.ego_facts.speed * APPROACH_TIME).clamp(6.0, 40.0) + ego_len / 2.0;
        (if queue { front(|a| a.2) + 1.0 } else { base }).max(standing).max(6.0)
    }

    /// Crossers on the ego's road near the junction, or placed from the ego, move to its
    /// crosswalk.
    fn move_to_crosswalk(&mut self, approach: f64) {
        for (i, d) in self.decisions.iter().enumerate() {
            let Some(d) = d.as_ref().filter(|d| d.arm == Arm::Ego && d.crosser) else { continue };
            let Some(first) = self.stations[i].first().map(|(s, _)| s.along) else { continue };
            if first > approach - 8.0 || d.target == Target::Ego {
                let shift = approach + CROSSWALK - first;
                for (s, _) in &mut self.stations[i] {
                    s.along += shift;
                }
            }
        }
    }

    /// Moving traffic ahead past the stop line is already across the junction: all of it
    /// moves on to the opposite arm by the same distance, so that none is inside the
    /// junction and their relations hold.
    fn across_junction(&mut self, road: &Road) {
        let Some(half) =
            road.junction.as_ref().filter(|j| j.arms.contains(&Arm::Opposite) && road.opposite > 0).map(|j| j.half)
        else {
            return;
        };
        let beyond = |i: usize| {
            let f = &self.group_facts[i];
            self.decisions[i].as_ref().is_some_and(|d| d.arm == Arm::Ego && d.lane > 0 && !d.crosser)
                && !f.is_static()
                && f.body == Body::Vehicle
                && turn_of(f.motion) == Turn::Straight
        };
        let exit = road.approach + 2.0 * half;
        let mut push: f64 = 0.0;
        for i in (0..self.stations.len()).filter(|&i| beyond(i)) {
            let len = self.group_facts[i].length;
            for (s, _) in self.stations[i].iter().filter(|(s, _)| s.along + len / 2.0 > road.approach - 0.5) {
                push = push.max(exit + len / 2.0 + 0.5 - s.along);
            }
        }
        for i in (0..self.stations.len()).filter(|&i| beyond(i)) {
            let f = &self.group_facts[i];
            let lane = self.decisions[i].as_ref().map_or(1, |d| d.lane);
            for (s, _) in self.stations[i].iter_mut().filter(|(s, _)| s.along + f.length / 2.0 > road.approach - 0.5) {
                let along = s.along + push - exit;
                *s = Station { arm: Arm::Opposite, along };
                self.occupied.entry((Arm::Opposite, Key::Lane(-lane))).or_default().push((
                    along - f.length / 2.0,
                    along + f.length / 2.0,
                    f.speed,
                ));
            }
        }
    }

    /// The agents at their stations, then steps 6 and 7: their paths and their timing.
    fn build(&self, road: &Road) -> Built {
        let mut ego = self.ego_agent(road);
        let mut groups: Vec<GroupLayout> =
            (0..self.scenario.groups.len()).filter_map(|i| self.group_layout(road, i)).collect();
        Self::paths(road, &mut ego, &mut groups);
        let (conflicts, late) = self.timing(road, &ego, &mut groups);
        Built { ego, groups, conflicts, late }
    }

    /// The ego's agent, at station 0 of its lane.
    fn ego_agent(&self, road: &Road) -> Agent {
        let f = &self.ego_facts;
        let station = Station { arm: Arm::Ego, along: 0.0 };
        Agent {
            group: None,
            index: 0,
            body: Body::Vehicle,
            length: f.length,
            width: f.width,
            station,
            lane: self.ego_lane,
            place: Place::Lane,
            lateral: road.lateral(self.ego_lane),
            facing: Facing::Along,
            motion: f.motion,
            turn: turn_of(f.motion),
            speed: if f.is_static() { 0.0 } else { f.speed },
            moving: !f.is_static(),
            start: Start::default(),
            pose: road.lane_pose(station, self.ego_lane),
            path: Path::default(),
            path_start: 0.0,
        }
    }

    /// Group `i`'s agents, one at each of its stations; `None` when it was not placed.
    fn group_layout(&self, road: &Road, i: usize) -> Option<GroupLayout> {
        let group = &self.scenario.groups[i];
        let f = self.group_facts[i].clone();
        let d = self.decisions[i].as_ref()?;
        let delay = group.delay.given().map_or(0.0, |p| p.nominal().0.max(0.0));
        let trigger = group.trigger.given().map(|p| p.nominal().0.max(0.0));
        let waits = delay > 0.0 || trigger.is_some();
        let agents = self.stations[i]
            .iter()
            .enumerate()
            .map(|(k, &(station, lateral))| {
                let (lane, lateral, pose) = stand(road, d, station, lateral);
                Agent {
                    group: Some(self.ids[i]),
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
                    start: Start { delay, trigger, meet: None },
                    pose,
                    path: Path::default(),
                    path_start: 0.0,
                }
            })
            .collect();
        Some(GroupLayout { group: self.ids[i], facts: f, agents, slack: self.slack[i] })
    }

    /// Step 6: every agent's path and its start on it, overtaking what stands on the ego's
    /// road.
    fn paths(road: &Road, ego: &mut Agent, groups: &mut [GroupLayout]) {
        let obstacles: Vec<(i64, f64, f64)> = groups
            .iter()
            .flat_map(|g| &g.agents)
            .filter(|a| {
                a.is_static() && a.station.arm == Arm::Ego && a.place != Place::Sidewalk && a.facing == Facing::Along
            })
            .map(|a| (a.lane, a.station.along - a.length / 2.0, a.station.along + a.length / 2.0))
            .collect();
        path_of(road, ego, &obstacles);
        for g in groups {
            for a in &mut g.agents {
                path_of(road, a, &obstacles);
            }
        }
    }

    /// Step 7: every moving group without a written distance, delay or trigger is timed to
    /// its conflict with a moving ego ([`time_group`]); returns the conflicts and how late the
    /// latest crossing walker is, s.
    fn timing(&self, road: &Road, ego: &Agent, groups: &mut [GroupLayout]) -> (Vec<Conflict>, f64) {
        let mut conflicts = Vec::new();
        let mut late: f64 = 0.0;
        if !(ego.moving && ego.speed > 0.5) {
            return (conflicts, late);
        }
        for (i, g) in groups.iter_mut().enumerate() {
            let Some(d) = self.decisions[i].as_ref() else { continue };
            let group = &self.scenario.groups[i];
            let written_timing = d.distance.is_some() || group.delay.is_given() || group.trigger.is_given();
            if written_timing || g.facts.is_static() || g.agents.is_empty() {
                continue;
            }
            if let Some((conflict, lateness)) = time_group(road, ego, d, g) {
                conflicts.push(conflict);
                late = late.max(lateness);
            }
        }
        (conflicts, late)
    }

    /// A walker `late` seconds late for its crossing at a junction moves the ego's start back
    /// (its approach longer, the walkers at its crosswalk with it); whether it did.
    fn wait_for_walkers(&mut self, road: &mut Road, late: f64) -> bool {
        if road.junction.is_none() || late <= 0.05 {
            return false;
        }
        let delta = (late * self.ego_facts.speed + 1.0).min(MAX_REACH - road.approach);
        if delta <= 0.0 {
            return false;
        }
        road.approach += delta;
        for (i, d) in self.decisions.iter().enumerate() {
            if d.as_ref().is_some_and(|d| d.arm == Arm::Ego && d.crosser) {
                for (s, _) in &mut self.stations[i] {
                    s.along += delta;
                }
            }
        }
        true
    }

    /// The layout: the road, the agents and their conflicts, the findings (what was chosen
    /// last).
    fn finish(self, road: Road, built: Built) -> Layout {
        let Built { ego, groups, conflicts, .. } = built;
        let mut findings = self.findings;
        findings.extend(self.chosen.into_iter().map(Finding::Chosen));
        Layout { road, ego, ego_facts: self.ego_facts, groups, conflicts, findings }
    }
}

/// The ego's lane: the one written, else the middle one of the road's (a choice).
fn ego_lane(scenario: &Scenario, written_lanes: Option<u32>, ego_section: Span, chosen: &mut Vec<Chosen>) -> i64 {
    match scenario.ego.lane.get() {
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
    }
}

/// The ego's road's lanes in its direction and in the other (as written, else as many as
/// the lanes used), and whether it is one way (then none in the other).
fn road_lanes(
    scenario: &Scenario,
    written_lanes: Option<u32>,
    ego_lane: i64,
    limits: Option<Limits>,
) -> (u32, u32, bool) {
    let one_way =
        scenario.road.direction.given().and_then(|d| scenario.entries.resolved(d)).and_then(|e| e.attrs.opposite_lanes)
            == Some(false);
    let used = |positive: bool| {
        scenario
            .groups
            .iter()
            .filter_map(|g| g.lane.get().map(Lane::index))
            .map(|l| limits.map_or(l, |limits| limits.fit(l)))
            .chain([ego_lane])
            .filter(|l| (*l > 0) == positive)
            .map(|l| l.unsigned_abs().min(12) as u32)
            .max()
            .unwrap_or(0)
    };
    let lanes = written_lanes.unwrap_or_else(|| used(true).max(1)).max(ego_lane as u32);
    let opposite = if one_way { 0 } else { lanes.max(used(false)) };
    match limits {
        Some(l) => (lanes.min(l.same.max(1)), opposite.min(l.other), one_way),
        None => (lanes, opposite, one_way),
    }
}

/// The road's shape, and whether it leads to a junction: by its shape, or a light that
/// shows something, a junction's sign or the ego's turn.
fn road_kind(scenario: &Scenario, ego_facts: &Facts) -> (Shape, bool) {
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
    (shape, matches!(shape, Shape::Junction { .. }) || lit || junction_sign || turning)
}

/// Where a group's actor stands at a station: its lane and lateral offset (moved across the
/// junction: in an outgoing lane of the opposite arm) and its pose, turned across the road
/// when it crosses.
fn stand(road: &Road, d: &Decision, station: Station, lateral: f64) -> (i64, f64, Pose) {
    let moved = station.arm != d.arm;
    let lane = if moved { -d.lane } else { d.lane };
    let lateral = if moved { road.lateral(lane) } else { lateral };
    let pose = road.pose_at(station, if d.crosser { 1 } else { lane }, lateral);
    let yaw = match d.facing {
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
    (lane, lateral, Pose { yaw, ..pose })
}

struct Built {
    ego: Agent,
    groups: Vec<GroupLayout>,
    conflicts: Vec<Conflict>,
    /// How late the latest crossing walker is for its conflict, s.
    late: f64,
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
    let placing = Placing::new(road, d, f, reference);
    if placing.across {
        let first = placing.clear_strip(min_first, occupied);
        placing.walkers(first, occupied)
    } else {
        placing.along(occupied)
    }
}

/// What placing one group's actors shares: the group, its first station, and the way and
/// spacing its actors follow one another.
struct Placing<'p> {
    road: &'p Road,
    d: &'p Decision,
    f: &'p Facts,
    /// Walkers about to cross, side by side along the sidewalk.
    across: bool,
    /// The way the group extends from its reference, in stations.
    step: f64,
    /// An actor's size along the arm, and the distance from one actor to the next.
    extent: f64,
    spacing: f64,
    /// The first actor's station before anything already there moves it on.
    first: f64,
    /// The free room kept between the group and its reference.
    room: f64,
    /// What the group occupies along its arm.
    key: Key,
}

impl<'p> Placing<'p> {
    /// The group's first station and spacing, from its reference and its distance (written,
    /// else a gap that grows with speed, with some room kept).
    fn new(road: &'p Road, d: &'p Decision, f: &'p Facts, reference: Extent) -> Placing<'p> {
        let forward = reference.forward;
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
        let key = match (d.facing, d.place) {
            (Facing::Across { from }, _) => Key::Sidewalk(from),
            (_, Place::Sidewalk) => Key::Sidewalk(if d.lane > 0 { Side::Right } else { Side::Left }),
            _ => Key::Lane(d.lane),
        };
        Placing { road, d, f, across, step, extent, spacing, first, room, key }
    }

    /// The lateral offset of a walker across in row `row` on the sidewalk on side `side`:
    /// rows further back, row by row.
    fn side_lateral(&self, side: Side, row: usize) -> f64 {
        let (road, f) = (self.road, self.f);
        let curb = match (self.d.arm, side) {
            (Arm::Ego, s) => road.curb(s),
            (arm, Side::Right) => -(road.arm_lanes(arm).0 as f64) * road.lane_width,
            (arm, Side::Left) => road.arm_lanes(arm).1 as f64 * road.lane_width,
        };
        let out = if road.sidewalks { 0.6 + road::SIDEWALK_WIDTH * 0.3 } else { 0.6 }
            + f.length / 2.0
            + row as f64 * (f.length + 0.3);
        if side == Side::Right { curb - out } else { curb + out }
    }

    /// The lateral offset of an actor along its lane at `place` there.
    fn lane_lateral(&self, place: Place) -> f64 {
        let (road, d, f) = (self.road, self.d, self.f);
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
            Place::Sidewalk => self.side_lateral(if d.lane > 0 { Side::Right } else { Side::Left }, 0),
        }
    }

    /// Walkers about to cross: the first column's station, not before `min_first` and moved
    /// on until the strip they cross is clear in every lane of the arm, which it then takes.
    fn clear_strip(&self, min_first: f64, occupied: &mut Occupied) -> f64 {
        let (d, step, extent, spacing) = (self.d, self.step, self.extent, self.spacing);
        let columns = self.f.count.min(4) as f64;
        let strip = |first: f64| {
            let ends =
                [first - step * (extent / 2.0 + 0.3), first + step * ((columns - 1.0) * spacing + extent / 2.0 + 0.3)];
            (ends[0].min(ends[1]), ends[0].max(ends[1]))
        };
        let mut first_at = if step > 0.0 { self.first.max(min_first) } else { self.first };
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
        let (incoming, outgoing) = self.road.arm_lanes(d.arm);
        for lane in (-i64::from(outgoing)..=i64::from(incoming)).filter(|l| *l != 0) {
            occupied.entry((d.arm, Key::Lane(lane))).or_default().push((lo, hi, 0.0));
        }
        first_at
    }

    /// Walkers about to cross, from `first`: in rows of four along the sidewalk, row after
    /// row further back.
    fn walkers(&self, first: f64, occupied: &mut Occupied) -> (Vec<(Station, f64)>, f64) {
        let (d, f) = (self.d, self.f);
        let Facing::Across { from } = d.facing else { return (Vec::new(), 0.0) };
        let list = occupied.entry((d.arm, self.key)).or_default();
        let out: Vec<(Station, f64)> = (0..f.count)
            .map(|k| {
                let along = first + self.step * (k % 4) as f64 * self.spacing;
                (Station { arm: d.arm, along }, self.side_lateral(from, k / 4))
            })
            .collect();
        for (s, _) in &out {
            list.push((s.along - f.width / 2.0, s.along + f.width / 2.0, 0.0));
        }
        (out, 0.0)
    }

    /// Actors along a lane (or its curb or sidewalk), one after another from the first, each
    /// where it touches nothing already there; with the room kept.
    fn along(&self, occupied: &mut Occupied) -> (Vec<(Station, f64)>, f64) {
        let (d, f) = (self.d, self.f);
        let list = occupied.entry((d.arm, self.key)).or_default();
        let mut out = Vec::new();
        let mut centre = self.first;
        for k in 0..f.count {
            // never on top of what is already there: move on, away from the reference (beside
            // it, whichever way is nearer)
            let mut along = self.free(list, centre, self.step);
            if d.longitudinal == Longitudinal::Same && k == 0 {
                let back = self.free(list, self.first, -self.step);
                if (back - self.first).abs() < (along - self.first).abs() {
                    along = back;
                }
            }
            list.push((
                along - self.extent / 2.0,
                along + self.extent / 2.0,
                if f.is_static() { 0.0 } else { f.speed },
            ));
            out.push((Station { arm: d.arm, along }, self.lane_lateral(d.place)));
            centre = along + self.step * self.spacing;
        }
        (out, if d.longitudinal == Longitudinal::Same { 0.0 } else { self.room })
    }

    /// The first station from `start`, going `way`, where an actor touches nothing in `list`:
    /// a vehicle keeps its headway to what it shares the lane with, moving or not.
    fn free(&self, list: &[(f64, f64, f64)], start: f64, way: f64) -> f64 {
        let (f, extent) = (self.f, self.extent);
        let keep = |speed: f64| {
            if f.body == Body::Vehicle && (speed > 0.0 || f.speed > 0.0) { 2.0 + speed.max(f.speed) } else { 0.5 }
        };
        let mut along = start;
        for _ in 0..200 {
            let (lo, hi) = (along - extent / 2.0, along + extent / 2.0);
            match list.iter().find(|(a, b, speed)| lo - keep(*speed) + 0.25 < *b && *a < hi + keep(*speed) - 0.25) {
                Some(&(a, b, speed)) => {
                    let keep = keep(speed);
                    along = if way > 0.0 { b + extent / 2.0 + keep } else { a - extent / 2.0 - keep };
                }
                None => break,
            }
        }
        along
    }
}

/// The agent's path and its start on it.
fn path_of(road: &Road, a: &mut Agent, obstacles: &[(i64, f64, f64)]) {
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
    let reach = (ego.width + first.width) / 2.0 + MEET_MARGIN;
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
        // walkers wait on the sidewalk until the ego is as near as their walk, then cross
        let travel = s_own / v;
        let wait = time - travel;
        for a in &mut g.agents {
            if wait > 0.0 {
                a.start.meet = Some(Meet { point, travel });
            }
            a.moving = false;
        }
        return Some((Conflict { group: g.group, point, time, travel, spread: 1.0 }, -wait));
    }
    // move the whole group along its path by the difference, keeping its relation
    let mut shift = s_own - v * time; // > 0: start nearer the conflict point
    if d.arm == Arm::Ego && d.longitudinal == Longitudinal::Behind && same_way {
        // catching the ego up from behind: later than the first overlap it ends up behind
        // the ego and follows it, so it starts nearer by what it gains on the ego in half
        // a second, and its sampled spread lies mostly on the early side of that time
        shift += crate::half_spread(v - ego.speed);
    }
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
            // early: it stands until the ego is as near the point as it is
            a.start.meet = Some(Meet { point, travel: arrival });
            a.moving = false;
        }
    }
    Some((Conflict { group: g.group, point, time, travel: arrival, spread: v }, (-early).max(0.0)))
}

fn sample_path(path: &Path, from: f64, to: f64) -> Vec<Vec2> {
    let n = ((to - from).max(0.0).ceil() as usize).clamp(1, 4000);
    (0..=n).map(|k| path.pose(from + (to - from) * k as f64 / n as f64).position).collect()
}
