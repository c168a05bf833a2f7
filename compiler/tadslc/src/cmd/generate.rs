//! `tadslc gen`: scenarios for a region, with the fitted generator (`--generator
//! fitted:MODEL`, `tad_eval::generator::draw_many`: no language model, each scenario drawn
//! again until it checks without errors) or with a language model through the
//! check-and-repair loop (`tad_frontend::generate`): the region's examples (aligned), its
//! name only (`--baseline`), or the short prompt a fine-tuned model learnt (`--tuned`).

use std::path::{Path, PathBuf};

use tad_frontend::{Summary, backend, store};
use tad_llm::Constraint;

use crate::llm::{LlmArgs, report_summary};
use crate::output::CliError;
use crate::{Status, errln, out, plural};

/// `tadslc gen`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The region (for `llm`; a fitted model knows its own)
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: Option<String>,
    /// `llm`, or `fitted:MODEL` (a file written by `tadslc fit`)
    #[arg(long, value_name = "GENERATOR", default_value = "llm")]
    pub generator: String,
    /// How many scenarios (at most 100,000)
    #[arg(short = 'n', long = "count", value_name = "N", default_value_t = 40, value_parser = crate::count::<100_000>)]
    pub count: usize,
    /// Write the scenarios, a manifest and a summary here (default: print them)
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Remove what an earlier run left in `--out` (else it is an error)
    #[arg(long, requires = "out")]
    pub force: bool,
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
pub fn run(cmd: &Args) -> Result<Status, CliError> {
    if let Some(dir) = &cmd.out {
        let ours = |name: &str| name.ends_with(".tad") || name.starts_with("gen.") || name == "summary.json";
        crate::files::fresh_output(dir, cmd.force, &ours)?;
    }
    if let Some(model) = cmd.generator.strip_prefix("fitted:") {
        return fitted(&FittedGen {
            model: Path::new(model),
            n: cmd.count,
            seed: cmd.llm.seed,
            out: cmd.out.as_deref(),
            attempts: cmd.attempts,
        });
    }
    match &cmd.region {
        _ if cmd.generator != "llm" => {
            Err(CliError::usage(format!("unknown generator `{}` (expected `llm` or `fitted:MODEL`)", cmd.generator)))
        }
        None => Err(CliError::usage("`--generator llm` needs `--region REGION`")),
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

/// What a language model is asked for: `n` scenarios of `region`.
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

/// `tadslc gen --region R -n N` (and `eval`'s llm generators).
pub fn generate(g: &GenArgs, args: &LlmArgs) -> Result<Status, CliError> {
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
    let mut summary = Summary::of_scenarios();
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

/// `tadslc gen --generator fitted:MODEL`'s request.
pub struct FittedGen<'a> {
    pub model: &'a Path,
    pub n: usize,
    pub seed: u64,
    pub out: Option<&'a Path>,
    /// Draws per scenario before giving up on it.
    pub attempts: usize,
}

/// The fitted generator's scenarios: item `i` drawn with seed `seed + i`, again until it
/// checks without errors (at most `attempts` draws).
fn fitted(g: &FittedGen) -> Result<Status, CliError> {
    let text = std::fs::read_to_string(g.model)
        .map_err(|e| CliError::usage(format!("cannot read `{}`: {e}", g.model.display())))?;
    let fitted =
        tad_fit::Fitted::from_json(&text).map_err(|e| CliError::usage(format!("{}: {e}", g.model.display())))?;
    let stem = fitted.region.clone().unwrap_or_else(|| tad_eval::corpus::name_of(g.model));
    let generator = format!("fitted:{}", g.model.display());
    let run =
        tad_eval::generator::Draws { generator: &generator, stem: &stem, n: g.n, seed: g.seed, attempts: g.attempts };
    let mut status = Status::Ok;
    let summary = tad_eval::generator::draw_many(&fitted, &run, |drawn| -> Result<(), CliError> {
        let Some(text) = drawn.text else {
            status = status.max(Status::Failed);
            errln!("warning: scenario {} not generated: {} drawn, none valid", drawn.index + 1, g.attempts)?;
            return Ok(());
        };
        let provenance = tad_frontend::Provenance {
            comments: vec![format!(
                "generated by tadslc {} from the fitted model {} ({} scenarios), seed {}",
                env!("CARGO_PKG_VERSION"),
                g.model.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                fitted.scenarios,
                drawn.seed
            )],
            region: fitted.region.clone(),
            ..Default::default()
        };
        let program = tad_frontend::with_provenance(&text, &provenance);
        match g.out {
            Some(dir) => {
                let path = dir.join(format!("{}.tad", drawn.name));
                tad_frontend::store::write_atomic(&path, program.as_bytes())
                    .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
            }
            None => out!("{program}\n")?,
        }
        Ok(())
    })?;
    if let Some(dir) = g.out {
        let json = serde_json::to_string_pretty(&summary).unwrap_or_default();
        tad_frontend::store::write_atomic(&dir.join("summary.json"), json.as_bytes()).map_err(CliError::usage)?;
    }
    errln!(
        "generated {} ({} complete, {} incomplete) from {} draws ({} rejected by the checker)",
        plural(summary.generated, "scenario"),
        summary.complete,
        summary.incomplete,
        summary.draws,
        summary.rejected
    )?;
    Ok(status)
}
