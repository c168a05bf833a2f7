//! `tadslc stats`: the statistics of corpora (`tad-stats`): the corpus table and a
//! histogram per attribute, as tables, CSV or JSON, and SVG bar charts. Each path is one
//! corpus; a corpus that cannot be read is reported and the others still counted.

use std::path::PathBuf;

use tad_stats::Stats;

use crate::corpus;
use crate::output::CliError;
use crate::{Status, errln, out, outln, plural};

/// `tadslc stats`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The corpora
    #[arg(required = true)]
    pub corpora: Vec<PathBuf>,
    /// Markdown tables, long-form CSV, or JSON
    #[arg(long, value_enum, default_value_t = TableFormat::Table)]
    pub format: TableFormat,
    /// Also write an SVG bar chart per attribute into this directory
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TableFormat {
    /// Markdown tables
    Table,
    Csv,
    Json,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    let mut status = Status::Ok;
    let mut corpora = Vec::new();
    for path in &args.corpora {
        match corpus::load(std::slice::from_ref(path)) {
            Ok((corpus, read)) => {
                status = status.max(read);
                corpora.push(corpus);
            }
            // the other corpora are still counted
            Err(CliError::Exit(s, message)) => {
                status = status.max(s);
                errln!("error: {message}")?;
            }
            Err(e) => return Err(e),
        }
    }
    tad_eval::corpus::unique_names(&mut corpora);
    if corpora.is_empty() {
        return Ok(status);
    }
    let all: Vec<Stats> = corpora.iter().map(|c| Stats::of(&c.name, &corpus::features(c))).collect();
    match args.format {
        TableFormat::Table => out!("{}", tad_stats::stats::markdown(&all))?,
        TableFormat::Csv => out!("{}", tad_stats::stats::csv(&all))?,
        TableFormat::Json => outln!("{}", serde_json::to_string_pretty(&all).unwrap_or_default())?,
    }
    if let Some(dir) = args.plot.as_deref() {
        std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
        let plots = tad_stats::plot::corpora(&all);
        for (name, svg) in &plots {
            let path = dir.join(format!("{name}.svg"));
            std::fs::write(&path, svg)
                .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
        }
        errln!("wrote {} to `{}`", plural(plots.len(), "plot"), dir.display())?;
    }
    Ok(status)
}
