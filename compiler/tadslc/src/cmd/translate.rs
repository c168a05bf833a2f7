//! `tadslc translate`: a description to a TAD program with a language model, the compiler
//! in the loop (`tad_frontend::translate`): one description to a file or standard output,
//! or several (or directories of `*.txt`) into `-o DIR` with a manifest and a summary. The
//! exit status names the class it ended in (`spec/output.md`).

use std::path::PathBuf;

use tad_frontend::backend;
use tad_frontend::shots::Pool;
use tad_frontend::translate::{self, Translator};
use tad_frontend::{Round, Session, store};
use tad_llm::Constraint;

use crate::llm::{LlmArgs, report_summary, status_of};
use crate::output::CliError;
use crate::{Status, errln, out};

/// `tadslc translate`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The description (a text file; `-` reads standard input), or several, or
    /// directories of `*.txt` descriptions
    #[arg(required_unless_present = "text", conflicts_with = "text")]
    pub description: Vec<PathBuf>,
    /// The description itself, instead of a file
    #[arg(long, value_name = "WORDS")]
    pub text: Option<String>,
    /// Write the program here (default: standard output); with several descriptions, the
    /// directory for their programs, `translate.jsonl` and `summary.json`
    #[arg(short, long, value_name = "PATH")]
    pub output: Option<PathBuf>,
    /// Append every round (request, answer, diagnostics) as JSON lines
    #[arg(long, value_name = "FILE")]
    pub transcript: Option<PathBuf>,
    /// The region: its module's names are in scope and in the prompt
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: Option<String>,
    /// Show the model's answers on standard error as they are written (one description)
    #[arg(long)]
    pub stream: bool,
    #[command(flatten)]
    pub shots: ShotArgs,
    #[command(flatten)]
    pub llm: LlmArgs,
}

/// Translations retrieved from a pool and shown before each description
/// (`tad_frontend::shots`).
#[derive(clap::Args, Clone, Debug)]
pub struct ShotArgs {
    /// Before each description, show the model the translations of this pool whose
    /// descriptions read most like it: programs with a `source.description` (a region's
    /// corpus, checked translations), or `truth/NAME.tad` beside `descriptions/NAME.txt`
    #[arg(long, value_name = "DIR")]
    pub pool: Option<PathBuf>,
    /// How many of the pool's translations are shown
    #[arg(long, value_name = "N", default_value_t = 2, requires = "pool")]
    pub shots: usize,
}

impl ShotArgs {
    /// The pool, if one is named; a warning names the programs it leaves out.
    pub fn load(&self) -> Result<Option<Pool>, CliError> {
        let Some(dir) = &self.pool else { return Ok(None) };
        let pool = Pool::load(dir).map_err(CliError::usage)?;
        if !pool.skipped.is_empty() {
            errln!(
                "warning: the pool leaves out {} program{}: {}",
                pool.skipped.len(),
                if pool.skipped.len() == 1 { "" } else { "s" },
                pool.skipped.join(", ")
            )?;
        }
        Ok(Some(pool))
    }
}

pub fn run(t: &Args) -> Result<Status, CliError> {
    let args = &t.llm;
    let (paths, output, transcript, region, stream) =
        (&t.description, t.output.as_deref(), t.transcript.as_deref(), t.region.as_deref(), t.stream);
    let files = match &t.text {
        Some(_) => vec![PathBuf::from("text")],
        None => translate::descriptions(paths).map_err(CliError::usage)?,
    };
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
            Some(store::Jsonl::append(p).map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", p.display())))?)
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
    let pool = t.shots.load()?;
    let shots = pool.as_ref().map(|p| (p, t.shots.shots));
    let translator = Translator { session: &session, runtime: &runtime, region, tool: &tool, shots };
    if !batch {
        let text = match &t.text {
            Some(words) if words.trim().is_empty() => {
                return Err(CliError::usage("--text is empty: there is nothing to translate"));
            }
            Some(words) => words.trim().to_string(),
            None => translate::read_description(&files[0]).map_err(CliError::usage)?,
        };
        let (outcome, program) = translator.one(&files[0], &text, &mut on_round);
        match (&program, output) {
            (Some(p), Some(path)) => store::write_atomic(path, p.as_bytes())
                .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?,
            (Some(p), None) => out!("{p}")?,
            (None, _) => {}
        }
        for line in &outcome.diagnostics {
            errln!("  {line}")?;
        }
        if let Some(line) = outcome.suggested_line() {
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
