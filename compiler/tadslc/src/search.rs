//! `tadslc search`: ChatScene's adversarial search (`tad-search`) over scenario files with
//! one ego, the chosen scenes written as TAD with their parameters fixed.
//!
//! Scenarios are searched in parallel (rayon; each search's rounds are parallel too), each
//! from its own seed, so the files written do not depend on the number of threads. Every
//! written scene is compiled and run again with the same ego and seed; the summary says
//! whether it reproduced the searched outcome. `--shard I/N` searches every N-th input.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use tad_metrics::Mode;
use tad_policy::EgoPolicy;
use tad_search::{Config, Outcome};

use crate::output::{CliError, Closed};
use crate::run::Loaded;
use crate::{Status, errln, outln};
use tad_policy::EgoSpec;

/// `tadslc search`'s arguments.
#[derive(clap::Args)]
pub struct SearchArgs {
    /// Scenario files or directories (searched recursively), or `.tadc` files
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The ego the scenes are searched against: `idm`, `naive`, `learned:PATH`
    #[arg(long, default_value = "idm")]
    pub ego: String,
    /// The directory the chosen scenes and `search.json` are written to
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Scenes sampled per scenario
    #[arg(long, default_value_t = tad_search::Config::default().samples)]
    pub samples: usize,
    /// Ranges are re-fitted after every this many scenes
    #[arg(long, default_value_t = tad_search::Config::default().round)]
    pub round: usize,
    /// Scenes kept per scenario
    #[arg(long, default_value_t = tad_search::Config::default().keep)]
    pub keep: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Search every N-th input from I (a job array's index I of N jobs, from 0)
    #[arg(long, value_name = "I/N", default_value = "0/1")]
    pub shard: tad_base::Shard,
    /// Score as SafeBench's scorer does, quirks included
    #[arg(long)]
    pub compat: bool,
}

pub fn run(args: &SearchArgs, color: bool) -> Status {
    crate::output::finish(search_in(args, color))
}

/// One written scene.
#[derive(serde::Serialize)]
pub struct Written {
    pub file: Option<String>,
    pub trial: usize,
    pub seed: u64,
    pub params: serde_json::Map<String, serde_json::Value>,
    pub collision: bool,
    pub os: Option<f64>,
    /// The written scene, run again, collided as the trial did and scored within 0.01.
    pub reproduced: Option<bool>,
}

fn search_in(args: &SearchArgs, color: bool) -> Result<Status, CliError> {
    let ego = EgoSpec::parse(&args.ego).map_err(|e| CliError::usage(format!("--ego {}: {e}", args.ego)))?;
    // raised by inputs that do not load, and scenes that could not be written
    let mut status = Status::Ok;
    let scenes = crate::run::load_shard(&args.paths, args.shard, color, &mut status)?;
    if scenes.is_empty() {
        return Err(CliError::usage("nothing to search"));
    }
    std::fs::create_dir_all(&args.out)
        .map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", args.out.display())))?;
    let mode = if args.compat { Mode::Compat } else { Mode::Fixed };
    let config = Config { samples: args.samples, round: args.round, keep: args.keep, seed: args.seed, mode };
    let total: usize =
        scenes.iter().map(|s| if s.scene.program.params.is_empty() { 1 } else { args.samples.max(1) }).sum();
    let progress = crate::output::progress(total, "episodes");
    let done = AtomicUsize::new(0);
    let tick = || {
        done.fetch_add(1, Ordering::Relaxed);
        progress.inc(1);
    };
    let make = || ego.make();
    let started = std::time::Instant::now();
    let outcomes: Vec<Outcome> =
        scenes.par_iter().map(|l| tad_search::search(&l.scene, &make, &config, &tick)).collect();
    progress.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();

    let mut writer = Writer { args, ego: &ego, mode, color, taken: HashSet::new() };
    let mut summary = Vec::new();
    outln!("{:<40} {:>5} {:>9}  {:<24} chosen (OS)", "scenario", "slots", "episodes", "collisions by round")?;
    for (loaded, outcome) in scenes.iter().zip(&outcomes) {
        let mut written = Vec::new();
        for (k, &i) in outcome.chosen.iter().enumerate() {
            let trial = &outcome.trials[i];
            let (file, reproduced) = match write_scene(&mut writer, loaded, outcome, i, k)? {
                Ok((file, reproduced)) => (Some(file), Some(reproduced)),
                Err(e) => {
                    status = status.max(Status::Failed);
                    errln!("{}: scene {} not written: {e}", loaded.name, trial.index)?;
                    (None, None)
                }
            };
            let params = loaded
                .scene
                .program
                .params
                .iter()
                .zip(&trial.params)
                .map(|(slot, v)| (slot.name.clone(), serde_json::json!(round(*v))))
                .collect();
            written.push(Written {
                file,
                trial: trial.index,
                seed: trial.seed,
                params,
                collision: trial.collision,
                os: trial.score.as_ref().map(|s| round(s.metrics.os)),
                reproduced,
            });
        }
        let rates: Vec<String> = outcome.collision_rates().iter().map(|r| format!("{:.0}%", 100.0 * r)).collect();
        let chosen: Vec<String> = written
            .iter()
            .map(|w| {
                format!("{}{}", if w.collision { "hit " } else { "" }, w.os.map_or("-".into(), |o| format!("{o:.3}")))
            })
            .collect();
        let name: String = loaded.scene.name.chars().take(40).collect();
        outln!(
            "{name:<40} {:>5} {:>9}  {:<24} {}",
            loaded.scene.program.params.len(),
            outcome.trials.len(),
            rates.join(" "),
            chosen.join(", ")
        )?;
        summary.push(serde_json::json!({
            "input": loaded.name,
            "scenario": loaded.scene.name,
            "slots": loaded.scene.program.params.iter().map(|p| serde_json::json!({"name": p.name, "min": p.min, "max": p.max})).collect::<Vec<_>>(),
            "ranges": outcome.ranges.iter().map(|r| r.iter().map(|(a, b)| [round(*a), round(*b)]).collect::<Vec<_>>()).collect::<Vec<_>>(),
            "collision_rates": outcome.collision_rates(),
            "chosen": written,
        }));
    }
    let episodes = done.load(Ordering::Relaxed);
    let file = args.out.join(args.shard.file_name("search", "json"));
    let value = serde_json::json!({
        "format": "tadsl-search/1",
        "ego": args.ego,
        "seed": args.seed,
        "samples": args.samples,
        "round": args.round,
        "keep": args.keep,
        "shard": args.shard.to_string(),
        "episodes": episodes,
        "seconds": round(seconds),
        "scenarios": summary,
    });
    let text = serde_json::to_string_pretty(&value).unwrap_or_default();
    std::fs::write(&file, text + "\n")
        .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", file.display())))?;
    errln!(
        "searched {} with {}: {episodes} episodes in {seconds:.1} s on {}; scenes and {} in {}",
        crate::plural(scenes.len(), "scenario"),
        args.ego,
        crate::plural(rayon::current_num_threads(), "thread"),
        file.file_name().map_or(String::new(), |f| f.to_string_lossy().into_owned()),
        args.out.display()
    )?;
    Ok(status)
}

/// What writing the chosen scenes shares: the search's arguments, its ego and scoring, and
/// the file names taken so far.
struct Writer<'a> {
    args: &'a SearchArgs,
    ego: &'a EgoSpec,
    mode: Mode,
    color: bool,
    taken: HashSet<String>,
}

/// Writes chosen scene `k` (trial `i`) of `loaded` as TAD, then runs it again: (file name,
/// reproduced). The outer error is closed output; the inner one why it was not written.
fn write_scene(
    w: &mut Writer,
    loaded: &Loaded,
    outcome: &Outcome,
    i: usize,
    k: usize,
) -> Result<Result<(String, bool), String>, Closed> {
    let (args, ego, mode, color) = (w.args, w.ego, w.mode, w.color);
    let taken = &mut w.taken;
    let Some(input) = &loaded.source else {
        return Ok(Err("a bytecode file has no source to write".into()));
    };
    let trial = &outcome.trials[i];
    let db = std::cell::RefCell::new(tad_db::Database::new(tad_check::Options::default()));
    let compile = |text: &str| {
        let mut again = input.clone();
        again.text = text.to_string();
        crate::bytecode::compile(&mut db.borrow_mut(), &again, "searched", color).ok().flatten()
    };
    let text = match tad_search::fix(&input.text, &loaded.scene.program, &trial.params, &compile) {
        Ok(text) => text,
        Err(e) => return Ok(Err(e.to_string())),
    };
    let stem =
        input.path.as_deref().and_then(Path::file_stem).map_or("scenario".into(), |s| s.to_string_lossy().into_owned());
    let mut name = format!("{stem}.adv{}.tad", k + 1);
    let mut n = 2;
    while !taken.insert(name.clone()) {
        name = format!("{stem}-{n}.adv{}.tad", k + 1);
        n += 1;
    }
    let verdict = |collision: bool| if collision { "a collision" } else { "no collision" };
    let header = format!(
        "// tadslc search: scene {} of {} (trial seed {}), with ego {}: {}, OS {}\n",
        trial.index,
        loaded.name,
        trial.seed,
        args.ego,
        verdict(trial.collision),
        trial.score.as_ref().map_or("-".into(), |s| format!("{:.3}", s.metrics.os)),
    );
    let path = args.out.join(&name);
    if let Err(e) = std::fs::write(&path, format!("{header}{text}")) {
        return Ok(Err(format!("cannot write `{}`: {e}", path.display())));
    }
    // the written scene, run again
    let reproduced = compile(&text).and_then(|p| tad_runtime::Scene::new(&p).ok()).is_some_and(|scene| {
        let mut policy: Box<dyn EgoPolicy> = ego.make();
        let opts = tad_runtime::Options { mode, ..Default::default() };
        let episode = tad_runtime::run(&scene, Some(trial.seed), Vec::new(), policy.as_mut(), &opts);
        let collision = episode.records.iter().any(|r| r.collision);
        let os = tad_metrics::score_episode(&episode.records, mode).ok().map(|s| s.metrics.os);
        collision == trial.collision
            && match (os, &trial.score) {
                (Some(a), Some(b)) => (a - b.metrics.os).abs() <= 0.01,
                (a, b) => a.is_none() && b.is_none(),
            }
    });
    Ok(Ok((name, reproduced)))
}

fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}
