//! `bench --runtime`: the runtime's speed on one core, against Scenic's Newtonian
//! simulator as a peer, and the throughput of ChatScene's parameter search.
//!
//! - **Episodes.** Traffic scenarios with 1, 14 (Los Angeles density) and 50 actors,
//!   generated as TAD text ([`traffic`]): a straight road of four lanes each way, the ego
//!   and NPC vehicles driving their lanes (IDM, MOBIL for background traffic). They are
//!   compiled as `tadslc run` compiles a file, and each episode runs with the `idm` ego for the
//!   program's 300 steps; the time is the best of `runs` (sampling the parameters and the
//!   episode, not scoring it). A straight road's route is 100 m, so the ego drives at
//!   10 km/h (83 m in 30 s) to use every step; a row says so when an episode stopped early.
//! - **Scenic.** The same scenarios built for Scenic's Newtonian simulator and simulated
//!   for as many steps, headless, by the fidelity suite's tracer
//!   (`compiler/backends/scenic/tools/scenic_trace.py` through `tad_scenic_run::trace`):
//!   its `sim_s` (simulation only, not compiling or sampling), one simulation per scenario,
//!   as a Scenic run takes seconds to a minute. Four lanes each way let all 50 actors fit
//!   on CARLA's Town04, so both simulators run the same actors (checked).
//! - **Search.** ChatScene's parameter search: episodes of the safety examples round robin,
//!   each example with seeds 0, 1, ..., the parameters sampled per seed, the `idm` ego,
//!   each episode scored; episodes stop early (collision, route completed) as in the
//!   search. One timed pass.
//!
//! Everything runs on the calling thread; the Scenic peer is a child process.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::{BenchError, Outcome, Report, best_of};
use tad_base::plural;
use tad_db::Database;
use tad_db::host::{Input, register};
use tad_metrics::Mode;
use tad_runtime::{Options, Scene, sample::sample};
use tad_scenic::{EmitOptions, Simulator};

/// Actors (the ego included) of the measured scenarios: alone, Los Angeles' density in
/// TrafficAlign's data, and a dense scene.
pub const ACTORS: [usize; 3] = [1, 14, 50];
/// Lanes each way of the generated road.
const LANES: usize = 4;
/// The ego's speed, km/h: slow enough not to finish its 100-m route in 300 steps.
const EGO_SPEED: u32 = 10;
/// The NPCs' speed, km/h.
const NPC_SPEED: u32 = 20;
/// The ego policy of every measurement.
const EGO: &str = "idm";

/// What `bench --runtime` measures.
#[derive(Clone, Debug)]
pub struct RuntimeArgs {
    /// Timed repetitions of each episode (the best is reported).
    pub runs: usize,
    /// Episodes of the search.
    pub episodes: usize,
    /// Steps per episode (the program's 300 unless a test asks for fewer).
    pub steps: u32,
    /// The Python with Scenic for the peer (else `TADSL_SCENIC_PYTHON`, else the
    /// repository's `.venv-scenic`).
    pub scenic_python: Option<PathBuf>,
    /// Skip the Scenic peer.
    pub no_scenic: bool,
}

/// A straight road of [`LANES`] lanes each way with the ego in lane 2 and `actors − 1` NPC
/// vehicles at [`NPC_SPEED`], dealt round robin to the places around the ego: in front of
/// and behind it in each lane of its direction, oncoming in each opposite lane. A place's
/// vehicles are one group, or several of at most `tad_layout::MAX_GROUP` (the layout puts
/// a later group of the same place past the earlier one).
pub fn traffic(actors: usize) -> String {
    let ego_lane = LANES.div_ceil(2) as i64;
    let mut places: Vec<(i64, String)> = Vec::new();
    for lane in 1..=LANES as i64 {
        let side = match lane.cmp(&ego_lane) {
            std::cmp::Ordering::Less => "left_",
            std::cmp::Ordering::Equal => "",
            std::cmp::Ordering::Greater => "right_",
        };
        places.push((lane, format!("{side}front")));
        places.push((lane, format!("{side}behind")));
    }
    places.extend((1..=LANES as i64).map(|lane| (-lane, "opposite".to_string())));
    let mut counts = vec![0usize; places.len()];
    for k in 0..actors.saturating_sub(1) {
        counts[k % places.len()] += 1;
    }
    let mut text = format!(
        "// `tadslc bench --runtime`: {actors} on a straight road of {LANES} lanes each way\n\
         scenario traffic_{n} {{\n  environment {{\n    weather: clear\n    time: daytime\n  }}\n  \
         road {{\n    type: straight_road\n    lanes: {LANES}\n    direction: two_way\n  }}\n  \
         ego {{\n    behavior: move_forward\n    speed: {EGO_SPEED} km/h\n    lane: {ego_lane}\n  }}\n",
        actors = plural(actors, "actor"),
        n = actors,
    );
    let mut group = 0;
    for ((lane, relation), &count) in places.iter().zip(&counts) {
        let mut left = count;
        while left > 0 {
            let n = left.min(tad_layout::MAX_GROUP);
            left -= n;
            group += 1;
            text.push_str(&format!(
                "  actor traffic_{group}: {n} car {{\n    behavior: move_forward\n    speed: {NPC_SPEED} km/h\n    \
                 position: {relation} of ego\n    lane: {lane}\n  }}\n"
            ));
        }
    }
    text.push_str("}\n");
    text
}

/// One generated scenario, compiled, and its measurements.
struct Measured {
    name: String,
    actors: usize,
    /// Its TAD text.
    text: String,
    /// The steps the timed episode ran and why it stopped.
    steps: u32,
    stop: tad_runtime::StopReason,
    /// The best episode.
    time: Duration,
}

/// What Scenic did with one scenario.
struct Peer {
    sim_s: f64,
    steps: usize,
    objects: usize,
}

/// A scenario's program, as `tadslc run` compiles a file: checked (refused when it has
/// errors), resolved, laid out and lowered. `Err`: why not, as the CLI says it (the
/// diagnostics rendered without colour, then `NAME: not VERB`).
fn compile(db: &mut Database, input: &Input, verb: &str) -> Result<tad_bytecode::Program, String> {
    tad_eval::pipeline::compile(db, input).map_err(|refusal| refusal.render(input, verb, false).trim_end().to_string())
}

/// `bench --runtime`: the episodes, Scenic's runs, the search. Errors of a scenario (it is
/// left out) and what takes long go to `progress` as they come.
pub fn run(args: &RuntimeArgs, progress: &mut dyn FnMut(&str)) -> Result<Report, BenchError> {
    let mut policy = tad_policy::parse_policy(EGO).map_err(|e| format!("the {EGO} ego: {e}"))?;
    let mut report = Report::default();
    let measured = episodes(args, policy.as_mut(), &mut report, progress);
    let peers =
        if args.no_scenic { Err("--no-scenic".to_string()) } else { simulate_in_scenic(args, &measured, progress) };
    report.lines.extend(table(args, &measured, &peers));
    search(args, policy.as_mut(), &mut report, progress);
    Ok(report)
}

/// Each generated scenario of [`ACTORS`] compiled and its episode timed; one that does not
/// compile or run is said and left out.
fn episodes(
    args: &RuntimeArgs,
    policy: &mut dyn tad_policy::EgoPolicy,
    report: &mut Report,
    progress: &mut dyn FnMut(&str),
) -> Vec<Measured> {
    let mut db = Database::new(tad_check::Options::default());
    let mut measured = Vec::new();
    for actors in ACTORS {
        let name = format!("traffic_{actors}");
        let input = Input { name: format!("{name}.tad"), path: None, text: traffic(actors), invalid_utf8: None };
        let program = match compile(&mut db, &input, "measured") {
            Ok(program) => program,
            Err(why) => {
                report.outcome = report.outcome.max(Outcome::InputErrors);
                progress(&why);
                continue;
            }
        };
        let spawns = program.code.iter().filter(|i| matches!(i, tad_bytecode::Instr::Spawn { .. })).count();
        if spawns + 1 != actors {
            report.outcome = report.outcome.max(Outcome::InputErrors);
            progress(&format!(
                "error: {name}: the program has {} (the ego and its spawns), not {actors}",
                plural(spawns + 1, "actor")
            ));
            continue;
        }
        let mut scene = match Scene::new(&program) {
            Ok(scene) => scene,
            Err(e) => {
                report.outcome = report.outcome.max(Outcome::InputErrors);
                progress(&format!("error: {name}: not run: {e}"));
                continue;
            }
        };
        scene.limits.max_steps = args.steps;
        let mut last = None;
        let time = best_of(args.runs, || {
            let params = sample(&scene.program.params, Some(0));
            let episode = tad_runtime::run(&scene, Some(0), params, &mut *policy, &Options::default());
            last = Some((episode.steps, episode.stop_reason));
            black_box(episode);
        });
        let (steps, stop) = last.unwrap_or((0, tad_runtime::StopReason::MaxSteps));
        measured.push(Measured { name, actors, text: input.text, steps, stop, time });
    }
    measured
}

/// The Newtonian Scenic program of a generated scenario, loading its map from `maps`;
/// `None` when the backend refuses it.
fn scenic_program(db: &mut Database, m: &Measured, maps: &Path) -> Option<String> {
    let input = Input { name: format!("{}.tad", m.name), path: None, text: m.text.clone(), invalid_utf8: None };
    let file = register(db, &input);
    let module = &tad_db::analyze(db, file).module;
    let scenario = tad_db::resolve(db, file);
    let options = EmitOptions {
        simulator: Simulator::Newtonian,
        map: None,
        map_dir: Some(maps.display().to_string()),
        source: Some(input.name.clone()),
    };
    let emitted = tad_scenic::build(module, scenario.as_ref(), &options);
    (!emitted.diagnostics.iter().any(|d| d.is_error())).then_some(emitted.text)
}

/// Each scenario's run in Scenic's Newtonian simulator, in `measured`'s order; `Err` (why)
/// when Scenic is not available.
fn simulate_in_scenic(
    args: &RuntimeArgs,
    measured: &[Measured],
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Result<Peer, String>>, String> {
    use tad_scenic_run::{self as scenic, trace};
    let python = match &args.scenic_python {
        Some(p) if scenic::imports_scenic(p) => p.clone(),
        Some(p) => return Err(format!("`{}` is not a Python that imports scenic", p.display())),
        None => scenic::python()
            .ok_or("no Python with Scenic 3.1.1 (give --scenic-python PATH or set TADSL_SCENIC_PYTHON)".to_string())?,
    };
    let script = trace::script().ok_or("scenic_trace.py is not found (set TADSL_SCENIC_TRACE)")?;
    let base = std::env::temp_dir().join("tadslc-bench-scenic");
    // links to the CARLA maps, where Scenic's parsed-map cache stays between runs
    let maps = scenic::map_dir(&base)
        .ok_or("the CARLA maps are not found (set TADSL_SCENIC_MAPS, or put them in ../shared/maps/CARLA)")?;
    let dir = base.join(format!("programs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    let mut db = Database::new(tad_check::Options::default());
    let mut files = Vec::new();
    for m in measured {
        let Some(text) = scenic_program(&mut db, m, &maps) else { continue };
        let file = dir.join(format!("{}.scenic", m.name));
        std::fs::write(&file, text).map_err(|e| format!("cannot write `{}`: {e}", file.display()))?;
        files.push(file);
    }
    progress(&format!(
        "bench: simulating {} in Scenic's Newtonian simulator (a minute or two)",
        plural(files.len(), "scenario")
    ));
    let options = trace::TraceOptions { seeds: vec![0], steps: args.steps, jobs: 1, args: Vec::new() };
    let traces = trace::try_run(&python, &script, &files, &options);
    let _ = std::fs::remove_dir_all(&dir);
    let traces = traces?;
    Ok(measured
        .iter()
        .map(|m| {
            let file = dir.join(format!("{}.scenic", m.name));
            let Some(t) = traces.iter().find(|t| t.file == file) else {
                return Err("the Scenic backend did not build it".to_string());
            };
            match (t.ok, t.sim_s) {
                (true, Some(sim_s)) => Ok(Peer { sim_s, steps: t.steps(), objects: t.objects.len() }),
                _ => Err(t.error.clone().unwrap_or_else(|| "no simulation time".to_string())),
            }
        })
        .collect())
}

/// The episodes' table, a row per scenario, then its notes.
fn table(args: &RuntimeArgs, measured: &[Measured], peers: &Result<Vec<Result<Peer, String>>, String>) -> Vec<String> {
    let mut lines = vec![format!(
        "runtime: straight road, {LANES} lanes each way, NPC vehicles at {NPC_SPEED} km/h (IDM), {EGO} ego at {EGO_SPEED} km/h; \
         best of {}, one core",
        plural(args.runs.max(1), "run")
    )];
    lines.push(format!(
        "{:<12} {:>6} {:>6} {:>11} {:>9} {:>14} {:>9} {:>15}",
        "scenario", "actors", "steps", "ms/episode", "µs/step", "actor-steps/s", "Scenic s", "Scenic/runtime"
    ));
    let mut notes = Vec::new();
    for (k, m) in measured.iter().enumerate() {
        let secs = m.time.as_secs_f64().max(1e-9);
        let steps = f64::from(m.steps.max(1));
        let peer = peers.as_ref().ok().and_then(|p| p.get(k));
        let (scenic, ratio) = match peer {
            Some(Ok(p)) => (format!("{:.3}", p.sim_s), format!("{:.0}x", p.sim_s / secs)),
            _ => ("-".to_string(), "-".to_string()),
        };
        lines.push(format!(
            "{:<12} {:>6} {:>6} {:>11.3} {:>9.2} {:>14.0} {scenic:>9} {ratio:>15}",
            m.name,
            m.actors,
            m.steps,
            secs * 1e3,
            secs * 1e6 / steps,
            m.actors as f64 * steps / secs
        ));
        if m.steps < args.steps {
            notes.push(format!(
                "{}: the episode stopped at step {} ({}); its figures are for the steps it ran",
                m.name,
                m.steps,
                m.stop.as_str()
            ));
        }
        match peer {
            Some(Ok(p)) if p.objects != m.actors || p.steps != args.steps as usize => notes.push(format!(
                "{}: Scenic simulated {} for {} steps",
                m.name,
                plural(p.objects, "object"),
                p.steps
            )),
            Some(Err(e)) => notes.push(format!("{}: Scenic failed: {}", m.name, e.lines().next().unwrap_or(""))),
            _ => {}
        }
    }
    match peers {
        Ok(_) => notes.push(format!(
            "Scenic: its Newtonian simulator, headless, one simulation of {} steps per scenario (seed 0): simulation time only",
            args.steps
        )),
        Err(why) => notes.push(format!("Scenic peer skipped: {why}")),
    }
    lines.extend(notes);
    lines
}

/// ChatScene's search: the safety examples round robin, seeds 0.. each; its line.
fn search(
    args: &RuntimeArgs,
    policy: &mut dyn tad_policy::EgoPolicy,
    report: &mut Report,
    progress: &mut dyn FnMut(&str),
) {
    let mut db = Database::new(tad_check::Options::default());
    let mut scenes = Vec::new();
    let safety =
        tad_eval::examples::EXAMPLES.iter().filter(|(p, _)| p.starts_with("examples/safety/") && p.ends_with(".tad"));
    for (path, text) in safety {
        let input =
            Input { name: path.to_string(), path: Some(path.into()), text: text.to_string(), invalid_utf8: None };
        let program = match compile(&mut db, &input, "searched") {
            Ok(program) => program,
            Err(why) => {
                report.outcome = report.outcome.max(Outcome::InputErrors);
                progress(&why);
                continue;
            }
        };
        match Scene::new(&program) {
            Ok(mut scene) => {
                scene.limits.max_steps = scene.limits.max_steps.min(args.steps);
                scenes.push(scene);
            }
            Err(e) => {
                report.outcome = report.outcome.max(Outcome::InputErrors);
                progress(&format!("error: {}: not run: {e}", input.name));
            }
        }
    }
    if scenes.is_empty() {
        report.outcome = report.outcome.max(Outcome::Unusable);
        progress("error: no safety example to search (examples/safety/ is embedded)");
        return;
    }
    let mut steps = 0u64;
    let mut stops: Vec<(&'static str, usize)> = Vec::new();
    let start = Instant::now();
    for k in 0..args.episodes {
        let scene = &scenes[k % scenes.len()];
        let seed = (k / scenes.len()) as u64;
        let params = sample(&scene.program.params, Some(seed));
        let episode = tad_runtime::run(scene, Some(seed), params, policy, &Options::default());
        black_box(tad_metrics::score_episode(&episode.records, Mode::Fixed).ok());
        steps += u64::from(episode.steps);
        let reason = episode.stop_reason.as_str();
        match stops.iter_mut().find(|(r, _)| *r == reason) {
            Some((_, n)) => *n += 1,
            None => stops.push((reason, 1)),
        }
    }
    let secs = start.elapsed().as_secs_f64().max(1e-9);
    let seeds = args.episodes.div_ceil(scenes.len());
    let stops: Vec<String> = stops.iter().map(|(r, n)| format!("{r} {n}")).collect();
    report.lines.push(format!(
        "search: {} of the {} (examples/safety, round robin, seeds 0..{seeds} each, parameters per seed, {EGO} ego, \
         scored), one core: {secs:.2} s, {:.0} episodes/s; {steps} steps, {:.0} steps/s; stops: {}",
        plural(args.episodes, "episode"),
        plural(scenes.len(), "safety example"),
        args.episodes as f64 / secs,
        steps as f64 / secs,
        stops.join(", ")
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn program(actors: usize) -> tad_bytecode::Program {
        let mut db = Database::new(tad_check::Options::default());
        let input = Input { name: "t.tad".into(), path: None, text: traffic(actors), invalid_utf8: None };
        let diagnostics = tad_db::host::diagnose_in(&mut db, &input).diagnostics;
        assert!(diagnostics.is_empty(), "{actors} actors: {diagnostics:?}");
        compile(&mut db, &input, "tested").expect("the scenario compiles")
    }

    #[test]
    fn the_scenarios_have_the_actors_they_claim_and_use_every_step() {
        for actors in ACTORS {
            let program = program(actors);
            let spawns = program.code.iter().filter(|i| matches!(i, tad_bytecode::Instr::Spawn { .. })).count();
            assert_eq!(spawns + 1, actors);
            let scene = Scene::new(&program).unwrap();
            assert_eq!(scene.limits.max_steps, 300);
            let mut policy = tad_policy::parse_policy(EGO).unwrap();
            let episode = tad_runtime::run(
                &scene,
                Some(0),
                sample(&scene.program.params, Some(0)),
                policy.as_mut(),
                &Options::default(),
            );
            assert_eq!(
                (episode.steps, episode.stop_reason),
                (300, tad_runtime::StopReason::MaxSteps),
                "{actors} actors"
            );
        }
    }

    #[test]
    fn more_than_a_group_of_actors_at_one_place_makes_several_groups() {
        let actors = 1 + 12 * (tad_layout::MAX_GROUP + 1);
        let text = traffic(actors);
        let counts: Vec<usize> = text
            .lines()
            .filter_map(|l| {
                l.trim().strip_prefix("actor traffic_")?.split(": ").nth(1)?.split(' ').next()?.parse().ok()
            })
            .collect();
        assert_eq!(counts.iter().sum::<usize>(), actors - 1);
        assert!(counts.iter().all(|&n| (1..=tad_layout::MAX_GROUP).contains(&n)), "{counts:?}");
        assert_eq!(counts.iter().filter(|&&n| n == tad_layout::MAX_GROUP).count(), 12);
    }
}
