//! The fidelity suite's measurements: the examples, built for Scenic's Newtonian simulator,
//! run in the real Scenic 3.1.1 with several seeds, every object's pose traced per step
//! (`tools/scenic_trace.py` through `tad_test_support::trace`). Needs the Scenic venv;
//! skipped (loudly) without it unless `TAD_REQUIRE_SCENIC=1`.
//!
//! `measure_examples` (ignored by default: about two minutes on two cores) prints, as
//! Markdown, what the programs do today: whether each simulation ran, which actors overlap
//! in the first 3 s, when any two objects first overlap, and how close each group comes to
//! the ego. `TADSL_FIDELITY_REPORT=FILE` also writes it to FILE:
//!
//! ```text
//! TADSL_FIDELITY_REPORT=$PWD/BEFORE.md cargo test -p tad-scenic --test fidelity -- --ignored --nocapture
//! ```

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use tad_scenic::{EmitOptions, Simulator};
use tad_test_support::trace::{self, Group, Label, Trace, TraceOptions, Tracer};

const SEEDS: [u64; 5] = [0, 1, 2, 3, 4];
const STEPS: u32 = 100;
/// Steps in which actors should not overlap each other (3 s).
const EARLY_STEPS: usize = 30;

/// An emitted example: its stem, program file and actor groups.
struct Program {
    stem: String,
    file: PathBuf,
    groups: Vec<Group>,
}

/// Emit `examples` for the Newtonian simulator into `dir`, naming the tracer's maps.
fn emit(examples: &[PathBuf], dir: &Path, tracer: &Tracer) -> Vec<Program> {
    std::fs::create_dir_all(dir).unwrap();
    let options = EmitOptions {
        simulator: Simulator::Newtonian,
        map_dir: Some(tracer.maps.to_string_lossy().into_owned()),
        ..EmitOptions::default()
    };
    examples
        .iter()
        .map(|example| {
            let emitted = common::build(example, &options);
            let stem = common::stem(example);
            let file = dir.join(format!("{stem}.scenic"));
            std::fs::write(&file, &emitted.text).unwrap();
            Program { stem, file, groups: trace::program_groups(&emitted.text) }
        })
        .collect()
}

fn tracer() -> Option<Tracer> {
    trace::tracer(Path::new(env!("CARGO_TARGET_TMPDIR")))
}

/// A trace of the smallest example: the ego first, one object per member of each group in
/// the program's order, every step recorded at 0.1 s.
#[test]
fn a_trace_has_the_ego_then_the_groups_and_every_step() {
    let Some(tracer) = tracer() else { return };
    let example = common::repo().join("examples/safety/vehicle_passing.tad");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-trace-smoke");
    let programs = emit(&[example], &dir, &tracer);
    let files = vec![programs[0].file.clone()];
    let traces = tracer.run(&files, &TraceOptions { seeds: vec![0, 1], steps: 10, ..TraceOptions::default() });
    assert_eq!(traces.len(), 2);
    let groups = &programs[0].groups;
    let members: usize = groups.iter().map(|g| g.count).sum();
    for (t, seed) in traces.iter().zip([0, 1]) {
        assert!(t.ok, "{:?}", t.error);
        assert_eq!((t.seed, t.file.as_path()), (seed, files[0].as_path()));
        assert_eq!(t.ego(), Some(0));
        assert_eq!(t.objects.len(), 1 + members, "{groups:?}");
        assert_eq!(t.states.len(), 11);
        assert!((t.dt - 0.1).abs() < 1e-9, "{}", t.dt);
        let labels = trace::labels(t, groups);
        assert!(labels.iter().all(Option::is_some), "{labels:?}");
        // Scenic samples a scene without overlaps
        assert_eq!(t.overlapping_pairs(0), [], "seed {seed}");
        // the ego moves
        let (start, end) = (t.states[0][0], t.states[10][0]);
        assert!((end.x - start.x).hypot(end.y - start.y) > 1.0, "{start:?} {end:?}");
    }
}

fn name(labels: &[Option<Label>], i: usize) -> String {
    labels[i].as_ref().map_or_else(|| format!("object {i}"), Label::to_string)
}

/// The row of one (example, seed): whether it ran, the actor pairs overlapping in the first
/// 3 s, and the first overlap of any two objects.
fn run_row(out: &mut String, program: &Program, t: &Trace) {
    let labels = trace::labels(t, &program.groups);
    let ran = if t.ok {
        "yes".to_string()
    } else {
        format!("**no** ({} steps): {}", t.steps(), t.error.as_deref().unwrap_or("?").replace('|', "\\|"))
    };
    let ego = t.ego();
    let mut early: Vec<(usize, usize)> = Vec::new();
    for step in 0..=EARLY_STEPS.min(t.steps()) {
        for (i, j) in t.overlapping_pairs(step) {
            if Some(i) != ego && Some(j) != ego && !early.contains(&(i, j)) {
                early.push((i, j));
            }
        }
    }
    early.sort();
    let early_text = if early.is_empty() {
        "none".to_string()
    } else {
        let shown: Vec<String> =
            early.iter().take(6).map(|&(i, j)| format!("{}–{}", name(&labels, i), name(&labels, j))).collect();
        let more = if early.len() > 6 { format!(", … ({} pairs)", early.len()) } else { String::new() };
        format!("**{}**: {}{more}", early.len(), shown.join(", "))
    };
    let first = match t.first_overlap(0..t.states.len(), |_, _| true) {
        Some((step, i, j)) => format!("{:.1} s: {}–{}", t.time(step), name(&labels, i), name(&labels, j)),
        None => "none".to_string(),
    };
    let _ =
        writeln!(out, "| {} | {} | {} | {} | {} | {} |", program.stem, t.seed, t.objects.len(), ran, early_text, first);
}

/// The rows of one example's groups: per seed, the least distance between any member and
/// the ego, and when.
fn distance_rows(out: &mut String, program: &Program, traces: &[&Trace]) {
    for group in &program.groups {
        let mut cells = Vec::new();
        for t in traces {
            let labels = trace::labels(t, &program.groups);
            let (Some(ego), false) = (t.ego(), t.states.is_empty()) else {
                cells.push("–".to_string());
                continue;
            };
            let closest = (0..t.objects.len())
                .filter(|&i| labels[i].as_ref().is_some_and(|l| l.group == group.name))
                .filter_map(|i| t.closest_approach(i, ego))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            cells.push(match closest {
                Some((0.0, step)) => format!("**0** @ {:.1}", t.time(step)),
                Some((d, step)) => format!("{d:.1} @ {:.1}", t.time(step)),
                None => "–".to_string(),
            });
        }
        let _ = writeln!(out, "| {} | {} ({}) | {} |", program.stem, group.name, group.count, cells.join(" | "));
    }
}

fn report(programs: &[Program], traces: &[Trace], seconds: f64) -> String {
    let per_file = |p: &Program| traces.iter().filter(|t| t.file == p.file).collect::<Vec<_>>();
    let mut out = String::new();
    let ran = traces.iter().filter(|t| t.ok).count();
    let with_early = traces.iter().filter(|t| early_overlap(t)).count();
    let with_any = traces.iter().filter(|t| t.first_overlap(0..t.states.len(), |_, _| true).is_some()).count();
    let _ = writeln!(out, "# Fidelity: before\n");
    let _ = writeln!(
        out,
        "{} examples built for Scenic's Newtonian simulator, run in Scenic 3.1.1 (2D mode, headless) with seeds {:?}, \
         {STEPS} steps of 0.1 s; traced in {seconds:.0} s. Footprints are oriented rectangles (position, heading, \
         length, width); touching is not overlapping. Objects are named as the program names them (`group` or \
         `group_k`).\n",
        programs.len(),
        SEEDS
    );
    let _ = writeln!(out, "- simulations that ran all {STEPS} steps: {ran} of {}", traces.len());
    let _ = writeln!(out, "- simulations in which two actors (not the ego) overlap within 3 s: {with_early}");
    let _ = writeln!(out, "- simulations in which any two objects overlap within {} s: {with_any}\n", STEPS / 10);
    let _ = writeln!(out, "## Runs and overlaps\n");
    let _ = writeln!(
        out,
        "| example | seed | objects | ran | actor pairs overlapping in the first 3 s | first overlap (any two) |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    for p in programs {
        for t in per_file(p) {
            run_row(&mut out, p, t);
        }
    }
    let _ = writeln!(out, "\n## Closest approach to the ego\n");
    let _ = writeln!(
        out,
        "Per group, the least footprint-to-footprint distance (m) between any of its actors and the ego, and \
         when (s); 0 = touching or overlapping.\n"
    );
    let header: Vec<String> = SEEDS.iter().map(|s| format!("seed {s}")).collect();
    let _ = writeln!(out, "| example | group (count) | {} |", header.join(" | "));
    let _ = writeln!(out, "|---|---|{}", "---|".repeat(SEEDS.len()));
    for p in programs {
        distance_rows(&mut out, p, &per_file(p));
    }
    out
}

fn early_overlap(t: &Trace) -> bool {
    let ego = t.ego();
    t.first_overlap(0..EARLY_STEPS + 1, |i, j| Some(i) != ego && Some(j) != ego).is_some()
}

#[test]
#[ignore = "about two minutes: run with --ignored to measure the examples"]
fn measure_examples() {
    let Some(tracer) = tracer() else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-fidelity");
    let programs = emit(&common::examples(), &dir, &tracer);
    let files: Vec<PathBuf> = programs.iter().map(|p| p.file.clone()).collect();
    let start = Instant::now();
    let traces = tracer.run(&files, &TraceOptions { seeds: SEEDS.to_vec(), steps: STEPS, jobs: 2, args: Vec::new() });
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!(traces.len(), files.len() * SEEDS.len());
    for p in &programs {
        let members: usize = p.groups.iter().map(|g| g.count).sum();
        for t in traces.iter().filter(|t| t.file == p.file && !t.objects.is_empty()) {
            assert_eq!(t.ego(), Some(0), "{}: the ego is not the first object", p.stem);
            assert_eq!(t.objects.len(), 1 + members, "{}: objects vs groups {:?}", p.stem, p.groups);
        }
    }
    let text = report(&programs, &traces, seconds);
    println!("{text}");
    if let Some(path) = std::env::var_os("TADSL_FIDELITY_REPORT") {
        std::fs::write(&path, &text).unwrap_or_else(|e| panic!("{}: {e}", PathBuf::from(&path).display()));
    }
}
