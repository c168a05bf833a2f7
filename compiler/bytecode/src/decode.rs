//! The loader: `.tadc` bytes to a verified [`Program`] (`spec/bytecode.md` §2–§6).
//!
//! Two stages. Reading checks the bytes: the magic, the version, section lengths that
//! add up to the file, canonical varints, UTF-8, pool indices, opcodes and tags; every
//! count is checked against the bytes left before anything is allocated for it, so a
//! length field never makes the loader allocate more than the file's size. Then
//! [`crate::verify()`] checks the rules the runtime relies on, and its item (an
//! instruction, a slot, a path) becomes the byte offset where that item starts.
//! Nothing here panics, whatever the bytes.

use tad_road::road::Junction;
use tad_road::{Arm, Road, Shape};

use crate::error::{ErrorKind, Item, LoadError};
use crate::format::{self, FORMAT_VERSION, HEADER_LEN, MAGIC, Op, Tag};
use crate::program::{Instr, ParamSlot, Phase, Polyline, Program, Size, Value, from_mm};

/// The largest path coordinate the loader accepts, mm (1000 km).
const MAX_MM: i64 = 1_000_000_000;

/// A verified program from `.tadc` bytes.
pub fn decode(bytes: &[u8]) -> std::result::Result<Program, LoadError> {
    let at = |offset: usize, kind: ErrorKind| LoadError { offset, kind };
    let magic_len = bytes.len().min(MAGIC.len());
    if bytes[..magic_len] != MAGIC[..magic_len] || bytes.is_empty() {
        return Err(at(0, ErrorKind::NotBytecode));
    }
    if let Some(v) = bytes.get(4..6) {
        let version = u16::from_le_bytes([v[0], v[1]]);
        if version > FORMAT_VERSION {
            return Err(at(4, ErrorKind::NewerFormat { found: version, reads: FORMAT_VERSION }));
        }
        if version == 0 {
            return Err(at(4, ErrorKind::UnknownFormat { found: version }));
        }
    }
    let Some(header) = bytes.get(..HEADER_LEN) else {
        return Err(at(bytes.len(), ErrorKind::Truncated { inside: "the header" }));
    };
    let flags = u16::from_le_bytes([header[6], header[7]]);
    if flags != 0 {
        return Err(at(6, ErrorKind::Flags(flags)));
    }
    let len = |i: usize| u32::from_le_bytes([header[i], header[i + 1], header[i + 2], header[i + 3]]) as usize;
    let sections = [("pool", len(8)), ("program", len(12)), ("code", len(16))];
    let mut start = HEADER_LEN;
    let mut spans = Vec::with_capacity(3);
    for (name, length) in sections {
        let end = start.saturating_add(length);
        if end > bytes.len() {
            let inside = match name {
                "pool" => "the pool section",
                "program" => "the program section",
                _ => "the code section",
            };
            return Err(at(bytes.len(), ErrorKind::Truncated { inside }));
        }
        spans.push((name, start, end));
        start = end;
    }
    if start < bytes.len() {
        return Err(at(start, ErrorKind::TrailingBytes { count: bytes.len() - start }));
    }

    let mut d = Decoder::default();
    let mut program = Program::default();
    let mut offsets = Offsets::default();
    let code_start = spans[2].1;
    for (name, start, end) in spans {
        let mut r = Reader { bytes: &bytes[start..end], pos: 0, base: start };
        match name {
            "pool" => d.pool(&mut r, &mut program, &mut offsets)?,
            "program" => d.meta(&mut r, &mut program, &mut offsets)?,
            _ => d.code(&mut r, &mut program, &mut offsets)?,
        }
        if r.pos < r.bytes.len() {
            return Err(at(r.offset(), ErrorKind::SectionLeftover { section: name, count: r.bytes.len() - r.pos }));
        }
    }
    crate::verify(&program).map_err(|e| {
        let offset = match e.at {
            Item::Program => code_start,
            Item::Param(i) => offsets.params.get(i).copied().unwrap_or(code_start),
            Item::Path(i) => offsets.paths.get(i).copied().unwrap_or(code_start),
            Item::Instr(i) => offsets.code.get(i).copied().unwrap_or(code_start),
        };
        LoadError { offset, kind: e.kind }
    })?;
    Ok(program)
}

/// Where each item starts in the file.
#[derive(Default)]
struct Offsets {
    params: Vec<usize>,
    paths: Vec<usize>,
    code: Vec<usize>,
}

/// A cursor over one section.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// The section's offset in the file.
    base: usize,
}

type Result<T> = std::result::Result<T, LoadError>;

impl<'a> Reader<'a> {
    fn offset(&self) -> usize {
        self.base + self.pos
    }

    fn left(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn error(&self, offset: usize, kind: ErrorKind) -> LoadError {
        LoadError { offset, kind }
    }

    fn take(&mut self, n: usize, inside: &'static str) -> Result<&'a [u8]> {
        match self.bytes.get(self.pos..self.pos.saturating_add(n)) {
            Some(b) => {
                self.pos += n;
                Ok(b)
            }
            None => Err(self.error(self.base + self.bytes.len(), ErrorKind::Truncated { inside })),
        }
    }

    fn u8(&mut self, inside: &'static str) -> Result<u8> {
        Ok(self.take(1, inside)?[0])
    }

    /// Unsigned LEB128 of at most `bits` bits, in its shortest form.
    fn leb(&mut self, bits: u32, inside: &'static str) -> Result<u64> {
        let start = self.offset();
        let mut value: u64 = 0;
        let mut shift = 0u32;
        loop {
            let byte = self.u8(inside)?;
            let low = u64::from(byte & 0x7f);
            // too many bytes, or bits beyond the value's width
            if shift >= bits || (bits - shift < 7 && low >> (bits - shift) != 0) {
                return Err(self.error(start, ErrorKind::BadVarint));
            }
            value |= low << shift;
            if byte & 0x80 == 0 {
                // the last byte of a longer encoding is never 0
                if byte == 0 && shift > 0 {
                    return Err(self.error(start, ErrorKind::BadVarint));
                }
                return Ok(value);
            }
            shift += 7;
        }
    }

    fn uleb(&mut self, inside: &'static str) -> Result<u64> {
        self.leb(32, inside)
    }

    fn sleb(&mut self, inside: &'static str) -> Result<i64> {
        let z = self.leb(64, inside)?;
        Ok(((z >> 1) as i64) ^ -((z & 1) as i64))
    }

    /// A count of items of at least `min_size` bytes each, no more than the bytes left hold.
    fn count(&mut self, what: &'static str, min_size: usize) -> Result<usize> {
        let start = self.offset();
        let count = self.uleb(what)?;
        let left = self.left();
        if count > (left / min_size.max(1)) as u64 {
            return Err(self.error(start, ErrorKind::TooMany { what, count, left }));
        }
        Ok(count as usize)
    }

    fn f64(&mut self, inside: &'static str) -> Result<f64> {
        let b = self.take(8, inside)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }

    fn tag<T: Tag>(&mut self) -> Result<T> {
        let start = self.offset();
        let tag = self.u8(T::WHAT)?;
        T::from_tag(tag).ok_or_else(|| self.error(start, ErrorKind::BadTag { what: T::WHAT, tag }))
    }

    fn flag(&mut self, what: &'static str) -> Result<bool> {
        let start = self.offset();
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            tag => Err(self.error(start, ErrorKind::BadTag { what, tag })),
        }
    }

    /// A byte of flags, none outside `known`.
    fn flags(&mut self, what: &'static str, known: u8) -> Result<u8> {
        let start = self.offset();
        let tag = self.u8(what)?;
        if tag & !known != 0 {
            return Err(self.error(start, ErrorKind::BadTag { what, tag }));
        }
        Ok(tag)
    }

    /// An id or index that fits 16 bits.
    fn u16(&mut self, what: &'static str) -> Result<u16> {
        let start = self.offset();
        let v = self.uleb(what)?;
        u16::try_from(v)
            .map_err(|_| self.error(start, ErrorKind::OutOfRange { what, value: v as f64, expected: "at most 65535" }))
    }
}

#[derive(Default)]
struct Decoder {
    strings: Vec<String>,
    numbers: Vec<f64>,
}

impl Decoder {
    fn pool(&mut self, r: &mut Reader, program: &mut Program, offsets: &mut Offsets) -> Result<()> {
        let n = r.count("strings", 1)?;
        self.strings.reserve(n);
        for _ in 0..n {
            let start = r.offset();
            let len = r.count("string bytes", 1)?;
            let bytes = r.take(len, "a string")?;
            let s = std::str::from_utf8(bytes).map_err(|_| r.error(start, ErrorKind::BadUtf8))?;
            self.strings.push(s.to_string());
        }
        let n = r.count("numbers", 8)?;
        self.numbers.reserve(n);
        for _ in 0..n {
            self.numbers.push(r.f64("a number")?);
        }
        let n = r.count("paths", 1)?;
        program.paths.reserve(n);
        for _ in 0..n {
            offsets.paths.push(r.offset());
            let points = r.count("path points", 2)?;
            let mut out = Vec::with_capacity(points);
            let mut last = (0i64, 0i64);
            for _ in 0..points {
                let start = r.offset();
                let (dx, dy) = (r.sleb("a path point")?, r.sleb("a path point")?);
                let (x, y) = (last.0.checked_add(dx), last.1.checked_add(dy));
                let (Some(x), Some(y)) = (x, y) else {
                    return Err(r.error(start, coordinate(i64::MAX)));
                };
                for v in [x, y] {
                    if v.unsigned_abs() > MAX_MM.unsigned_abs() {
                        return Err(r.error(start, coordinate(v)));
                    }
                }
                out.push([from_mm(x), from_mm(y)]);
                last = (x, y);
            }
            program.paths.push(Polyline(out));
        }
        Ok(())
    }

    fn meta(&mut self, r: &mut Reader, program: &mut Program, offsets: &mut Offsets) -> Result<()> {
        program.name = self.string(r)?;
        program.source = self.string(r)?;
        let n = r.count("parameter slots", 4)?;
        program.params.reserve(n);
        for _ in 0..n {
            offsets.params.push(r.offset());
            let name = self.string(r)?;
            let (min, max, default) = (self.number(r)?, self.number(r)?, self.number(r)?);
            program.params.push(ParamSlot { name, min, max, default });
        }
        Ok(())
    }

    fn code(&mut self, r: &mut Reader, program: &mut Program, offsets: &mut Offsets) -> Result<()> {
        let n = r.count("instructions", 2)?;
        program.code.reserve(n);
        offsets.code.reserve(n);
        for _ in 0..n {
            offsets.code.push(r.offset());
            let instr = self.instr(r)?;
            program.code.push(instr);
        }
        Ok(())
    }

    fn string(&self, r: &mut Reader) -> Result<String> {
        let start = r.offset();
        let i = r.uleb("a string index")?;
        self.strings.get(i as usize).cloned().ok_or_else(|| {
            r.error(start, ErrorKind::IndexOutOfRange { what: "string", index: i, len: self.strings.len() })
        })
    }

    fn number(&self, r: &mut Reader) -> Result<f64> {
        let start = r.offset();
        let i = r.uleb("a number index")?;
        self.numbers.get(i as usize).copied().ok_or_else(|| {
            r.error(start, ErrorKind::IndexOutOfRange { what: "number", index: i, len: self.numbers.len() })
        })
    }

    fn value(&self, r: &mut Reader) -> Result<Value> {
        let base = self.number(r)?;
        let start = r.offset();
        let slot = r.uleb("a value's slot")?;
        let slot = match slot {
            0 => None,
            s => Some(u16::try_from(s - 1).map_err(|_| {
                r.error(
                    start,
                    ErrorKind::OutOfRange {
                        what: "a parameter slot",
                        value: (s - 1) as f64,
                        expected: "at most 65535",
                    },
                )
            })?),
        };
        Ok(Value { base, slot })
    }

    fn size(&self, r: &mut Reader) -> Result<Size> {
        Ok(Size { length: self.number(r)?, width: self.number(r)?, height: self.number(r)? })
    }

    fn lanes(r: &mut Reader) -> Result<u32> {
        Ok(r.uleb("a lane count")? as u32)
    }

    fn instr(&self, r: &mut Reader) -> Result<Instr> {
        let start = r.offset();
        let byte = r.u8("an instruction")?;
        let op = Op::from_byte(byte).ok_or_else(|| r.error(start, ErrorKind::UnknownOpcode(byte)))?;
        let actor = |r: &mut Reader| r.u16("an actor id");
        Ok(match op {
            Op::Road => {
                let mut shape: Shape = r.tag()?;
                let arms_at = r.offset();
                let arms = r.u8("a junction's arm count")?;
                match &mut shape {
                    Shape::Junction { arms: a, .. } => *a = arms,
                    _ if arms != 0 => {
                        return Err(r.error(
                            arms_at,
                            ErrorKind::BadTag { what: "an arm count of a road with no junction", tag: arms },
                        ));
                    }
                    _ => {}
                }
                let (lanes, opposite, cross_lanes) = (Self::lanes(r)?, Self::lanes(r)?, Self::lanes(r)?);
                let lane_width = self.number(r)?;
                let flags = r.flags("a set of road flags", format::ROAD_SIDEWALKS | format::ROAD_CROSSWALKS)?;
                let signal = r.tag()?;
                let approach = self.number(r)?;
                let junction = if r.flag("a junction marker")? {
                    let set = r.flags("a set of arms", 0x0f)?;
                    let jf = r.flags(
                        "a set of junction flags",
                        format::JUNCTION_ROUNDABOUT | format::JUNCTION_SIGNALISED | format::JUNCTION_STOP_SIGNS,
                    )?;
                    let half = self.number(r)?;
                    Some(Junction {
                        arms: Arm::ALL.into_iter().filter(|a| set & format::arm_bit(*a) != 0).collect(),
                        roundabout: jf & format::JUNCTION_ROUNDABOUT != 0,
                        half,
                        signalised: jf & format::JUNCTION_SIGNALISED != 0,
                        stop_signs: jf & format::JUNCTION_STOP_SIGNS != 0,
                    })
                } else {
                    None
                };
                Instr::Road(Road {
                    shape,
                    lanes,
                    opposite,
                    cross_lanes,
                    lane_width,
                    sidewalks: flags & format::ROAD_SIDEWALKS != 0,
                    crosswalks: flags & format::ROAD_CROSSWALKS != 0,
                    signal,
                    junction,
                    approach,
                })
            }
            Op::Limits => Instr::Limits {
                dt: self.number(r)?,
                max_steps: r.uleb("a step count")? as u32,
                max_distance: self.number(r)?,
                timeout: self.number(r)?,
            },
            Op::Signal => {
                let arm = r.tag()?;
                let n = r.count("phases", 2)?;
                let mut phases = Vec::with_capacity(n);
                for _ in 0..n {
                    phases.push(Phase { light: r.tag()?, seconds: self.number(r)? });
                }
                Instr::Signal { arm, phases }
            }
            Op::Ego => Instr::Ego {
                class: self.string(r)?,
                size: self.size(r)?,
                lane: r.sleb("a lane")?,
                turn: r.tag()?,
                path: r.u16("a path index")?,
                start: self.number(r)?,
                route_length: self.number(r)?,
                speed: self.value(r)?,
            },
            Op::Spawn => Instr::Spawn {
                actor: actor(r)?,
                group: self.string(r)?,
                index: r.u16("an index in a group")?,
                body: r.tag()?,
                class: self.string(r)?,
                size: self.size(r)?,
                arm: r.tag()?,
                lane: r.sleb("a lane")?,
                place: r.tag()?,
                along: self.value(r)?,
                lateral: self.number(r)?,
                facing: r.tag()?,
                yaw: self.number(r)?,
                speed: self.number(r)?,
            },
            Op::Wait => Instr::Wait { actor: actor(r)?, seconds: self.value(r)? },
            Op::WaitNear => Instr::WaitNear { actor: actor(r)?, distance: self.value(r)? },
            Op::Meet => {
                Instr::Meet { actor: actor(r)?, point: [self.number(r)?, self.number(r)?], travel: self.value(r)? }
            }
            Op::Drive => Instr::Drive { actor: actor(r)?, speed: self.value(r)?, turn: r.tag()? },
            Op::Follow => Instr::Follow { actor: actor(r)?, path: r.u16("a path index")?, speed: self.value(r)? },
            Op::Cross => Instr::Cross { actor: actor(r)?, speed: self.value(r)? },
            Op::ChangeLane => Instr::ChangeLane { actor: actor(r)?, lanes: r.sleb("a lane change")? },
            Op::Speed => Instr::Speed { actor: actor(r)?, speed: self.value(r)? },
            Op::Stop => Instr::Stop { actor: actor(r)? },
            Op::Signals => Instr::Signals { actor: actor(r)?, obey: r.flag("a boolean")? },
            Op::Mobil => Instr::Mobil { actor: actor(r)?, on: r.flag("a boolean")? },
        })
    }
}

fn coordinate(mm: i64) -> ErrorKind {
    ErrorKind::OutOfRange { what: "a path coordinate", value: from_mm(mm), expected: "within ±1000 km" }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encode::{sleb, uleb};

    fn reader(bytes: &[u8]) -> Reader<'_> {
        Reader { bytes, pos: 0, base: 0 }
    }

    #[test]
    fn varints_round_trip_in_their_shortest_form_only() {
        for v in [0u64, 1, 127, 128, 300, 16_383, 16_384, u64::from(u32::MAX)] {
            let mut out = Vec::new();
            uleb(&mut out, v);
            let mut r = reader(&out);
            assert_eq!(r.uleb("x"), Ok(v));
            assert_eq!(r.pos, out.len());
        }
        for v in [0i64, -1, 1, -64, 64, i64::MIN, i64::MAX, -1_000_000_000] {
            let mut out = Vec::new();
            sleb(&mut out, v);
            assert_eq!(reader(&out).sleb("x"), Ok(v), "{v}");
        }
        // over-long, too large for 32 bits, unterminated
        for bad in [
            &[0x80, 0x00][..],
            &[0xff, 0x80, 0x00],
            &[0x80, 0x80, 0x80, 0x80, 0x10],
            &[0x80, 0x80, 0x80, 0x80, 0x80, 0x01],
        ] {
            assert_eq!(reader(bad).uleb("x").map_err(|e| e.kind), Err(ErrorKind::BadVarint), "{bad:x?}");
        }
        assert!(matches!(reader(&[0x80, 0x80]).uleb("x").map_err(|e| e.kind), Err(ErrorKind::Truncated { .. })));
        // 64-bit: the tenth byte holds one bit
        let mut max = vec![0xff; 9];
        max.push(0x01);
        assert_eq!(reader(&max).leb(64, "x"), Ok(u64::MAX));
        max[9] = 0x02;
        assert_eq!(reader(&max).leb(64, "x").map_err(|e| e.kind), Err(ErrorKind::BadVarint));
    }
}
