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
