//! `tadslc search`: ChatScene's adversarial search (`tad-search`) over scenario files with
//! one ego, the chosen scenes written as TAD with their parameters fixed.
//!
//! Scenarios are searched in parallel (rayon; each search's rounds are parallel too), each
//! from its own seed, so the files written do not depend on the number of threads. Every
//! written scene is compiled and run again with the same ego and seed; the summary says
//! whether it reproduced the searched outcome. `--shard I/N` searches every N-th input.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use tad_eval::{Journal, searched};
use tad_metrics::Mode;
use tad_search::{Config, Outcome};

use crate::output::CliError;
use crate::{Status, errln, outln};
use tad_policy::EgoSpec;

/// `tadslc search`'s arguments.
#[derive(clap::Args)]
pub struct SearchArgs {
    /// Scenario files or directories (searched recursively), or `.tadc` files
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The ego the scenes are searched against: `idm`, `naive`, `ppo`, `sac`, `td3`,
    /// `learned:PATH`
    #[arg(long, default_value = "idm", value_parser = crate::EgoNames)]
    pub ego: String,
    /// The directory the chosen scenes and `search.json` are written to
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Scenes sampled per scenario (at most 1,000,000)
    #[arg(long, default_value_t = tad_search::Config::default().samples, value_parser = crate::count::<1_000_000>)]
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
    /// Remove the scenes and summaries an earlier run left in `--out` (else they are an
    /// error; a shard of a job array leaves the other shards' files alone)
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: &SearchArgs, color: bool) -> Result<Status, CliError> {
    let ego = EgoSpec::parse(&args.ego).map_err(|e| CliError::usage(format!("--ego {}: {e}", args.ego)))?;
    // raised by inputs that do not load, and scenes that could not be written
    let (scenes, mut status) = crate::scenes::load_shard(&args.paths, args.shard, color)?;
    if scenes.is_empty() {
        return Err(CliError::usage("nothing to search"));
    }
    // a shard shares the directory with the other shards of its run
    let ours = |name: &str| {
        args.shard == tad_base::Shard::ALL
            && (name.ends_with(".tad") || (name.starts_with("search") && name.ends_with(".json")))
    };
    let mode = if args.compat { Mode::Compat } else { Mode::Fixed };
    let config = Config { samples: args.samples, round: args.round, keep: args.keep, seed: args.seed, mode };
    // an interrupted run of this very command is taken up again; its files are rewritten
    let head = journal_head(args, &scenes);
    let path = searched::journal_path(&args.out, args.shard);
    let resuming = Journal::holds(&path, &head);
    crate::files::fresh_output(&args.out, args.force || resuming, &ours)?;
    let (journal, finished) = Journal::open_at::<_, searched::Finished>(path, &head)
        .map_err(|e| CliError::usage(format!("cannot write the journal in `{}`: {e}", args.out.display())))?;
    let done: BTreeMap<usize, Outcome> = finished.into_iter().map(|f| (f.index, f.outcome)).collect();
    if !done.is_empty() {
        errln!(
            "resumed {} of {} from `{}`",
            done.len(),
            crate::plural(scenes.len(), "scenario"),
            journal.file().display()
        )?;
    }
    let episodes_of =
        |l: &crate::scenes::Loaded| if l.scene.program.params.is_empty() { 1 } else { args.samples.max(1) };
    let total: usize =
        scenes.iter().enumerate().filter(|(k, _)| !done.contains_key(k)).map(|(_, l)| episodes_of(l)).sum();
    let progress = crate::output::progress(total, "episodes");
    let episodes = AtomicUsize::new(0);
    let tick = || {
        episodes.fetch_add(1, Ordering::Relaxed);
        progress.inc(1);
    };
    let make = || ego.make();
    let stop = crate::output::on_interrupt("searches");
    let started = std::time::Instant::now();
    // each search from its own seed; a finished one goes to the journal at once
    let outcomes: Vec<Option<Outcome>> = scenes
        .par_iter()
        .enumerate()
        .map(|(k, l)| {
            if let Some(outcome) = done.get(&k) {
                return Some(outcome.clone());
            }
            if stop.load(Ordering::SeqCst) {
                return None;
            }
            let outcome = tad_search::search(&l.scene, &make, &config, &tick);
            journal.record(&searched::Finished { index: k, outcome: outcome.clone() });
            Some(outcome)
        })
        .collect();
    progress.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    if let Some(e) = journal.failure() {
        status = Status::Usage;
        errln!("error: cannot write the journal: {e}")?;
    }
    let left = outcomes.iter().filter(|o| o.is_none()).count();
    let searched_now = outcomes.len() - left - done.len();
    let interrupted = left > 0;

    let mut writer = searched::Writer::new(&args.out, &args.ego, &ego, mode);
    let mut summary = Vec::new();
    outln!("{}", searched::table_header())?;
    for (loaded, outcome) in scenes.iter().zip(&outcomes) {
        let Some(outcome) = outcome else { continue };
        let mut written = Vec::new();
        for (k, &i) in outcome.chosen.iter().enumerate() {
            let (scene, error) = writer.write(loaded.source.as_ref(), &loaded.scene, outcome, (i, k));
            if let Some(e) = error {
                status = status.max(Status::Failed);
                errln!("{}: scene {} not written: {e}", loaded.name, scene.trial)?;
            }
            written.push(scene);
        }
        outln!("{}", searched::table_line(&loaded.scene, outcome, &written))?;
        summary.push(searched::scenario_json(&loaded.name, &loaded.scene, outcome, &written));
    }
    let file = args.out.join(args.shard.file_name("search", "json"));
    let mut value = serde_json::json!({
        "format": searched::FORMAT,
        "ego": args.ego,
        "seed": args.seed,
        "samples": args.samples,
        "round": args.round,
        "keep": args.keep,
        "shard": args.shard.to_string(),
        // every search's, resumed ones too, so a resumed run writes an unbroken one's file
        "episodes": outcomes.iter().flatten().map(|o| o.trials.len()).sum::<usize>(),
        "seconds": searched::round(seconds),
        "scenarios": summary,
    });
    if interrupted {
        // the scenarios not searched are missing: a rerun searches them
        value["interrupted"] = true.into();
    }
    let text = serde_json::to_string_pretty(&value).unwrap_or_default();
    std::fs::write(&file, text + "\n")
        .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", file.display())))?;
    errln!(
        "searched {} with {}: {} in {seconds:.1} s on {}; scenes and {} in `{}`",
        crate::plural(searched_now, "scenario"),
        args.ego,
        crate::plural(episodes.load(Ordering::Relaxed), "episode"),
        crate::plural(rayon::current_num_threads(), "thread"),
        file.file_name().map_or(String::new(), |f| f.to_string_lossy().into_owned()),
        args.out.display()
    )?;
    if interrupted {
        errln!(
            "interrupted: {} not searched; run the same command again to search {} and keep the rest",
            crate::plural(left, "scenario"),
            if left == 1 { "it" } else { "them" }
        )?;
        return Ok(status.max(Status::Failed));
    }
    // the run is whole: its files say everything
    if let Err(e) = journal.remove() {
        errln!("warning: cannot remove the journal: {e}")?;
    }
    Ok(status)
}

/// What the journal of this search belongs to.
fn journal_head(args: &SearchArgs, scenes: &[crate::scenes::Loaded]) -> searched::Head {
    searched::Head {
        format: searched::JOURNAL_FORMAT.into(),
        ego: args.ego.clone(),
        seed: args.seed,
        samples: args.samples,
        round: args.round,
        keep: args.keep,
        compat: args.compat,
        shard: args.shard,
        inputs: scenes
            .iter()
            .map(|l| {
                // a `.tadc` input has no source: its program's bytes stand for it
                let hash = match &l.source {
                    Some(input) => searched::input_hash(input.text.as_bytes()),
                    None => searched::input_hash(&tad_bytecode::encode(&l.scene.program)),
                };
                (l.name.clone(), hash)
            })
            .collect(),
    }
}
