//! `tadslc sft-export`: supervised fine-tuning data (`tad_frontend::sft`), TRL's
//! conversational `messages.jsonl` and `prompt_completion.jsonl`, for `tadslc finetune`,
//! Unsloth or TRL: a corpus, each scenario the answer to the tuned generation prompt; or,
//! with `--translate`, descriptions, each answered by its truth as `translate` asks it.

use std::path::PathBuf;

use crate::corpus;
use crate::output::CliError;
use crate::{Status, errln, plural};

/// `tadslc sft-export`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The corpus (directories or files of scenarios); with --translate, the descriptions
    /// (`.txt` files, or directories of them)
    #[arg(required = true)]
    pub corpus: Vec<PathBuf>,
    /// Translation pairs: each description asked as `translate` asks it, answered by its
    /// truth (`DIR/NAME.tad` for `NAME.txt`, from the first --truth DIR that has it)
    #[arg(long, requires = "truth", conflicts_with = "region")]
    pub translate: bool,
    /// Where the truths of --translate's descriptions are (repeatable)
    #[arg(long, value_name = "DIR", requires = "translate")]
    pub truth: Vec<PathBuf>,
    /// The output directory
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// The region of scenarios that state none (and of every scenario, if given)
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: Option<String>,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    if args.translate {
        let export = translations(&args.corpus, &args.truth)?;
        write(&args.output, &export)?;
        let total: usize = export.regions.values().sum();
        errln!(
            "wrote {} to `{}` (messages.jsonl, prompt_completion.jsonl; prompt {})",
            plural(total, "translation"),
            args.output.display(),
            tad_frontend::prompt::TRANSLATE.id
        )?;
        return Ok(Status::Ok);
    }
    let (paths, output, region) = (&args.corpus, &args.output, args.region.as_deref());
    let (corpus, status) = corpus::load(paths)?;
    let examples = corpus.items.iter().map(|item| tad_frontend::sft::Example {
        name: &item.name,
        tad: &item.tad,
        region: item.region.as_deref(),
    });
    let export = tad_frontend::sft::export(examples, region);
    for name in &export.no_region {
        errln!("warning: {name} states no region (give --region); skipped")?;
    }
    write(output, &export)?;
    let total: usize = export.regions.values().sum();
    errln!(
        "wrote {} to `{}` (messages.jsonl, prompt_completion.jsonl; prompt {}): {}",
        plural(total, "example"),
        output.display(),
        tad_frontend::prompt::GENERATE_TUNED.id,
        export.regions.iter().map(|(r, n)| format!("{r} {n}")).collect::<Vec<_>>().join(", ")
    )?;
    Ok(status)
}

/// The two files of `export` in `output`.
fn write(output: &std::path::Path, export: &tad_frontend::sft::Export) -> Result<(), CliError> {
    for (name, text) in [("messages.jsonl", &export.messages), ("prompt_completion.jsonl", &export.prompt_completion)] {
        let path = output.join(name);
        tad_frontend::store::write_atomic(&path, text.as_bytes())
            .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    }
    Ok(())
}

/// The descriptions in `paths` with their truths in `truths`, as translation pairs. A
/// description without a truth, or a truth the checker rejects, is an error: a pair that
/// teaches a wrong answer is worse than none.
fn translations(paths: &[PathBuf], truths: &[PathBuf]) -> Result<tad_frontend::sft::Export, CliError> {
    let checker = tad_frontend::backend::checker(None).map_err(CliError::usage)?;
    let mut texts = Vec::new();
    for file in tad_frontend::translate::descriptions(paths).map_err(CliError::usage)? {
        let description = tad_frontend::translate::read_description(&file).map_err(CliError::usage)?;
        let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let name = format!("{stem}.tad");
        let Some(path) = truths.iter().map(|dir| dir.join(&name)).find(|p| p.is_file()) else {
            let dirs: Vec<String> = truths.iter().map(|d| format!("`{}`", d.display())).collect();
            return Err(CliError::usage(format!("{}: no truth `{name}` in {}", file.display(), dirs.join(", "))));
        };
        let tad = std::fs::read_to_string(&path)
            .map_err(|e| CliError::usage(format!("cannot read `{}`: {e}", path.display())))?;
        let verdict = checker.check(&tad, tad_db::Language::Tad);
        if verdict.errors > 0 {
            let error = verdict.lines.first().map_or("", String::as_str);
            return Err(CliError::usage(format!("{}: the truth is not valid: {error}", path.display())));
        }
        texts.push((description, tad));
    }
    let pairs = texts.iter().map(|(d, t)| tad_frontend::sft::Translation { description: d, truth: t });
    Ok(tad_frontend::sft::export_translations(pairs, &checker))
}
