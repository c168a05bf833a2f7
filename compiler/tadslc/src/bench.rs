//! `tadslc bench`: the experiments of `tad-bench`, their reports printed.
//!
//! [`run`] measures check throughput against serde_json; [`runtime`], [`lsp`], [`llm`] and
//! [`align`] are `--runtime`, `--lsp`, `--llm` and `--align`. A report's lines go to
//! standard output, its notes and an experiment's progress to standard error; its outcome
//! is the exit status.

use crate::Status;
use crate::output::{CliError, finish};
use tad_bench::{BenchError, Outcome, Report};

/// `experiment` run with its progress streamed to standard error, then its report printed.
fn streamed(context: &str, experiment: impl FnOnce(&mut dyn FnMut(&str)) -> Result<Report, BenchError>) -> Status {
    // the first failed write to standard error, for the status
    let mut closed = None;
    let report = experiment(&mut |line| {
        if closed.is_none() {
            closed = crate::errln!("{line}").err();
        }
    });
    finish(match closed {
        Some(closed) => Err(closed.into()),
        None => print(report, context),
    })
}

/// `report` printed (an error as `error: {context}{error}`, status 2), its status.
fn print(report: Result<Report, BenchError>, context: &str) -> Result<Status, CliError> {
    let report = report.map_err(|e| CliError::usage(format!("{context}{e}")))?;
    report.lines.iter().try_for_each(|line| crate::outln!("{line}"))?;
    report.notes.iter().try_for_each(|note| crate::errln!("{note}"))?;
    Ok(match report.outcome {
        Outcome::Complete => Status::Ok,
        Outcome::InputErrors => Status::Failed,
        Outcome::Unusable => Status::Usage,
    })
}

/// `bench`: check throughput.
pub fn run(n: usize, seed: u64, examples: Option<&std::path::Path>, runs: usize) -> Status {
    finish(print(Ok(tad_bench::run(n, seed, examples, runs)), ""))
}

pub mod runtime {
    pub use tad_bench::runtime::RuntimeArgs;

    pub fn run(args: &RuntimeArgs) -> crate::Status {
        super::streamed("", |progress| tad_bench::runtime::run(args, progress))
    }
}

/// `bench --lsp`: this binary's `lsp`.
pub mod lsp {
    pub fn run(samples: usize, runs: usize) -> crate::Status {
        super::streamed("bench --lsp: ", |progress| {
            let exe = std::env::current_exe()?;
            tad_bench::lsp::run(&exe, samples, runs, progress)
        })
    }
}

pub mod llm {
    pub use tad_bench::llm::LlmArgs;

    pub fn run(args: &LlmArgs) -> crate::Status {
        super::streamed("bench --llm: ", |progress| tad_bench::llm::run(args, progress))
    }
}

/// `bench --align`: the extra corpora read and the sentences embedded as `compare` does.
pub mod align {
    use std::path::PathBuf;

    use crate::Status;
    use crate::align::{Embedding, counted, embed, read};
    use crate::output::CliError;
    pub use tad_bench::align::parse_extra;
    use tad_eval::recovery::Extra;

    pub struct AlignArgs {
        pub n: usize,
        pub seed: u64,
        pub resamples: usize,
        pub embedding: Embedding,
        pub out: PathBuf,
        /// `(label, region label, dir)`: more corpora to compare with a region's held-out set.
        pub extra: Vec<(String, String, PathBuf)>,
        pub json: bool,
    }

    pub fn run(args: &AlignArgs) -> Status {
        crate::output::finish(run_in(args))
    }

    fn run_in(args: &AlignArgs) -> Result<Status, CliError> {
        let corpora = tad_bench::align::corpora(args.n, args.seed, &args.out).map_err(CliError::usage)?;
        // an extra corpus that cannot be read or has no valid scenario is said (status 2);
        // the experiment goes on without it
        let mut status = Status::Ok;
        let mut extra = Vec::new();
        for (label, region, dir) in &args.extra {
            let (corpus, read) = read(std::slice::from_ref(dir))?;
            status = status.max(read);
            let features = match counted(corpus) {
                Ok(corpus) => corpus.items.into_iter().map(|i| i.features).collect(),
                Err(CliError::Exit(failed, why)) => {
                    status = status.max(failed);
                    crate::errln!("error: {why}")?;
                    Vec::new()
                }
                Err(closed) => return Err(closed),
            };
            extra.push(Extra { label: label.clone(), region: region.clone(), features });
        }
        let embed = |a: &[tad_stats::Features], b: &[tad_stats::Features]| embed(args.embedding, a, b);
        let report = tad_bench::align::report(&corpora, &extra, &embed, args.resamples, args.seed, args.json);
        Ok(super::print(report, "")?.max(status))
    }
}
