//! The loader on seeded random mutations of every example's encoding (bit flips, byte
//! changes, truncations, insertions, deletions, splices of another example's bytes, random
//! bytes behind a valid header): it never panics, and what it accepts is a verified
//! program that encodes back to itself (paths in their canonical form) and disassembles.
//! Also: `decode(encode(p)) == p` for programs whose fields are random.

mod common;

use tad_bytecode::{Instr, Polyline, Program, Value, decode, disasm, encode, lower, verify};
use tad_ir::{Rng, SplitMix64};

/// Mutations per example.
const ROUNDS: usize = 1000;

fn encodings() -> Vec<Vec<u8>> {
    common::examples()
        .iter()
        .map(|path| {
            let scenario = common::resolved(path).unwrap();
            encode(&lower(&scenario, &tad_layout::lay_out(&scenario), &path.display().to_string()))
        })
        .collect()
}

/// Keep the header's section lengths consistent with an edit of `delta` bytes at `at`, so
/// the edit reaches the section parsers instead of failing the length check.
fn fix_lengths(bytes: &mut [u8], at: usize, delta: i64) {
    let mut start = 20;
    for field in [8, 12, 16] {
        let Some(raw) = bytes.get(field..field + 4) else { return };
        let len = u32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]]) as usize;
        if at >= start && at <= start + len {
            let fixed = (len as i64 + delta).max(0) as u32;
            bytes[field..field + 4].copy_from_slice(&fixed.to_le_bytes());
            return;
        }
        start += len;
    }
}

fn mutate(rng: &mut SplitMix64, bytes: &[u8], other: &[u8]) -> Vec<u8> {
    let mut m = bytes.to_vec();
    let n = m.len().max(1);
    match rng.below(9) {
        0 => {
            for _ in 0..=rng.below(8) {
                let i = rng.below(n);
                if let Some(b) = m.get_mut(i) {
                    *b ^= 1 << rng.below(8);
                }
            }
        }
        1 => {
            for _ in 0..=rng.below(4) {
                let i = rng.below(n);
                if let Some(b) = m.get_mut(i) {
                    *b = rng.next_u64() as u8;
                }
            }
        }
        2 => m.truncate(rng.below(n)),
        3 => {
            // insert random bytes, the header kept consistent
            let at = 20 + rng.below(n.saturating_sub(20).max(1));
            let count = 1 + rng.below(6);
            let at = at.min(m.len());
            m.splice(at..at, (0..count).map(|_| rng.next_u64() as u8));
            fix_lengths(&mut m, at, count as i64);
        }
        4 => {
            // delete a range, the header kept consistent
            let at = (20 + rng.below(n.saturating_sub(20).max(1))).min(m.len());
            let count = (1 + rng.below(8)).min(m.len() - at);
            m.drain(at..at + count);
            fix_lengths(&mut m, at, -(count as i64));
        }
        5 => {
            // splice a piece of another encoding over a piece of this one
            let at = rng.below(n).min(m.len());
            let from = rng.below(other.len().max(1)).min(other.len());
            let count = (1 + rng.below(32)).min(other.len() - from).min(m.len() - at);
            m[at..at + count].copy_from_slice(&other[from..from + count]);
        }
        6 => {
            // random bytes behind this header
            let len = rng.below(2 * n);
            m.truncate(20.min(m.len()));
            m.extend((0..len).map(|_| rng.next_u64() as u8));
        }
        7 => {
            // a changed section length
            let field = [8, 12, 16][rng.below(3)];
            if let Some(raw) = m.get_mut(field..field + 4) {
                raw.copy_from_slice(&(rng.next_u64() as u32 >> rng.below(32)).to_le_bytes());
            }
        }
        _ => {
            // an operand byte in the code section set to an extreme
            let at = n - 1 - rng.below(n.min(64));
            if let Some(b) = m.get_mut(at) {
                *b = [0x00, 0x7f, 0x80, 0xff][rng.below(4)];
            }
        }
    }
    m
}

fn canonical_paths(p: &Program) -> Program {
    Program { paths: p.paths.iter().map(Polyline::canonical).collect(), ..p.clone() }
}

#[test]
fn the_loader_survives_thousands_of_mutations_of_every_example() {
    let encodings = encodings();
    let mut rng = SplitMix64::new(0x7ADC);
    let (mut accepted, mut rejected) = (0usize, 0usize);
    let mut kinds = std::collections::BTreeSet::new();
    for (e, bytes) in encodings.iter().enumerate() {
        let other = &encodings[(e + 1) % encodings.len()];
        for round in 0..ROUNDS {
            let m = mutate(&mut rng, bytes, other);
            let decoded = std::panic::catch_unwind(|| decode(&m));
            let Ok(decoded) = decoded else {
                panic!("example {e} round {round}: decode panicked on {m:02x?}");
            };
            match decoded {
                Ok(p) => {
                    accepted += 1;
                    assert_eq!(verify(&p), Ok(()), "example {e} round {round}: accepted but invalid");
                    assert!(!disasm(&p).is_empty());
                    assert_eq!(decode(&encode(&p)), Ok(canonical_paths(&p)), "example {e} round {round}");
                }
                Err(err) => {
                    rejected += 1;
                    assert!(err.offset <= m.len(), "example {e} round {round}: {err} past the end");
                    assert!(!err.to_string().is_empty());
                    kinds.insert(format!("{:?}", err.kind).split(['(', ' ']).next().unwrap_or("").to_string());
                }
            }
        }
    }
    println!("accepted {accepted}, rejected {rejected}, kinds {kinds:?}");
    assert!(accepted + rejected >= 5000, "thousands of inputs");
    assert!(rejected > accepted, "most mutations are caught");
    assert!(kinds.len() >= 10, "the mutations reach many checks: {kinds:?}");
}

#[test]
fn random_programs_round_trip_exactly() {
    let mut rng = SplitMix64::new(42);
    let base = common::program(&common::example("right_turn"));
    for _ in 0..300 {
        let mut p = base.clone();
        let number = |rng: &mut SplitMix64| (rng.unit() - 0.5) * 10f64.powi(rng.below(8) as i32 - 2);
        for slot in &mut p.params {
            let (a, b) = (number(&mut rng), number(&mut rng));
            slot.min = a.min(b);
            slot.max = a.max(b);
            slot.default = slot.min;
        }
        for instr in &mut p.code {
            match instr {
                Instr::Spawn { along, lateral, yaw, .. } => {
                    *along = Value { base: number(&mut rng), slot: along.slot };
                    *lateral = number(&mut rng);
                    *yaw = number(&mut rng);
                }
                Instr::Ego { start, .. } => *start = rng.unit() * 100.0,
                _ => {}
            }
        }
        p.paths =
            p.paths.iter().map(|l| Polyline(l.0.iter().map(|q| [q[0] + number(&mut rng), q[1]]).collect())).collect();
        let back = decode(&encode(&p));
        // whatever the numbers, the bytes give them back bit for bit; paths to the millimetre
        let expected = canonical_paths(&p);
        match back {
            Ok(q) => assert_eq!(q, expected),
            Err(e) => assert_eq!(verify(&expected).map_err(|v| v.kind), Err(e.kind)),
        }
        for (a, b) in p.paths.iter().zip(&expected.paths) {
            for q in &a.0 {
                let near = b.0.windows(2).any(|w| distance(*q, w[0], w[1]) <= Polyline::TOLERANCE + 1e-3);
                assert!(near, "every point stays within 1 cm (+ rounding) of the stored path");
            }
        }
    }
}

fn distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a[0] + dx * t - p[0]).hypot(a[1] + dy * t - p[1])
}
