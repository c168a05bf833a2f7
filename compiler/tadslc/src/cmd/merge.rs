//! `tadslc merge`: the table of several results files (`tadsl-eval/1`, the shards of one
//! `eval --shard` or `run --shard --out` command, or the directory they were written to),
//! as the unsharded run prints it: `run`'s per-scenario table for `run`'s files. Files of
//! another command are refused; missing shards are a warning and status 1.

use std::path::{Path, PathBuf};

use tad_base::Shard;
use tad_eval::results::{self, MergeError};
use tad_eval::{Results, TableFormat};

use crate::output::{CliError, Closed};
use crate::{Status, errln, out};

/// `tadslc merge`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The results files, or the directories `--out` wrote them in
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[arg(long, value_enum, default_value_t = EvalFormat::Markdown)]
    pub format: EvalFormat,
    /// Draw the OS of each generator and ego as an SVG bar chart
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// What `eval` and `merge` print.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EvalFormat {
    Markdown,
    Csv,
    Json,
}

impl From<EvalFormat> for TableFormat {
    fn from(format: EvalFormat) -> TableFormat {
        match format {
            EvalFormat::Markdown => TableFormat::Markdown,
            EvalFormat::Csv => TableFormat::Csv,
            EvalFormat::Json => TableFormat::Json,
        }
    }
}

/// `tadslc merge FILES`: the table of several results files (the shards of one command).
pub fn run(args: &Args) -> Result<Status, CliError> {
    let (format, plot) = (args.format, args.plot.as_deref());
    let files = &results_files(&args.files)?;
    let all = files
        .iter()
        .map(|path| Results::read(path).map_err(|e| CliError::usage(format!("{}: {e}", path.display()))))
        .collect::<Result<Vec<Results>, CliError>>()?;
    let shown = |index: usize| files[index].display();
    let missing = results::check_merge(&all).map_err(|e| match e {
        MergeError::OtherSetup { index } => CliError::usage(format!(
            "{} comes from another command than {} (regions, generators, egos, sizes or seed differ)",
            shown(index),
            shown(0)
        )),
        MergeError::OtherCount { index, shard, count } => {
            CliError::usage(format!("{} is shard {shard} but {} is of {count}", shown(index), shown(0)))
        }
        e @ (MergeError::Empty | MergeError::Twice(_)) => CliError::usage(e),
    })?;
    let mut status = Status::Ok;
    if !missing.is_empty() {
        status = Status::Failed;
        let missing: Vec<String> = missing.iter().map(Shard::to_string).collect();
        errln!("warning: shards {} are missing: the table covers part of the work", missing.join(", "))?;
    }
    Ok(status.max(print(&all, format, plot)?))
}

/// The results files `paths` name: a directory stands for those `--out` wrote in it
/// (`results.json`, `results.I-of-N.json`), in name order.
fn results_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>, CliError> {
    let mut files = Vec::new();
    for path in paths {
        if !path.is_dir() {
            files.push(path.clone());
            continue;
        }
        let found: Vec<PathBuf> = tad_db::host::with_extension(path, "json")
            .into_iter()
            .filter(|p| p.parent() == Some(path.as_path()))
            .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(is_results_name))
            .collect();
        if found.is_empty() {
            return Err(CliError::usage(format!(
                "no results files in `{}` (`results.json` or `results.I-of-N.json`)",
                path.display()
            )));
        }
        files.extend(found);
    }
    Ok(files)
}

/// `results.json` or `results.I-of-N.json`.
fn is_results_name(name: &str) -> bool {
    let Some(middle) = name.strip_prefix("results").and_then(|n| n.strip_suffix(".json")) else { return false };
    middle.is_empty()
        || middle
            .strip_prefix('.')
            .and_then(|m| m.split_once("-of-"))
            .is_some_and(|(i, n)| i.parse::<usize>().is_ok() && n.parse::<usize>().is_ok())
}

/// The table of `all` on standard output, and its plot; a plot that cannot be written is
/// reported (the table still printed) and makes the status 2.
pub fn print(all: &[Results], format: EvalFormat, plot: Option<&Path>) -> Result<Status, Closed> {
    // `run`'s shards: the per-scenario table the unsharded run prints
    match (format, tad_eval::record::merged_table(all)) {
        (EvalFormat::Markdown, Some(table)) => out!("{table}")?,
        _ => out!("{}", results::table(all, format.into()))?,
    }
    if let Some(path) = plot
        && let Err(e) = std::fs::write(path, results::plot(all))
    {
        errln!("error: cannot write `{}`: {e}", path.display())?;
        return Ok(Status::Usage);
    }
    Ok(Status::Ok)
}
