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

/// An ego flag's value (`--ego`, `--egos`, `--search-ego`): any text, checked where the
/// policies are made; its named values are offered by help and shell completion
/// ([`tad_policy::named_egos`], `learned:PATH`, `external:CMD`).
#[derive(Clone, Copy, Debug)]
pub struct EgoNames;

impl clap::builder::TypedValueParser for EgoNames {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        clap::builder::StringValueParser::new().parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        use clap::builder::PossibleValue;
        let named = tad_policy::named_egos().into_iter().map(|(name, what)| PossibleValue::new(name).help(what));
        let with_argument = [
            PossibleValue::new("learned:").help("learned:PATH, an actor in safetensors (train-ego's, SafeBench's SAC)"),
            PossibleValue::new("external:").help("external:CMD, a process answering JSON lines"),
        ];
        Some(Box::new(named.chain(with_argument)))
    }
}

/// A count flag's value from 1 to `MAX`: numbers that would only exhaust memory or time
/// are usage errors before anything is allocated. The bounds are in the flags' help.
pub fn count<const MAX: usize>(text: &str) -> Result<usize, String> {
    let n: usize = text.trim().parse().map_err(|_| format!("`{text}` is not a whole number"))?;
    if n == 0 || n > MAX {
        return Err(format!("must be from 1 to {MAX}"));
    }
    Ok(n)
}
