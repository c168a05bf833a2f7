//! `tadslc fit`: the generator fitted to a corpus (`tad-fit`'s count tables, through
//! `tad_eval::generator::fit`), for `tadslc gen --generator fitted:MODEL`.

use std::path::PathBuf;

use crate::corpus;
use crate::output::CliError;
use crate::{Status, errln, plural};

/// `tadslc fit`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The corpus (directories or files of scenarios)
    #[arg(required = true)]
    pub corpus: Vec<PathBuf>,
    /// The model file to write
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    let (paths, output) = (&args.corpus, &args.output);
    let (corpus, status) = corpus::load(paths)?;
    let (fitted, fitted_from) = tad_eval::generator::fit(corpus.items.iter());
    tad_frontend::store::write_atomic(output, fitted.to_json().as_bytes())
        .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", output.display())))?;
    errln!(
        "fitted {} of {} ({} fields, region {}) into `{}`",
        plural(fitted_from, "scenario"),
        corpus.name,
        fitted.tables.len(),
        fitted.region.as_deref().unwrap_or("none"),
        output.display()
    )?;
    Ok(status)
}
