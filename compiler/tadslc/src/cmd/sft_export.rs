//! `tadslc sft-export`: a corpus as supervised fine-tuning data (`tad_frontend::sft`):
//! TRL's conversational `messages.jsonl` and `prompt_completion.jsonl`, each scenario the
//! answer to the tuned generation prompt, for `tadslc finetune`, Unsloth or TRL.

use std::path::PathBuf;

use crate::corpus;
use crate::output::CliError;
use crate::{Status, errln, plural};

/// `tadslc sft-export`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The corpus (directories or files of scenarios)
    #[arg(required = true)]
    pub corpus: Vec<PathBuf>,
    /// The output directory
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// The region of scenarios that state none (and of every scenario, if given)
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: Option<String>,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
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
    for (name, text) in [("messages.jsonl", &export.messages), ("prompt_completion.jsonl", &export.prompt_completion)] {
        let path = output.join(name);
        tad_frontend::store::write_atomic(&path, text.as_bytes())
            .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    }
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
