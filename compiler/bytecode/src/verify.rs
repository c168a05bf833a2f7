//! The rules a program keeps so that the runtime can index and divide without checks
//! (`spec/bytecode.md` §6): every number finite and in its range, every slot, path and
//! actor index valid, the set-up complete and before the behaviour. The loader runs them
//! on every file; [`crate::lower()`]'s programs keep them (its tests check).

use tad_road::{Arm, Road, Shape};

use crate::error::{ErrorKind, Invalid, Item};
use crate::program::{Instr, Program, Size, Value};

/// The most lanes a road has each way, and the largest lane index.
pub const MAX_LANES: i64 = 12;
/// The farthest a path point is from the origin on either axis, m.
pub const MAX_COORDINATE: f64 = 1e6;
/// The most steps a run may last.
pub const MAX_STEPS: u32 = 1_000_000;
/// How far the ego's route may end past its path's end, m (rounding).
const ROUTE_SLACK: f64 = 0.01;

type Check = Result<(), ErrorKind>;

fn finite(what: &'static str, v: f64) -> Check {
    if v.is_finite() { Ok(()) } else { Err(ErrorKind::NonFinite { what }) }
}

fn within(what: &'static str, v: f64, ok: bool, expected: &'static str) -> Check {
    finite(what, v)?;
    if ok { Ok(()) } else { Err(ErrorKind::OutOfRange { what, value: v, expected }) }
}

fn positive(what: &'static str, v: f64) -> Check {
    within(what, v, v > 0.0, "above 0")
}

fn non_negative(what: &'static str, v: f64) -> Check {
    within(what, v, v >= 0.0, "0 or more")
}

fn size(s: Size) -> Check {
    positive("a length", s.length)?;
    positive("a width", s.width)?;
    positive("a height", s.height)
}

/// A value's base is finite and its slot exists; with `non_negative`, it is at least 0
/// whatever its slot draws.
fn value(p: &Program, what: &'static str, v: Value, non_negative: bool) -> Check {
    finite(what, v.base)?;
    let least = match v.slot {
        None => v.base,
        Some(s) => match p.params.get(usize::from(s)) {
            Some(slot) => v.base + slot.min,
            None => {
                return Err(ErrorKind::IndexOutOfRange {
                    what: "parameter slot",
                    index: u64::from(s),
                    len: p.params.len(),
                });
            }
        },
    };
    // the slot's bounds are finite (checked first), so `least` is a number
    if non_negative && least < 0.0 {
        return Err(ErrorKind::OutOfRange { what, value: least, expected: "0 or more for every value of its slot" });
    }
    Ok(())
}

fn path(p: &Program, index: u16) -> Result<&crate::Polyline, ErrorKind> {
    p.paths.get(usize::from(index)).ok_or(ErrorKind::IndexOutOfRange {
        what: "path",
        index: u64::from(index),
        len: p.paths.len(),
    })
}

fn lane_change(lanes: i64) -> Check {
    if lanes != 0 && lanes.unsigned_abs() <= MAX_LANES.unsigned_abs() {
        Ok(())
    } else {
        Err(ErrorKind::OutOfRange { what: "a lane change", value: lanes as f64, expected: "±1 to ±12 lanes" })
    }
}

fn road(r: &Road) -> Check {
    let count = |what: &'static str, n: u32, least: u32| {
        let ok = n >= least && i64::from(n) <= MAX_LANES;
        within(what, f64::from(n), ok, if least == 0 { "0 to 12" } else { "1 to 12" })
    };
    count("the road's lanes", r.lanes, 1)?;
    count("the road's opposite lanes", r.opposite, 0)?;
    count("the crossing roads' lanes", r.cross_lanes, 1)?;
    within("the lane width", r.lane_width, r.lane_width > 0.0 && r.lane_width <= 10.0, "above 0 m, at most 10 m")?;
    non_negative("the ego's approach", r.approach)?;
    if let Shape::Junction { arms, .. } = r.shape {
        within("a junction's arm count", f64::from(arms), arms == 3 || arms == 4, "3 or 4")?;
        match &r.junction {
            Some(j) if j.arms.len() == usize::from(arms) => {}
            _ => return Err(ErrorKind::Misplaced("the road's shape and its junction's arms disagree")),
        }
    }
    if let Some(j) = &r.junction {
        if !j.arms.contains(&Arm::Ego) || j.arms.len() < 3 {
            return Err(ErrorKind::Misplaced("a junction needs the ego's arm and two others"));
        }
        // a set, in `Arm::ALL`'s order: as the format stores it
        if j.arms.windows(2).any(|w| w[0] >= w[1]) {
            return Err(ErrorKind::Misplaced("a junction's arms repeat or are out of order"));
        }
        positive("the junction's half-size", j.half)?;
    }
    Ok(())
}

/// Every rule of `spec/bytecode.md` §6, in order; the first broken one.
pub fn verify(p: &Program) -> Result<(), Invalid> {
    let fail = |at: Item| move |kind: ErrorKind| Invalid { at, kind };
    for (i, slot) in p.params.iter().enumerate() {
        let bad =
            |problem| Invalid { at: Item::Param(i), kind: ErrorKind::BadSlot { name: slot.name.clone(), problem } };
        if slot.name.is_empty() {
            return Err(bad("it has no name"));
        }
        for v in [slot.min, slot.max, slot.default] {
            finite("a parameter slot's bound or default", v).map_err(fail(Item::Param(i)))?;
        }
        if slot.min > slot.max {
            return Err(bad("its minimum is above its maximum"));
        }
        if !(slot.min..=slot.max).contains(&slot.default) {
            return Err(bad("its default is outside its range"));
        }
    }
    for (i, line) in p.paths.iter().enumerate() {
        let at = fail(Item::Path(i));
        if line.0.len() < 2 {
            return Err(at(ErrorKind::BadPath("a path needs two points or more")));
        }
        for v in line.0.iter().flatten() {
            within("a path coordinate", *v, v.abs() <= MAX_COORDINATE, "within ±1000 km")
                .map_err(fail(Item::Path(i)))?;
        }
        if line.0.windows(2).any(|w| w[0] == w[1]) {
            return Err(at(ErrorKind::BadPath("a path repeats a point")));
        }
    }

    let Some(first_road) = p.code.iter().position(|i| matches!(i, Instr::Road(_))) else {
        return Err(Invalid { at: Item::Program, kind: ErrorKind::Missing("`road` instruction") });
    };
    if first_road != 0 {
        return Err(Invalid {
            at: Item::Instr(first_road),
            kind: ErrorKind::Misplaced("`road` must be the first instruction"),
        });
    }
    let mut state = State::default();
    for (i, instr) in p.code.iter().enumerate() {
        state.instr(p, instr).map_err(fail(Item::Instr(i)))?;
    }
    let missing = |what| Err(Invalid { at: Item::Program, kind: ErrorKind::Missing(what) });
    if !state.limits {
        return missing("`limits` instruction");
    }
    if !state.ego {
        return missing("`ego` instruction");
    }
    Ok(())
}

/// What the instructions so far have set up.
#[derive(Default)]
struct State<'p> {
    road: Option<&'p Road>,
    limits: bool,
    ego: bool,
    behaviour: bool,
    spawned: usize,
    signals: Vec<Arm>,
}

impl<'p> State<'p> {
    fn actor(&self, actor: u16) -> Check {
        if usize::from(actor) < self.spawned {
            Ok(())
        } else {
            Err(ErrorKind::UnknownActor { actor, spawned: self.spawned })
        }
    }

    fn instr(&mut self, p: &Program, instr: &'p Instr) -> Check {
        let setup = matches!(
            instr,
            Instr::Road(_) | Instr::Limits { .. } | Instr::Signal { .. } | Instr::Ego { .. } | Instr::Spawn { .. }
        );
        if setup && self.behaviour {
            return Err(ErrorKind::Misplaced("a set-up instruction after a behaviour instruction"));
        }
        self.behaviour |= !setup;
        match instr {
            Instr::Road(r) => {
                if self.road.is_some() {
                    return Err(ErrorKind::Duplicate("`road` instruction"));
                }
                road(r)?;
                self.road = Some(r);
                Ok(())
            }
            Instr::Limits { dt, max_steps, max_distance, timeout } => {
                if std::mem::replace(&mut self.limits, true) {
                    return Err(ErrorKind::Duplicate("`limits` instruction"));
                }
                within("the step length", *dt, *dt > 0.0 && *dt <= 1.0, "above 0 s, at most 1 s")?;
                let steps = f64::from(*max_steps);
                within("the step count", steps, (1..=MAX_STEPS).contains(max_steps), "1 to 1000000")?;
                positive("the longest drive", *max_distance)?;
                positive("the timeout", *timeout)
            }
            Instr::Signal { arm, phases } => {
                let junction = self.road.and_then(|r| r.junction.as_ref()).filter(|j| j.signalised);
                let Some(junction) = junction else {
                    return Err(ErrorKind::Misplaced("a `signal` on a road without a signalised junction"));
                };
                if !junction.arms.contains(arm) {
                    return Err(ErrorKind::Misplaced("a `signal` for an arm the junction does not have"));
                }
                if self.signals.contains(arm) {
                    return Err(ErrorKind::Duplicate("`signal` for one arm"));
                }
                self.signals.push(*arm);
                if phases.is_empty() {
                    return Err(ErrorKind::Missing("phase in a `signal`"));
                }
                phases.iter().try_for_each(|ph| positive("a phase's duration", ph.seconds))
            }
            Instr::Ego { size: s, lane, path: id, start, route_length, speed, .. } => {
                if std::mem::replace(&mut self.ego, true) {
                    return Err(ErrorKind::Duplicate("`ego` instruction"));
                }
                size(*s)?;
                let lanes = self.road.map_or(1, |r| i64::from(r.lanes));
                if !(1..=lanes).contains(lane) {
                    return Err(ErrorKind::OutOfRange {
                        what: "the ego's lane",
                        value: *lane as f64,
                        expected: "a lane of the ego's direction",
                    });
                }
                let length = path(p, *id)?.length();
                within("the ego's start", *start, *start >= 0.0 && *start <= length, "on its path")?;
                positive("the ego's route", *route_length)?;
                let end = start + route_length;
                within("the ego's route's end", end, end <= length + ROUTE_SLACK, "on its path")?;
                value(p, "the ego's speed", *speed, true)
            }
            Instr::Spawn { actor, size: s, arm, lane, along, lateral, yaw, speed, .. } => {
                if usize::from(*actor) != self.spawned {
                    return Err(ErrorKind::SpawnOrder { actor: *actor, expected: self.spawned });
                }
                self.spawned += 1;
                size(*s)?;
                if !self.road.is_some_and(|r| r.has_arm(*arm)) {
                    return Err(ErrorKind::Misplaced("a spawn on an arm the road does not have"));
                }
                if *lane == 0 || lane.unsigned_abs() > MAX_LANES.unsigned_abs() {
                    return Err(ErrorKind::OutOfRange {
                        what: "a spawn's lane",
                        value: *lane as f64,
                        expected: "±1 to ±12",
                    });
                }
                value(p, "a spawn's station", *along, false)?;
                finite("a spawn's lateral offset", *lateral)?;
                finite("a spawn's heading", *yaw)?;
                non_negative("a spawn's speed", *speed)
            }
            Instr::Wait { actor, seconds } => {
                self.actor(*actor)?;
                value(p, "a wait", *seconds, true)
            }
            Instr::WaitNear { actor, distance } => {
                self.actor(*actor)?;
                value(p, "a trigger distance", *distance, true)
            }
            Instr::Meet { actor, point, travel } => {
                self.actor(*actor)?;
                for v in point {
                    within("a conflict point's coordinate", *v, v.abs() <= MAX_COORDINATE, "within ±1000 km")?;
                }
                value(p, "a travel time", *travel, true)
            }
            Instr::Drive { actor, speed, .. } | Instr::Cross { actor, speed } | Instr::Speed { actor, speed } => {
                self.actor(*actor)?;
                value(p, "a speed", *speed, true)
            }
            Instr::Follow { actor, path: id, speed } => {
                self.actor(*actor)?;
                path(p, *id)?;
                value(p, "a speed", *speed, true)
            }
            Instr::ChangeLane { actor, lanes } => {
                self.actor(*actor)?;
                lane_change(*lanes)
            }
            Instr::Stop { actor } | Instr::Signals { actor, .. } | Instr::Mobil { actor, .. } => self.actor(*actor),
        }
    }
}
