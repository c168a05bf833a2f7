//! `tadslc man [-o DIR]`: the manual pages (`clap_mangen`), generated from the command
//! line's own definition, so they never disagree with it.

use std::path::PathBuf;

use crate::output::CliError;
use crate::{Status, errln, plural};

/// `tadslc man`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Write `tadslc.1` and a page per subcommand (`tadslc-check.1`, ...) into this
    /// directory instead of printing `tadslc.1`
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Print `tadslc.1`, or write it and a page per subcommand into the directory;
/// `command` is the command line's definition.
pub fn run(args: &Args, command: clap::Command) -> Result<Status, CliError> {
    let dir = args.output.as_deref();
    let Some(dir) = dir else {
        let mut page = Vec::new();
        clap_mangen::Man::new(command)
            .render(&mut page)
            .map_err(|e| CliError::usage(format!("cannot render the manual page: {e}")))?;
        crate::output::out_bytes(&page)?;
        return Ok(Status::Ok);
    };
    std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
    let pages = 1 + command.get_subcommands().filter(|s| !s.is_hide_set() && s.get_name() != "help").count();
    clap_mangen::generate_to(command, dir)
        .map_err(|e| CliError::usage(format!("cannot write the manual pages into `{}`: {e}", dir.display())))?;
    errln!("wrote {} into {}", plural(pages, "manual page"), dir.display())?;
    Ok(Status::Ok)
}
