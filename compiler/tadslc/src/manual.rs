//! `tadslc completions SHELL` and `tadslc man [-o DIR]`: the shell completion scripts
//! (`clap_complete`) and the manual pages (`clap_mangen`), generated from the command
//! line's own definition, so they never disagree with it.

use crate::output::Closed;
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
    crate::output::run(|status| man_in(command, dir, status))
}

fn man_in(command: clap::Command, dir: Option<&Path>, status: &mut Status) -> Result<(), Closed> {
    let Some(dir) = dir else {
        let mut page = Vec::new();
        if let Err(e) = clap_mangen::Man::new(command).render(&mut page) {
            *status = Status::Usage;
            return errln!("error: cannot render the manual page: {e}");
        }
        return crate::output::out_bytes(&page);
    };
    if let Err(e) = std::fs::create_dir_all(dir) {
        *status = Status::Usage;
        return errln!("error: cannot create `{}`: {e}", dir.display());
    }
    let pages = 1 + command.get_subcommands().filter(|s| !s.is_hide_set() && s.get_name() != "help").count();
    match clap_mangen::generate_to(command, dir) {
        Ok(()) => errln!("wrote {} into {}", plural(pages, "manual page"), dir.display()),
        Err(e) => {
            *status = Status::Usage;
            errln!("error: cannot write the manual pages into `{}`: {e}", dir.display())
        }
    }
}
