//! `tadslc disasm`: the listing of a bytecode program (`spec/bytecode.md`). A file that
//! does not load is status 1, with the loader's reason and byte offset, as under `run`.

use std::path::PathBuf;

use crate::output::CliError;
use crate::{Status, out};

/// `tadslc disasm`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The `.tadc` file
    pub path: PathBuf,
}

/// `disasm FILE.tadc`: the listing on standard output.
pub fn run(args: &Args) -> Result<Status, CliError> {
    let path = &args.path;
    let bytes = std::fs::read(path).map_err(|e| CliError::usage(format!("cannot read `{}`: {e}", path.display())))?;
    // a file that does not load is input with errors (status 1), as under `run`
    let program = tad_bytecode::decode(&bytes).map_err(|e| CliError::failed(format!("{}: {e}", path.display())))?;
    out!("{}", tad_bytecode::disasm(&program))?;
    Ok(Status::Ok)
}
