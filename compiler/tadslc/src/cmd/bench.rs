//! `tadslc bench`: the experiments of `tad-bench`, their reports printed.
//!
//! Check throughput against serde_json by default; `--runtime`, `--lsp`, `--llm`, `--translate` and
//! `--align` choose another experiment. A report's lines go to standard output, its notes
//! and an experiment's progress to standard error; its outcome is the exit status.

use std::path::PathBuf;

use crate::Status;
use crate::cmd::compare::{Embedding, embed};
use crate::output::CliError;
use tad_bench::{BenchError, Outcome, Report};
use tad_eval::recovery::Extra;

/// `tadslc bench`'s arguments: check throughput, or one of the other experiments.
#[derive(clap::Args)]
pub struct Args {
    /// Number of generated scenarios
    #[arg(long, default_value_t = 10_000, conflicts_with_all = ["runtime", "lsp", "llm", "align", "translate"])]
    pub scenarios: usize,
    /// Seed of the corpus generator (and of the alignment experiment, and of the
    /// translation benchmark's bootstrap)
    #[arg(long, default_value_t = 1, conflicts_with_all = ["runtime", "lsp", "llm"])]
    pub seed: u64,
    /// Directory of real scenarios to measure as well
    #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm"])]
    pub examples: Option<PathBuf>,
    /// Timed repetitions of each measurement (the best is reported)
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Measure the runtime instead: episode time with 1, 14 and 50 actors, Scenic's
    /// Newtonian simulator on the same scenarios, and a parameter search's episodes per
    /// second
    #[arg(long, conflicts_with_all = ["lsp", "llm"])]
    pub runtime: bool,
    /// Measure the language server instead: didChange → diagnostics, completion and
    /// hover latency on a 2,000-line file, and its memory with every example open
    #[arg(long, conflicts_with = "llm")]
    pub lsp: bool,
    /// Measure the local model instead: prefill and decode tokens/s, unconstrained and
    /// constrained, and peak memory, against llama.cpp's llama-server on the same GGUF
    /// and thread count
    #[arg(long)]
    pub llm: bool,
    /// The llama-server binary for the peer (default: TADSL_LLAMA_SERVER); without one
    /// the peer is skipped
    #[arg(long, value_name = "PATH", requires = "llm")]
    pub llama_server: Option<PathBuf>,
    /// Threads of both models (`--llm`), of the model (`--translate`)
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub threads: usize,
    /// Translate prompts measured (the first N descriptions)
    #[arg(long, value_name = "N", default_value_t = 4, requires = "llm")]
    pub prompts: usize,
    /// Tokens per answer
    #[arg(long, value_name = "N", default_value_t = 256, requires = "llm")]
    pub max_tokens: u32,
    /// The descriptions the prompts are made of (`--llm`), or that are translated
    /// (`--translate`)
    #[arg(long, value_name = "DIR", default_value = "tests/llm/descriptions")]
    pub descriptions: PathBuf,
    /// Measure a model's faithfulness instead: each description translated (the compiler
    /// in the loop, as `translate` does) and scored attribute by attribute against its
    /// hand-written ground truth
    #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm", "align", "rl"])]
    pub translate: bool,
    /// The ground truth of each description (`NAME.tad` for `NAME.txt`)
    #[arg(long, value_name = "DIR", default_value = "tests/llm/truth", requires = "translate")]
    pub truth: PathBuf,
    /// The model that translates, as `translate --model` takes it (default: as `translate`
    /// chooses: the environment, else the embedded local model); `local:NAME` for another
    /// of `tadslc model list`. With `--llm`, the local model measured (`NAME` or
    /// `local:NAME`; default: the embedded one)
    #[arg(long)]
    pub model: Option<String>,
    /// Repair and refinement requests after the first answer
    #[arg(long, value_name = "N", default_value_t = 3, requires = "translate")]
    pub max_rounds: u32,
    /// A LoRA adapter for the local model that translates, as `translate --adapter` takes
    /// it (a PEFT directory, as `tadslc finetune` writes)
    #[arg(long, value_name = "DIR", requires = "translate", conflicts_with = "answers")]
    pub adapter: Option<PathBuf>,
    /// Score the translations already in DIR (`NAME.tad`, and `faithfulness.jsonl` for the
    /// rounds, tokens and seconds, as `--out` writes them) instead of running a model: a
    /// server's, or an interrupted run's
    #[arg(long, value_name = "DIR", requires = "translate", conflicts_with_all = ["model", "out"])]
    pub answers: Option<PathBuf>,
    /// Also score the translations kept in DIR (as `--answers` reads them) on the same
    /// descriptions, and print how many points this run is above them, with a paired
    /// bootstrap interval
    #[arg(long, value_name = "DIR", requires = "translate")]
    pub against: Option<PathBuf>,
    #[command(flatten)]
    pub shots: crate::cmd::translate::ShotArgs,
    /// Samples of each language server measurement
    #[arg(long, value_name = "N", default_value_t = 200, requires = "lsp")]
    pub samples: usize,
    /// The Python with Scenic 3.1.1 for the Scenic peer (default: TADSL_SCENIC_PYTHON);
    /// without one the peer is skipped
    #[arg(long, value_name = "PATH", requires = "runtime")]
    pub scenic_python: Option<PathBuf>,
    /// Skip the Scenic peer
    #[arg(long, requires = "runtime", conflicts_with = "scenic_python")]
    pub no_scenic: bool,
    /// Episodes of the parameter search (the safety examples round robin)
    #[arg(long, value_name = "N", default_value_t = 20_000, requires = "runtime")]
    pub episodes: usize,
    /// Steps per episode (fewer for tests)
    #[arg(long, default_value_t = 300, requires = "runtime", hide = true)]
    pub steps: u32,
    /// Measure reinforcement learning instead: environment steps and gradient updates per
    /// second for PPO, SAC and TD3, against Stable-Baselines3 with the same networks,
    /// batches and threads
    #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm", "align"])]
    pub rl: bool,
    /// The Python with stable-baselines3 and torch for `--rl`'s peer (default `python3`)
    #[arg(long, value_name = "PATH", requires = "rl")]
    pub python: Option<PathBuf>,
    /// Skip the Stable-Baselines3 peer
    #[arg(long, requires = "rl", conflicts_with = "python")]
    pub no_sb3: bool,
    /// Learning steps timed per measurement (`--rl`)
    #[arg(long, value_name = "N", default_value_t = 200, requires = "rl")]
    pub updates: usize,
    /// Exploring episodes timed per measurement (`--rl`)
    #[arg(long = "rl-episodes", value_name = "N", default_value_t = 32, requires = "rl")]
    pub rl_episodes: usize,
    /// Thread counts measured (`--rl`)
    #[arg(long = "rl-threads", value_name = "N,...", value_delimiter = ',', default_value = "1,2", requires = "rl")]
    pub rl_threads: Vec<usize>,
    /// Run the alignment recovery experiment instead: labelled synthetic regions, the
    /// fitted generator against the unaligned baseline on held-out samples
    #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm"])]
    pub align: bool,
    /// Scenarios per sample (training, held-out, generated)
    #[arg(long, value_name = "N", default_value_t = 100, requires = "align")]
    pub per_region: usize,
    /// The embedding of the MMD and Fréchet columns
    #[arg(long, value_enum, default_value_t = Embedding::Features, requires = "align")]
    pub embedding: Embedding,
    /// Bootstrap resamples
    #[arg(long, value_name = "N", default_value_t = 200, requires = "align")]
    pub resamples: usize,
    /// Where the corpora are written (`--align`; default: a directory under the system's
    /// temporary one), or the answers (`--translate`: `NAME.tad` and `faithfulness.jsonl`)
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Another generator's output to compare with a region's held-out sample
    #[arg(long = "corpus", value_name = "LABEL=REGION:DIR", value_parser = tad_bench::align::parse_extra, requires = "align")]
    pub extra: Vec<(String, String, PathBuf)>,
    /// Print the rows as JSON
    #[arg(long, requires = "align")]
    pub json: bool,
    /// Check and format hostile files (a run of one bad character, deep nesting, 100k
    /// fields, ...) against a clean file of the same size: time and peak memory
    #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm", "align", "translate", "rl"])]
    pub hostile: bool,
    /// Bytes per file
    #[arg(long, value_name = "BYTES", default_value_t = 1_000_000, requires = "hostile")]
    pub size: usize,
    /// Measure one shape in this process and print it as JSON (what each child does)
    #[arg(long, value_name = "I", requires = "hostile", hide = true)]
    pub shape: Option<usize>,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    if args.align {
        return align(args);
    }
    if args.translate {
        return translate(args);
    }
    if args.hostile {
        if let Some(shape) = args.shape {
            let line = tad_bench::hostile::one(shape, args.size, args.runs)
                .map_err(|e| CliError::usage(format!("bench --hostile: {e}")))?;
            crate::outln!("{line}")?;
            return Ok(Status::Ok);
        }
        return streamed("bench --hostile: ", |progress| {
            tad_bench::hostile::run(&std::env::current_exe()?, args.size, args.runs, progress)
        });
    }
    if args.lsp {
        return streamed("bench --lsp: ", |progress| {
            let exe = std::env::current_exe()?;
            tad_bench::lsp::run(&exe, args.samples, args.runs, progress)
        });
    }
    if args.llm {
        let llm = tad_bench::llm::LlmArgs {
            llama_server: args.llama_server.clone(),
            threads: args.threads,
            prompts: args.prompts,
            max_tokens: args.max_tokens,
            descriptions: args.descriptions.clone(),
            model: args.model.as_deref().map(|m| m.strip_prefix("local:").unwrap_or(m).to_string()),
        };
        return streamed("bench --llm: ", |progress| tad_bench::llm::run(&llm, progress));
    }
    if args.rl {
        let rl = tad_bench::rl::RlArgs {
            python: (!args.no_sb3).then(|| args.python.clone().unwrap_or_else(|| "python3".into())),
            updates: args.updates,
            episodes: args.rl_episodes,
            threads: args.rl_threads.clone(),
        };
        return streamed("bench --rl: ", |progress| tad_bench::rl::run(&rl, progress));
    }
    if args.runtime {
        let runtime = tad_bench::runtime::RuntimeArgs {
            runs: args.runs,
            episodes: args.episodes,
            steps: args.steps,
            scenic_python: args.scenic_python.clone(),
            no_scenic: args.no_scenic,
        };
        return streamed("", |progress| tad_bench::runtime::run(&runtime, progress));
    }
    print(Ok(tad_bench::run(args.scenarios, args.seed, args.examples.as_deref(), args.runs)), "")
}

/// `experiment` run with its progress streamed to standard error, then its report printed.
fn streamed(
    context: &str,
    experiment: impl FnOnce(&mut dyn FnMut(&str)) -> Result<Report, BenchError>,
) -> Result<Status, CliError> {
    // the first failed write to standard error, for the status
    let mut closed = None;
    let report = experiment(&mut |line| {
        if closed.is_none() {
            closed = crate::errln!("{line}").err();
        }
    });
    match closed {
        Some(closed) => Err(closed.into()),
        None => print(report, context),
    }
}

/// `report` printed (an error as `error: {context}{error}`, status 2), its status.
fn print(report: Result<Report, BenchError>, context: &str) -> Result<Status, CliError> {
    let report = report.map_err(|e| CliError::usage(format!("{context}{e}")))?;
    report.lines.iter().try_for_each(|line| crate::outln!("{line}"))?;
    report.notes.iter().try_for_each(|note| crate::errln!("{note}"))?;
    Ok(match report.outcome {
        Outcome::Complete => Status::Ok,
        Outcome::InputErrors => Status::Failed,
        Outcome::Unusable => Status::Usage,
    })
}

/// `bench --translate`: the session `translate` would build, each case through it, scored.
fn translate(args: &Args) -> Result<Status, CliError> {
    use tad_bench::translate::{Answer, Case};
    use tad_frontend::{backend, store, translate::Translator};

    /// The LLM flags parsed as `translate` parses them, so their defaults live there; every
    /// model is constrained, a server as `translate --constrain` asks it.
    #[derive(clap::Parser)]
    struct Flags {
        #[command(flatten)]
        llm: crate::llm::LlmArgs,
    }
    let mut argv = vec!["bench".to_string(), "--constrain".into(), "--threads".into(), args.threads.to_string()];
    argv.extend(["--max-rounds".into(), args.max_rounds.to_string()]);
    argv.extend(args.model.iter().flat_map(|m| ["--model".to_string(), m.clone()]));
    argv.extend(args.adapter.iter().flat_map(|a| ["--adapter".to_string(), a.display().to_string()]));
    let llm = <Flags as clap::Parser>::try_parse_from(argv).map_err(|e| CliError::usage(e.to_string()))?.llm;

    let cases = tad_bench::translate::cases(&args.descriptions, &args.truth).map_err(|e| CliError::usage(e.0))?;
    if let Some(dir) = &args.answers {
        return answered(args, &cases, dir);
    }
    let backend = llm.open(1).map_err(CliError::usage)?;
    let checker = backend::checker(None).map_err(CliError::usage)?;
    let constraint = backend.constraint_for(llm.constrained(&backend), None).map_err(CliError::usage)?;
    let session = llm.session(&backend, &checker, constraint, 0.0);
    let runtime = backend::runtime().map_err(CliError::usage)?;
    let tool = format!("tadslc {}", env!("CARGO_PKG_VERSION"));
    let pool = args.shots.load()?;
    let shots = pool.as_ref().map(|p| (p, args.shots.shots));
    let translator = Translator { session: &session, runtime: &runtime, region: None, tool: &tool, shots };
    let mut manifest = match &args.out {
        Some(dir) => Some(
            store::Jsonl::append(&dir.join("faithfulness.jsonl"))
                .map_err(|e| CliError::usage(format!("cannot write in `{}`: {e}", dir.display())))?,
        ),
        None => None,
    };
    let label = backend.chat().label();
    streamed("bench --translate: ", |progress| {
        progress(&format!("bench --translate: {} descriptions, model {label}", cases.len()));
        let mut write_error = None;
        let mut one = |case: &Case, text: &str| {
            let start = std::time::Instant::now();
            let (outcome, program) = translator.one(&case.description, text, &mut |_| {});
            if let (Some(dir), Some(program)) = (&args.out, &program) {
                let written = store::write_atomic(&store::inside(dir, &case.name, "tad"), program.as_bytes());
                write_error = write_error.take().or(written.err().map(|e| e.to_string()));
            }
            let seconds = start.elapsed().as_secs_f64();
            if let Some(m) = manifest.as_mut() {
                let record = serde_json::json!({ "case": case.name, "outcome": outcome, "seconds": seconds });
                write_error = write_error.take().or(m.write(&record).err().map(|e| e.to_string()));
            }
            Answer {
                program: outcome.program,
                valid_round: outcome.valid_round,
                suggested: outcome.suggested.len(),
                rounds: outcome.rounds,
                tokens: outcome.usage.total(),
                seconds,
            }
        };
        let scored = tad_bench::translate::run(&cases, &mut one, progress)?;
        match write_error {
            Some(e) => Err(BenchError(format!("cannot write the answers: {e}"))),
            None => {
                let mut report = tad_bench::translate::report(&label, &scored, true, args.seed);
                against(args, &cases, &scored, &mut report)?;
                Ok(report)
            }
        }
    })
}

/// `bench --translate --answers DIR`: the answers `--out DIR` kept, scored.
fn answered(args: &Args, cases: &[tad_bench::translate::Case], dir: &std::path::Path) -> Result<Status, CliError> {
    let (cases, recorded, mut one) = kept(cases, dir);
    let label = format!("the answers in `{}`", dir.display());
    streamed("bench --translate: ", |progress| {
        let scored = tad_bench::translate::run(&cases, &mut one, progress)?;
        let mut report = tad_bench::translate::report(&label, &scored, recorded, args.seed);
        against(args, &cases, &scored, &mut report)?;
        Ok(report)
    })
}

/// The answers `--out DIR` kept in `dir`: the `cases` its manifest records (an interrupted
/// run's; all of them without one), whether it has one, and the answers as the benchmark's
/// callback, with the rounds, tokens and seconds the manifest holds; a case without a file
/// has no program.
fn kept(
    cases: &[tad_bench::translate::Case],
    dir: &std::path::Path,
) -> (
    Vec<tad_bench::translate::Case>,
    bool,
    impl FnMut(&tad_bench::translate::Case, &str) -> tad_bench::translate::Answer,
) {
    use tad_bench::translate::{Answer, Case};
    use tad_frontend::store;
    let mut records = std::collections::HashMap::new();
    if let Ok(text) = std::fs::read_to_string(dir.join("faithfulness.jsonl")) {
        for record in text.lines().filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok()) {
            if let Some(case) = record["case"].as_str().map(String::from) {
                records.insert(case, record);
            }
        }
    }
    let cases = cases.iter().filter(|c| records.is_empty() || records.contains_key(&c.name)).cloned().collect();
    let recorded = !records.is_empty();
    let dir = dir.to_path_buf();
    let one = move |case: &Case, _: &str| {
        let record = records.get(&case.name);
        let outcome = |key: &str| record.map(|r| r["outcome"][key].clone()).unwrap_or_default();
        let usage: tad_llm::Usage = serde_json::from_value(outcome("usage")).unwrap_or_default();
        Answer {
            program: std::fs::read_to_string(store::inside(&dir, &case.name, "tad")).ok(),
            valid_round: outcome("valid_round").as_u64().map(|r| r as u32),
            suggested: outcome("suggested").as_array().map_or(0, Vec::len),
            rounds: outcome("rounds").as_u64().unwrap_or(0) as u32,
            tokens: usage.total(),
            seconds: record.and_then(|r| r["seconds"].as_f64()).unwrap_or(0.0),
        }
    };
    (cases, recorded, one)
}

/// With `--against DIR`: the answers kept there scored on the cases both runs have, and how
/// many points this run is above them, paired by description.
fn against(
    args: &Args,
    cases: &[tad_bench::translate::Case],
    scored: &[tad_bench::translate::Scored],
    report: &mut tad_bench::Report,
) -> Result<(), BenchError> {
    let Some(dir) = &args.against else { return Ok(()) };
    let (cases, _, mut one) = kept(cases, dir);
    let theirs = tad_bench::translate::run(&cases, &mut one, &mut |_| {})?;
    let line = match tad_bench::translate::difference(&theirs, scored, args.seed) {
        Some(paired) => format!(
            "against the answers in `{}` ({:.1} %): {:+.1} points [{:+.1}, {:+.1}] on the {} descriptions both scored",
            dir.display(),
            paired.before,
            paired.points.value,
            paired.points.low,
            paired.points.high,
            paired.cases
        ),
        None => format!("against the answers in `{}`: no description both scored", dir.display()),
    };
    report.lines.push(line);
    Ok(())
}

/// `bench --align`: the extra corpora read and the sentences embedded as `compare` does.
fn align(args: &Args) -> Result<Status, CliError> {
    let out = args.out.clone().unwrap_or_else(|| std::env::temp_dir().join("tadsl-bench-align"));
    let corpora = tad_bench::align::corpora(args.per_region, args.seed, &out).map_err(CliError::usage)?;
    // an extra corpus that cannot be read or has no valid scenario is said (status 2);
    // the experiment goes on without it
    let mut status = Status::Ok;
    let mut extra = Vec::new();
    for (label, region, dir) in &args.extra {
        let (corpus, read) = crate::corpus::read(std::slice::from_ref(dir))?;
        status = status.max(read);
        let features = match crate::corpus::counted(corpus) {
            Ok(corpus) => corpus.items.into_iter().map(|i| i.features).collect(),
            Err(CliError::Exit(failed, why)) => {
                status = status.max(failed);
                crate::errln!("error: {why}")?;
                Vec::new()
            }
            Err(closed) => return Err(closed),
        };
        extra.push(Extra { label: label.clone(), region: region.clone(), features });
    }
    let embed = |a: &[tad_stats::Features], b: &[tad_stats::Features]| embed(args.embedding, a, b);
    let report = tad_bench::align::report(&corpora, &extra, &embed, args.resamples, args.seed, args.json);
    Ok(print(report, "")?.max(status))
}
