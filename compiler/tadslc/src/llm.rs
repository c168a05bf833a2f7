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

use tad_check::Options;
use tad_frontend::{Checker, Limits, Round, Session, Summary, store};
use tad_llm::{Chat, Client, Config, Constraint, Overrides};

use crate::Status;
use crate::{errln, out};

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

fn config_file(explicit: Option<&Path>) -> Result<Option<(String, String)>, String> {
    let path = match explicit {
        Some(p) => Some(p.to_path_buf()),
        None => std::env::var_os("TADSL_LLM_CONFIG").map(PathBuf::from).or_else(|| {
            let base = std::env::var_os("XDG_CONFIG_HOME")
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
            Some(base.join("tadsl/llm.toml")).filter(|p| p.exists())
        }),
    };
    let Some(path) = path else { return Ok(None) };
    let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(Some((path.display().to_string(), text)))
}

impl LlmArgs {
    /// The server the flags, environment and file name, or the local model when they name
    /// none (or `--model local`).
    fn client(&self, concurrency: usize) -> Result<Backend, String> {
        if let Some(name) = self.model.as_deref().and_then(|m| m.strip_prefix("local")) {
            let name = name.strip_prefix(':').filter(|n| !n.is_empty()).unwrap_or(tad_local::DEFAULT);
            return self.local(name, None);
        }
        let file = config_file(self.llm_config.as_deref())?;
        let cli = Overrides {
            base_url: self.base_url.clone(),
            model: self.model.clone(),
            dialect: self.dialect.clone(),
            timeout: self.timeout,
            max_retries: self.max_retries,
            concurrency: Some(concurrency),
        };
        let env = |k: &str| std::env::var(k).ok();
        let config = Config::resolve(&cli, &env, file.as_ref().map(|(n, t)| (n.as_str(), t.as_str())), self.seed)
            .map_err(|e| e.to_string())?;
        match config {
            Some(_) if self.adapter.is_some() => {
                Err("--adapter applies to the local model only, and a server is configured (pass --model local)".into())
            }
            Some(config) => Ok(Backend::Server(Client::new(config).map_err(|e| e.to_string())?)),
            None => self.local(
                tad_local::DEFAULT,
                Some(" (no server is configured: set TADSL_LLM_BASE_URL, e.g. http://127.0.0.1:8080/v1, or pass --base-url to use one)"),
            ),
        }
    }

    fn local(&self, name: &str, why: Option<&str>) -> Result<Backend, String> {
        let model = tad_local::model(name).ok_or_else(|| {
            let names: Vec<&str> = tad_local::MODELS.iter().map(|m| m.name).collect();
            format!("unknown local model `{name}` (the local models are: {})", names.join(", "))
        })?;
        let adapter = self.adapter.as_deref().map(tad_local::Adapter::load).transpose()?;
        let chat = tad_local::LocalChat::load_with(model, self.threads, adapter.as_ref())
            .map_err(|e| format!("{e}{}", why.unwrap_or("")))?;
        Ok(Backend::Local(chat))
    }

    /// Whether to constrain: `--constrain`, and always for the local model (its decoder
    /// follows the grammar in process) unless `--unconstrained`.
    fn constrained(&self, client: &Backend) -> bool {
        !self.unconstrained && (self.constrain || matches!(client, Backend::Local(_)))
    }

    fn limits(&self) -> Limits {
        Limits {
            max_rounds: self.max_rounds.min(10),
            max_tokens: self.max_tokens.clamp(16, 32_768),
            token_budget: self.token_budget,
            deadline: Duration::from_secs(self.deadline.max(1)),
        }
    }

    fn constraint(&self, client: &Backend, region: Option<&str>) -> Result<Constraint, String> {
        if !self.constrained(client) {
            return Ok(Constraint::None);
        }
        let (vocabulary, modules) = tad_grammar::scope(region)?;
        Ok(client.constraint(&vocabulary, &modules))
    }
}

fn runtime() -> Result<tokio::runtime::Runtime, String> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the async runtime: {e}"))
}

fn checker(region: Option<&str>) -> Result<Checker, String> {
    if let Some(r) = region {
        tad_grammar::scope(Some(r))?;
    }
    Ok(Checker { options: Options { region: region.map(String::from), ..Options::default() } })
}

fn model_label(client: &dyn Chat) -> String {
    client.label()
}

/// Who answers: a server, or the model in process.
pub enum Backend {
    Server(Client),
    Local(tad_local::LocalChat),
}

impl Backend {
    fn chat(&self) -> &dyn Chat {
        match self {
            Backend::Server(c) => c,
            Backend::Local(l) => l,
        }
    }

    /// What `--constrain` sends: the server dialect's choice, or the Lark grammar that the
    /// local model's decoder follows in process.
    fn constraint(&self, vocabulary: &tad_check::Vocabulary, modules: &[String]) -> Constraint {
        match self {
            Backend::Server(c) => tad_frontend::constraint(c.config().dialect, vocabulary, modules),
            Backend::Local(_) => {
                Constraint::Lark(tad_grammar::export(tad_grammar::Format::Lark, vocabulary, modules, "TAD"))
            }
        }
    }
}

/// The description files of `paths` (directories searched for `*.txt`), in order.
fn descriptions(paths: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for path in paths {
        if path.is_dir() {
            let found = crate::files::with_extension(path, "txt");
            if found.is_empty() {
                return Err(format!("{} holds no .txt descriptions", path.display()));
            }
            out.extend(found);
        } else {
            out.push(path.clone());
        }
    }
    Ok(out)
}

fn read_description(path: &Path) -> Result<String, String> {
    let text = if path == Path::new("-") {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut std::io::stdin(), &mut s)
            .map_err(|e| format!("cannot read standard input: {e}"))?;
        s
    } else {
        std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?
    };
    if text.trim().is_empty() {
        return Err(format!("{} is empty: there is nothing to translate", path.display()));
    }
    Ok(text.trim().to_string())
}

/// One description through the loop: the outcome and the program with its provenance.
fn translate_one(
    session: &Session,
    rt: &tokio::runtime::Runtime,
    path: &Path,
    text: &str,
    region: Option<&str>,
    on_round: &mut dyn FnMut(&Round),
) -> (tad_frontend::Outcome, Option<String>) {
    let item = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "stdin".into());
    let messages = tad_frontend::translate_messages(text, session.checker);
    let outcome = rt.block_on(session.run(&item, messages, tad_frontend::prompt::TRANSLATE.id, on_round));
    let provenance = tad_frontend::Provenance {
        comments: vec![format!(
            "translated by tadslc {} from {} with model {}, {} round{}, prompt {}",
            env!("CARGO_PKG_VERSION"),
            path.display(),
            model_label(session.client),
            outcome.rounds,
            if outcome.rounds == 1 { "" } else { "s" },
            tad_frontend::prompt::TRANSLATE.id
        )],
        region: region.map(String::from),
        description: Some(text.to_string()),
        ..Default::default()
    };
    let program = outcome.program.as_ref().map(|p| tad_frontend::with_provenance(p, &provenance));
    (outcome, program)
}

fn status_of(outcome: &tad_frontend::Outcome) -> Status {
    match (outcome.class, &outcome.stopped) {
        (Some("complete"), _) => Status::Ok,
        (Some("incomplete"), _) => Status::Incomplete,
        (Some("non_scenario"), _) => Status::NonScenario,
        (None, Some(_)) => Status::Unreachable,
        _ => Status::Failed,
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
    let TranslateArgs { paths, output, transcript, region, stream } = *t;
    let run = || -> Result<Status, String> {
        let files = descriptions(paths)?;
        let batch = files.len() > 1 || paths.iter().any(|p| p.is_dir());
        if batch && stream {
            return Err("--stream shows one description's answers; a batch reports in translate.jsonl".into());
        }
        let client = args.client(1)?;
        let show = |piece: &str| {
            use std::io::Write;
            let mut err = std::io::stderr().lock();
            let _ = err.write_all(piece.as_bytes());
            let _ = err.flush();
        };
        let checker = checker(region)?;
        let session = Session {
            client: client.chat(),
            checker: &checker,
            limits: args.limits(),
            constraint: args.constraint(&client, region)?,
            temperature: args.temperature.unwrap_or(0.0),
            seed: Some(args.seed),
            on_text: stream.then_some(&show as &tad_llm::OnText),
        };
        let mut transcript_file = match transcript {
            Some(p) => Some(store::Jsonl::append(p).map_err(|e| format!("cannot write {}: {e}", p.display()))?),
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
                if r.diagnostics.is_empty() {
                    String::new()
                } else {
                    format!(" ({} diagnostics)", r.diagnostics.len())
                }
            );
        };
        let rt = runtime()?;
        if !batch {
            let text = read_description(&files[0])?;
            let (outcome, program) = translate_one(&session, &rt, &files[0], &text, region, &mut on_round);
            match (&program, output) {
                (Some(p), Some(path)) => store::write_atomic(path, p.as_bytes())
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?,
                (Some(p), None) => {
                    let _ = out!("{p}");
                }
                (None, _) => {}
            }
            for line in &outcome.diagnostics {
                let _ = errln!("  {line}");
            }
            let _ = errln!(
                "{} after {} round{}; {} tokens{}",
                outcome.class.unwrap_or("no program"),
                outcome.rounds,
                if outcome.rounds == 1 { "" } else { "s" },
                outcome.usage.total(),
                outcome.stopped.as_deref().map(|s| format!("; stopped: {s}")).unwrap_or_default()
            );
            if let Some(e) = write_error {
                return Err(format!("cannot write the transcript: {e}"));
            }
            return Ok(status_of(&outcome));
        }
        let dir = output.ok_or("several descriptions need an output directory: -o DIR")?;
        let mut manifest = store::Jsonl::append(&dir.join("translate.jsonl"))
            .map_err(|e| format!("cannot write the manifest: {e}"))?;
        let mut summary = Summary::default();
        let bar = crate::output::progress(files.len(), "descriptions");
        let mut unreachable = 0;
        for path in &files {
            let text = match read_description(path) {
                Ok(t) => t,
                Err(e) => {
                    bar.println(format!("error: {e}"));
                    continue;
                }
            };
            let (outcome, program) = translate_one(&session, &rt, path, &text, region, &mut on_round);
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            let mut file = None;
            if let Some(p) = &program {
                let sub = if outcome.class == Some("invalid") { dir.join("rejected") } else { dir.to_path_buf() };
                let target = store::inside(&sub, &stem, "tad");
                store::write_atomic(&target, p.as_bytes())
                    .map_err(|e| format!("cannot write {}: {e}", target.display()))?;
                file = Some(target.display().to_string());
            }
            unreachable += usize::from(status_of(&outcome) == Status::Unreachable);
            summary.add(&outcome);
            let record =
                serde_json::json!({ "description": path.display().to_string(), "file": file, "outcome": outcome });
            manifest.write(&record).map_err(|e| format!("cannot write the manifest: {e}"))?;
            bar.inc(1);
        }
        bar.finish_and_clear();
        if let Some(e) = write_error {
            return Err(format!("cannot write the transcript: {e}"));
        }
        let constrained = !matches!(session.constraint, Constraint::None);
        write_summary(
            Some(dir),
            &summary,
            serde_json::json!({ "model": model_label(client.chat()), "constrained": constrained, "max_rounds": args.max_rounds }),
        )?;
        Ok(if unreachable == files.len() { Status::Unreachable } else { Status::Ok })
    };
    run().unwrap_or_else(|e| {
        let _ = errln!("error: {e}");
        Status::Usage
    })
}

fn write_summary(dir: Option<&Path>, summary: &Summary, extra: serde_json::Value) -> Result<(), String> {
    let _ = errln!("{}", summary.render());
    if let Some(dir) = dir {
        let mut value = serde_json::to_value(summary).unwrap_or_default();
        if let (Some(map), serde_json::Value::Object(extra)) = (value.as_object_mut(), extra) {
            map.extend(extra);
        }
        let text = serde_json::to_string_pretty(&value).unwrap_or_default() + "\n";
        store::write_atomic(&dir.join("summary.json"), text.as_bytes())
            .map_err(|e| format!("cannot write the summary: {e}"))?;
    }
    Ok(())
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
    let refuse = |message: std::fmt::Arguments| {
        let _ = errln!("error: {message}");
        Status::Usage
    };
    match &cmd.region {
        _ if cmd.generator != "llm" => {
            refuse(format_args!("unknown generator `{}` (expected `llm` or `fitted:MODEL`)", cmd.generator))
        }
        None => refuse(format_args!("`--generator llm` needs `--region REGION`")),
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
    let run = || -> Result<Status, String> {
        let (general, modules) = tad_grammar::scope(None)?;
        let (regional, region_modules) = tad_grammar::scope(Some(g.region))?;
        let client = args.client(g.jobs.max(1))?;
        let checker = checker(Some(g.region))?;
        let (vocabulary, constraint_scope) =
            if g.baseline { (&general, (&general, &modules)) } else { (&regional, (&regional, &region_modules)) };
        let constraint = if args.constrained(&client) {
            client.constraint(constraint_scope.0, constraint_scope.1)
        } else {
            Constraint::None
        };
        let session = Session {
            client: client.chat(),
            checker: &checker,
            limits: args.limits(),
            constraint,
            temperature: args.temperature.unwrap_or(0.8),
            seed: Some(args.seed),
            on_text: None,
        };
        let examples = region_examples(g.corpus, g.embedded, g.region);
        let spec = tad_frontend::generate::Spec {
            region: g.region,
            n: g.n,
            seed: args.seed,
            baseline: g.baseline,
            tuned: g.tuned,
            vocabulary,
            region_description: tad_frontend::description(&general, "region", g.region),
            examples,
            jobs: g.jobs,
            model: model_label(client.chat()),
        };
        let bar = crate::output::progress(g.n, "scenarios");
        let mut summary = Summary::default();
        let mut transcript = match g.out {
            Some(dir) => Some(store::Jsonl::append(&dir.join("gen.transcript.jsonl")).map_err(|e| e.to_string())?),
            None => None,
        };
        let records = runtime()?
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
                        let _ = out!("{p}\n");
                    }
                },
                &mut |r| {
                    if let Some(t) = transcript.as_mut() {
                        let _ = t.write(r);
                    }
                },
            ))
            .map_err(|e| format!("cannot write the scenarios: {e}"))?;
        bar.finish_and_clear();
        let mode = if g.baseline { "baseline" } else { "aligned" };
        write_summary(
            g.out,
            &summary,
            serde_json::json!({ "region": g.region, "mode": mode, "model": model_label(client.chat()) }),
        )?;
        let unreachable =
            !records.is_empty() && records.iter().all(|r| r.outcome.program.is_none() && r.outcome.stopped.is_some());
        Ok(if unreachable { Status::Unreachable } else { Status::Ok })
    };
    run().unwrap_or_else(|e| {
        let _ = errln!("error: {e}");
        Status::Usage
    })
}

/// The scenarios of `corpus` (files or directories; the embedded examples under `embedded`
/// when empty) that name `region` and count, for the prompt.
fn region_examples(corpus: &[PathBuf], embedded: &str, region: &str) -> Vec<String> {
    let corpus = if corpus.is_empty() {
        tad_eval::examples::corpus("examples", embedded)
    } else {
        let mut status = Status::Ok;
        match crate::align::read(corpus, &mut status) {
            Ok(corpus) => corpus,
            Err(_) => return Vec::new(),
        }
    };
    corpus
        .items
        .iter()
        .filter(|item| item.region.as_deref() == Some(region))
        .map(|item| tad_frontend::with_provenance(&item.tad, &tad_frontend::Provenance::default()))
        .collect()
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
    let run = || -> Result<Status, String> {
        let input = match (s.video, s.frames) {
            (Some(v), None) => tad_frontend::synth::Input::Video(v.to_path_buf()),
            (None, Some(d)) => tad_frontend::synth::Input::Frames(d.to_path_buf()),
            _ => return Err("give either --video FILE or --frames DIR".into()),
        };
        let client = args.client(s.jobs.max(1))?;
        let checker = checker(Some(s.region))?;
        let session = Session {
            client: client.chat(),
            checker: &checker,
            limits: args.limits(),
            constraint: args.constraint(&client, Some(s.region))?,
            temperature: args.temperature.unwrap_or(0.0),
            seed: Some(args.seed),
            on_text: None,
        };
        let spec = tad_frontend::synth::Spec {
            input,
            region: s.region.to_string(),
            out: s.out.to_path_buf(),
            every: s.every,
            shard: s.shard,
            jobs: s.jobs,
            max_refinements: s.max_refinements,
            model: model_label(client.chat()),
            ffmpeg: std::env::var("TADSL_FFMPEG").unwrap_or_else(|_| "ffmpeg".into()),
            ffprobe: std::env::var("TADSL_FFPROBE").unwrap_or_else(|_| "ffprobe".into()),
        };
        std::fs::create_dir_all(s.out).map_err(|e| format!("cannot create {}: {e}", s.out.display()))?;
        let stop = Arc::new(AtomicBool::new(false));
        let rt = runtime()?;
        {
            let stop = stop.clone();
            rt.spawn(async move {
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
        let report = rt
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
            .map_err(|e| e.0)?;
        bar.finish_and_clear();
        let _ = errln!(
            "{} frame{} in this shard: {} done before, {} now, {} failed (rerun to retry)",
            report.total,
            if report.total == 1 { "" } else { "s" },
            report.done_before,
            report.records.len() - failed,
            failed
        );
        write_summary(
            Some(s.out),
            &summary,
            serde_json::json!({ "region": s.region, "model": model_label(client.chat()), "shard": s.shard.to_string() }),
        )?;
        if report.interrupted {
            let _ = errln!("interrupted: run the same command again to continue");
            return Ok(Status::Failed);
        }
        Ok(if failed > 0 && failed == report.records.len() { Status::Unreachable } else { Status::Ok })
    };
    run().unwrap_or_else(|e| {
        let _ = errln!("error: {e}");
        Status::Usage
    })
}

/// `tadslc grammar`.
pub fn grammar(format: tad_grammar::Format, region: Option<&str>) -> Status {
    match tad_grammar::scope(region) {
        Ok((vocabulary, modules)) => {
            let header = format!(
                "TAD {} grammar from tadslc {} ({}); regenerate with `tadslc grammar --format {}{}`",
                format.name(),
                env!("CARGO_PKG_VERSION"),
                region.map(|r| format!("region {r}")).unwrap_or_else(|| "every standard module".into()),
                format.name(),
                region.map(|r| format!(" --region {r}")).unwrap_or_default()
            );
            let _ = out!("{}", tad_grammar::export(format, &vocabulary, &modules, &header));
            Status::Ok
        }
        Err(e) => {
            let _ = errln!("error: {e}");
            Status::Usage
        }
    }
}

/// `tadslc model list`.
pub fn model_list() -> Status {
    let _ = out!("cache: {}\n", tad_local::cache_dir().display());
    for m in tad_local::MODELS {
        let state = match m.installed() {
            Some(p) => format!("installed ({})", p.display()),
            None => format!("not installed (tadslc model fetch {})", m.aliases.first().unwrap_or(&m.name)),
        };
        let default = if m.name == tad_local::DEFAULT { " [default]" } else { "" };
        let aliases = if m.aliases.is_empty() { String::new() } else { format!(" (alias {})", m.aliases.join(", ")) };
        let _ = out!(
            "{}{default}{aliases}, {}: {}; {} MB from {}; {state}\n",
            m.name,
            m.kind.label(),
            m.description,
            m.bytes() / 1_000_000,
            m.packages()
        );
    }
    Status::Ok
}

/// `tadslc model fetch [NAME]`.
pub fn model_fetch(name: Option<&str>, python: Option<&str>) -> Status {
    let name = name.unwrap_or(tad_local::DEFAULT);
    let Some(model) = tad_local::model(name) else {
        let _ = errln!("error: unknown local model `{name}` (tadslc model list)");
        return Status::Usage;
    };
    let python =
        python.map(String::from).or_else(|| std::env::var("TADSL_PYTHON").ok()).unwrap_or_else(|| "python3".into());
    match model.fetch(&python, &mut |line| {
        let _ = errln!("{line}");
    }) {
        Ok(path) => {
            let _ = out!("{}\n", path.display());
            Status::Ok
        }
        Err(e) => {
            let _ = errln!("error: {e}");
            Status::Usage
        }
    }
}
