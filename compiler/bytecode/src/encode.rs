//! The writer: a [`Program`] to `.tadc` bytes (`spec/bytecode.md` §2–§4).
//!
//! The sections are written into buffers first, filling the constant pool as operands
//! are met (strings and numbers once each, numbers compared bit for bit), then joined
//! behind the header that gives their lengths. Paths are stored in their canonical form
//! ([`Polyline::canonical`]): millimetre points as zig-zag deltas. The writer checks
//! nothing: a program [`crate::verify()`] rejects is written as it is, and the loader
//! rejects its bytes.

use std::collections::HashMap;

use crate::format::{self, FORMAT_VERSION, MAGIC, Op, Tag};
use crate::program::{Instr, Polyline, Program, Size, Value, to_mm};

/// The `.tadc` bytes of a program.
pub fn encode(program: &Program) -> Vec<u8> {
    let mut pool = Pool::default();
    let mut meta = Vec::new();
    pool.string(&mut meta, &program.name);
    pool.string(&mut meta, &program.source);
    uleb(&mut meta, program.params.len() as u64);
    for slot in &program.params {
        pool.string(&mut meta, &slot.name);
        pool.number(&mut meta, slot.min);
        pool.number(&mut meta, slot.max);
        pool.number(&mut meta, slot.default);
    }
    let mut code = Vec::new();
    uleb(&mut code, program.code.len() as u64);
    for instr in &program.code {
        pool.instr(&mut code, instr);
    }
    let pool = pool.bytes(&program.paths);

    let mut out = Vec::with_capacity(format::HEADER_LEN + pool.len() + meta.len() + code.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    for section in [&pool, &meta, &code] {
        out.extend_from_slice(&u32::try_from(section.len()).unwrap_or(u32::MAX).to_le_bytes());
    }
    out.extend_from_slice(&pool);
    out.extend_from_slice(&meta);
    out.extend_from_slice(&code);
    out
}

/// Unsigned LEB128: seven bits a byte, low first, the high bit set on every byte but the last.
pub(crate) fn uleb(out: &mut Vec<u8>, mut v: u64) {
    loop {
        let byte = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

/// Signed: zig-zag (0, −1, 1, −2, … as 0, 1, 2, 3, …), then [`uleb`].
pub(crate) fn sleb(out: &mut Vec<u8>, v: i64) {
    uleb(out, ((v << 1) ^ (v >> 63)) as u64);
}

#[derive(Default)]
struct Pool {
    strings: Vec<String>,
    string_ids: HashMap<String, u64>,
    numbers: Vec<f64>,
    number_ids: HashMap<u64, u64>,
}

impl Pool {
    fn string(&mut self, out: &mut Vec<u8>, s: &str) {
        let id = match self.string_ids.get(s) {
            Some(id) => *id,
            None => {
                let id = self.strings.len() as u64;
                self.strings.push(s.to_string());
                self.string_ids.insert(s.to_string(), id);
                id
            }
        };
        uleb(out, id);
    }

    fn number(&mut self, out: &mut Vec<u8>, v: f64) {
        let numbers = &mut self.numbers;
        let id = *self.number_ids.entry(v.to_bits()).or_insert_with(|| {
            numbers.push(v);
            numbers.len() as u64 - 1
        });
        uleb(out, id);
    }

    fn value(&mut self, out: &mut Vec<u8>, v: Value) {
        self.number(out, v.base);
        uleb(out, v.slot.map_or(0, |s| u64::from(s) + 1));
    }

    fn size(&mut self, out: &mut Vec<u8>, s: Size) {
        for v in [s.length, s.width, s.height] {
            self.number(out, v);
        }
    }

    /// `road`: the shape, lanes, flags, light, approach and junction.
    fn road(&mut self, out: &mut Vec<u8>, road: &tad_road::Road) {
        out.push(Op::Road as u8);
        out.push(road.shape.tag());
        out.push(match road.shape {
            tad_road::Shape::Junction { arms, .. } => arms,
            _ => 0,
        });
        for n in [road.lanes, road.opposite, road.cross_lanes] {
            uleb(out, u64::from(n));
        }
        self.number(out, road.lane_width);
        let flags = if road.sidewalks { format::ROAD_SIDEWALKS } else { 0 }
            | if road.crosswalks { format::ROAD_CROSSWALKS } else { 0 };
        out.push(flags);
        out.push(road.signal.tag());
        self.number(out, road.approach);
        match &road.junction {
            None => out.push(0),
            Some(j) => {
                out.push(1);
                out.push(j.arms.iter().fold(0, |set, a| set | format::arm_bit(*a)));
                out.push(
                    if j.roundabout { format::JUNCTION_ROUNDABOUT } else { 0 }
                        | if j.signalised { format::JUNCTION_SIGNALISED } else { 0 }
                        | if j.stop_signs { format::JUNCTION_STOP_SIGNS } else { 0 },
                );
                self.number(out, j.half);
            }
        }
    }

    fn instr(&mut self, out: &mut Vec<u8>, instr: &Instr) {
        let op = |out: &mut Vec<u8>, op: Op| out.push(op as u8);
        match instr {
            Instr::Road(road) => self.road(out, road),
            Instr::Limits { dt, max_steps, max_distance, timeout } => {
                op(out, Op::Limits);
                self.number(out, *dt);
                uleb(out, u64::from(*max_steps));
                self.number(out, *max_distance);
                self.number(out, *timeout);
            }
            Instr::Signal { arm, phases } => {
                op(out, Op::Signal);
                out.push(arm.tag());
                uleb(out, phases.len() as u64);
                for p in phases {
                    out.push(p.light.tag());
                    self.number(out, p.seconds);
                }
            }
            Instr::Ego { class, size, lane, turn, path, start, route_length, speed } => {
                op(out, Op::Ego);
                self.string(out, class);
                self.size(out, *size);
                sleb(out, *lane);
                out.push(turn.tag());
                uleb(out, u64::from(*path));
                self.number(out, *start);
                self.number(out, *route_length);
                self.value(out, *speed);
            }
            Instr::Spawn {
                actor,
                group,
                index,
                body,
                class,
                size,
                arm,
                lane,
                place,
                along,
                lateral,
                facing,
                yaw,
                speed,
            } => {
                op(out, Op::Spawn);
                uleb(out, u64::from(*actor));
                self.string(out, group);
                uleb(out, u64::from(*index));
                out.push(body.tag());
                self.string(out, class);
                self.size(out, *size);
                out.push(arm.tag());
                sleb(out, *lane);
                out.push(place.tag());
                self.value(out, *along);
                self.number(out, *lateral);
                out.push(facing.tag());
                self.number(out, *yaw);
                self.number(out, *speed);
            }
            Instr::Wait { actor, seconds } => {
                op(out, Op::Wait);
                uleb(out, u64::from(*actor));
                self.value(out, *seconds);
            }
            Instr::WaitNear { actor, distance } => {
                op(out, Op::WaitNear);
                uleb(out, u64::from(*actor));
                self.value(out, *distance);
            }
            Instr::Meet { actor, point, travel } => {
                op(out, Op::Meet);
                uleb(out, u64::from(*actor));
                self.number(out, point[0]);
                self.number(out, point[1]);
                self.value(out, *travel);
            }
            Instr::Drive { actor, speed, turn } => {
                op(out, Op::Drive);
                uleb(out, u64::from(*actor));
                self.value(out, *speed);
                out.push(turn.tag());
            }
            Instr::Follow { actor, path, speed } => {
                op(out, Op::Follow);
                uleb(out, u64::from(*actor));
                uleb(out, u64::from(*path));
                self.value(out, *speed);
            }
            Instr::Cross { actor, speed } => {
                op(out, Op::Cross);
                uleb(out, u64::from(*actor));
                self.value(out, *speed);
            }
            Instr::ChangeLane { actor, lanes } => {
                op(out, Op::ChangeLane);
                uleb(out, u64::from(*actor));
                sleb(out, *lanes);
            }
            Instr::Speed { actor, speed } => {
                op(out, Op::Speed);
                uleb(out, u64::from(*actor));
                self.value(out, *speed);
            }
            Instr::Stop { actor } => {
                op(out, Op::Stop);
                uleb(out, u64::from(*actor));
            }
            Instr::Signals { actor, obey } => {
                op(out, Op::Signals);
                uleb(out, u64::from(*actor));
                out.push(u8::from(*obey));
            }
            Instr::Mobil { actor, on } => {
                op(out, Op::Mobil);
                uleb(out, u64::from(*actor));
                out.push(u8::from(*on));
            }
        }
    }

    /// The pool section: strings, numbers, paths.
    fn bytes(self, paths: &[Polyline]) -> Vec<u8> {
        let mut out = Vec::new();
        uleb(&mut out, self.strings.len() as u64);
        for s in &self.strings {
            uleb(&mut out, s.len() as u64);
            out.extend_from_slice(s.as_bytes());
        }
        uleb(&mut out, self.numbers.len() as u64);
        for n in &self.numbers {
            out.extend_from_slice(&n.to_le_bytes());
        }
        uleb(&mut out, paths.len() as u64);
        for path in paths {
            let points = path.canonical().0;
            uleb(&mut out, points.len() as u64);
            let mut last = (0i64, 0i64);
            for p in &points {
                let mm = (to_mm(p[0]), to_mm(p[1]));
                sleb(&mut out, mm.0.wrapping_sub(last.0));
                sleb(&mut out, mm.1.wrapping_sub(last.1));
                last = mm;
            }
        }
        out
    }
}
