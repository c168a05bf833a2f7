//! `tadslc completions SHELL` and `tadslc man [-o DIR]`: the shell completion scripts
//! (`clap_complete`) and the manual pages (`clap_mangen`), generated from the command
//! line's own definition, so they never disagree with it.

use crate::output::CliError;
use crate::{Status, errln, plural};
use clap_complete::Shell;
use std::path::Path;

/// Print the completion script for `shell`.
pub fn completions(mut command: clap::Command, shell: Shell) -> Status {
    let name = command.get_name().to_string();
    // into memory first: the generators panic when their writer fails
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut command, name, &mut script);
    crate::output::run(|_| crate::output::out_bytes(&script))
}

/// Print `tadslc.1`, or write it and a page per subcommand (`tadslc-check.1`, ...) into
/// `dir`.
pub fn man(command: clap::Command, dir: Option<&Path>) -> Status {
    crate::output::finish(man_in(command, dir))
}

fn man_in(command: clap::Command, dir: Option<&Path>) -> Result<Status, CliError> {
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
