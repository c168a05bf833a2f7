//! `tadslc lsp`: the language server (`tad-lsp`) on standard input and output, for the
//! editors in `editors/` (`spec/lsp.md`).

use crate::Status;
use crate::output::CliError;

/// `tadslc lsp`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Accepted for clients that pass it (stdio is the only transport)
    #[arg(long, hide = true)]
    pub stdio: bool,
}

pub fn run(_: &Args) -> Result<Status, CliError> {
    tad_lsp::run_stdio().map_err(|error| CliError::usage(format!("the language server could not start: {error}")))?;
    Ok(Status::Ok)
}
