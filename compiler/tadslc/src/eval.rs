//! `tadslc eval` and `tadslc merge`: the paper's results table in one command.
//!
//! ```text
//! corpus (examples/) ─▶ regions ─▶ per region, per generator: scenarios (fitted: tad-fit on
//!   the region's scenarios; baseline: the region-agnostic generator; llm*: `gen`'s loop;
//!   DIR: the files given)
//!   ─▶ checked, compiled ─▶ tad-search with the surrogate ego (the scenes kept per scenario)
//!   ─▶ every ego runs every kept scene ─▶ rows (one scored episode each)
//!   ─▶ aggregated per region × generator × ego: SafeBench's ten metrics and OS
//! with --finetune: kept scenes ─split 3/5 per behaviour─▶ tad-train (SAC) ─▶ every ego and
//!   the learned one before and after on the held-out 2/5 ─▶ the "after fine-tuning" table
//! ```
//!
//! Units of work are (region, generator, scenario) in a fixed order, so `--shard I/N` takes
//! every N-th; each shard writes its rows to its own results file and `merge` aggregates
//! the rows of all files, giving the table one run would have. Everything is seeded:
//! the fitted generator's scenario `i` is drawn with `seed + i`, the baseline's from the
//! seed mixed with the region's name, and every search uses `seed`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use tad_check::{Class, Options as CheckOptions};
use tad_db::{Database, Language, RealFs};
use tad_metrics::{EpisodeScore, METRICS, Mode};

use crate::output::Closed;
use crate::run::Ego;
use crate::shard::Shard;
use crate::{Status, errln, out, outln, plural};

/// What `eval` and `merge` print.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
pub enum EvalFormat {
    Markdown,
    Csv,
    Json,
}

pub struct EvalArgs {
    pub corpus: Vec<PathBuf>,
    pub regions: Vec<String>,
    pub generators: Vec<String>,
    pub egos: Vec<String>,
    pub search_ego: String,
    pub n: usize,
    pub samples: usize,
    pub keep: usize,
    pub seed: u64,
    pub format: EvalFormat,
    pub out: Option<PathBuf>,
    pub plot: Option<PathBuf>,
    pub shard: Shard,
    /// Requests in flight for the `llm` generators.
    pub jobs: usize,
    /// Episodes of the "after fine-tuning" stage (0: none).
    pub finetune: usize,
    pub finetune_updates: usize,
    pub finetune_from: Option<PathBuf>,
    pub llm: crate::llm::LlmArgs,
}

/// What produced a results file: shards merge only when these agree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Setup {
    pub regions: Vec<String>,
    pub generators: Vec<String>,
    pub egos: Vec<String>,
    pub search_ego: String,
    pub n: usize,
    pub samples: usize,
    pub keep: usize,
    pub seed: u64,
}

/// One scored episode: an ego on one kept scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    pub region: String,
    pub generator: String,
    pub ego: String,
    pub scenario: String,
    /// The scene's trial in the search, and the episode's seed.
    pub trial: usize,
    pub seed: u64,
    pub score: EpisodeScore,
}

/// A results file (`results.json`, `results.I-of-N.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Results {
    pub format: String,
    pub setup: Setup,
    pub shard: Shard,
    /// Scenarios generated (or given) and run, per region and generator, in this shard.
    pub scenarios: BTreeMap<String, usize>,
    pub rows: Vec<Row>,
}

pub const FORMAT: &str = "tadsl-eval/1";

/// One unit of work: a scenario of a generator in a region.
struct Unit {
    region: String,
    generator: String,
    name: String,
    scene: tad_runtime::Scene,
    /// Its behaviour, for the fine-tuning split (`train_ego::behaviour_of`).
    key: String,
}

pub fn eval(args: &EvalArgs, color: bool) -> Status {
    crate::output::run(|status| eval_in(args, color, status))
}

fn eval_in(args: &EvalArgs, _color: bool, status: &mut Status) -> Result<(), Closed> {
    let mut egos = Vec::new();
    for spec in args.egos.iter().chain(std::iter::once(&args.search_ego)) {
        match Ego::parse(spec) {
            Ok(ego) => egos.push(ego),
            Err(e) => {
                *status = Status::Usage;
                return errln!("error: ego `{spec}`: {e}");
            }
        }
    }
    let surrogate = egos.pop().expect("the search ego was pushed last");
    if args.finetune > 0 && args.shard != Shard::ALL {
        *status = Status::Usage;
        return errln!("error: --finetune trains on every kept scene: run it without --shard");
    }
    let corpus = crate::align::load(&args.corpus, status)?;
    if corpus.items.is_empty() {
        return Ok(());
    }
    // regions: the ones asked for, else every region with at least 3 scenarios
    let mut by_region: BTreeMap<String, Vec<&crate::align::Item>> = BTreeMap::new();
    for item in &corpus.items {
        if let Some(region) = region_of(&item.tad) {
            by_region.entry(region).or_default().push(item);
        }
    }
    let regions: Vec<String> = if args.regions.is_empty() {
        by_region.iter().filter(|(_, items)| items.len() >= 3).map(|(r, _)| r.clone()).collect()
    } else {
        args.regions.clone()
    };
    if regions.is_empty() {
        *status = Status::Usage;
        return errln!(
            "error: corpus `{}` has no region with 3 scenarios or more: name one with --region",
            corpus.name
        );
    }
    let setup = Setup {
        regions: regions.clone(),
        generators: args.generators.clone(),
        egos: args.egos.clone(),
        search_ego: args.search_ego.clone(),
        n: args.n,
        samples: args.samples,
        keep: args.keep,
        seed: args.seed,
    };

    // generate, check and compile, in the units' fixed order
    let mut units: Vec<Unit> = Vec::new();
    let mut db = Database::new(CheckOptions::default());
    for region in &regions {
        let own: &[&crate::align::Item] = by_region.get(region).map_or(&[], |v| v.as_slice());
        for generator in &args.generators {
            let texts = match scenarios(&mut db, args, generator, region, own, status)? {
                Some(texts) => texts,
                None => return Ok(()),
            };
            for (name, text) in texts {
                let key = crate::train_ego::behaviour_of(&text);
                let file =
                    db.set_source(PathBuf::from(format!("{generator}/{name}.tad")), text, Language::Tad, &RealFs);
                let Some(scenario) = tad_db::resolve(&db, file) else { continue };
                let layout = tad_layout::lay_out(scenario);
                let program = tad_bytecode::lower(scenario, &layout, &name);
                match tad_runtime::Scene::new(&program) {
                    Ok(scene) => {
                        units.push(Unit { region: region.clone(), generator: generator.clone(), name, scene, key })
                    }
                    Err(e) => errln!("note: {generator}/{name}: not run: {e}")?,
                }
            }
        }
    }
    let mine: Vec<&Unit> = units.iter().enumerate().filter(|(k, _)| args.shard.takes(*k)).map(|(_, u)| u).collect();
    let mut scenarios: BTreeMap<String, usize> = BTreeMap::new();
    for u in &mine {
        *scenarios.entry(format!("{}/{}", u.region, u.generator)).or_default() += 1;
    }
    let config = tad_search::Config { samples: args.samples, keep: args.keep, seed: args.seed, ..Default::default() };
    let per_unit = args.samples.max(1) + args.keep * egos.len();
    let progress = crate::run::Progress::new(mine.len() * per_unit, "episodes");
    let started = std::time::Instant::now();
    let searched: Vec<(Vec<Row>, Vec<Scene>)> = mine
        .par_iter()
        .map(|u| {
            let make = || surrogate.make();
            let outcome = tad_search::search(&u.scene, &make, &config, &|| progress.tick());
            let kept: Vec<Scene> = outcome
                .chosen
                .iter()
                .map(|&i| Scene { unit: u, params: outcome.trials[i].params.clone(), seed: outcome.trials[i].seed })
                .collect();
            let mut rows = Vec::new();
            for &i in &outcome.chosen {
                let trial = &outcome.trials[i];
                for (spec, ego) in args.egos.iter().zip(&egos) {
                    let score = play(&u.scene, &trial.params, trial.seed, ego);
                    progress.tick();
                    if let Some(score) = score {
                        rows.push(Row {
                            region: u.region.clone(),
                            generator: u.generator.clone(),
                            ego: spec.clone(),
                            scenario: u.name.clone(),
                            trial: trial.index,
                            seed: trial.seed,
                            score,
                        });
                    }
                }
            }
            (rows, kept)
        })
        .collect();
    progress.finish();
    let (rows, kept): (Vec<Vec<Row>>, Vec<Vec<Scene>>) = searched.into_iter().unzip();
    let rows: Vec<Row> = rows.into_iter().flatten().collect();
    let kept: Vec<Scene> = kept.into_iter().flatten().collect();
    let results = Results { format: FORMAT.into(), setup, shard: args.shard, scenarios, rows };
    if let Some(dir) = &args.out {
        let path = dir.join(args.shard.file_name("results", "json"));
        let written = std::fs::create_dir_all(dir)
            .and_then(|_| std::fs::write(&path, serde_json::to_string(&results).unwrap_or_default() + "\n"));
        if let Err(e) = written {
            *status = Status::Usage;
            return errln!("error: cannot write `{}`: {e}", path.display());
        }
        errln!("rows in {}", path.display())?;
    }
    errln!(
        "evaluated {} ({} of {}) in {:.1} s on {}",
        plural(mine.len(), "scenario"),
        plural(results.rows.len(), "episode"),
        plural(args.egos.len(), "ego"),
        started.elapsed().as_secs_f64(),
        plural(rayon::current_num_threads(), "thread")
    )?;
    print(&[results], args.format, args.plot.as_deref(), status)?;
    if args.finetune > 0 {
        finetune(args, &egos, &kept, status)?;
    }
    Ok(())
}

/// One episode of `ego` on a scene with fixed parameters, scored on its own (fixed mode);
/// `None` for an episode without a step.
fn play(scene: &tad_runtime::Scene, params: &[f64], seed: u64, ego: &Ego) -> Option<EpisodeScore> {
    let mut policy = ego.make();
    let episode =
        tad_runtime::run(scene, Some(seed), params.to_vec(), policy.as_mut(), &tad_runtime::Options::default());
    tad_metrics::score_episode(&episode.records, Mode::Fixed).ok()
}

/// A kept scene: its unit with the search's parameters and seed.
struct Scene<'a> {
    unit: &'a Unit,
    params: Vec<f64>,
    seed: u64,
}

/// The "after fine-tuning" table: a learned ego trained with SAC on 3/5 of each
/// behaviour's kept scenes (from `--finetune-from`, else from scratch), then it, the ego
/// it started from and the `--egos` on the held-out 2/5.
fn finetune(args: &EvalArgs, egos: &[Ego], kept: &[Scene], status: &mut Status) -> Result<(), Closed> {
    let keys: Vec<String> = kept.iter().map(|k| k.unit.key.clone()).collect();
    let (train, test) = tad_train::split(&keys, args.seed);
    if train.is_empty() || test.is_empty() {
        *status = (*status).max(Status::Failed);
        return errln!("warning: no fine-tuning: {} kept scenes are too few to hold some out", kept.len());
    }
    let config = tad_train::Config {
        episodes: args.finetune,
        updates_per_episode: args.finetune_updates,
        seed: args.seed,
        ..tad_train::Config::default()
    };
    // from a training checkpoint (actor, critics, optimizers, replay: as ChatScene resumes
    // SafeBench's), from an actor alone, or from scratch
    let made = match &args.finetune_from {
        Some(path) if path.is_dir() => tad_train::Trainer::load_checkpoint(path).and_then(|t| {
            let actor = t.actor()?;
            Ok((t, Some(actor)))
        }),
        Some(path) => tad_policy::Learned::load(path).map_err(tad_train::TrainError::from).and_then(|actor| {
            let mut t = tad_train::Trainer::new(config)?;
            t.init_actor(&actor)?;
            Ok((t, Some(actor)))
        }),
        None => tad_train::Trainer::new(config).map(|t| (t, None)),
    };
    let (mut trainer, before) = match made {
        Ok(made) => made,
        Err(e) => {
            *status = Status::Usage;
            return errln!("error: --finetune-from: {e}");
        }
    };
    let start = trainer.episodes() as usize;
    errln!(
        "fine-tuning a learned ego on {} ({} held out), {}",
        plural(train.len(), "scene"),
        test.len(),
        plural(args.finetune, "episode")
    )?;
    let progress = crate::run::Progress::new(args.finetune, "episodes");
    while (trainer.episodes() as usize) < start + args.finetune {
        let task = trainer.task(train.len());
        let scene = &kept[train[task.scenario]];
        if let Err(e) = trainer.step(&scene.unit.scene, scene.params.clone(), scene.seed) {
            *status = Status::Failed;
            return errln!("error: fine-tuning stopped: {e}");
        }
        progress.tick();
    }
    progress.finish();
    let after = match trainer.actor() {
        Ok(a) => a,
        Err(e) => {
            *status = Status::Failed;
            return errln!("error: {e}");
        }
    };
    if let Some(dir) = &args.out {
        let path = dir.join("finetuned.safetensors");
        if let Err(e) = after.save(&path) {
            *status = Status::Usage;
            return errln!("error: {e}");
        }
        errln!("the fine-tuned ego in {}", path.display())?;
    }
    // the held-out scenes, every ego
    let mut drivers: Vec<(String, Ego)> = Vec::new();
    if let Some(actor) = before {
        drivers.push(("learned (before)".into(), Ego::Learned(actor)));
    }
    drivers.push(("learned (fine-tuned)".into(), Ego::Learned(after)));
    for (spec, ego) in args.egos.iter().zip(egos) {
        drivers.push((spec.clone(), ego.copy()));
    }
    let rows: Vec<Row> = test
        .par_iter()
        .flat_map_iter(|&i| {
            let scene = &kept[i];
            drivers
                .iter()
                .filter_map(|(name, ego)| {
                    let score = play(&scene.unit.scene, &scene.params, scene.seed, ego)?;
                    Some(Row {
                        region: "held-out".into(),
                        generator: "searched".into(),
                        ego: name.clone(),
                        scenario: scene.unit.name.clone(),
                        trial: 0,
                        seed: scene.seed,
                        score,
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let collision_rate = |name: &str| {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.ego == name).collect();
        mine.iter().filter(|r| r.score.metrics.cr > 0.0).count() as f64 / mine.len().max(1) as f64
    };
    let setup = Setup {
        regions: vec!["held-out".into()],
        generators: vec!["searched".into()],
        egos: drivers.iter().map(|(n, _)| n.clone()).collect(),
        search_ego: args.search_ego.clone(),
        n: args.n,
        samples: args.samples,
        keep: args.keep,
        seed: args.seed,
    };
    let scenarios = [("held-out/searched".to_string(), test.len())].into_iter().collect();
    if args.format == EvalFormat::Markdown {
        outln!()?;
        outln!(
            "After fine-tuning: the learned ego trained on {} kept scenes (3/5 of each behaviour's), all egos on the {} held out:",
            train.len(),
            test.len()
        )?;
        outln!()?;
    }
    let (was, now) = (collision_rate("learned (before)"), collision_rate("learned (fine-tuned)"));
    let results = Results { format: FORMAT.into(), setup, shard: Shard::ALL, scenarios, rows };
    print(&[results], args.format, None, status)?;
    if drivers.iter().any(|(n, _)| n == "learned (before)") {
        let change = if was > 0.0 { format!("{:+.0} %", 100.0 * (now - was) / was) } else { "–".into() };
        errln!("held-out collision rate of the learned ego: {was:.3} before, {now:.3} after fine-tuning ({change})")?;
    }
    Ok(())
}

/// The baseline's seed for a region: each region draws its own sample of the same
/// region-agnostic generator (FNV-1a of the name, mixed with the seed).
fn regions_seed(seed: u64, region: &str) -> u64 {
    region.bytes().fold(0xcbf2_9ce4_8422_2325_u64 ^ seed, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// The region a scenario's `source` names.
fn region_of(text: &str) -> Option<String> {
    let module = tad_syntax::analyze(text).0;
    Some(module.scenario?.attr("source", "region")?.symbol()?.name.clone())
}

/// The scenarios of `generator` for `region`: (name, TAD text), checked; `None` after an
/// error that stops the command.
fn scenarios(
    db: &mut Database,
    args: &EvalArgs,
    generator: &str,
    region: &str,
    own: &[&crate::align::Item],
    status: &mut Status,
) -> Result<Option<Vec<(String, String)>>, Closed> {
    let (n, seed) = (args.n, args.seed);
    let dir = match generator {
        "llm" | "llm-baseline" | "llm-tuned" => {
            // through `tadslc gen`'s loop, into the results directory or a temporary one
            let base = args
                .out
                .clone()
                .unwrap_or_else(|| std::env::temp_dir().join(format!("tadsl-eval-{}", std::process::id())));
            let dir = base.join("generated").join(region).join(generator);
            if let Err(e) = std::fs::create_dir_all(&dir) {
                *status = Status::Usage;
                errln!("error: cannot create `{}`: {e}", dir.display())?;
                return Ok(None);
            }
            errln!(
                "{region}: generating {} with the language model ({generator}) into {}",
                plural(n, "scenario"),
                dir.display()
            )?;
            let request = crate::llm::GenArgs {
                region,
                n,
                out: Some(&dir),
                baseline: generator == "llm-baseline",
                tuned: generator == "llm-tuned",
                corpus: &args.corpus,
                jobs: args.jobs,
            };
            let done = crate::llm::generate(&request, &args.llm);
            if done != Status::Ok {
                *status = (*status).max(done);
                errln!("error: {region}: the language model generated nothing usable ({generator})")?;
                return Ok(None);
            }
            Some(dir)
        }
        "fitted" | "baseline" => None,
        path => Some(PathBuf::from(path)),
    };
    if let Some(dir) = dir {
        if !dir.is_dir() {
            *status = Status::Usage;
            errln!(
                "error: generator `{generator}` is not `fitted`, `baseline`, `llm`, `llm-baseline`, `llm-tuned` or a directory of scenarios"
            )?;
            return Ok(None);
        }
        let corpus = crate::align::load(std::slice::from_ref(&dir), status)?;
        let mut out: Vec<(String, String)> = corpus.items.into_iter().map(|i| (i.name, i.tad)).collect();
        out.retain(|(name, text)| {
            let file =
                db.set_source(PathBuf::from(format!("{generator}/{name}.tad")), text.clone(), Language::Tad, &RealFs);
            tad_db::check(db, file).class.is_some_and(|c| c != Class::Invalid)
        });
        return Ok(Some(out));
    }
    match generator {
        "fitted" => {
            if own.is_empty() {
                errln!("note: region `{region}` has no scenario to fit: no fitted scenarios")?;
                return Ok(Some(Vec::new()));
            }
            let (fitted, _) = crate::align::fit_items(own.iter().copied());
            let mut out = Vec::new();
            for i in 0..n {
                let name = format!("{region}_fitted_{:03}", i + 1);
                if let (Some((text, _)), _) =
                    crate::align::draw_fitted(db, &fitted, &name, seed.wrapping_add(i as u64), crate::align::ATTEMPTS)
                {
                    out.push((name, text));
                }
            }
            Ok(Some(out))
        }
        "baseline" => {
            // the region-agnostic generator (knows the language, not the region)
            let mut out = Vec::new();
            let own_seed = regions_seed(seed, region);
            for (i, g) in crate::corpus::generate(4 * n.max(1), own_seed).into_iter().enumerate() {
                if out.len() == n {
                    break;
                }
                let name = format!("{region}_baseline_{:03}", i + 1);
                let file = db.set_source(PathBuf::from(format!("{name}.tad")), g.tad.clone(), Language::Tad, &RealFs);
                if crate::align::counts(tad_db::check(db, file).class) {
                    out.push((name, g.tad));
                }
            }
            Ok(Some(out))
        }
        _ => Ok(Some(Vec::new())),
    }
}

/// `tadslc merge FILES`: the table of several results files (the shards of one command).
pub fn merge(files: &[PathBuf], format: EvalFormat, plot: Option<&Path>) -> Status {
    crate::output::run(|status| {
        let mut all: Vec<Results> = Vec::new();
        for path in files {
            let read = std::fs::read_to_string(path)
                .map_err(|e| e.to_string())
                .and_then(|t| serde_json::from_str::<Results>(&t).map_err(|e| format!("not a results file: {e}")));
            match read {
                Ok(r) if r.format == FORMAT => all.push(r),
                Ok(r) => {
                    *status = Status::Usage;
                    return errln!("error: {}: format `{}`, expected `{FORMAT}`", path.display(), r.format);
                }
                Err(e) => {
                    *status = Status::Usage;
                    return errln!("error: {}: {e}", path.display());
                }
            }
        }
        let Some(first) = all.first() else {
            *status = Status::Usage;
            return errln!("error: no results file to merge");
        };
        if let Some((i, _)) = all.iter().enumerate().find(|(_, r)| r.setup != first.setup) {
            *status = Status::Usage;
            return errln!(
                "error: {} comes from another command than {} (regions, generators, egos, sizes or seed differ)",
                files[i].display(),
                files[0].display()
            );
        }
        let count = first.shard.count;
        let mut seen = vec![0usize; count];
        for (i, r) in all.iter().enumerate() {
            if r.shard.count != count {
                *status = Status::Usage;
                return errln!(
                    "error: {} is shard {} but {} is of {count}",
                    files[i].display(),
                    r.shard,
                    files[0].display()
                );
            }
            seen[r.shard.index] += 1;
        }
        if let Some(twice) = seen.iter().position(|&k| k > 1) {
            *status = Status::Usage;
            return errln!("error: shard {twice}/{count} is given twice");
        }
        let missing: Vec<String> = (0..count).filter(|&k| seen[k] == 0).map(|k| format!("{k}/{count}")).collect();
        if !missing.is_empty() {
            *status = (*status).max(Status::Failed);
            errln!("warning: shards {} are missing: the table covers part of the work", missing.join(", "))?;
        }
        print(&all, format, plot, status)
    })
}

/// One table row: a region, generator and ego, over the rows of all results.
struct Line {
    region: String,
    generator: String,
    ego: String,
    scenarios: usize,
    agg: tad_metrics::Aggregate,
}

fn lines(all: &[Results]) -> Vec<Line> {
    let setup = &all[0].setup;
    let mut out = Vec::new();
    for region in &setup.regions {
        for generator in &setup.generators {
            let key = format!("{region}/{generator}");
            let scenarios: usize = all.iter().filter_map(|r| r.scenarios.get(&key)).sum();
            for ego in &setup.egos {
                let scores: Vec<EpisodeScore> = all
                    .iter()
                    .flat_map(|r| &r.rows)
                    .filter(|r| &r.region == region && &r.generator == generator && &r.ego == ego)
                    .map(|r| r.score.clone())
                    .collect();
                if let Ok(agg) = tad_metrics::aggregate(&scores, Mode::Fixed) {
                    out.push(Line {
                        region: region.clone(),
                        generator: generator.clone(),
                        ego: ego.clone(),
                        scenarios,
                        agg,
                    });
                }
            }
        }
    }
    out
}

fn print(all: &[Results], format: EvalFormat, plot: Option<&Path>, status: &mut Status) -> Result<(), Closed> {
    let lines = lines(all);
    let value = |m: &tad_metrics::Metrics, k: usize| -> Option<f64> { m.get(METRICS[k].metric) };
    match format {
        EvalFormat::Json => {
            for l in &lines {
                let v = serde_json::json!({
                    "region": l.region,
                    "generator": l.generator,
                    "ego": l.ego,
                    "scenarios": l.scenarios,
                    "episodes": l.agg.episodes,
                    "metrics": l.agg.raw,
                    "normalised": l.agg.normalised,
                    "OS": l.agg.normalised.os,
                });
                outln!("{v}")?;
            }
        }
        EvalFormat::Csv => {
            out!("region,generator,ego,scenarios,episodes")?;
            for m in METRICS.iter() {
                out!(",{}", m.key)?;
            }
            outln!(",OS")?;
            for l in &lines {
                out!("{},{},{},{},{}", l.region, l.generator, l.ego, l.scenarios, l.agg.episodes)?;
                for k in 0..METRICS.len() {
                    match value(&l.agg.normalised, k) {
                        Some(v) => out!(",{v:.4}")?,
                        None => out!(",")?,
                    }
                }
                outln!(",{:.4}", l.agg.normalised.os)?;
            }
        }
        EvalFormat::Markdown => {
            out!("| region | generator | ego | scenes |")?;
            for m in METRICS.iter() {
                out!(" {} |", m.key)?;
            }
            outln!(" OS |")?;
            out!("|---|---|---|---:|")?;
            for _ in METRICS.iter() {
                out!("---:|")?;
            }
            outln!("---:|")?;
            for l in &lines {
                out!("| {} | {} | {} | {} |", l.region, l.generator, l.ego, l.agg.episodes)?;
                for k in 0..METRICS.len() {
                    match value(&l.agg.normalised, k) {
                        Some(v) => out!(" {v:.3} |")?,
                        None => out!(" – |")?,
                    }
                }
                outln!(" **{:.3}** |", l.agg.normalised.os)?;
            }
            outln!()?;
            let setup = &all[0].setup;
            let scenes = if setup.keep == 0 {
                "each scene is one scenario run with one seed (`tadslc run`)".to_string()
            } else {
                format!(
                    "each scene is one of the {} kept per scenario by the adversarial search against `{}`",
                    setup.keep, setup.search_ego
                )
            };
            outln!(
                "Normalised as in TrafficAlign's tables (value / max; lower is better but for RF and Comp; OS 1 is perfect); {scenes}."
            )?;
        }
    }
    if let Some(path) = plot {
        let svg = tad_stats::plot::grouped(
            "Overall score (OS) by generator and ego",
            &lines
                .iter()
                .map(|l| (format!("{} · {}", l.region, l.generator), l.ego.clone(), l.agg.normalised.os))
                .collect::<Vec<_>>(),
        );
        if let Err(e) = std::fs::write(path, svg) {
            *status = Status::Usage;
            errln!("error: cannot write `{}`: {e}", path.display())?;
        }
    }
    Ok(())
}
