//! The flags every language-model subcommand (`translate`, `synth`, `gen`, `eval`'s llm
//! generators) shares, and what they do with them: who answers (`tad_frontend::backend`:
//! the flags, then the environment and a TOML file, else the local model), the loop's
//! bounds, the session, the exit status an outcome's class names (`spec/output.md`).

use std::path::{Path, PathBuf};
use std::time::Duration;

use tad_frontend::backend::{Backend, Choice};
use tad_frontend::translate::{self};
use tad_frontend::{Checker, Limits, Session, Summary};
use tad_llm::Constraint;

use crate::output::CliError;
use crate::{Status, errln};

/// The flags every LLM subcommand shares.
#[derive(Clone, Debug, clap::Args)]
pub struct LlmArgs {
    /// The server, up to `/v1` (default: TADSL_LLM_BASE_URL)
    #[arg(long, value_name = "URL")]
    pub base_url: Option<String>,
    /// The model name sent to the server (default: TADSL_LLM_MODEL), or `local` (`local:NAME`)
    /// for the model in process, the default when no server is configured
    #[arg(long)]
    pub model: Option<String>,
    /// How the server takes grammars: openai, vllm, vllm-legacy, sglang, llama-cpp
    #[arg(long)]
    pub dialect: Option<String>,
    /// A TOML file with base_url, model, dialect, api_key_env, timeout, ...
    #[arg(long, value_name = "FILE")]
    pub llm_config: Option<PathBuf>,
    /// Constrain decoding to TAD's grammar (GBNF) or, on OpenAI, the YAML form's JSON Schema
    #[arg(long)]
    pub constrain: bool,
    /// Do not constrain the local model's decoding (for comparisons)
    #[arg(long, conflicts_with = "constrain")]
    pub unconstrained: bool,
    /// Repair and refinement requests after the first answer
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub max_rounds: u32,
    /// Tokens per answer
    #[arg(long, value_name = "N", default_value_t = 1024)]
    pub max_tokens: u32,
    /// Tokens (prompt and answers) per item
    #[arg(long, value_name = "N", default_value_t = 60_000)]
    pub token_budget: u64,
    /// Seconds per item
    #[arg(long, value_name = "S", default_value_t = 600)]
    pub deadline: u64,
    /// Seconds per request
    #[arg(long, value_name = "S")]
    pub timeout: Option<f64>,
    /// Retries of a failed request
    #[arg(long, value_name = "N")]
    pub max_retries: Option<u32>,
    /// Sampling temperature
    #[arg(long)]
    pub temperature: Option<f64>,
    /// Threads of the local model
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub threads: usize,
    /// A LoRA adapter for the local model (a PEFT directory, as `tadslc finetune` writes)
    #[arg(long, value_name = "DIR")]
    pub adapter: Option<PathBuf>,
    /// Seed of the requests (and of the client's backoff)
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

impl LlmArgs {
    /// Who answers, as the flags choose (the environment and config file fill the rest).
    pub(crate) fn open(&self, concurrency: usize) -> Result<Backend, String> {
        self.choice().open(concurrency)
    }

    /// Whether a server answers (not the local model), loading nothing.
    pub(crate) fn names_server(&self) -> Result<bool, String> {
        Ok(self.choice().server(1)?.is_some())
    }

    fn choice(&self) -> Choice {
        Choice {
            base_url: self.base_url.clone(),
            model: self.model.clone(),
            dialect: self.dialect.clone(),
            config_file: self.llm_config.clone(),
            timeout: self.timeout,
            max_retries: self.max_retries,
            adapter: self.adapter.clone(),
            threads: self.threads,
            seed: self.seed,
        }
    }

    pub(crate) fn constrained(&self, backend: &Backend) -> bool {
        backend.constrained(self.constrain, self.unconstrained)
    }

    pub(crate) fn limits(&self) -> Limits {
        Limits {
            max_rounds: self.max_rounds.min(10),
            max_tokens: self.max_tokens.clamp(16, 32_768),
            token_budget: self.token_budget,
            deadline: Duration::from_secs(self.deadline.max(1)),
        }
    }

    /// A session of `backend` checking against `checker`.
    pub(crate) fn session<'a>(
        &self,
        backend: &'a Backend,
        checker: &'a Checker,
        constraint: Constraint,
        temperature: f64,
    ) -> Session<'a> {
        Session {
            client: backend.chat(),
            checker,
            limits: self.limits(),
            constraint,
            temperature: self.temperature.unwrap_or(temperature),
            seed: Some(self.seed),
            on_text: None,
        }
    }
}

pub(crate) fn status_of(outcome: &tad_frontend::Outcome) -> Status {
    match outcome.class {
        Some("complete") => Status::Ok,
        Some("incomplete") => Status::Incomplete,
        Some("non_scenario") => Status::NonScenario,
        _ if outcome.unreachable() => Status::Unreachable,
        _ => Status::Failed,
    }
}

/// The summary on standard error, and in `dir/summary.json` with `extra` beside it.
pub(crate) fn report_summary(dir: Option<&Path>, summary: &Summary, extra: serde_json::Value) -> Result<(), CliError> {
    errln!("{}", summary.render())?;
    match dir {
        Some(dir) => translate::write_summary(dir, summary, extra).map_err(CliError::usage),
        None => Ok(()),
    }
}
