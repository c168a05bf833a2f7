//! `tadslc run`: scenarios run in the runtime against ego policies, scored with SafeBench's
//! metrics.
//!
//! Inputs are scenario files (checked, resolved, laid out and lowered to bytecode in memory,
//! the path `build --target bytecode` takes) or `.tadc` files (loaded and verified). Each
//! (scenario, ego, seed) is one episode with the parameters sampled from the seed. A file with
//! errors is reported and skipped (status 1); a corrupt `.tadc` too (status 2); the others
//! still run. Episodes are independent and deterministic.

use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};

use crate::files::{self, Search};
use crate::output::{CliError, Closed};
use crate::{Status, errln, out, outln};
use tad_check::Options as CheckOptions;
use tad_db::Database;
use tad_metrics::Mode;
use tad_runtime::{Episode, Options, Scene};

/// What `run` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RunFormat {
    Table,
    Json,
}

/// `tadslc run`'s arguments.
#[derive(clap::Args)]
pub struct RunArgs {
    /// Scenario files or directories (searched recursively for *.tad and *.yaml), or
    /// `.tadc` bytecode files
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The ego policies, comma-separated or repeated: `idm`, `naive`, `learned:PATH`
    /// (a SafeBench SAC actor in safetensors)
    #[arg(long = "ego", value_delimiter = ',', default_values_t = ["idm".to_string(), "naive".to_string()])]
    pub egos: Vec<String>,
    /// Seeds `A..B` (B excluded, as in Rust), `A..=B` (B included) or one seed `A`
    #[arg(long, default_value = "0..3", value_parser = crate::run::parse_seeds)]
    pub seeds: std::ops::Range<u64>,
    /// Output format: a table for people, or JSON lines (one object per episode, then
    /// one aggregate object per ego)
    #[arg(long, value_enum, default_value_t = crate::run::RunFormat::Table)]
    pub format: crate::run::RunFormat,
    /// Write every actor's pose at every step as JSON lines
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// Draw the first episode: `.svg` (a figure) or `.gif` (an animation)
    #[arg(long, value_name = "FILE")]
    pub render: Option<PathBuf>,
    /// Score as SafeBench's scorer does, quirks included (TS 0 when nothing completes,
    /// yaw not unwrapped, off-road never ends an episode)
    #[arg(long)]
    pub compat: bool,
    /// Run every N-th input from I (a job array's index I of N jobs, from 0)
    #[arg(long, value_name = "I/N", default_value = "0/1")]
    pub shard: tad_base::Shard,
    /// Write the scored episodes to DIR/results.json (DIR/results.I-of-N.json with
    /// --shard), for `tadslc merge`
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// `A..B` (B excluded, as in Rust), `A..=B` (B included) or a single seed `A`.
pub fn parse_seeds(text: &str) -> Result<Range<u64>, String> {
    let number = |s: &str| s.trim().parse::<u64>().map_err(|_| format!("`{s}` is not a seed (a whole number)"));
    let range = match text.split_once("..") {
        Some((a, b)) => match b.strip_prefix('=') {
            Some(last) => number(a)?..number(last)?.saturating_add(1),
            None => number(a)?..number(b)?,
        },
        None => {
            let a = number(text)?;
            a..a.saturating_add(1)
        }
    };
    if range.is_empty() {
        return Err(format!("`{text}` holds no seed: give A..B with A < B (B excluded)"));
    }
    Ok(range)
}

/// One scenario ready to run, named for people.
pub struct Loaded {
    pub name: String,
    pub scene: Scene,
    /// The source it was compiled from (`None` for a `.tadc` file).
    pub source: Option<files::Input>,
    /// Its behaviour, the key of the fine-tuning split (`None` for a `.tadc` file).
    pub key: Option<String>,
}

/// Every input as a scene: sources compiled, `.tadc` files loaded.
pub fn load(paths: &[PathBuf], color: bool, status: &mut Status) -> Result<Vec<Loaded>, Closed> {
    let (bytecode, sources): (Vec<PathBuf>, Vec<PathBuf>) =
        paths.iter().cloned().partition(|p| p.extension().is_some_and(|e| e == "tadc"));
    let mut loaded = Vec::new();
    let mut db = Database::new(CheckOptions::default());
    if !sources.is_empty() {
        for input in files::load(&sources, Search::Scenarios, status)? {
            let Some(program) = crate::bytecode::compile(&mut db, &input, "run", color)? else {
                *status = (*status).max(Status::Failed);
                continue;
            };
            let file = crate::check::register(&mut db, &input);
            let key = tad_eval::corpus::behaviour_of(&db, file);
            match Scene::new(&program) {
                Ok(scene) => {
                    loaded.push(Loaded { name: input.name.clone(), scene, source: Some(input.clone()), key: Some(key) })
                }
                Err(e) => {
                    *status = (*status).max(Status::Failed);
                    errln!("{}: not run: {e}", input.name)?;
                }
            }
        }
    }
    for path in bytecode {
        let name = path.display().to_string();
        // a file that cannot be read is an I/O failure (2); one that does not load is
        // input with errors (1), as under `disasm`
        let program = match std::fs::read(&path) {
            Ok(bytes) => tad_bytecode::decode(&bytes).map_err(|e| (Status::Failed, e.to_string())),
            Err(e) => Err((Status::Usage, format!("cannot read it: {e}"))),
        };
        match program.and_then(|p| Scene::new(&p).map_err(|e| (Status::Failed, e.to_string()))) {
            Ok(scene) => loaded.push(Loaded { name, scene, source: None, key: None }),
            Err((failed, e)) => {
                *status = (*status).max(failed);
                errln!("error: {name}: {e}")?;
            }
        }
    }
    Ok(loaded)
}

/// The inputs of one shard: every N-th loaded scenario from I.
pub fn load_shard(
    paths: &[PathBuf],
    shard: tad_base::Shard,
    color: bool,
    status: &mut Status,
) -> Result<Vec<Loaded>, Closed> {
    Ok(load(paths, color, status)?.into_iter().enumerate().filter(|(k, _)| shard.takes(*k)).map(|(_, l)| l).collect())
}

pub fn run(args: &RunArgs, color: bool) -> Status {
    crate::output::finish(run_in(args, color))
}

/// One finished episode with its scores.
struct Done {
    file: usize,
    ego: usize,
    episode: Episode,
    score: tad_metrics::EpisodeScore,
}

fn run_in(args: &RunArgs, color: bool) -> Result<Status, CliError> {
    let mut policies = Vec::new();
    for spec in &args.egos {
        policies.push(tad_policy::parse_policy(spec).map_err(|e| CliError::usage(format!("--ego {spec}: {e}")))?);
    }
    // raised by inputs that do not load, and by output that cannot be written
    let mut status = Status::Ok;
    let scenes = load_shard(&args.paths, args.shard, color, &mut status)?;
    if scenes.is_empty() {
        return Err(CliError::usage("nothing to run"));
    }
    let mode = if args.compat { Mode::Compat } else { Mode::Fixed };
    let keep_frames = args.trace.is_some() || args.render.is_some();
    let opts = Options { mode, keep_frames, ..Options::default() };
    let total = scenes.len() * policies.len() * (args.seeds.end - args.seeds.start) as usize;
    let progress = crate::output::progress(total, "episodes");
    let mut trace = match &args.trace {
        Some(path) => Some(std::io::BufWriter::new(
            std::fs::File::create(path)
                .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?,
        )),
        None => None,
    };
    let mut done: Vec<Done> = Vec::new();
    for (f, loaded) in scenes.iter().enumerate() {
        for (e, policy) in policies.iter_mut().enumerate() {
            for seed in args.seeds.clone() {
                let params = tad_runtime::sample::sample(&loaded.scene.program.params, Some(seed));
                let episode = tad_runtime::run(&loaded.scene, Some(seed), params, policy.as_mut(), &opts);
                let Ok(score) = tad_metrics::score_episode(&episode.records, mode) else { continue };
                if let Some(w) = trace.as_mut()
                    && let Err(err) = write_trace(w, &loaded.name, policy.name(), &loaded.scene, &episode)
                {
                    return Err(CliError::usage(format!("cannot write the trace: {err}")));
                }
                if args.format == RunFormat::Json {
                    outln!("{}", episode_json(&loaded.name, policy.name(), &episode, &score))?;
                }
                let mut episode = episode;
                if args.render.is_none() || !done.is_empty() {
                    episode.frames = Vec::new();
                }
                done.push(Done { file: f, ego: e, episode, score });
                progress.inc(1);
            }
        }
    }
    progress.finish_and_clear();
    if let Some(w) = trace.as_mut()
        && let Err(e) = w.flush()
    {
        status = Status::Usage;
        errln!("error: cannot write the trace: {e}")?;
    }
    let names: Vec<String> = policies.iter().map(|p| p.name().to_string()).collect();
    if let Some(dir) = &args.out
        && let Err(e) = write_results(dir, args, &scenes, &done)
    {
        status = Status::Usage;
        errln!("error: cannot write the results to `{}`: {e}", dir.display())?;
    }
    match args.format {
        RunFormat::Json => {
            for (e, name) in names.iter().enumerate() {
                let scores: Vec<tad_metrics::EpisodeScore> =
                    done.iter().filter(|d| d.ego == e).map(|d| d.score.clone()).collect();
                let Ok(agg) = tad_metrics::aggregate(&scores, mode) else { continue };
                let value = serde_json::json!({
                    "aggregate": true,
                    "ego": name,
                    "episodes": agg.episodes,
                    "completed": agg.completed,
                    "mode": mode.as_str(),
                    "metrics": agg.raw,
                    "normalised": agg.normalised,
                    "safety": agg.safety,
                    "task": agg.task,
                    "comfort": agg.comfort,
                });
                outln!("{value}")?;
            }
        }
        RunFormat::Table => print_table(&scenes, &names, &done, mode)?,
    }
    if let (Some(path), Some(first)) = (&args.render, done.first()) {
        let loaded = &scenes[first.file];
        if let Err(e) = render(path, &loaded.scene, &names[first.ego], &first.episode) {
            status = Status::Usage;
            errln!("error: cannot write `{}`: {e}", path.display())?;
        } else {
            errln!(
                "{}: rendered seed {} with {} to {}",
                loaded.name,
                first.episode.seed.unwrap_or(0),
                names[first.ego],
                path.display()
            )?;
        }
    }
    Ok(status)
}

/// The episodes as a results file of `eval`'s form (one region `all`, one generator
/// `files`), for `tadslc merge`.
fn write_results(dir: &Path, args: &RunArgs, scenes: &[Loaded], done: &[Done]) -> std::io::Result<()> {
    use tad_eval::{Results, Row, Setup};
    let rows: Vec<Row> = done
        .iter()
        .map(|d| Row {
            region: "all".into(),
            generator: "files".into(),
            ego: args.egos[d.ego].clone(),
            scenario: scenes[d.file].name.clone(),
            trial: 0,
            seed: d.episode.seed.unwrap_or(0),
            score: d.score.clone(),
        })
        .collect();
    let results = Results::new(
        Setup {
            regions: vec!["all".into()],
            generators: vec!["files".into()],
            egos: args.egos.clone(),
            search_ego: String::new(),
            n: 0,
            samples: (args.seeds.end - args.seeds.start) as usize,
            keep: 0,
            seed: args.seeds.start,
        },
        args.shard,
        [("all/files".to_string(), scenes.len())].into_iter().collect(),
        rows,
    );
    results.write(dir).map(|_| ())
}

fn episode_json(file: &str, ego: &str, e: &Episode, score: &tad_metrics::EpisodeScore) -> serde_json::Value {
    serde_json::json!({
        "file": file,
        "seed": e.seed,
        "ego": ego,
        "steps": e.steps,
        "stop_reason": e.stop_reason.as_str(),
        "metrics": score.metrics,
    })
}

fn write_trace(w: &mut impl Write, file: &str, ego: &str, scene: &Scene, e: &Episode) -> std::io::Result<()> {
    let labels: Vec<String> =
        std::iter::once("ego".to_string()).chain(scene.actors.iter().map(|a| a.label.clone())).collect();
    for (step, frame) in e.frames.iter().enumerate() {
        let actors: Vec<serde_json::Value> = frame
            .poses
            .iter()
            .zip(&frame.speeds)
            .zip(&labels)
            .map(|((&(x, y, yaw), &v), label)| {
                serde_json::json!({"id": label, "x": round(x), "y": round(y), "yaw": round(yaw), "v": round(v)})
            })
            .collect();
        let lights: serde_json::Map<String, serde_json::Value> = frame
            .lights
            .iter()
            .map(|(arm, l)| (arm.as_str().to_string(), format!("{l:?}").to_lowercase().into()))
            .collect();
        let line = serde_json::json!({
            "file": file, "seed": e.seed, "ego": ego, "step": step,
            "t": round(step as f64 * scene.limits.dt), "actors": actors, "lights": lights,
        });
        writeln!(w, "{line}")?;
    }
    Ok(())
}

fn round(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

fn render(path: &Path, scene: &Scene, ego: &str, e: &Episode) -> std::io::Result<()> {
    use tad_render::{ActorInfo, Frame, Kind};
    let size = scene.ego.size;
    let actors =
        std::iter::once(ActorInfo { label: "ego".into(), kind: Kind::Ego, length: size.length, width: size.width })
            .chain(scene.actors.iter().map(|a| ActorInfo {
                label: a.label.clone(),
                kind: match a.body {
                    tad_layout::Body::Vehicle => Kind::Vehicle,
                    tad_layout::Body::Walker => Kind::Walker,
                    tad_layout::Body::Object => Kind::Object,
                },
                length: a.size.length,
                width: a.size.width,
            }))
            .collect();
    let frames = e
        .frames
        .iter()
        .map(|f| Frame {
            poses: f.poses.iter().map(|&(x, y, yaw)| Some([x, y, yaw])).collect(),
            lights: f.lights.clone(),
        })
        .collect();
    let (start, length) = (scene.ego.start, scene.ego.route_length);
    let route = (0..=(length / 2.0).ceil() as usize)
        .map(|k| scene.ego.route.pose(start + (2.0 * k as f64).min(length)).position)
        .map(|p| [p.x, p.y])
        .collect();
    let events = e
        .events
        .iter()
        .map(|ev| tad_render::Event {
            step: ev.step as usize,
            position: [ev.position.x, ev.position.y],
            label: match ev.other {
                Some(k) => {
                    format!("{} with {}", ev.kind.as_str(), scene.actors.get(k).map_or("?", |a| a.label.as_str()))
                }
                None => ev.kind.as_str().replace('_', " "),
            },
        })
        .collect();
    let picture = tad_render::Scene {
        road: &scene.world.road,
        title: format!("{} · seed {} · ego {ego}", scene.name, e.seed.unwrap_or(0)),
        actors,
        frames,
        dt: scene.limits.dt,
        route,
        events,
    };
    let bytes = if path.extension().is_some_and(|x| x.eq_ignore_ascii_case("gif")) {
        tad_render::gif(&picture, tad_render::GifOptions::default())
    } else {
        tad_render::svg(&picture).into_bytes()
    };
    std::fs::write(path, bytes)
}

/// One row per scenario and ego (aggregated over the seeds), then one per ego over all
/// scenarios: the paper's normalised values (value / max) and OS.
fn print_table(scenes: &[Loaded], egos: &[String], done: &[Done], mode: Mode) -> Result<(), Closed> {
    let width = scenes.iter().map(|s| s.scene.name.len()).max().unwrap_or(8).clamp(8, 40);
    let header: Vec<&str> = tad_metrics::METRICS.iter().map(|m| m.key).collect();
    out!("{:<width$}  {:<10} {:>4}", "scenario", "ego", "runs")?;
    for key in &header {
        out!(" {key:>6}")?;
    }
    outln!(" {:>6}  stops", "OS")?;
    let row = |label: &str, ego: &str, rows: &[&Done]| -> Result<(), Closed> {
        let scores: Vec<tad_metrics::EpisodeScore> = rows.iter().map(|d| d.score.clone()).collect();
        let Ok(agg) = tad_metrics::aggregate(&scores, mode) else { return Ok(()) };
        out!("{label:<width$}  {ego:<10} {:>4}", rows.len())?;
        for m in tad_metrics::METRICS.iter() {
            match agg.normalised.get(m.metric) {
                Some(v) => out!(" {v:>6.3}")?,
                None => out!(" {:>6}", "-")?,
            }
        }
        let mut stops: Vec<(&str, usize)> = Vec::new();
        for d in rows {
            let name = d.episode.stop_reason.as_str();
            match stops.iter_mut().find(|(n, _)| *n == name) {
                Some((_, k)) => *k += 1,
                None => stops.push((name, 1)),
            }
        }
        let stops: Vec<String> = stops.iter().map(|(n, k)| format!("{n} {k}")).collect();
        outln!(" {:>6.3}  {}", agg.normalised.os, stops.join(", "))
    };
    for (f, loaded) in scenes.iter().enumerate() {
        for (e, ego) in egos.iter().enumerate() {
            let rows: Vec<&Done> = done.iter().filter(|d| d.file == f && d.ego == e).collect();
            let name: String = loaded.scene.name.chars().take(width).collect();
            row(&name, ego, &rows)?;
        }
    }
    if scenes.len() > 1 {
        for (e, ego) in egos.iter().enumerate() {
            let rows: Vec<&Done> = done.iter().filter(|d| d.ego == e).collect();
            row("all", ego, &rows)?;
        }
    }
    outln!()?;
    outln!("values normalised as in TrafficAlign's tables (value / max; OS 1 is perfect); {} scoring", mode.as_str())
}

#[cfg(test)]
mod tests {
    use super::parse_seeds;

    #[test]
    fn seeds_are_rust_ranges() {
        assert_eq!(parse_seeds("3..6"), Ok(3..6));
        assert_eq!(parse_seeds("3..=6"), Ok(3..7));
        assert_eq!(parse_seeds("4"), Ok(4..5));
        assert!(parse_seeds("5..5").unwrap_err().contains("holds no seed"));
        assert!(parse_seeds("a..3").unwrap_err().contains("not a seed"));
    }
}
