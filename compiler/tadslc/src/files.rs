//! Finding and reading input files: [`tad_db::host`], and [`load`], which reports what
//! cannot be read.

use crate::errln;
use crate::output::Closed;
use std::path::PathBuf;
pub use tad_db::host::{Input, Search, collect, read, with_extension};

/// Every input `paths` name (see [`collect`]), in order, and the status reading them
/// reached: paths that cannot be read are reported on standard error and make it
/// [`Status::Usage`](crate::Status); the other inputs are still returned.
pub fn load(paths: &[PathBuf], search: Search) -> Result<(Vec<Input>, crate::Status), Closed> {
    let (files, errors) = collect(paths, search);
    let mut status = crate::Status::Ok;
    for error in &errors {
        status = crate::Status::Usage;
        errln!("error: {error}")?;
    }
    let mut inputs = Vec::with_capacity(files.len());
    for path in &files {
        match read(path) {
            Ok(input) => inputs.push(input),
            Err(e) => {
                status = crate::Status::Usage;
                errln!("error: {e}")?;
            }
        }
    }
    Ok((inputs, status))
}
