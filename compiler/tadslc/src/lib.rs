//! The `tadslc` library: the command line's subcommands, shared with its tests.
//!
//! Exit codes: 0 success, 1 the input has errors (or warnings with `--deny-warnings`, or
//! unformatted files with `fmt --check`), 2 usage or I/O failure; `translate` adds 3
//! (incomplete), 4 (non-scenario) and 5 (the model's server could not be used).

pub mod align;
pub mod bench;
pub mod build;
pub mod bytecode;
pub mod check;
pub mod corpus;
pub mod eval;
pub mod explain;
pub mod files;
pub mod finetune;
pub mod fmt;
pub mod interchange;
pub mod llm;
pub mod manual;
pub mod output;
pub mod run;
pub mod search;
pub mod shard;
pub mod train_ego;

/// Output format of `check`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Human,
    Json,
    Sarif,
}

/// Exit statuses, in increasing precedence.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok = 0,
    Failed = 1,
    Usage = 2,
    /// `translate` ended with a valid but incomplete scenario.
    Incomplete = 3,
    /// `translate` ended with a non-scenario.
    NonScenario = 4,
    /// The language-model server could not be used.
    Unreachable = 5,
}

impl From<Status> for std::process::ExitCode {
    fn from(status: Status) -> Self {
        std::process::ExitCode::from(status as u8)
    }
}

/// `1 file`, `2 files`: a count with its noun in the right number (regular plurals).
pub fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}
