//! Finding and reading input files: [`tad_db::host`], and [`load`], which reports what
//! cannot be read.

use crate::errln;
use crate::output::Closed;
use std::path::PathBuf;
pub use tad_db::host::{Input, Search, read, with_extension};

/// Every input `paths` name ([`tad_db::host::load`]), in order, and the status reading
/// them reached: paths that cannot be read are reported on standard error and make it
/// [`Status::Usage`](crate::Status); the other inputs are still returned.
pub fn load(paths: &[PathBuf], search: Search) -> Result<(Vec<Input>, crate::Status), Closed> {
    let (inputs, errors) = tad_db::host::load(paths, search);
    for error in &errors {
        errln!("error: {error}")?;
    }
    Ok((inputs, if errors.is_empty() { crate::Status::Ok } else { crate::Status::Usage }))
}

/// `dir` made ready for one run's output: created when missing; files an earlier run left
/// there (those `ours` claims, in `dir` and `dir/rejected`) are refused (status 2, naming
/// one of them and `--force`), or removed first with `force`, so that later commands that
/// read the directory see this run's files only.
pub fn fresh_output(
    dir: &std::path::Path,
    force: bool,
    ours: &dyn Fn(&str) -> bool,
) -> Result<(), crate::output::CliError> {
    use crate::output::CliError;
    let mut stale = Vec::new();
    for sub in [dir.to_path_buf(), dir.join("rejected")] {
        let Ok(entries) = std::fs::read_dir(&sub) else { continue };
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if entry.file_type().is_ok_and(|t| t.is_file()) && ours(&name) {
                stale.push(entry.path());
            }
        }
    }
    stale.sort();
    if let Some(first) = stale.first()
        && !force
    {
        return Err(CliError::usage(format!(
            "`{}` holds {} from an earlier run (such as `{}`): choose another directory, or pass --force to remove them first",
            dir.display(),
            crate::plural(stale.len(), "file"),
            first.display()
        )));
    }
    for file in &stale {
        std::fs::remove_file(file).map_err(|e| CliError::usage(format!("cannot remove `{}`: {e}", file.display())))?;
    }
    std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))
}
