//! The `tadslc` library: the command line's subcommands ([`cmd`]), what several of them
//! share (reading corpora, files and scenes, the language-model flags), and the output
//! module, the only one that prints; shared with its tests.
//!
//! Exit statuses are [`Status`]; [`EXIT_STATUSES`] says them in one sentence, the same in
//! `--help`, README.md and spec/output.md (a test holds them together).

pub mod cmd;
pub mod corpus;
pub mod files;
pub mod llm;
pub mod output;
pub mod scenes;

/// The exit statuses in one sentence (a macro, so `--help` can `concat!` it).
#[macro_export]
macro_rules! exit_statuses {
    () => {
        "Exit status: 0 success, 1 the input has errors, 2 usage or I/O failure; 3 incomplete and 4 non-scenario (`translate`); 5 the model's server could not be used (`translate`, `gen`, `synth`). The table is in spec/output.md."
    };
}

/// [`exit_statuses!`] as a constant.
pub const EXIT_STATUSES: &str = exit_statuses!();

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

pub use tad_base::plural;

/// A count flag's value from 1 to `MAX`: numbers that would only exhaust memory or time
/// are usage errors before anything is allocated. The bounds are in the flags' help.
pub fn count<const MAX: usize>(text: &str) -> Result<usize, String> {
    let n: usize = text.trim().parse().map_err(|_| format!("`{text}` is not a whole number"))?;
    if n == 0 || n > MAX {
        return Err(format!("must be from 1 to {MAX}"));
    }
    Ok(n)
}
