//! A client for OpenAI-compatible chat-completion servers (OpenAI, vLLM, SGLang, llama.cpp's
//! `llama-server`, llama-cpp-python, Ollama's `/v1`), for the LLM front-end.
//!
//! ```text
//! Request (messages: text and image parts, limits, Constraint) ──dialect──▶ JSON body
//!     ──reqwest, under a concurrency limit──▶ server
//!     ◀── JSON answer, or SSE chunks (streaming) ── Answer { text, finish, usage }
//!     ◀── an error status ── retried (connect errors, timeouts, 408/409/429/5xx, honouring
//!                             Retry-After) or mapped to an `Error` in words
//! ```
//!
//! Servers' answers are untrusted: bodies are read leniently, bounded in size, and an
//! unexpected shape is an error, never a panic. The API key is sent as a bearer token and
//! never printed: `Config`'s `Debug` hides it and error texts have it scrubbed. Every random
//! choice (the jitter of backoff) takes the configured seed.

mod config;
mod error;
mod request;
mod response;

use std::sync::{Arc, Mutex};
use std::time::Duration;

use futures_util::StreamExt;
use tokio::sync::Semaphore;

pub use config::{Config, ConfigError, Dialect, Overrides};
pub use error::{Error, ErrorKind};
pub use request::{Constraint, Message, Part, Request, Role, supports};
pub use response::{Answer, Finish, Usage};

/// A chat answer under way.
pub type ChatFuture<'a> = std::pin::Pin<Box<dyn std::future::Future<Output = Result<Answer, Error>> + Send + 'a>>;

/// Receives an answer's text piece by piece as it is written.
pub type OnText = dyn Fn(&str) + Sync;

/// What answers chat requests: a server through [`Client`], or a model in process
/// (`tad-local`). The front-end's loop is written against this.
pub trait Chat: Send + Sync {
    fn chat<'a>(&'a self, request: &'a Request) -> ChatFuture<'a>;
    /// As [`Chat::chat`], giving `on_text` the answer's text as it is written (the pieces
    /// concatenate to the answer's text). By default, the whole text at the end.
    fn chat_streaming<'a>(&'a self, request: &'a Request, on_text: &'a OnText) -> ChatFuture<'a> {
        Box::pin(async move {
            let answer = self.chat(request).await?;
            on_text(&answer.text);
            Ok(answer)
        })
    }
    /// Who answers, for provenance: `MODEL at URL`, `local smollm2-135m`.
    fn label(&self) -> String;
}

impl Chat for Client {
    fn chat<'a>(&'a self, request: &'a Request) -> ChatFuture<'a> {
        Box::pin(Client::chat(self, request, None))
    }

    fn chat_streaming<'a>(&'a self, request: &'a Request, on_text: &'a OnText) -> ChatFuture<'a> {
        let mut streamed = request.clone();
        streamed.stream = true;
        Box::pin(async move { Client::chat(self, &streamed, Some(on_text)).await })
    }

    fn label(&self) -> String {
        format!("{} at {}", self.config.model, self.config.base_url)
    }
}

/// The most bytes of a server's answer read (a program is a few kilobytes).
const MAX_BODY: usize = 8 << 20;

/// A chat client; cheap to clone, shared between concurrent tasks.
#[derive(Clone)]
pub struct Client {
    http: reqwest::Client,
    config: Arc<Config>,
    limit: Arc<Semaphore>,
    usage: Arc<Mutex<Usage>>,
}

impl Client {
    pub fn new(config: Config) -> Result<Client, Error> {
        let http = reqwest::Client::builder()
            .connect_timeout(config.connect_timeout)
            .build()
            .map_err(|e| Error::new(ErrorKind::Connect, format!("cannot set up the HTTP client: {e}")))?;
        let limit = Arc::new(Semaphore::new(config.concurrency.max(1)));
        Ok(Client { http, config: Arc::new(config), limit, usage: Arc::default() })
    }

    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The tokens used by every request so far.
    pub fn usage(&self) -> Usage {
        *self.usage.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// One chat completion, retried as the policy allows. `on_text` receives the answer's
    /// text as it streams in (when the request streams).
    pub async fn chat(&self, request: &Request, on_text: Option<&OnText>) -> Result<Answer, Error> {
        request.validate()?;
        if !supports(self.config.dialect, &request.constraint) {
            return Err(Error::new(
                ErrorKind::Request,
                format!("a `{}` server takes no grammar of this notation", self.config.dialect.name()),
            ));
        }
        let body = request::body(request, &self.config);
        let _permit = self.limit.acquire().await.map_err(|_| Error::new(ErrorKind::Connect, "the client is closed"))?;
        let mut attempt = 0u32;
        let mut server_errors = 0u32;
        loop {
            let result = self.once(&body, request.stream, on_text).await;
            let error = match result {
                Ok(mut answer) => {
                    answer.attempts = attempt + 1;
                    let mut usage = self.usage.lock().unwrap_or_else(|e| e.into_inner());
                    usage.add(answer.usage);
                    return Ok(answer);
                }
                Err(e) => e,
            };
            if error.kind == ErrorKind::Server {
                server_errors += 1;
            }
            // an identical body that failed with a server error twice will fail again
            let retry = error.retryable && attempt < self.config.max_retries && server_errors <= 2;
            if !retry {
                return Err(error.attempts(attempt + 1).scrub(self.config.api_key.as_deref()));
            }
            let delay = match error.retry_after {
                Some(wait) if wait > self.config.max_retry_after => {
                    let text = format!(
                        "{} (the server asks to wait {:.0} s, more than the {:.0} s allowed)",
                        error.message,
                        wait.as_secs_f64(),
                        self.config.max_retry_after.as_secs_f64()
                    );
                    return Err(Error { message: text, ..error }.attempts(attempt + 1));
                }
                Some(wait) => wait,
                None => self.backoff(attempt),
            };
            tokio::time::sleep(delay).await;
            attempt += 1;
        }
    }

    /// `min(base·2^n, 8 s)`, less up to a quarter by a jitter drawn from the seed.
    fn backoff(&self, attempt: u32) -> Duration {
        let base = self.config.backoff.as_secs_f64() * 2f64.powi(attempt.min(16) as i32);
        let capped = base.min(8.0);
        let jitter = 1.0 - 0.25 * unit_random(self.config.seed.wrapping_add(attempt as u64));
        Duration::from_secs_f64(capped * jitter)
    }

    async fn once(&self, body: &serde_json::Value, stream: bool, on_text: Option<&OnText>) -> Result<Answer, Error> {
        let url = format!("{}/chat/completions", self.config.base_url.trim_end_matches('/'));
        let mut builder = self.http.post(&url).json(body);
        if let Some(key) = &self.config.api_key {
            builder = builder.bearer_auth(key);
        }
        if !stream {
            builder = builder.timeout(self.config.timeout);
        }
        let response = builder.send().await.map_err(|e| Error::transport(&e, &url))?;
        let status = response.status();
        if !status.is_success() {
            let headers = response.headers().clone();
            let text = read_bounded(response).await.unwrap_or_default();
            return Err(Error::status(status.as_u16(), &headers, &text));
        }
        if stream {
            self.read_stream(response, on_text).await
        } else {
            let text = read_bounded(response).await?;
            response::parse(&text)
        }
    }

    async fn read_stream(&self, response: reqwest::Response, on_text: Option<&OnText>) -> Result<Answer, Error> {
        use eventsource_stream::Eventsource;
        let mut events = response.bytes_stream().eventsource();
        let mut answer = response::Streamed::default();
        loop {
            let next = tokio::time::timeout(self.config.idle_timeout, events.next()).await.map_err(|_| {
                Error::new(
                    ErrorKind::Timeout,
                    format!(
                        "the server sent nothing for {:.0} s while streaming",
                        self.config.idle_timeout.as_secs_f64()
                    ),
                )
                .retryable()
            })?;
            let Some(event) = next else { break };
            let event = event.map_err(|e| Error::new(ErrorKind::Protocol, format!("a broken event stream: {e}")))?;
            if event.data.trim() == "[DONE]" {
                break;
            }
            let piece = answer.feed(&event.event, &event.data)?;
            if let (Some(f), false) = (on_text, piece.is_empty()) {
                f(&piece);
            }
            if answer.len() > MAX_BODY {
                return Err(Error::new(ErrorKind::Protocol, "the streamed answer is larger than 8 MiB"));
            }
        }
        answer.finish()
    }
}

async fn read_bounded(mut response: reqwest::Response) -> Result<String, Error> {
    let mut bytes = Vec::new();
    while let Some(chunk) = response
        .chunk()
        .await
        .map_err(|e| Error::new(ErrorKind::Connect, format!("the answer broke off: {e}")).retryable())?
    {
        bytes.extend_from_slice(&chunk);
        if bytes.len() > MAX_BODY {
            return Err(Error::new(ErrorKind::Protocol, "the answer is larger than 8 MiB"));
        }
    }
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// A number in [0, 1) from a seed.
fn unit_random(seed: u64) -> f64 {
    use tad_base::Rng as _;
    tad_base::SplitMix64::new(seed).unit()
}
