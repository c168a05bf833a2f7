//! `translate`, `synth`, `gen` and `grammar`: the LLM front-end on the command line.
//!
//! The server comes from flags, the environment (`TADSL_LLM_BASE_URL`, `TADSL_LLM_API_KEY`,
//! `TADSL_LLM_MODEL`, `TADSL_LLM_DIALECT`) and a TOML file (`--llm-config`, else
//! `TADSL_LLM_CONFIG`, else `$XDG_CONFIG_HOME/tadsl/llm.toml`). Exit statuses of
//! `translate` name the class it ended in (`spec/output.md`).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use tad_frontend::backend::{self, Backend, Choice};
use tad_frontend::translate::{self, Translator};
use tad_frontend::{Checker, Limits, Round, Session, Summary, store};
use tad_llm::Constraint;

use crate::output::CliError;
use crate::{Status, errln, out};

/// The flags every LLM subcommand shares.
#[derive(Clone, Debug, clap::Args)]
pub struct LlmArgs {
    /// The server, up to `/v1` (default: TADSL_LLM_BASE_URL)
    #[arg(long, value_name = "URL")]
    pub base_url: Option<String>,
    /// The model name sent to the server (default: TADSL_LLM_MODEL), or `local` (`local:NAME`)
    /// for the model in process, the default when no server is configured
    #[arg(long)]
    pub model: Option<String>,
    /// How the server takes grammars: openai, vllm, vllm-legacy, sglang, llama-cpp
    #[arg(long)]
    pub dialect: Option<String>,
    /// A TOML file with base_url, model, dialect, api_key_env, timeout, ...
    #[arg(long, value_name = "FILE")]
    pub llm_config: Option<PathBuf>,
    /// Constrain decoding to TAD's grammar (GBNF) or, on OpenAI, the YAML form's JSON Schema
    #[arg(long)]
    pub constrain: bool,
    /// Do not constrain the local model's decoding (for comparisons)
    #[arg(long, conflicts_with = "constrain")]
    pub unconstrained: bool,
    /// Repair and refinement requests after the first answer
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub max_rounds: u32,
    /// Tokens per answer
    #[arg(long, value_name = "N", default_value_t = 1024)]
    pub max_tokens: u32,
    /// Tokens (prompt and answers) per item
    #[arg(long, value_name = "N", default_value_t = 60_000)]
    pub token_budget: u64,
    /// Seconds per item
    #[arg(long, value_name = "S", default_value_t = 600)]
    pub deadline: u64,
    /// Seconds per request
    #[arg(long, value_name = "S")]
    pub timeout: Option<f64>,
    /// Retries of a failed request
    #[arg(long, value_name = "N")]
    pub max_retries: Option<u32>,
    /// Sampling temperature
    #[arg(long)]
    pub temperature: Option<f64>,
    /// Threads of the local model
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub threads: usize,
    /// A LoRA adapter for the local model (a PEFT directory, as `tadslc finetune` writes)
    #[arg(long, value_name = "DIR")]
    pub adapter: Option<PathBuf>,
    /// Seed of the requests (and of the client's backoff)
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

impl LlmArgs {
    /// Who answers, as the flags choose (the environment and config file fill the rest).
    fn open(&self, concurrency: usize) -> Result<Backend, String> {
        Choice {
            base_url: self.base_url.clone(),
            model: self.model.clone(),
            dialect: self.dialect.clone(),
            config_file: self.llm_config.clone(),
            timeout: self.timeout,
            max_retries: self.max_retries,
            adapter: self.adapter.clone(),
            threads: self.threads,
            seed: self.seed,
        }
        .open(concurrency)
    }

    fn constrained(&self, backend: &Backend) -> bool {
        backend.constrained(self.constrain, self.unconstrained)
    }

    fn limits(&self) -> Limits {
        Limits {
            max_rounds: self.max_rounds.min(10),
            max_tokens: self.max_tokens.clamp(16, 32_768),
            token_budget: self.token_budget,
            deadline: Duration::from_secs(self.deadline.max(1)),
        }
    }

    /// A session of `backend` checking against `checker`.
    fn session<'a>(
        &self,
        backend: &'a Backend,
        checker: &'a Checker,
        constraint: Constraint,
        temperature: f64,
    ) -> Session<'a> {
        Session {
            client: backend.chat(),
            checker,
            limits: self.limits(),
            constraint,
            temperature: self.temperature.unwrap_or(temperature),
            seed: Some(self.seed),
            on_text: None,
        }
    }
}

fn status_of(outcome: &tad_frontend::Outcome) -> Status {
    match outcome.class {
        Some("complete") => Status::Ok,
        Some("incomplete") => Status::Incomplete,
        Some("non_scenario") => Status::NonScenario,
        _ if outcome.unreachable() => Status::Unreachable,
        _ => Status::Failed,
    }
}

/// The summary on standard error, and in `dir/summary.json` with `extra` beside it.
fn report_summary(dir: Option<&Path>, summary: &Summary, extra: serde_json::Value) -> Result<(), CliError> {
    errln!("{}", summary.render())?;
    match dir {
        Some(dir) => translate::write_summary(dir, summary, extra).map_err(CliError::usage),
        None => Ok(()),
    }
}

/// What `tadslc translate` reads and writes.
#[derive(Clone, Copy)]
pub struct TranslateArgs<'a> {
    pub paths: &'a [PathBuf],
    pub output: Option<&'a Path>,
    pub transcript: Option<&'a Path>,
    pub region: Option<&'a str>,
    /// The model's answers on standard error as they are written.
    pub stream: bool,
}

/// `tadslc translate DESC...`: one description to a file or standard output, or several
/// (or directories of `*.txt`) into the directory `-o DIR` with a manifest and a summary.
pub fn translate(t: &TranslateArgs, args: &LlmArgs) -> Status {
    crate::output::finish(translate_in(t, args))
}

fn translate_in(t: &TranslateArgs, args: &LlmArgs) -> Result<Status, CliError> {
    let TranslateArgs { paths, output, transcript, region, stream } = *t;
    let files = translate::descriptions(paths).map_err(CliError::usage)?;
    let batch = files.len() > 1 || paths.iter().any(|p| p.is_dir());
    if batch && stream {
        return Err(CliError::usage("--stream shows one description's answers; a batch reports in translate.jsonl"));
    }
    let backend = args.open(1).map_err(CliError::usage)?;
    let show = |piece: &str| {
        let _ = crate::output::err(format_args!("{piece}"));
    };
    let checker = backend::checker(region).map_err(CliError::usage)?;
    let constraint = backend.constraint_for(args.constrained(&backend), region).map_err(CliError::usage)?;
    let session = Session {
        on_text: stream.then_some(&show as &tad_llm::OnText),
        ..args.session(&backend, &checker, constraint, 0.0)
    };
    let mut transcript_file = match transcript {
        Some(p) => {
            Some(store::Jsonl::append(p).map_err(|e| CliError::usage(format!("cannot write {}: {e}", p.display())))?)
        }
        None => None,
    };
    let mut write_error = None;
    let mut on_round = |r: &Round| {
        if let Some(t) = transcript_file.as_mut()
            && let Err(e) = t.write(r)
        {
            write_error.get_or_insert(e);
        }
        let _ = errln!(
            "{}{} round {}: {}{}",
            if stream { "\n" } else { "" },
            r.item,
            r.round,
            r.error
                .as_deref()
                .map(|e| format!("error: {e}"))
                .unwrap_or_else(|| r.class.unwrap_or("no program").to_string()),
            if r.diagnostics.is_empty() { String::new() } else { format!(" ({} diagnostics)", r.diagnostics.len()) }
        );
    };
    let runtime = backend::runtime().map_err(CliError::usage)?;
    let tool = format!("tadslc {}", env!("CARGO_PKG_VERSION"));
    let translator = Translator { session: &session, runtime: &runtime, region, tool: &tool };
    if !batch {
        let text = translate::read_description(&files[0]).map_err(CliError::usage)?;
        let (outcome, program) = translator.one(&files[0], &text, &mut on_round);
        match (&program, output) {
            (Some(p), Some(path)) => store::write_atomic(path, p.as_bytes())
                .map_err(|e| CliError::usage(format!("cannot write {}: {e}", path.display())))?,
            (Some(p), None) => out!("{p}")?,
            (None, _) => {}
        }
        for line in &outcome.diagnostics {
            errln!("  {line}")?;
        }
        errln!(
            "{} after {} round{}; {} tokens{}",
            outcome.class.unwrap_or("no program"),
            outcome.rounds,
            if outcome.rounds == 1 { "" } else { "s" },
            outcome.usage.total(),
            outcome.stopped.as_deref().map(|s| format!("; stopped: {s}")).unwrap_or_default()
        )?;
        if let Some(e) = write_error {
            return Err(CliError::usage(format!("cannot write the transcript: {e}")));
        }
        return Ok(status_of(&outcome));
    }
    let dir = output.ok_or_else(|| CliError::usage("several descriptions need an output directory: -o DIR"))?;
    let bar = crate::output::progress(files.len(), "descriptions");
    let (summary, unreachable) = translator
        .batch(&files, dir, &mut on_round, &mut |item| match item {
            Ok(_) => bar.inc(1),
            Err(e) => bar.println(format!("error: {e}")),
        })
        .map_err(CliError::usage)?;
    bar.finish_and_clear();
    if let Some(e) = write_error {
        return Err(CliError::usage(format!("cannot write the transcript: {e}")));
    }
    let constrained = !matches!(session.constraint, Constraint::None);
    report_summary(
        Some(dir),
        &summary,
        serde_json::json!({ "model": backend.chat().label(), "constrained": constrained, "max_rounds": args.max_rounds }),
    )?;
    Ok(if unreachable == files.len() { Status::Unreachable } else { Status::Ok })
}

pub struct GenArgs<'a> {
    pub region: &'a str,
    pub n: usize,
    pub out: Option<&'a Path>,
    pub baseline: bool,
    /// The short prompt of a fine-tuned model (`generate-tuned.v1`).
    pub tuned: bool,
    /// The region's examples come from these files or directories; when there are none,
    /// from the embedded examples whose path starts with `embedded`.
    pub corpus: &'a [PathBuf],
    pub embedded: &'a str,
    pub jobs: usize,
}

/// `tadslc gen`'s arguments.
#[derive(clap::Args)]
pub struct GenCommand {
    /// The region (for `llm`; a fitted model knows its own)
    #[arg(long, value_name = "REGION")]
    pub region: Option<String>,
    /// `llm`, or `fitted:MODEL` (a file written by `tadslc fit`)
    #[arg(long, value_name = "GENERATOR", default_value = "llm")]
    pub generator: String,
    /// How many scenarios
    #[arg(short = 'n', long = "count", value_name = "N", default_value_t = 40)]
    pub count: usize,
    /// Write the scenarios, a manifest and a summary here (default: print them)
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The paper's unaligned baseline: the region's name only, no examples, the general
    /// vocabulary
    #[arg(long, conflicts_with = "tuned")]
    pub baseline: bool,
    /// Ask with the short prompt of `tadslc sft-export` (for a fine-tuned model)
    #[arg(long)]
    pub tuned: bool,
    /// Scenarios of the region to show as examples (default: the repository's
    /// `examples/regions/`, embedded in tadslc)
    #[arg(long, value_name = "PATH")]
    pub corpus: Vec<PathBuf>,
    /// Requests under way at once
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub jobs: usize,
    /// With a fitted generator: draws per scenario before giving up on it
    #[arg(long, value_name = "N", default_value_t = tad_eval::ATTEMPTS)]
    pub attempts: usize,
    #[command(flatten)]
    pub llm: LlmArgs,
}

/// `tadslc gen`: the fitted generator (`--generator fitted:MODEL`) or a language model.
pub fn gen_command(cmd: &GenCommand) -> Status {
    if let Some(model) = cmd.generator.strip_prefix("fitted:") {
        return crate::align::generate_fitted(&crate::align::FittedGen {
            model: Path::new(model),
            n: cmd.count,
            seed: cmd.llm.seed,
            out: cmd.out.as_deref(),
            attempts: cmd.attempts,
        });
    }
    match &cmd.region {
        _ if cmd.generator != "llm" => crate::output::finish(Err(CliError::usage(format!(
            "unknown generator `{}` (expected `llm` or `fitted:MODEL`)",
            cmd.generator
        )))),
        None => crate::output::finish(Err(CliError::usage("`--generator llm` needs `--region REGION`"))),
        Some(region) => generate(
            &GenArgs {
                region,
                n: cmd.count,
                out: cmd.out.as_deref(),
                baseline: cmd.baseline,
                tuned: cmd.tuned,
                corpus: &cmd.corpus,
                embedded: "examples/regions/",
                jobs: cmd.jobs,
            },
            &cmd.llm,
        ),
    }
}

/// `tadslc gen --region R -n N`.
pub fn generate(g: &GenArgs, args: &LlmArgs) -> Status {
    crate::output::finish(generate_in(g, args))
}

fn generate_in(g: &GenArgs, args: &LlmArgs) -> Result<Status, CliError> {
    let (general, modules) = tad_grammar::scope(None).map_err(CliError::usage)?;
    let (regional, region_modules) = tad_grammar::scope(Some(g.region)).map_err(CliError::usage)?;
    let backend = args.open(g.jobs.max(1)).map_err(CliError::usage)?;
    let checker = backend::checker(Some(g.region)).map_err(CliError::usage)?;
    let (vocabulary, scope_modules) = if g.baseline { (&general, &modules) } else { (&regional, &region_modules) };
    let constraint =
        if args.constrained(&backend) { backend.constraint(vocabulary, scope_modules) } else { Constraint::None };
    let session = args.session(&backend, &checker, constraint, 0.8);
    let spec = tad_frontend::generate::Spec {
        region: g.region,
        n: g.n,
        seed: args.seed,
        baseline: g.baseline,
        tuned: g.tuned,
        vocabulary,
        region_description: tad_frontend::description(&general, "region", g.region),
        examples: region_examples(g.corpus, g.embedded, g.region)?,
        jobs: g.jobs,
        model: backend.chat().label(),
    };
    let bar = crate::output::progress(g.n, "scenarios");
    let mut summary = Summary::default();
    let mut transcript = match g.out {
        Some(dir) => Some(store::Jsonl::append(&dir.join("gen.transcript.jsonl")).map_err(CliError::usage)?),
        None => None,
    };
    let mut printed = Ok(());
    let records = backend::runtime()
        .map_err(CliError::usage)?
        .block_on(tad_frontend::generate::run(
            &session,
            &spec,
            g.out,
            &mut |record, program| {
                summary.add(&record.outcome);
                bar.inc(1);
                bar.set_message(record.outcome.class.unwrap_or("no program").to_string());
                if g.out.is_none()
                    && let Some(p) = program
                {
                    printed = printed.and(out!("{p}\n"));
                }
            },
            &mut |r| {
                if let Some(t) = transcript.as_mut() {
                    let _ = t.write(r);
                }
            },
        ))
        .map_err(|e| CliError::usage(format!("cannot write the scenarios: {e}")))?;
    bar.finish_and_clear();
    printed?;
    let mode = if g.baseline { "baseline" } else { "aligned" };
    report_summary(
        g.out,
        &summary,
        serde_json::json!({ "region": g.region, "mode": mode, "model": backend.chat().label() }),
    )?;
    let unreachable =
        !records.is_empty() && records.iter().all(|r| r.outcome.program.is_none() && r.outcome.stopped.is_some());
    Ok(if unreachable { Status::Unreachable } else { Status::Ok })
}

/// The scenarios of `corpus` (files or directories; the embedded examples under `embedded`
/// when empty) that name `region` and count, for the prompt; a path that cannot be read is
/// an error.
fn region_examples(corpus: &[PathBuf], embedded: &str, region: &str) -> Result<Vec<String>, CliError> {
    let corpus = if corpus.is_empty() {
        tad_eval::examples::corpus("examples", embedded)
    } else {
        let (corpus, errors) = tad_eval::corpus::read(corpus);
        if let Some(e) = errors.first() {
            return Err(CliError::usage(e));
        }
        corpus
    };
    Ok(corpus
        .items
        .iter()
        .filter(|item| item.region.as_deref() == Some(region))
        .map(|item| tad_frontend::with_provenance(&item.tad, &tad_frontend::Provenance::default()))
        .collect())
}

pub struct SynthArgs<'a> {
    pub video: Option<&'a Path>,
    pub frames: Option<&'a Path>,
    pub region: &'a str,
    pub out: &'a Path,
    pub every: f64,
    pub shard: tad_base::Shard,
    pub jobs: usize,
    pub max_refinements: u32,
}

/// `tadslc synth`.
pub fn synth(s: &SynthArgs, args: &LlmArgs) -> Status {
    crate::output::finish(synth_in(s, args))
}

fn synth_in(s: &SynthArgs, args: &LlmArgs) -> Result<Status, CliError> {
    let input = match (s.video, s.frames) {
        (Some(v), None) => tad_frontend::synth::Input::Video(v.to_path_buf()),
        (None, Some(d)) => tad_frontend::synth::Input::Frames(d.to_path_buf()),
        _ => return Err(CliError::usage("give either --video FILE or --frames DIR")),
    };
    let backend = args.open(s.jobs.max(1)).map_err(CliError::usage)?;
    let checker = backend::checker(Some(s.region)).map_err(CliError::usage)?;
    let constraint = backend.constraint_for(args.constrained(&backend), Some(s.region)).map_err(CliError::usage)?;
    let session = args.session(&backend, &checker, constraint, 0.0);
    let spec = tad_frontend::synth::Spec {
        input,
        region: s.region.to_string(),
        out: s.out.to_path_buf(),
        every: s.every,
        shard: s.shard,
        jobs: s.jobs,
        max_refinements: s.max_refinements,
        model: backend.chat().label(),
        ffmpeg: std::env::var("TADSL_FFMPEG").unwrap_or_else(|_| "ffmpeg".into()),
        ffprobe: std::env::var("TADSL_FFPROBE").unwrap_or_else(|_| "ffprobe".into()),
    };
    std::fs::create_dir_all(s.out).map_err(|e| CliError::usage(format!("cannot create {}: {e}", s.out.display())))?;
    let stop = Arc::new(AtomicBool::new(false));
    let runtime = backend::runtime().map_err(CliError::usage)?;
    {
        let stop = stop.clone();
        runtime.spawn(async move {
            if tokio::signal::ctrl_c().await.is_ok() {
                stop.store(true, Ordering::SeqCst);
                let _ = errln!("\ninterrupted: finishing the frames under way (Ctrl-C again to abort)");
                if tokio::signal::ctrl_c().await.is_ok() {
                    std::process::exit(130);
                }
            }
        });
    }
    let bar = crate::output::progress(0, "frames");
    let mut summary = Summary::default();
    let mut failed = 0usize;
    let report = runtime
        .block_on(tad_frontend::synth::run(
            &session,
            &spec,
            &stop,
            &mut |record| {
                if record.status == "failed" {
                    failed += 1;
                    bar.println(format!("{}: {}", record.frame, record.reasons.join("; ")));
                } else {
                    summary.add(&record.outcome);
                }
                if bar.length() == Some(0) {
                    bar.set_length(1);
                }
                bar.inc(1);
                bar.set_message(record.status.to_string());
            },
            &mut |_| {},
        ))
        .map_err(|e| CliError::usage(e.0))?;
    bar.finish_and_clear();
    errln!(
        "{} in this shard: {} done before, {} now, {} failed (rerun to retry)",
        crate::plural(report.total, "frame"),
        report.done_before,
        report.records.len() - failed,
        failed
    )?;
    report_summary(
        Some(s.out),
        &summary,
        serde_json::json!({ "region": s.region, "model": backend.chat().label(), "shard": s.shard.to_string() }),
    )?;
    if report.interrupted {
        errln!("interrupted: run the same command again to continue")?;
        return Ok(Status::Failed);
    }
    Ok(if failed > 0 && failed == report.records.len() { Status::Unreachable } else { Status::Ok })
}

/// `tadslc grammar`.
pub fn grammar(format: tad_grammar::Format, region: Option<&str>) -> Status {
    crate::output::finish(grammar_in(format, region))
}

fn grammar_in(format: tad_grammar::Format, region: Option<&str>) -> Result<Status, CliError> {
    let (vocabulary, modules) = tad_grammar::scope(region).map_err(CliError::usage)?;
    let header = format!(
        "TAD {} grammar from tadslc {} ({}); regenerate with `tadslc grammar --format {}{}`",
        format.name(),
        env!("CARGO_PKG_VERSION"),
        region.map(|r| format!("region {r}")).unwrap_or_else(|| "every standard module".into()),
        format.name(),
        region.map(|r| format!(" --region {r}")).unwrap_or_default()
    );
    out!("{}", tad_grammar::export(format, &vocabulary, &modules, &header))?;
    Ok(Status::Ok)
}

/// `tadslc model list`.
pub fn model_list() -> Status {
    crate::output::finish(model_list_in())
}

fn model_list_in() -> Result<Status, CliError> {
    out!("cache: {}\n", tad_local::cache_dir().display())?;
    for m in tad_local::MODELS {
        let state = match m.installed() {
            Some(p) => format!("installed ({})", p.display()),
            None => format!("not installed (tadslc model fetch {})", m.aliases.first().unwrap_or(&m.name)),
        };
        let default = if m.name == tad_local::DEFAULT { " [default]" } else { "" };
        let aliases = if m.aliases.is_empty() { String::new() } else { format!(" (alias {})", m.aliases.join(", ")) };
        out!(
            "{}{default}{aliases}, {}: {}; {} MB from {}; {state}\n",
            m.name,
            m.kind.label(),
            m.description,
            m.bytes() / 1_000_000,
            m.packages()
        )?;
    }
    Ok(Status::Ok)
}

/// `tadslc model fetch [NAME]`.
pub fn model_fetch(name: Option<&str>, python: Option<&str>) -> Status {
    crate::output::finish(model_fetch_in(name, python))
}

fn model_fetch_in(name: Option<&str>, python: Option<&str>) -> Result<Status, CliError> {
    let name = name.unwrap_or(tad_local::DEFAULT);
    let model = tad_local::model(name)
        .ok_or_else(|| CliError::usage(format!("unknown local model `{name}` (tadslc model list)")))?;
    let python =
        python.map(String::from).or_else(|| std::env::var("TADSL_PYTHON").ok()).unwrap_or_else(|| "python3".into());
    let path = model
        .fetch(&python, &mut |line| {
            let _ = errln!("{line}");
        })
        .map_err(CliError::usage)?;
    out!("{}\n", path.display())?;
    Ok(Status::Ok)
}
