//! The listing of a program (`spec/bytecode.md` §4): a header, the parameter slots, the
//! paths, then one instruction a line, its operands named. Numbers show at most two
//! decimals; a value with a slot shows as `base+$slot`; strings with control characters
//! are escaped, so a line is always one instruction. A pure function of the program.

use std::fmt::Write;

use tad_road::{Facing, Place, Road, Shape, Side};

use crate::format::{self, FORMAT_VERSION, Op};
use crate::program::{Instr, Phase, Program, Size, Value};

/// The listing of a program.
pub fn disasm(p: &Program) -> String {
    let mut out = String::new();
    let _ = write(&mut out, p);
    out
}

fn write(out: &mut String, p: &Program) -> std::fmt::Result {
    writeln!(out, "; TADSL bytecode, format {FORMAT_VERSION}")?;
    writeln!(out, "program  {}", text(&p.name))?;
    writeln!(out, "source   {}", text(&p.source))?;
    writeln!(out, "params   {}", p.params.len())?;
    for (i, s) in p.params.iter().enumerate() {
        writeln!(out, "  ${i:<3} {:<24} {}..{} default {}", text(&s.name), num(s.min), num(s.max), num(s.default))?;
    }
    writeln!(out, "paths    {}", p.paths.len())?;
    for (i, line) in p.paths.iter().enumerate() {
        let point =
            |q: Option<&[f64; 2]>| q.map_or_else(|| "-".to_string(), |q| format!("({}, {})", num(q[0]), num(q[1])));
        writeln!(
            out,
            "  #{i:<3} {} points {} m {} .. {}",
            line.0.len(),
            num(line.length()),
            point(line.0.first()),
            point(line.0.last())
        )?;
    }
    writeln!(out, "code     {}", p.code.len())?;
    for instr in &p.code {
        writeln!(out, "  {}", instruction(p, instr))?;
    }
    Ok(())
}

/// One instruction: its mnemonic, padded, then its operands.
fn instruction(p: &Program, instr: &Instr) -> String {
    let v = |value: &Value| val(p, value);
    let (op, operands) = match instr {
        Instr::Road(road) => (Op::Road, road_operands(road)),
        Instr::Limits { dt, max_steps, max_distance, timeout } => (
            Op::Limits,
            format!("dt={}s steps={max_steps} distance={}m timeout={}s", num(*dt), num(*max_distance), num(*timeout)),
        ),
        Instr::Signal { arm, phases } => (Op::Signal, format!("arm={} {}", format::arm_name(*arm), phase_list(phases))),
        Instr::Ego { class, size: s, lane, turn, path, start, route_length, speed } => (
            Op::Ego,
            format!(
                "{} {} lane={lane} turn={} path=#{path} start={} route={}m v={}",
                text(class),
                dims(*s),
                format::turn_name(*turn),
                num(*start),
                num(*route_length),
                v(speed)
            ),
        ),
        Instr::Spawn {
            actor,
            group,
            index,
            body,
            class,
            size: s,
            arm,
            lane,
            place,
            along,
            lateral,
            facing,
            yaw,
            speed,
        } => {
            let mut o = format!(
                "a{actor} {}[{index}] {} {} {} arm={} lane={lane}",
                text(group),
                format::body_name(*body),
                text(class),
                dims(*s),
                format::arm_name(*arm)
            );
            if *place != Place::Lane {
                let _ = write!(o, " place={}", format::place_name(*place));
            }
            let _ = write!(o, " along={} lateral={}", v(along), num(*lateral));
            if let Facing::Across { from } = facing {
                let _ = write!(o, " across-from={}", if *from == Side::Left { "left" } else { "right" });
            }
            let _ = write!(o, " yaw={}° v={}", num(yaw.to_degrees()), num(*speed));
            (Op::Spawn, o)
        }
        Instr::Wait { actor, seconds } => (Op::Wait, format!("a{actor} {}s", v(seconds))),
        Instr::WaitNear { actor, distance } => (Op::WaitNear, format!("a{actor} {}m", v(distance))),
        Instr::Meet { actor, point, travel } => {
            (Op::Meet, format!("a{actor} at=({}, {}) {}s", num(point[0]), num(point[1]), v(travel)))
        }
        Instr::Drive { actor, speed, turn } => {
            (Op::Drive, format!("a{actor} v={} turn={}", v(speed), format::turn_name(*turn)))
        }
        Instr::Follow { actor, path, speed } => (Op::Follow, format!("a{actor} path=#{path} v={}", v(speed))),
        Instr::Cross { actor, speed } => (Op::Cross, format!("a{actor} v={}", v(speed))),
        Instr::ChangeLane { actor, lanes } => (Op::ChangeLane, format!("a{actor} {lanes:+}")),
        Instr::Speed { actor, speed } => (Op::Speed, format!("a{actor} v={}", v(speed))),
        Instr::Stop { actor } => (Op::Stop, format!("a{actor}")),
        Instr::Signals { actor, obey } => (Op::Signals, format!("a{actor} {}", if *obey { "obey" } else { "ignore" })),
        Instr::Mobil { actor, on } => (Op::Mobil, format!("a{actor} {}", if *on { "on" } else { "off" })),
    };
    format!("{:<8} {operands}", op.mnemonic())
}

fn road_operands(r: &Road) -> String {
    let mut o = match r.shape {
        Shape::Straight => "straight".to_string(),
        Shape::Curve { left } => format!("curve-{}", if left { "left" } else { "right" }),
        Shape::Junction { arms, roundabout } => {
            format!("{} arms={arms}", if roundabout { "roundabout" } else { "junction" })
        }
    };
    let _ = write!(o, " lanes={} opposite={} cross={} width={}", r.lanes, r.opposite, r.cross_lanes, num(r.lane_width));
    if r.sidewalks {
        o.push_str(" sidewalks");
    }
    if r.crosswalks {
        o.push_str(" crosswalks");
    }
    if let Some(signal) = r.signal {
        let _ = write!(o, " light={}", tad_ir::ClosedSet::as_str(signal));
    }
    let _ = write!(o, " approach={}", num(r.approach));
    if let Some(j) = &r.junction {
        let arms: Vec<&str> = j.arms.iter().map(|a| format::arm_name(*a)).collect();
        let _ = write!(o, " junction=[{}] half={}", arms.join(" "), num(j.half));
        for (on, word) in [(j.roundabout, "roundabout"), (j.signalised, "signalised"), (j.stop_signs, "stop-signs")] {
            if on {
                let _ = write!(o, " {word}");
            }
        }
    }
    o
}

fn phase_list(phases: &[Phase]) -> String {
    let each: Vec<String> =
        phases.iter().map(|p| format!("{} {}s", format::light_name(p.light), num(p.seconds))).collect();
    each.join(", ")
}

fn dims(s: Size) -> String {
    format!("{}x{}x{}", num(s.length), num(s.width), num(s.height))
}

/// A value: its base, and `+$slot` (or `$slot` alone on a base of 0).
fn val(p: &Program, v: &Value) -> String {
    let Some(slot) = v.slot else { return num(v.base) };
    let name = p.params.get(usize::from(slot)).map_or_else(|| format!("${slot}"), |s| format!("${}", text(&s.name)));
    if v.base == 0.0 { name } else { format!("{}+{name}", num(v.base)) }
}

/// A number with at most two decimals, at least one: `31.2`, `1.75`, `90.0`.
fn num(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let s = format!("{v:.2}");
    let s = s.strip_suffix('0').unwrap_or(&s);
    let s = if s == "-0.0" { "0.0" } else { s };
    s.to_string()
}

/// A string as one line: control characters escaped.
fn text(s: &str) -> String {
    if s.chars().any(char::is_control) { s.escape_debug().to_string() } else { s.to_string() }
}
