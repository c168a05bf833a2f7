//! The layout rendered as instructions (`spec/bytecode.md` §5): the road, the run's
//! limits, the lights' phase programs, the ego and its route, one spawn per actor, then
//! each actor's script (its start, then its motion).
//!
//! Nothing is placed here: every station, path and timing is the layout's. What this
//! module decides is how to say it: which motion instruction renders an actor's path
//! (`Drive` when the path is its lane's own, `Follow` otherwise), which of the layout's
//! free room becomes a parameter slot, and the phase programs of the lights. `lower` is
//! total: whatever the layout, it returns a program (the tests check that every example
//! and fixture's program verifies).

use std::collections::HashMap;

use tad_ir::{GroupId, Motion, Param, Reference, Scenario, Signal};
use tad_layout::{Agent, GroupLayout, Layout};
use tad_road::geom::{Path, Vec2};
use tad_road::{Arm, Body, Facing, Place, Road};

use crate::program::{ActorId, Instr, Light, ParamSlot, PathId, Phase, Polyline, Program, Size, Slot, Value};

/// Step length, s, and steps of a run (SafeBench: CARLA at 0.1 s, 300 steps).
const DT: f64 = 0.1;
const MAX_STEPS: u32 = 300;
/// The ego's longest drive: its route and this much more, within SafeBench's 150–200 m.
const DRIVE_BEYOND_ROUTE: f64 = 50.0;
const MIN_DRIVE: f64 = 150.0;
const MAX_DRIVE: f64 = 200.0;
/// ChatScene's timeout: a second per metre of route, at least this many seconds.
const MIN_TIMEOUT: f64 = 10.0;
/// The ego's route: through the junction and this far past it, else this far ahead, m.
const PAST_JUNCTION: f64 = 30.0;
const WITHOUT_JUNCTION: f64 = 100.0;
/// The route lasts, at the ego's speed, at least this long, s, and this long past the last
/// thing timed to happen (a conflict, a start delay): a fast ego's 100 m would end first.
const MIN_ROUTE_TIME: f64 = 6.0;
const AFTER_LAST_EVENT: f64 = 2.0;
/// How long a lane changer drives its lane before it changes, s (the layout's `ego_road_path`).
const LANE_CHANGE_AFTER: f64 = 1.5;
/// A slot for the layout's free room is made only when its range is at least this wide, m.
const MIN_ROOM: f64 = 0.5;
/// How far a layout's path may lie from a lane's path and still be that lane's, m.
const SAME_PATH: f64 = 0.05;

/// Light phases, s: how long the stated light holds at least, and yellow.
const HOLD: f64 = 30.0;
const YELLOW: f64 = 3.0;
/// A stated yellow holds this long (the scenario's moment lasts the first 20 s).
const YELLOW_HOLD: f64 = 20.0;

/// The phase programs of the ego's axis (its arm and the opposite one) and of the crossing
/// axis, starting with what the ego's light shows; both cycles have the same length.
fn phase_programs(signal: Signal) -> (Vec<Phase>, Vec<Phase>) {
    let p = |light, seconds| Phase { light, seconds };
    use Light::*;
    match signal {
        Signal::Green => (
            vec![p(Green, HOLD), p(Yellow, YELLOW), p(Red, HOLD + YELLOW)],
            vec![p(Red, HOLD + YELLOW), p(Green, HOLD), p(Yellow, YELLOW)],
        ),
        Signal::Red => (
            vec![p(Red, HOLD + YELLOW), p(Green, HOLD), p(Yellow, YELLOW)],
            vec![p(Green, HOLD), p(Yellow, YELLOW), p(Red, HOLD + YELLOW)],
        ),
        Signal::Yellow => (
            vec![p(Yellow, YELLOW_HOLD), p(Red, HOLD + YELLOW), p(Green, HOLD)],
            vec![p(Red, YELLOW_HOLD + YELLOW), p(Green, HOLD - YELLOW), p(Yellow, YELLOW), p(Red, HOLD)],
        ),
        Signal::Off => (vec![p(Off, 2.0 * (HOLD + YELLOW))], vec![p(Off, 2.0 * (HOLD + YELLOW))]),
    }
}

/// Height of an actor whose type states none, m.
fn default_height(body: Body) -> f64 {
    match body {
        Body::Vehicle => 1.5,
        Body::Walker => 1.7,
        Body::Object => 1.0,
    }
}

/// The program of a scenario's layout; `source` names the file it came from.
pub fn lower(scenario: &Scenario, layout: &Layout, source: &str) -> Program {
    let mut b = Builder {
        program: Program {
            name: scenario.name.as_ref().map_or_else(|| "unnamed".to_string(), |n| n.value.clone()),
            source: source.to_string(),
            ..Program::default()
        },
        slots: HashMap::new(),
    };
    let mut road = layout.road.clone();
    if let Some(j) = road.junction.as_mut() {
        // the format stores the arms as a set, read back in `Arm::ALL`'s order
        j.arms.sort();
        j.arms.dedup();
    }

    // the ego's route: a standing ego's layout path is a stub; it gets its lane's path
    let ego = &layout.ego;
    let ego_path = if ego.speed > 0.0 && ego.path.length() > 1.0 {
        ego.path.clone()
    } else {
        layout.road.vehicle_path(ego.station, ego.lane, ego.turn).0
    };
    let ego_line = Polyline(ego_path.points().iter().map(|p| [p.x, p.y]).collect()).canonical();
    let on_path = path_of(&ego_line);
    let start = on_path.project(ego.pose.position).0;
    let ahead = (on_path.length() - start).max(0.0);
    let last_event = layout.conflicts.iter().map(|c| c.time).chain(layout.agents().map(|a| a.start.delay));
    let lasting = ego.speed * (last_event.fold(0.0, f64::max) + AFTER_LAST_EVENT).max(MIN_ROUTE_TIME);
    let route = match past_junction(&road, &on_path, start) {
        Some(exit) => exit + PAST_JUNCTION - start,
        None => WITHOUT_JUNCTION,
    }
    .max(lasting)
    .min(ahead);
    let ego_path_id = b.path(ego_line);

    b.program.code.push(Instr::Road(road.clone()));
    b.program.code.push(Instr::Limits {
        dt: DT,
        max_steps: MAX_STEPS,
        // SafeBench's 150–200 m, and never short of a longer route
        max_distance: (route + DRIVE_BEYOND_ROUTE).clamp(MIN_DRIVE, MAX_DRIVE.max(route + DRIVE_BEYOND_ROUTE)),
        timeout: route.floor().max(MIN_TIMEOUT),
    });
    if let (Some(signal), Some(junction)) = (road.signal, road.junction.as_ref().filter(|j| j.signalised)) {
        let (along, across) = phase_programs(signal);
        for &arm in &junction.arms {
            let phases = match arm {
                Arm::Ego | Arm::Opposite => along.clone(),
                Arm::Left | Arm::Right => across.clone(),
            };
            b.program.code.push(Instr::Signal { arm, phases });
        }
    }
    let ego_type = tad_layout::facts::ego_type(scenario);
    // the stated speed, also of an ego that stands at the start: the policies' desired speed
    let stated = layout.ego_facts.speed;
    let ego_speed = match scenario.ego.speed.given() {
        Some(Param::Range { min, max }) => b.range(None, "ego", "speed", min.0, max.0, stated),
        _ => Value::lit(stated),
    };
    if let Some(path) = ego_path_id {
        b.program.code.push(Instr::Ego {
            class: ego_type.map_or_else(|| "vehicle".to_string(), |t| t.name.clone()),
            size: Size {
                length: ego.length,
                width: ego.width,
                height: positive(ego_type.and_then(|t| t.attrs.height).map(|h| h.0))
                    .unwrap_or(default_height(Body::Vehicle)),
            },
            lane: ego.lane,
            turn: ego.turn,
            path,
            start,
            route_length: route,
            speed: ego_speed,
        });
    }

    // spawns, then each actor's script
    let mut scripts: Vec<Vec<Instr>> = Vec::new();
    'groups: for gl in &layout.groups {
        let Some(group) = scenario.group(gl.group) else { continue };
        let (moved, along_slot) = match group.offset.given() {
            Some(offset) => {
                let (low, high) = (offset.min().0, offset.max().0);
                if high > low && low.is_finite() && high.is_finite() {
                    let slot = b.slot(Some(gl.group), &group.name, "offset", (low, high, 0.0_f64.clamp(low, high)));
                    (0.0, slot)
                } else {
                    (if low.is_finite() { low } else { 0.0 }, None)
                }
            }
            None => (0.0, b.along_slot(scenario, layout, gl, &group.name)),
        };
        let entry = group.actor_type.given().and_then(|t| scenario.entries.resolved(t));
        let class = group
            .actor_type
            .given()
            .map(|t| scenario.entries.name(t))
            .filter(|n| !n.is_empty())
            .unwrap_or(crate::format::body_name(gl.facts.body))
            .to_string();
        for agent in &gl.agents {
            let Ok(actor) = ActorId::try_from(scripts.len()) else { break 'groups };
            let height =
                positive(entry.and_then(|e| e.attrs.height).map(|h| h.0)).unwrap_or(default_height(agent.body));
            b.program.code.push(Instr::Spawn {
                actor,
                group: group.name.clone(),
                index: u16::try_from(agent.index).unwrap_or(u16::MAX),
                body: agent.body,
                class: class.clone(),
                size: Size { length: agent.length, width: agent.width, height },
                arm: agent.station.arm,
                lane: agent.lane,
                place: agent.place,
                along: Value { base: agent.station.along + moved, slot: along_slot },
                lateral: agent.lateral,
                facing: agent.facing,
                yaw: agent.pose.yaw,
                speed: if agent.moving { agent.speed } else { 0.0 },
            });
            scripts.push(b.script(layout, gl, group, agent, actor));
        }
    }
    b.program.code.extend(scripts.into_iter().flatten());
    b.program
}

fn positive(v: Option<f64>) -> Option<f64> {
    v.filter(|v| *v > 0.0 && v.is_finite())
}

fn path_of(line: &Polyline) -> Path {
    Path::new(line.0.iter().map(|p| Vec2::new(p[0], p[1])))
}

/// The arc length at which a path, from `start`, leaves the junction's square after
/// entering it; `None` without a junction or when the path never enters it.
fn past_junction(road: &Road, path: &Path, start: f64) -> Option<f64> {
    let half = road.junction.as_ref()?.half;
    let centre = road.centre();
    let inside = |s: f64| {
        let p = path.pose(s).position - centre;
        p.x.abs() <= half && p.y.abs() <= half
    };
    let steps = ((path.length() - start).max(0.0) / 0.5).ceil().min(20_000.0) as usize;
    let mut entered = false;
    for k in 0..=steps {
        let s = start + k as f64 * 0.5;
        match (entered, inside(s)) {
            (false, true) => entered = true,
            (true, false) => return Some(s),
            _ => {}
        }
    }
    None
}

/// Whether `path` from `from` on is the lane's path `lane` from its own start: every point
/// of the first within [`SAME_PATH`] of the second, as far as both go.
fn same_path(path: &Path, from: f64, lane: &Path, lane_from: f64) -> bool {
    let rest = (path.length() - from).min(lane.length() - lane_from);
    let some = rest > 0.0;
    if !some {
        return false;
    }
    let n = (rest / 2.0).ceil().clamp(1.0, 1000.0) as usize;
    (0..=n).all(|k| lane.project(path.pose(from + rest * k as f64 / n as f64).position).1 <= SAME_PATH)
}

struct Builder {
    program: Program,
    /// Each group's slots (the ego's: `None`), by what they vary.
    slots: HashMap<(Option<GroupId>, &'static str), Slot>,
}

impl Builder {
    /// A slot's index, made on first use; `None` when the program has all it can index.
    fn slot(&mut self, group: Option<GroupId>, name: &str, what: &'static str, slot: (f64, f64, f64)) -> Option<Slot> {
        if let Some(s) = self.slots.get(&(group, what)) {
            return Some(*s);
        }
        let s = Slot::try_from(self.program.params.len()).ok()?;
        let (min, max, default) = slot;
        self.program.params.push(ParamSlot { name: format!("{name}.{what}"), min, max, default });
        self.slots.insert((group, what), s);
        Some(s)
    }

    /// A written range as a value: its slot (when the range has width), else `nominal`.
    fn range(
        &mut self,
        group: Option<GroupId>,
        name: &str,
        what: &'static str,
        min: f64,
        max: f64,
        nominal: f64,
    ) -> Value {
        let (min, max) = (min.max(0.0), max.max(0.0));
        let wide = max > min && nominal.is_finite();
        if !wide {
            return Value::lit(nominal);
        }
        match self.slot(group, name, what, (min, max, nominal.clamp(min, max))) {
            Some(slot) => Value { base: 0.0, slot: Some(slot) },
            None => Value::lit(nominal),
        }
    }

    fn path(&mut self, line: Polyline) -> Option<PathId> {
        let line = line.canonical();
        if line.0.len() < 2 {
            return None;
        }
        if let Some(i) = self.program.paths.iter().position(|p| *p == line) {
            return PathId::try_from(i).ok();
        }
        let id = PathId::try_from(self.program.paths.len()).ok()?;
        self.program.paths.push(line);
        Some(id)
    }

    /// The slot a group's stations are sampled by: a timed adversary's spread either way,
    /// else the layout's free room towards its reference (never into the junction).
    fn along_slot(&mut self, scenario: &Scenario, layout: &Layout, gl: &GroupLayout, name: &str) -> Option<Slot> {
        let first = gl.agents.first()?;
        let group = Some(gl.group);
        if layout.conflict(gl.group).is_some() {
            let spread = gl.agents.iter().map(|a| layout.conflict_spread(a)).fold(f64::INFINITY, f64::min);
            return (spread.is_finite() && 2.0 * spread >= MIN_ROOM)
                .then(|| self.slot(group, name, "spread", (-spread, spread, 0.0)))
                .flatten();
        }
        let reference = match scenario.group(gl.group).and_then(|g| g.position.given()).map(|p| &p.reference.value) {
            Some(Reference::Group(r)) => layout
                .group(*r)
                .and_then(|r| r.agents.first())
                .filter(|r| r.station.arm == first.station.arm)
                .map_or(0.0, |r| r.station.along),
            _ => 0.0,
        };
        let slack = gl.shift_room();
        let roomy = slack >= MIN_ROOM && slack.is_finite();
        if !roomy {
            return None;
        }
        let range = if first.station.along >= reference { (-slack, 0.0, 0.0) } else { (0.0, slack, 0.0) };
        self.slot(group, name, "shift", range)
    }

    /// One actor's script: ignoring lights when timed, its start, its motion.
    fn script(
        &mut self,
        layout: &Layout,
        gl: &GroupLayout,
        group: &tad_ir::Group,
        agent: &Agent,
        actor: ActorId,
    ) -> Vec<Instr> {
        let mut out = Vec::new();
        let id = Some(gl.group);
        let name = group.name.as_str();
        if layout.conflict(gl.group).is_some() {
            out.push(Instr::Signals { actor, obey: false });
        }
        if agent.start.delay > 0.0 {
            let seconds = match group.delay.given() {
                Some(Param::Range { min, max }) => self.range(id, name, "delay", min.0, max.0, agent.start.delay),
                _ => Value::lit(agent.start.delay),
            };
            out.push(Instr::Wait { actor, seconds });
        }
        if let Some(meet) = agent.start.meet {
            let point = [meet.point.x, meet.point.y];
            out.push(Instr::Meet { actor, point, travel: Value::lit(meet.travel) });
        }
        if let Some(trigger) = agent.start.trigger {
            let distance = match group.trigger.given() {
                Some(Param::Range { min, max }) => self.range(id, name, "trigger", min.0, max.0, trigger),
                _ => Value::lit(trigger),
            };
            out.push(Instr::WaitNear { actor, distance });
        }
        if agent.is_static() {
            return out;
        }
        let speed = match group.speed.given() {
            Some(Param::Range { min, max }) => self.range(id, name, "speed", min.0, max.0, agent.speed),
            _ => Value::lit(agent.speed),
        };
        match (agent.facing, agent.body) {
            (Facing::Across { .. }, _) => out.push(Instr::Cross { actor, speed }),
            (Facing::Along, Body::Vehicle) => {
                let road = &layout.road;
                let (mut lane_path, _) = road.vehicle_path(agent.station, agent.lane, agent.turn);
                if agent.place != Place::Lane {
                    let offset = agent.lateral - road.lateral(agent.lane);
                    lane_path = lane_path.offset(if agent.lane < 0 { -offset } else { offset });
                }
                let lane_start = lane_path.project(agent.pose.position).0;
                let change = match agent.motion {
                    Some(Motion::ChangeLaneLeft) => Some(-1),
                    Some(Motion::ChangeLaneRight) => Some(1),
                    _ => None,
                };
                if same_path(&agent.path, agent.path_start, &lane_path, lane_start) {
                    out.push(Instr::Drive { actor, speed, turn: agent.turn });
                    // background traffic (not timed, keeping its lane, with lanes beside it
                    // its way) passes what blocks it, as drivers do
                    let (incoming, outgoing) = road.arm_lanes(agent.station.arm);
                    let beside = if agent.lane > 0 { incoming } else { outgoing };
                    if layout.conflict(gl.group).is_none()
                        && change.is_none()
                        && agent.place == Place::Lane
                        && beside >= 2
                    {
                        out.push(Instr::Mobil { actor, on: true });
                    }
                } else if let Some(lanes) = change {
                    // the layout baked the change after 1.5 s of driving: the runtime's own
                    // lane change, at the same moment
                    out.push(Instr::Drive { actor, speed, turn: agent.turn });
                    out.push(Instr::Wait { actor, seconds: Value::lit(LANE_CHANGE_AFTER) });
                    out.push(Instr::ChangeLane { actor, lanes });
                } else {
                    self.follow(&mut out, actor, agent, speed);
                }
            }
            (Facing::Along, _) => self.follow(&mut out, actor, agent, speed),
        }
        out
    }

    fn follow(&mut self, out: &mut Vec<Instr>, actor: ActorId, agent: &Agent, speed: Value) {
        let line = Polyline(agent.path.points().iter().map(|p| [p.x, p.y]).collect());
        if let Some(path) = self.path(line) {
            out.push(Instr::Follow { actor, path, speed });
        }
    }
}
