//! Where the client sends requests and how it behaves, from (strongest first) the command
//! line, the environment (`TADSL_LLM_BASE_URL`, `TADSL_LLM_API_KEY`, `TADSL_LLM_MODEL`,
//! `TADSL_LLM_DIALECT`) and a TOML file.

use std::time::Duration;

use serde::Deserialize;

/// How a server spells what the OpenAI API does not have (grammars, schemas).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Dialect {
    /// OpenAI: `response_format` with a JSON Schema; no free grammar on chat output.
    #[default]
    OpenAi,
    /// vLLM 0.12 and later: `structured_outputs` (`grammar`, `json`).
    Vllm,
    /// vLLM before 0.12: `guided_grammar`, `guided_json`.
    VllmLegacy,
    /// SGLang: `ebnf`, `response_format`.
    Sglang,
    /// llama.cpp's `llama-server` and llama-cpp-python: `grammar` (GBNF), `json_schema`.
    LlamaCpp,
}

impl Dialect {
    pub const NAMES: &[(&str, Dialect)] = &[
        ("openai", Dialect::OpenAi),
        ("vllm", Dialect::Vllm),
        ("vllm-legacy", Dialect::VllmLegacy),
        ("sglang", Dialect::Sglang),
        ("llama-cpp", Dialect::LlamaCpp),
    ];

    pub fn parse(name: &str) -> Option<Dialect> {
        Self::NAMES.iter().find(|(n, _)| *n == name).map(|(_, d)| *d)
    }

    pub fn name(self) -> &'static str {
        Self::NAMES.iter().find(|(_, d)| *d == self).map(|(n, _)| *n).unwrap_or("openai")
    }
}

#[derive(Clone)]
pub struct Config {
    /// Up to and including `/v1`: `http://127.0.0.1:8080/v1`.
    pub base_url: String,
    pub api_key: Option<String>,
    pub model: String,
    pub dialect: Dialect,
    /// A whole non-streaming request.
    pub timeout: Duration,
    pub connect_timeout: Duration,
    /// The longest silence between two chunks of a streamed answer.
    pub idle_timeout: Duration,
    pub max_retries: u32,
    /// The first backoff delay; each retry doubles it, up to 8 s.
    pub backoff: Duration,
    /// The longest `Retry-After` obeyed; a server asking for more fails the request.
    pub max_retry_after: Duration,
    /// Requests in flight at once.
    pub concurrency: usize,
    /// `max_tokens`, or `max_completion_tokens` for OpenAI's reasoning models.
    pub max_tokens_field: String,
    pub seed: u64,
}

impl std::fmt::Debug for Config {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Config")
            .field("base_url", &self.base_url)
            .field("api_key", &self.api_key.as_ref().map(|_| "(hidden)"))
            .field("model", &self.model)
            .field("dialect", &self.dialect)
            .field("timeout", &self.timeout)
            .field("max_retries", &self.max_retries)
            .field("concurrency", &self.concurrency)
            .finish_non_exhaustive()
    }
}

impl Config {
    pub fn new(base_url: impl Into<String>, model: impl Into<String>) -> Config {
        Config {
            base_url: base_url.into(),
            api_key: None,
            model: model.into(),
            dialect: Dialect::default(),
            timeout: Duration::from_secs(600),
            connect_timeout: Duration::from_secs(5),
            idle_timeout: Duration::from_secs(120),
            max_retries: 2,
            backoff: Duration::from_millis(500),
            max_retry_after: Duration::from_secs(60),
            concurrency: 4,
            max_tokens_field: "max_tokens".into(),
            seed: 0,
        }
    }
}

/// What the command line says; `None` leaves it to the environment and the file.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub base_url: Option<String>,
    pub model: Option<String>,
    pub dialect: Option<String>,
    pub timeout: Option<f64>,
    pub max_retries: Option<u32>,
    pub concurrency: Option<usize>,
}

/// The configuration file's keys (all optional). The key itself is better named by
/// `api_key_env` than written in the file.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    base_url: Option<String>,
    api_key: Option<String>,
    api_key_env: Option<String>,
    model: Option<String>,
    dialect: Option<String>,
    timeout: Option<f64>,
    connect_timeout: Option<f64>,
    idle_timeout: Option<f64>,
    max_retries: Option<u32>,
    concurrency: Option<usize>,
    max_tokens_field: Option<String>,
}

#[derive(Debug, PartialEq, Eq)]
pub struct ConfigError(pub String);

impl std::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl Config {
    /// The configuration from the command line, the environment (`env`) and a file's text
    /// (`file`: its name and TOML text); `Ok(None)` when none of them names a server.
    pub fn resolve(
        cli: &Overrides,
        env: &dyn Fn(&str) -> Option<String>,
        file: Option<(&str, &str)>,
        seed: u64,
    ) -> Result<Option<Config>, ConfigError> {
        let parsed: File = match file {
            Some((name, text)) => toml::from_str(text).map_err(|e| ConfigError(format!("{name}: {}", e.message())))?,
            None => File::default(),
        };
        let env = |k: &str| env(k).filter(|v| !v.trim().is_empty());
        let Some(base_url) = cli.base_url.clone().or_else(|| env("TADSL_LLM_BASE_URL")).or(parsed.base_url) else {
            return Ok(None);
        };
        if !(base_url.starts_with("http://") || base_url.starts_with("https://")) {
            return Err(ConfigError(format!(
                "the server address `{base_url}` does not start with http:// or https://"
            )));
        }
        let model =
            cli.model.clone().or_else(|| env("TADSL_LLM_MODEL")).or(parsed.model).unwrap_or_else(|| "default".into());
        let mut config = Config::new(base_url, model);
        config.api_key = env("TADSL_LLM_API_KEY")
            .or_else(|| parsed.api_key_env.as_deref().and_then(&env))
            .or(parsed.api_key)
            .filter(|k| !k.is_empty());
        if let Some(name) = cli.dialect.clone().or_else(|| env("TADSL_LLM_DIALECT")).or(parsed.dialect) {
            config.dialect = Dialect::parse(&name).ok_or_else(|| {
                let names: Vec<&str> = Dialect::NAMES.iter().map(|(n, _)| *n).collect();
                ConfigError(format!("unknown server dialect `{name}` (one of: {})", names.join(", ")))
            })?;
        }
        let seconds = |s: f64, what: &str| {
            if s.is_finite() && s > 0.0 && s < 1e6 {
                Ok(Duration::from_secs_f64(s))
            } else {
                Err(ConfigError(format!("{what} must be a positive number of seconds, not {s}")))
            }
        };
        if let Some(t) = cli.timeout.or(parsed.timeout) {
            config.timeout = seconds(t, "the timeout")?;
        }
        if let Some(t) = parsed.connect_timeout {
            config.connect_timeout = seconds(t, "the connect timeout")?;
        }
        if let Some(t) = parsed.idle_timeout {
            config.idle_timeout = seconds(t, "the idle timeout")?;
        }
        if let Some(n) = cli.max_retries.or(parsed.max_retries) {
            config.max_retries = n.min(10);
        }
        if let Some(n) = cli.concurrency.or(parsed.concurrency) {
            config.concurrency = n.clamp(1, 256);
        }
        if let Some(field) = parsed.max_tokens_field {
            config.max_tokens_field = field;
        }
        config.seed = seed;
        Ok(Some(config))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(pairs: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |k| pairs.iter().find(|(n, _)| *n == k).map(|(_, v)| v.to_string())
    }

    #[test]
    fn the_command_line_beats_the_environment_which_beats_the_file() {
        let file = "base_url = \"http://file/v1\"\nmodel = \"m-file\"\napi_key_env = \"MY_KEY\"\ndialect = \"vllm\"\n";
        let e = env(&[("TADSL_LLM_MODEL", "m-env"), ("MY_KEY", "sk-secret")]);
        let cli = Overrides { base_url: Some("http://cli/v1".into()), ..Default::default() };
        let c = Config::resolve(&cli, &e, Some(("llm.toml", file)), 1).unwrap().unwrap();
        assert_eq!((c.base_url.as_str(), c.model.as_str(), c.dialect), ("http://cli/v1", "m-env", Dialect::Vllm));
        assert_eq!(c.api_key.as_deref(), Some("sk-secret"));
        assert!(!format!("{c:?}").contains("sk-secret"));
    }

    #[test]
    fn no_server_anywhere_is_none_and_mistakes_are_named() {
        assert!(Config::resolve(&Overrides::default(), &env(&[]), None, 0).unwrap().is_none());
        let bad = Config::resolve(&Overrides::default(), &env(&[]), Some(("f.toml", "base_url = 3")), 0);
        assert!(bad.unwrap_err().0.starts_with("f.toml: "));
        let cli = Overrides { base_url: Some("ftp://x".into()), ..Default::default() };
        assert!(Config::resolve(&cli, &env(&[]), None, 0).is_err());
        let cli = Overrides { base_url: Some("http://x".into()), dialect: Some("gpt".into()), ..Default::default() };
        assert!(Config::resolve(&cli, &env(&[]), None, 0).unwrap_err().0.contains("llama-cpp"));
    }
}
