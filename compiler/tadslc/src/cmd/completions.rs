//! `tadslc completions SHELL`: the shell completion script (`clap_complete`), generated
//! from the command line's own definition, so it never disagrees with it.

use clap_complete::Shell;

use crate::Status;
use crate::output::CliError;

/// `tadslc completions`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The shell
    #[arg(value_enum)]
    pub shell: Shell,
}

/// Print the completion script for the shell; `command` is the command line's definition.
pub fn run(args: &Args, mut command: clap::Command) -> Result<Status, CliError> {
    let name = command.get_name().to_string();
    // into memory first: the generators panic when their writer fails
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, name, &mut script);
    crate::output::out_bytes(&script)?;
    Ok(Status::Ok)
}
