//! One test per class of load error (`spec/bytecode.md` §6): what it says and at which
//! byte. Byte-level errors are made by editing a valid file; rule errors by encoding a
//! program that breaks the rule (the encoder writes whatever it is given).

use tad_bytecode::format::{HEADER_LEN, Op};
use tad_bytecode::{ErrorKind, Instr, LoadError, ParamSlot, Polyline, Program, Size, Value, decode, encode, verify};
use tad_road::{Arm, Body, Facing, Place, Road, Shape, Turn};

fn road() -> Road {
    Road {
        shape: Shape::Straight,
        lanes: 2,
        opposite: 1,
        cross_lanes: 2,
        lane_width: 3.5,
        sidewalks: false,
        crosswalks: false,
        signal: None,
        junction: None,
        approach: 0.0,
    }
}

fn spawn(actor: u16) -> Instr {
    Instr::Spawn {
        actor,
        group: "lead".into(),
        index: actor,
        body: Body::Vehicle,
        class: "car".into(),
        size: Size { length: 4.5, width: 1.8, height: 1.5 },
        arm: Arm::Ego,
        lane: 1,
        place: Place::Lane,
        along: Value { base: 20.0, slot: Some(0) },
        lateral: -1.75,
        facing: Facing::Along,
        yaw: 0.0,
        speed: 10.0,
    }
}

/// A small valid program: road, limits, ego, one actor that drives.
fn valid() -> Program {
    Program {
        name: "t".into(),
        source: "t.tad".into(),
        params: vec![ParamSlot { name: "lead.shift".into(), min: -2.0, max: 0.0, default: 0.0 }],
        paths: vec![Polyline(vec![[-100.0, -1.75], [200.0, -1.75]])],
        code: vec![
            Instr::Road(road()),
            Instr::Limits { dt: 0.1, max_steps: 300, max_distance: 150.0, timeout: 100.0 },
            Instr::Ego {
                class: "car".into(),
                size: Size { length: 4.5, width: 1.8, height: 1.5 },
                lane: 1,
                turn: Turn::Straight,
                path: 0,
                start: 100.0,
                route_length: 100.0,
                speed: Value::lit(10.0),
            },
            spawn(0),
            Instr::Drive { actor: 0, speed: Value::lit(10.0), turn: Turn::Straight },
        ],
    }
}

fn load(p: &Program) -> LoadError {
    decode(&encode(p)).expect_err("the program is invalid")
}

/// The error of a program changed by `edit`; its offset is where the `nth` instruction starts.
fn rule(edit: impl FnOnce(&mut Program)) -> (LoadError, Vec<u8>) {
    let mut p = valid();
    edit(&mut p);
    let bytes = encode(&p);
    (decode(&bytes).expect_err("the program is invalid"), bytes)
}

fn section_start(bytes: &[u8], section: usize) -> usize {
    let len = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    HEADER_LEN + (0..section).map(|s| len(8 + 4 * s)).sum::<usize>()
}

#[test]
fn the_valid_program_loads() {
    assert_eq!(verify(&valid()), Ok(()));
    assert_eq!(decode(&encode(&valid())), Ok(valid()));
}

#[test]
fn a_file_of_another_kind_is_not_bytecode() {
    for bytes in [&b"PK\x03\x04rest"[..], b"scenario x {}", b"", b"TADX\x01\x00"] {
        let e = decode(bytes).unwrap_err();
        assert_eq!((e.offset, &e.kind), (0, &ErrorKind::NotBytecode), "{bytes:?}");
        assert!(e.to_string().starts_with("not a TADSL bytecode file"), "{e}");
    }
}

#[test]
fn a_newer_or_unknown_format_is_refused_by_number() {
    let mut bytes = encode(&valid());
    bytes[4..6].copy_from_slice(&7u16.to_le_bytes());
    let e = decode(&bytes).unwrap_err();
    assert_eq!(e.offset, 4);
    assert_eq!(e.to_string(), "built by a newer tadslc (format 7, this reads 2) (at byte 4)");
    // even when the rest is cut: the version says why
    assert_eq!(decode(&bytes[..8]).unwrap_err().kind, ErrorKind::NewerFormat { found: 7, reads: 2 });
    // format 1 (before `meet`) still loads
    bytes[4..6].copy_from_slice(&1u16.to_le_bytes());
    assert_eq!(decode(&bytes).map(|p| p.code.len()), Ok(valid().code.len()));
    bytes[4..6].copy_from_slice(&0u16.to_le_bytes());
    assert_eq!(decode(&bytes).unwrap_err().kind, ErrorKind::UnknownFormat { found: 0 });
    let mut bytes = encode(&valid());
    bytes[6] = 1;
    assert_eq!(decode(&bytes).unwrap_err(), LoadError { offset: 6, kind: ErrorKind::Flags(1) });
}

#[test]
fn truncations_say_what_they_cut() {
    let bytes = encode(&valid());
    let e = decode(&bytes[..10]).unwrap_err();
    assert_eq!(e, LoadError { offset: 10, kind: ErrorKind::Truncated { inside: "the header" } });
    let cut = bytes.len() - 3;
    let e = decode(&bytes[..cut]).unwrap_err();
    assert_eq!(e, LoadError { offset: cut, kind: ErrorKind::Truncated { inside: "the code section" } });
    // a section shorter than what it holds
    let mut short = bytes[..bytes.len() - 1].to_vec();
    let code_len = u32::from_le_bytes(short[16..20].try_into().unwrap()) - 1;
    short[16..20].copy_from_slice(&code_len.to_le_bytes());
    let e = decode(&short).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Truncated { .. }) && e.offset == short.len(), "{e}");
    assert!(e.to_string().starts_with("truncated inside"), "{e}");
}

#[test]
fn trailing_and_leftover_bytes_are_refused() {
    let mut bytes = encode(&valid());
    let end = bytes.len();
    bytes.push(0);
    assert_eq!(decode(&bytes).unwrap_err(), LoadError { offset: end, kind: ErrorKind::TrailingBytes { count: 1 } });
    // the same byte counted in the code section: content ends before the section does
    let code_len = u32::from_le_bytes(bytes[16..20].try_into().unwrap()) + 1;
    bytes[16..20].copy_from_slice(&code_len.to_le_bytes());
    assert_eq!(
        decode(&bytes).unwrap_err(),
        LoadError { offset: end, kind: ErrorKind::SectionLeftover { section: "code", count: 1 } }
    );
}

/// A file made of raw sections.
fn file(pool: &[u8], meta: &[u8], code: &[u8]) -> Vec<u8> {
    let mut out = b"TADC".to_vec();
    out.extend_from_slice(&1u16.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    for s in [pool, meta, code] {
        out.extend_from_slice(&(s.len() as u32).to_le_bytes());
    }
    for s in [pool, meta, code] {
        out.extend_from_slice(s);
    }
    out
}

#[test]
fn malformed_varints_strings_and_counts_are_refused() {
    // an over-long encoding of 0 as the string count
    let e = decode(&file(&[0x80, 0x00, 0, 0, 0], &[], &[])).unwrap_err();
    assert_eq!(e, LoadError { offset: 20, kind: ErrorKind::BadVarint });
    // more than 32 bits
    let e = decode(&file(&[0xff, 0xff, 0xff, 0xff, 0x7f], &[], &[])).unwrap_err();
    assert_eq!(e.kind, ErrorKind::BadVarint);
    // one string of two bytes that are not UTF-8
    let e = decode(&file(&[1, 2, 0xc3, 0x28, 0, 0], &[], &[])).unwrap_err();
    assert_eq!(e, LoadError { offset: 21, kind: ErrorKind::BadUtf8 });
    // a count the bytes left cannot hold: nothing is allocated for it
    let e = decode(&file(&[0xff, 0xff, 0xff, 0xff, 0x0f], &[], &[])).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooMany { what: "strings", count: 4294967295, .. }), "{e}");
    let e = decode(&file(&[0, 0x90, 0x4e], &[], &[])).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooMany { what: "numbers", count: 10000, left: 0 }), "{e}");
}

#[test]
fn pool_indices_out_of_range_are_refused() {
    // the program's name is string 3 of none
    let e = decode(&file(&[0, 0, 0], &[3, 0, 0], &[0])).unwrap_err();
    assert_eq!(e, LoadError { offset: 23, kind: ErrorKind::IndexOutOfRange { what: "string", index: 3, len: 0 } });
    assert_eq!(e.to_string(), "string index 3 out of range (there are 0) (at byte 23)");
    // a slot's bound is number 0 of none
    let e = decode(&file(&[1, 1, b'x', 0, 0], &[0, 0, 1, 0, 0, 0, 0], &[0])).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::IndexOutOfRange { what: "number", index: 0, len: 0 }), "{e}");
    // a value's slot, a path
    let (e, bytes) =
        rule(|p| p.code[4] = Instr::Drive { actor: 0, speed: Value { base: 1.0, slot: Some(9) }, turn: Turn::Left });
    assert_eq!(e.kind, ErrorKind::IndexOutOfRange { what: "parameter slot", index: 9, len: 1 });
    assert_eq!(bytes[e.offset], Op::Drive as u8, "the offset is the instruction's");
    let e = load(&Program {
        code: vec![valid().code[0].clone(), Instr::Follow { actor: 0, path: 4, speed: Value::lit(1.0) }],
        ..valid()
    });
    assert!(matches!(e.kind, ErrorKind::UnknownActor { .. }), "the actor is checked first: {e}");
    let (e, _) = rule(|p| p.code.push(Instr::Follow { actor: 0, path: 4, speed: Value::lit(1.0) }));
    assert_eq!(e.kind, ErrorKind::IndexOutOfRange { what: "path", index: 4, len: 1 });
}

#[test]
fn unknown_opcodes_and_tags_are_refused() {
    let bytes = encode(&valid());
    let code = section_start(&bytes, 2);
    // the first instruction (after the count byte) is the road
    assert_eq!(bytes[code + 1], Op::Road as u8);
    let mut bad = bytes.clone();
    bad[code + 1] = 0x7f;
    assert_eq!(decode(&bad).unwrap_err(), LoadError { offset: code + 1, kind: ErrorKind::UnknownOpcode(0x7f) });
    assert!(decode(&bad).unwrap_err().to_string().starts_with("unknown opcode 0x7f"));
    let mut bad = bytes.clone();
    bad[code + 2] = 9; // the road's shape
    assert_eq!(
        decode(&bad).unwrap_err(),
        LoadError { offset: code + 2, kind: ErrorKind::BadTag { what: "a road shape", tag: 9 } }
    );
}

#[test]
fn non_finite_and_out_of_range_numbers_are_refused_at_their_instruction() {
    let (e, bytes) =
        rule(|p| p.code[1] = Instr::Limits { dt: f64::NAN, max_steps: 300, max_distance: 150.0, timeout: 1.0 });
    assert_eq!(e.kind, ErrorKind::NonFinite { what: "the step length" });
    assert_eq!(bytes[e.offset], Op::Limits as u8);
    let (e, _) =
        rule(|p| p.code[4] = Instr::Drive { actor: 0, speed: Value::lit(f64::INFINITY), turn: Turn::Straight });
    assert_eq!(e.kind, ErrorKind::NonFinite { what: "a speed" });
    let (e, bytes) = rule(|p| p.code[4] = Instr::Drive { actor: 0, speed: Value::lit(-3.0), turn: Turn::Straight });
    assert_eq!(
        e.kind,
        ErrorKind::OutOfRange { what: "a speed", value: -3.0, expected: "0 or more for every value of its slot" }
    );
    assert_eq!(bytes[e.offset], Op::Drive as u8);
    // a speed whose slot can make it negative
    let (e, _) = rule(|p| {
        p.code[4] = Instr::Drive { actor: 0, speed: Value { base: 1.0, slot: Some(0) }, turn: Turn::Straight }
    });
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "a speed", value: -1.0, .. }), "{e}");
    let (e, _) = rule(|p| {
        if let Instr::Ego { lane, .. } = &mut p.code[2] {
            *lane = 3;
        }
    });
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "the ego's lane", .. }), "{e}");
    let (e, _) = rule(|p| {
        if let Instr::Ego { route_length, .. } = &mut p.code[2] {
            *route_length = 250.0;
        }
    });
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "the ego's route's end", .. }), "{e}");
    let (e, _) = rule(|p| p.code[0] = Instr::Road(Road { lanes: 13, ..road() }));
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "the road's lanes", .. }), "{e}");
}

#[test]
fn behaviour_of_an_actor_never_spawned_is_refused() {
    let (e, bytes) = rule(|p| p.code.push(Instr::Stop { actor: 3 }));
    assert_eq!(e.kind, ErrorKind::UnknownActor { actor: 3, spawned: 1 });
    assert_eq!(bytes[e.offset], Op::Stop as u8);
    assert_eq!(e.to_string(), format!("actor a3 is never spawned (only 1 actor) (at byte {})", e.offset));
    let (e, _) = rule(|p| p.code[3] = spawn(1));
    assert_eq!(e.kind, ErrorKind::SpawnOrder { actor: 1, expected: 0 });
}

#[test]
fn missing_duplicate_and_misplaced_set_up_is_refused() {
    let (e, bytes) = rule(|p| {
        p.code.remove(0);
    });
    assert_eq!(e.kind, ErrorKind::Missing("`road` instruction"));
    assert_eq!(e.offset, section_start(&bytes, 2), "a missing instruction is reported at the code section");
    let (e, _) = rule(|p| {
        p.code.remove(2);
    });
    assert_eq!(e.kind, ErrorKind::Missing("`ego` instruction"));
    let (e, _) = rule(|p| {
        p.code.remove(1);
    });
    assert_eq!(e.kind, ErrorKind::Missing("`limits` instruction"));
    let (e, _) = rule(|p| p.code.insert(1, p.code[1].clone()));
    assert_eq!(e.kind, ErrorKind::Duplicate("`limits` instruction"));
    let (e, _) = rule(|p| p.code.swap(0, 1));
    assert_eq!(e.kind, ErrorKind::Misplaced("`road` must be the first instruction"));
    let (e, _) = rule(|p| p.code.push(spawn(1)));
    assert_eq!(e.kind, ErrorKind::Misplaced("a set-up instruction after a behaviour instruction"));
    let (e, _) = rule(|p| {
        p.code.insert(
            2,
            Instr::Signal {
                arm: Arm::Ego,
                phases: vec![tad_bytecode::Phase { light: tad_bytecode::Light::Red, seconds: 5.0 }],
            },
        )
    });
    assert_eq!(e.kind, ErrorKind::Misplaced("a `signal` on a road without a signalised junction"));
    let (e, _) = rule(|p| {
        if let Instr::Spawn { arm, .. } = &mut p.code[3] {
            *arm = Arm::Left;
        }
    });
    assert_eq!(e.kind, ErrorKind::Misplaced("a spawn on an arm the road does not have"));
}

#[test]
fn bad_parameter_slots_are_refused() {
    let (e, bytes) = rule(|p| p.params[0] = ParamSlot { name: "lead.shift".into(), min: 2.0, max: 0.0, default: 1.0 });
    assert_eq!(e.kind, ErrorKind::BadSlot { name: "lead.shift".into(), problem: "its minimum is above its maximum" });
    assert_eq!(e.offset, section_start(&bytes, 1) + 3, "the slot's record, after the name, source and count");
    let (e, _) = rule(|p| p.params[0].default = 5.0);
    assert_eq!(e.kind, ErrorKind::BadSlot { name: "lead.shift".into(), problem: "its default is outside its range" });
    let (e, _) = rule(|p| p.params[0].max = f64::NAN);
    assert!(matches!(e.kind, ErrorKind::NonFinite { .. }), "{e}");
}

#[test]
fn paths_the_runtime_cannot_follow_are_refused() {
    let (e, bytes) = rule(|p| p.paths.push(Polyline(vec![[1.0, 1.0]])));
    assert_eq!(e.kind, ErrorKind::BadPath("a path needs two points or more"));
    assert!(e.offset > section_start(&bytes, 0) && e.offset < section_start(&bytes, 1), "in the pool");
    let (e, _) = rule(|p| p.paths.push(Polyline(vec![[1.0, 1.0], [2e6, 1.0]])));
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "a path coordinate", .. }), "{e}");
    // repeated points in a program (not in a file: the writer drops them)
    let mut p = valid();
    let first = p.paths[0].0[0];
    p.paths[0].0.insert(1, first);
    assert_eq!(verify(&p).unwrap_err().kind, ErrorKind::BadPath("a path repeats a point"));
    assert_eq!(decode(&encode(&p)), Ok(valid()));
}

#[test]
fn extreme_integers_are_refused_not_overflowed() {
    // a path's first x of i64::MIN millimetres (zig-zag u64::MAX), a lane of i64::MIN
    let mut pool = vec![0, 0, 1, 2];
    pool.extend([0xff; 9]);
    pool.extend([0x01, 0x00, 0x02, 0x00]);
    let e = decode(&file(&pool, &[], &[])).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "a path coordinate", .. }), "{e}");
    let (e, _) = rule(|p| {
        if let Instr::Spawn { lane, .. } = &mut p.code[3] {
            *lane = i64::MIN;
        }
    });
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "a spawn's lane", .. }), "{e}");
    let (e, _) = rule(|p| p.code.push(Instr::ChangeLane { actor: 0, lanes: i64::MIN }));
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "a lane change", .. }), "{e}");
    let (e, _) = rule(|p| {
        if let Instr::Ego { lane, .. } = &mut p.code[2] {
            *lane = i64::MIN;
        }
    });
    assert!(matches!(e.kind, ErrorKind::OutOfRange { what: "the ego's lane", .. }), "{e}");
}

#[test]
fn a_junctions_arms_are_a_set_in_order() {
    let junction = |arms: Vec<Arm>| {
        Instr::Road(Road {
            shape: Shape::Junction { arms: arms.len() as u8, roundabout: false },
            junction: Some(tad_road::road::Junction {
                arms,
                roundabout: false,
                half: 10.0,
                signalised: false,
                stop_signs: false,
            }),
            ..road()
        })
    };
    // in memory only: the file stores a set, read back in order
    let mut p = valid();
    p.code[0] = junction(vec![Arm::Ego, Arm::Right, Arm::Left]);
    let e = verify(&p).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Misplaced("a junction's arms repeat or are out of order"));
    assert_eq!(e.to_string(), "instruction 0: a junction's arms repeat or are out of order");
    let sorted = Program {
        code: [vec![junction(vec![Arm::Ego, Arm::Left, Arm::Right])], p.code[1..].to_vec()].concat(),
        ..p.clone()
    };
    assert_eq!(decode(&encode(&p)), Ok(sorted.clone()));
    assert_eq!(decode(&encode(&sorted)), Ok(sorted));
}
