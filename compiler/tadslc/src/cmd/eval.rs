//! `tadslc eval` and `tadslc merge` on the command line: arguments in, `tad-eval` does the
//! work, tables and notes out.
//!
//! The host's part: reading the corpus and directories, running the language-model
//! generators through `gen`'s loop (they need a server or the local model), the progress
//! bar, the journal and results files under `--out`, the fine-tuning stage's messages and
//! table (`--finetune`, through `tad-eval`'s one training driver), and the exit status.

use std::collections::BTreeMap;
use std::path::PathBuf;

use tad_base::Shard;
use tad_db::Database;
use tad_eval::finetune::{self, FinetuneError};
use tad_eval::generator::{self, Generator};
use tad_eval::{Item, Journal, Kept, Plan, Results, Setup, Unit};
use tad_policy::EgoSpec;
use tad_train::Config;

use super::merge::EvalFormat;
use crate::output::CliError;
use crate::{Status, errln, outln, plural};

/// `tadslc eval`'s arguments.
#[derive(clap::Args)]
pub struct EvalArgs {
    /// The corpus the regions and the fitted generators come from (default: the
    /// repository's `examples/`, embedded in tadslc)
    pub corpus: Vec<PathBuf>,
    /// Regions, comma-separated or repeated
    #[arg(long = "region", value_delimiter = ',', value_parser = tad_db::region)]
    pub regions: Vec<String>,
    /// Generators: `chatscene` (ChatScene's eight safety-critical categories with its
    /// parameter ranges), `fitted` (fitted on the region's scenarios), `baseline`
    /// (region-agnostic), `llm`, `llm-baseline`, `llm-tuned` (a language model through
    /// `tadslc gen`'s loop: the aligned prompt, the paper's unaligned region prompt, the
    /// fine-tuned model's prompt with `--adapter`), or a directory of scenarios
    #[arg(long, value_delimiter = ',', default_value = "chatscene,fitted,baseline")]
    pub generators: Vec<String>,
    /// The egos evaluated, comma-separated or repeated: the shipped `ppo`, `sac`, `td3`, `idm`, `naive`, `learned:PATH`,
    /// `external:CMD` (which takes the rest of its list, commas and all)
    #[arg(long, default_value = "ppo,sac,td3,idm,naive", value_parser = crate::EgoNames)]
    pub egos: Vec<String>,
    /// The ego the scenes are searched against (ChatScene's surrogate: the pretrained SAC)
    #[arg(long, default_value = "sac", value_parser = crate::EgoNames)]
    pub search_ego: String,
    /// Scenarios per region and generator (at most 100,000)
    #[arg(short, default_value_t = 10, value_parser = crate::count::<100_000>)]
    pub n: usize,
    /// Scenes sampled per scenario by the search (at most 1,000,000)
    #[arg(long, default_value_t = tad_search::Config::default().samples, value_parser = crate::count::<1_000_000>)]
    pub samples: usize,
    /// Scenes kept per scenario
    #[arg(long, default_value_t = tad_search::Config::default().keep)]
    pub keep: usize,
    /// Requests in flight to the model's server, for the `llm` generators
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    #[arg(long, value_enum, default_value_t = EvalFormat::Markdown)]
    pub format: EvalFormat,
    /// Write the scored episodes to DIR/results.json (DIR/results.I-of-N.json with --shard)
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Draw the OS of each generator and ego as an SVG bar chart
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Evaluate every N-th scenario from I (a job array's index I of N jobs, from 0)
    #[arg(long, value_name = "I/N", default_value = "0/1")]
    pub shard: tad_base::Shard,
    /// Also the "after fine-tuning" table: each learned ego (`ppo`, `sac`, `td3`,
    /// `learned:PATH`) fine-tuned for this many episodes with its algorithm on 3/5 of each
    /// behaviour's kept scenes of each generator (the paper: 500), keeping the actor that
    /// scores best on those scenes every 50 episodes; every ego on the other 2/5
    #[arg(long, value_name = "EPISODES", default_value_t = 0)]
    pub finetune: usize,
    /// Off-policy learning steps per fine-tuning episode (default: the algorithm's; ChatScene's SAC: 1)
    #[arg(long, value_name = "N")]
    pub finetune_updates: Option<usize>,
    /// Where fine-tuning starts: a `train-ego` checkpoint directory (actor, critics, replay),
    /// or an actor alone (a safetensors file, as `learned:PATH` reads)
    #[arg(long, value_name = "FILE")]
    pub finetune_from: Option<PathBuf>,
    /// The model for the `llm` generators (`--seed` seeds every generator and the search)
    #[command(flatten)]
    pub llm: crate::llm::LlmArgs,
}

pub fn run(args: &EvalArgs) -> Result<Status, CliError> {
    let names: Vec<String> = args.egos.iter().flat_map(|list| tad_policy::split_specs(list)).collect();
    let mut egos = Vec::new();
    for spec in names.iter().chain(std::iter::once(&args.search_ego)) {
        egos.push(EgoSpec::parse(spec).map_err(|e| CliError::usage(format!("ego `{spec}`: {e}")))?);
    }
    let surrogate = egos.pop().expect("the search ego was pushed last");
    if args.finetune > 0 && args.shard != Shard::ALL {
        return Err(CliError::usage("--finetune trains on every kept scene: run it without --shard"));
    }
    // raised by files that cannot be read, and by what fails without ending the run
    let (corpus, mut status) = if args.corpus.is_empty() {
        (crate::corpus::counted(tad_eval::examples::corpus("examples", "examples/"))?, Status::Ok)
    } else {
        crate::corpus::load(&args.corpus)?
    };
    // regions: the ones asked for, else every region with at least 3 scenarios
    let by_region = corpus.by_region();
    let regions: Vec<String> = if args.regions.is_empty() {
        by_region.iter().filter(|(_, items)| items.len() >= 3).map(|(r, _)| r.clone()).collect()
    } else {
        args.regions.clone()
    };
    if regions.is_empty() {
        return Err(CliError::usage(format!(
            "corpus `{}` has no region with 3 scenarios or more: name one with --region",
            corpus.name
        )));
    }
    let plan = Plan {
        setup: Setup {
            regions: regions.clone(),
            generators: args.generators.clone(),
            egos: names.clone(),
            search_ego: args.search_ego.clone(),
            n: args.n,
            samples: args.samples,
            keep: args.keep,
            seed: args.llm.seed,
            compat: false,
        },
        egos,
        surrogate,
        shard: args.shard,
    };

    // generate, check and compile, in the units' fixed order
    let mut units: Vec<Unit> = Vec::new();
    let mut db = Database::new(tad_check::Options::default());
    for region in &regions {
        let own: &[&Item] = by_region.get(region).map_or(&[], |v| v.as_slice());
        for name in &args.generators {
            let generator = Generator::parse(name);
            let (texts, read) = scenarios(&mut db, args, &generator, region, own)?;
            status = status.max(read);
            let (mine, notes) = tad_eval::harness::units(&mut db, region, name, texts);
            for note in notes {
                errln!("note: {note}")?;
            }
            units.extend(mine);
        }
    }

    // the journal of a run killed before: its units are not run again
    let (journal, done) = match &args.out {
        Some(dir) => {
            let (journal, done) = Journal::open(dir, &plan.setup, plan.shard)
                .map_err(|e| CliError::usage(format!("cannot write the journal in `{}`: {e}", dir.display())))?;
            (Some(journal), done)
        }
        None => (None, BTreeMap::new()),
    };
    let mine = plan.mine(&units);
    let todo = mine.iter().filter(|(k, _)| !done.contains_key(k)).count();
    if let Some(journal) = &journal
        && todo < mine.len()
    {
        errln!("resumed {} of {} scenarios from `{}`", mine.len() - todo, mine.len(), journal.file().display())?;
    }
    let record = |entry: &tad_eval::Entry| {
        if let Some(journal) = &journal {
            journal.record(entry);
        }
    };
    let progress = crate::output::progress(todo * plan.episodes_per_unit(), "episodes");
    let started = std::time::Instant::now();
    let stop = crate::output::on_interrupt("scenarios");
    let evaluated = plan.evaluate(&units, &done, &record, &|| progress.inc(1), &stop);
    progress.finish_and_clear();
    if let Some(e) = journal.as_ref().and_then(Journal::failure) {
        status = Status::Usage;
        errln!("error: cannot write the journal: {e}")?;
    }
    let results = evaluated.results;
    if evaluated.skipped > 0 {
        return interrupted(args, &results, evaluated.skipped, mine.len(), journal.as_ref());
    }
    if let Some(dir) = &args.out {
        let path = results.write(dir).map_err(|e| {
            CliError::usage(format!("cannot write `{}`: {e}", Results::path(dir, args.shard).display()))
        })?;
        errln!("rows in `{}`", path.display())?;
    }
    errln!(
        "evaluated {} ({} of {}) in {:.1} s on {}",
        plural(mine.len(), "scenario"),
        plural(results.rows.len(), "episode"),
        plural(names.len(), "ego"),
        started.elapsed().as_secs_f64(),
        plural(rayon::current_num_threads(), "thread")
    )?;
    status = status.max(super::merge::print(&[results], args.format, args.plot.as_deref())?);
    if args.finetune > 0 {
        status = status.max(finetune(args, &plan, &evaluated.kept)?);
    }
    Ok(status)
}

/// The scenarios of `generator` for `region`: (name, TAD text), each one that counts, and
/// the status reading them reached (2 when a file could not be read).
fn scenarios(
    db: &mut Database,
    args: &EvalArgs,
    generator: &Generator,
    region: &str,
    own: &[&Item],
) -> Result<(Vec<(String, String)>, Status), CliError> {
    let (n, seed) = (args.n, args.llm.seed);
    let dir = match generator {
        Generator::Fitted if own.is_empty() => {
            errln!("note: region `{region}` has no scenario to fit: no fitted scenarios")?;
            return Ok((Vec::new(), Status::Ok));
        }
        Generator::Fitted => return Ok((generator::fitted(db, own, region, n, seed), Status::Ok)),
        Generator::Baseline => return Ok((generator::baseline(db, region, n, seed), Status::Ok)),
        Generator::ChatScene => return Ok((generator::chatscene(db, region, n, seed), Status::Ok)),
        Generator::Llm(prompt) => {
            // through `tadslc gen`'s loop, into the results directory or a temporary one
            let base = args
                .out
                .clone()
                .unwrap_or_else(|| std::env::temp_dir().join(format!("tadsl-eval-{}", std::process::id())));
            let dir = generator::llm_dir(&base, region, generator);
            std::fs::create_dir_all(&dir)
                .map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
            errln!(
                "{region}: generating {} with the language model ({generator}) into `{}`",
                plural(n, "scenario"),
                dir.display()
            )?;
            let request = super::generate::GenArgs {
                region,
                n,
                out: Some(&dir),
                baseline: *prompt == tad_eval::Prompt::Unaligned,
                tuned: *prompt == tad_eval::Prompt::Tuned,
                corpus: &args.corpus,
                embedded: "examples/",
                jobs: args.jobs,
            };
            // its errors said, as `gen` says them; the status says whether anything came
            let done = crate::output::finish(super::generate::generate(&request, &args.llm));
            if done != Status::Ok {
                let message = format!("{region}: the language model generated nothing usable ({generator})");
                return Err(CliError::Exit(done, message));
            }
            dir
        }
        Generator::Directory(dir) if dir.is_dir() => dir.clone(),
        Generator::Directory(_) => {
            return Err(CliError::usage(format!("generator `{generator}` is not {}", Generator::NAMES)));
        }
    };
    // a corpus holds only the scenarios that count
    let (corpus, read) = crate::corpus::load(std::slice::from_ref(&dir))?;
    Ok((corpus.items.into_iter().map(|i| (i.name, i.tad)).collect(), read))
}

/// The "after fine-tuning" table of `eval --finetune` (`tad_eval::finetune`): every learned
/// ego fine-tuned on each generator's kept scenes, all on the held-out composite set, and
/// each model's change with its interval.
pub fn finetune(args: &EvalArgs, plan: &Plan, kept: &[Kept]) -> Result<Status, CliError> {
    let seed = args.llm.seed;
    let (train, test) = finetune::split(kept, seed);
    if train.is_empty() || test.is_empty() {
        errln!("warning: no fine-tuning: {} kept scenes are too few to hold some out", kept.len())?;
        return Ok(Status::Failed);
    }
    let settings = |algo| {
        let base = Config::finetune(algo);
        Config {
            episodes: args.finetune,
            updates_per_episode: args.finetune_updates.unwrap_or(base.updates_per_episode),
            envs: FINETUNE_ENVS,
            seed,
            ..base
        }
    };
    let tunings = finetune::tunings(plan, args.finetune_from.as_deref(), settings);
    errln!(
        "fine-tuning {} on each generator's kept scenes ({} in all; {} held out), {} each",
        plural(tunings.len() / plan.setup.generators.len().max(1), "learned ego"),
        train.len(),
        test.len(),
        plural(args.finetune, "episode")
    )?;
    let progress = crate::output::progress(args.finetune * tunings.len(), "episodes");
    let mut tuned = Vec::new();
    for tuning in tunings {
        let subset = finetune::of_generator(kept, &train, &tuning.generator);
        if subset.is_empty() {
            progress.inc(args.finetune as u64);
            errln!("warning: `{}` kept no scene to train on: no `{}` row", tuning.generator, tuning.after)?;
            continue;
        }
        let after = tuning.after.clone();
        let from_flag =
            matches!(tuning.start, tad_eval::train::Start::Checkpoint(_) | tad_eval::train::Start::Actor(_));
        let t = finetune::tune(kept, &subset, tuning, || progress.inc(1)).map_err(|e| match e {
            FinetuneError::Start(e) if from_flag => CliError::usage(format!("--finetune-from: {e}")),
            FinetuneError::Start(e) => CliError::failed(format!("cannot start fine-tuning `{after}`: {e}")),
            FinetuneError::Training(e) => CliError::failed(format!("fine-tuning `{after}` stopped: {e}")),
            FinetuneError::Actor(e) => CliError::failed(e),
        })?;
        if t.updates == 0 {
            errln!(
                "warning: `{after}` took no learning step (its episodes stored too few transitions to start \
                 learning): its row is `{}`, the ego as it started",
                t.after_name
            )?;
        } else {
            let start = t
                .start_score
                .map(|s| format!("; OS {:.3}, route {:.3} at the start", s.os, s.route))
                .unwrap_or_default();
            errln!(
                "`{}`: kept the actor of episode {} of {} (OS {:.3}, route {:.3} on the {} it trained on{start})",
                t.after_name,
                t.kept_at,
                args.finetune,
                t.kept_score.os,
                t.kept_score.route,
                plural(subset.len(), "scene")
            )?;
        }
        if let Some(dir) = &args.out {
            let path = dir.join("finetuned").join(format!("{}.safetensors", file_name(&t.after_name)));
            std::fs::create_dir_all(dir.join("finetuned"))
                .and_then(|_| t.after.save(&path).map_err(std::io::Error::other))
                .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
        }
        tuned.push(t);
    }
    progress.finish_and_clear();
    if let Some(dir) = &args.out {
        errln!("the fine-tuned egos in `{}`", dir.join("finetuned").display())?;
    }
    let held_out = finetune::held_out(plan, kept, &test, tuned, seed);
    if args.format == EvalFormat::Markdown {
        outln!()?;
        outln!(
            "After fine-tuning: each learned ego trained on 3/5 of each behaviour's kept scenes of one generator, every ego on the {} held out:",
            test.len()
        )?;
        outln!()?;
    }
    let status = super::merge::print(&[held_out.results], args.format, None)?;
    print_changes(&held_out.changes, args.format)?;
    if let Some(dir) = &args.out {
        let path = dir.join("finetune-changes.json");
        let text = serde_json::to_string_pretty(&held_out.changes).unwrap_or_default() + "\n";
        std::fs::write(&path, text).map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    }
    Ok(status)
}

/// An interrupted evaluation: the table of the scenarios that finished, and how to go on.
/// No results file is written (it would pass for the whole shard's); the journal keeps
/// what finished for a rerun.
fn interrupted(
    args: &EvalArgs,
    results: &Results,
    skipped: usize,
    all: usize,
    journal: Option<&Journal>,
) -> Result<Status, CliError> {
    errln!("interrupted: {} of {} evaluated; the table covers those", all - skipped, plural(all, "scenario"))?;
    super::merge::print(std::slice::from_ref(results), args.format, None)?;
    match journal {
        Some(journal) => errln!(
            "{} kept in `{}`: run the same command again to evaluate the rest",
            plural(all - skipped, "scenario"),
            journal.file().display()
        )?,
        None => errln!("nothing was kept: with --out DIR, a rerun takes up what an interrupted run finished")?,
    }
    Ok(Status::Failed)
}

/// Episodes rolled out at once while fine-tuning (a setting, so results do not depend on
/// the machine).
const FINETUNE_ENVS: usize = 4;

/// A row name as a file name: `ppo (fine-tuned on fitted)` → `ppo-fine-tuned-on-fitted`.
fn file_name(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() || c == '_' {
            out.push(c);
        } else if !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_matches('-').to_string()
}

/// Each model's change: a table after the held-out one (Markdown), else on stderr.
fn print_changes(changes: &[tad_eval::interval::Change], format: EvalFormat) -> Result<(), CliError> {
    if changes.is_empty() {
        return Ok(());
    }
    let rows: Vec<String> = changes
        .iter()
        .map(|c| {
            format!(
                "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {} | {} |",
                c.before,
                c.after,
                c.scenes,
                c.cr_before,
                c.cr_after,
                c.cr_points,
                c.cr_relative,
                c.os_before,
                c.os_after
            )
        })
        .collect();
    let header = "| model | after | scenes | CR before | CR after | ΔCR (pp) | ΔCR (%) | OS before | OS after |";
    if format == EvalFormat::Markdown {
        outln!()?;
        outln!("Change after fine-tuning (95 % paired bootstrap intervals over the held-out scenes):")?;
        outln!()?;
        outln!("{header}")?;
        outln!("|---|---|---|---|---|---|---|---|---|")?;
        for row in rows {
            outln!("{row}")?;
        }
    } else {
        for c in changes {
            errln!(
                "held-out collision rate of {}: {:.3} before, {:.3} after ({}, {:+.1} pp, {:+.0} %)",
                c.before,
                c.cr_before.value,
                c.cr_after.value,
                c.after,
                c.cr_points.value,
                c.cr_relative.value
            )?;
        }
    }
    Ok(())
}
