//! Who answers: a server (`tad-llm`'s client) or the model in process (`tad-local`).
//!
//! [`Choice`] is what a user chose (flags, environment, a TOML file); [`Choice::open`] picks
//! the server those name, else the local model, with the reason in its error when neither
//! can be used. The config file is `--llm-config`, else `TADSL_LLM_CONFIG`, else
//! `$XDG_CONFIG_HOME/tadsl/llm.toml`; the environment is `TADSL_LLM_BASE_URL`,
//! `TADSL_LLM_API_KEY`, `TADSL_LLM_MODEL` and `TADSL_LLM_DIALECT`.

use std::path::{Path, PathBuf};

use tad_check::{Options, Vocabulary};
use tad_llm::{Chat, Client, Config, Constraint, Overrides};

use crate::Checker;

/// What a user chose; `None` leaves a setting to the environment and the config file.
#[derive(Clone, Debug, Default)]
pub struct Choice {
    pub base_url: Option<String>,
    /// A server's model name, or `local` / `local:NAME` for the model in process.
    pub model: Option<String>,
    pub dialect: Option<String>,
    pub config_file: Option<PathBuf>,
    pub timeout: Option<f64>,
    pub max_retries: Option<u32>,
    /// A LoRA adapter (a PEFT directory) for the local model.
    pub adapter: Option<PathBuf>,
    /// Threads of the local model.
    pub threads: usize,
    /// Seed of the client's backoff.
    pub seed: u64,
}

/// A server, or the model in process.
pub enum Backend {
    Server(Client),
    Local(tad_local::LocalChat),
}

impl Choice {
    /// The server the choice, the environment and the config file name, or the local model
    /// when they name none (or `model` is `local`); `concurrency` requests at once.
    pub fn open(&self, concurrency: usize) -> Result<Backend, String> {
        if let Some(name) = self.local_name() {
            return self.local(name, None);
        }
        match self.server(concurrency)? {
            Some(_) if self.adapter.is_some() => {
                Err("--adapter applies to the local model only, and a server is configured (pass --model local)".into())
            }
            Some(config) => Ok(Backend::Server(Client::new(config).map_err(|e| e.to_string())?)),
            None => self.local(
                None,
                Some(" (no server is configured: set TADSL_LLM_BASE_URL, e.g. http://127.0.0.1:8080/v1, or pass --base-url to use one)"),
            ),
        }
    }

    /// The server the choice, the environment and the config file name; `None` when they
    /// name none, or the model is `local` (nothing is loaded either way).
    pub fn server(&self, concurrency: usize) -> Result<Option<Config>, String> {
        if self.local_name().is_some() {
            return Ok(None);
        }
        let file = config_file(self.config_file.as_deref())?;
        let overrides = Overrides {
            base_url: self.base_url.clone(),
            model: self.model.clone(),
            dialect: self.dialect.clone(),
            timeout: self.timeout,
            max_retries: self.max_retries,
            concurrency: Some(concurrency),
        };
        let env = |k: &str| std::env::var(k).ok();
        Config::resolve(&overrides, &env, file.as_ref().map(|(n, t)| (n.as_str(), t.as_str())), self.seed)
            .map_err(|e| e.to_string())
    }

    /// Whether `--model` names the local model (`local`, `local:NAME`), and which
    /// (`None`: the default).
    fn local_name(&self) -> Option<Option<&str>> {
        let name = self.model.as_deref()?.strip_prefix("local")?;
        Some(name.strip_prefix(':').filter(|n| !n.is_empty()))
    }

    /// The local model `name`; without one, the model `--adapter` was trained on (its
    /// `base_model_name_or_path`, when it is one of ours), else the default.
    fn local(&self, name: Option<&str>, why: Option<&str>) -> Result<Backend, String> {
        let adapter = self.adapter.as_deref().map(tad_local::Adapter::load).transpose()?;
        let trained_on = adapter.as_ref().and_then(|a| tad_local::MODELS.iter().find(|m| m.upstream == a.base_model));
        let name = name.or(trained_on.map(|m| m.name)).unwrap_or(tad_local::DEFAULT);
        let model = tad_local::model(name).ok_or_else(|| {
            let names: Vec<&str> = tad_local::MODELS.iter().map(|m| m.name).collect();
            format!("unknown local model `{name}` (the local models are: {})", names.join(", "))
        })?;
        let chat = tad_local::LocalChat::load_with(model, self.threads, adapter.as_ref())
            .map_err(|e| format!("{e}{}", why.unwrap_or("")))?;
        Ok(Backend::Local(chat))
    }
}

/// The config file named, or the default one when it exists: its name and text.
fn config_file(explicit: Option<&Path>) -> Result<Option<(String, String)>, String> {
    let path = match explicit {
        Some(p) => Some(p.to_path_buf()),
        None => std::env::var_os("TADSL_LLM_CONFIG").map(PathBuf::from).or_else(|| {
            let base = std::env::var_os("XDG_CONFIG_HOME")
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
            Some(base.join("tadsl/llm.toml")).filter(|p| p.exists())
        }),
    };
    let Some(path) = path else { return Ok(None) };
    let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    Ok(Some((path.display().to_string(), text)))
}

impl Backend {
    pub fn chat(&self) -> &dyn Chat {
        match self {
            Backend::Server(c) => c,
            Backend::Local(l) => l,
        }
    }

    /// Whether decoding is constrained: when asked, and always for the local model (its
    /// decoder follows the grammar in process) unless `unconstrained`.
    pub fn constrained(&self, asked: bool, unconstrained: bool) -> bool {
        !unconstrained && (asked || matches!(self, Backend::Local(_)))
    }

    /// The constraint for `vocabulary`: the server dialect's choice ([`crate::constraint`]),
    /// or the Lark grammar the local model's decoder follows in process.
    pub fn constraint(&self, vocabulary: &Vocabulary, modules: &[String]) -> Constraint {
        match self {
            Backend::Server(c) => crate::constraint(c.config().dialect, vocabulary, modules),
            Backend::Local(_) => {
                Constraint::Lark(tad_grammar::export(tad_grammar::Format::Lark, vocabulary, modules, "TAD"))
            }
        }
    }

    /// The constraint for a region's scope (every standard module when `None`), or none
    /// when decoding is not constrained.
    pub fn constraint_for(&self, constrained: bool, region: Option<&str>) -> Result<Constraint, String> {
        if !constrained {
            return Ok(Constraint::None);
        }
        let (vocabulary, modules) = tad_grammar::scope(region)?;
        Ok(self.constraint(&vocabulary, &modules))
    }
}

/// The checker of a region's answers (an unknown region is refused).
pub fn checker(region: Option<&str>) -> Result<Checker, String> {
    if let Some(r) = region {
        tad_grammar::scope(Some(r))?;
    }
    Ok(Checker { options: Options { region: region.map(String::from), ..Options::default() } })
}

/// The async runtime the pipelines run on.
pub fn runtime() -> Result<tokio::runtime::Runtime, String> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the async runtime: {e}"))
}
