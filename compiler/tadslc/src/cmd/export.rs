//! `tadslc export`: a TAD scenario in TrafficAlign's YAML form, with extra keys for what
//! TAD adds. A file with errors is not exported (status 1).

use std::path::PathBuf;

use tad_check::Options;
use tad_db::Database;

use super::import::{report, write_output};
use crate::Status;
use crate::output::CliError;

/// `tadslc export`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The form to write: TrafficAlign's YAML form, with extra keys for everything
    /// TAD adds (the only one, and the default)
    #[arg(long, value_enum, default_value_t = ExportFormat::Yaml)]
    pub format: ExportFormat,
    /// The same as `--format yaml` (kept for compatibility)
    #[arg(long)]
    pub yaml: bool,
    /// The TAD file
    pub path: PathBuf,
    /// Where to write (default: standard output)
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// TrafficAlign's YAML form
    Yaml,
}

pub fn run(args: &Args, color: bool) -> Result<Status, CliError> {
    let (path, out) = (&args.path, args.output.as_deref());
    let input = tad_db::host::read(path).map_err(CliError::usage)?;
    let mut db = Database::new(Options::default());
    let checked = tad_db::host::diagnose_in(&mut db, &input);
    let errors = report(&input, &checked.diagnostics, color)?;
    if errors > 0 {
        return Err(CliError::failed(format!("`{}` has errors; not exported", input.name)));
    }
    let file = tad_db::host::register(&mut db, &input);
    let module = &tad_db::analyze(&db, file).module;
    write_output(out, &tad_yaml::export(module, &input.text))?;
    Ok(Status::Ok)
}
