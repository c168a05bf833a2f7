//! A failed request in words, with what the retry policy needs to know: whether trying
//! again can help and how long the server asked to wait.
//!
//! Error bodies differ by server (OpenAI and llama.cpp nest an `error` object, older vLLM
//! is flat, FastAPI says `detail`); they are read in that order, then as plain text.

use std::time::Duration;

use reqwest::header::HeaderMap;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The request itself is wrong (4xx): retrying cannot help.
    Request,
    /// No key, a wrong key, or no access to the model.
    Auth,
    /// Rate limited (429).
    RateLimit,
    /// The account has no quota left.
    Quota,
    /// The prompt does not fit the model's context.
    ContextOverflow,
    /// The server failed (5xx).
    Server,
    Timeout,
    /// No connection, or it broke.
    Connect,
    /// The answer is not what the API specifies.
    Protocol,
}

#[derive(Clone, Debug)]
pub struct Error {
    pub kind: ErrorKind,
    pub message: String,
    pub status: Option<u16>,
    pub retryable: bool,
    pub retry_after: Option<Duration>,
    /// How many requests were sent.
    pub attempts: u32,
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)?;
        if self.attempts > 1 {
            write!(f, " (after {} attempts)", self.attempts)?;
        }
        Ok(())
    }
}

impl std::error::Error for Error {}

impl Error {
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Error {
        Error { kind, message: message.into(), status: None, retryable: false, retry_after: None, attempts: 0 }
    }

    pub(crate) fn retryable(mut self) -> Error {
        self.retryable = true;
        self
    }

    pub(crate) fn attempts(mut self, n: u32) -> Error {
        self.attempts = n;
        self
    }

    /// The message without the API key, should a server echo it.
    pub(crate) fn scrub(mut self, key: Option<&str>) -> Error {
        if let Some(key) = key.filter(|k| k.len() >= 4) {
            self.message = self.message.replace(key, "(key)");
        }
        self
    }

    pub(crate) fn transport(e: &reqwest::Error, url: &str) -> Error {
        if e.is_timeout() {
            Error::new(ErrorKind::Timeout, format!("{url} did not answer in time")).retryable()
        } else if e.is_connect() {
            Error::new(ErrorKind::Connect, format!("cannot connect to {url}: is the server running?")).retryable()
        } else {
            Error::new(ErrorKind::Connect, format!("the request to {url} failed: {}", root_cause(e))).retryable()
        }
    }

    /// An error status with its body and headers.
    pub(crate) fn status(status: u16, headers: &HeaderMap, body: &str) -> Error {
        let (message, code, kind_text) = read_body(body);
        let lower = format!("{message} {code} {kind_text}").to_ascii_lowercase();
        let kind = match status {
            401 | 403 => ErrorKind::Auth,
            429 if lower.contains("insufficient_quota") || lower.contains("quota") => ErrorKind::Quota,
            429 => ErrorKind::RateLimit,
            400 | 413
                if lower.contains("context_length_exceeded")
                    || lower.contains("exceed_context_size")
                    || lower.contains("context length")
                    || lower.contains("maximum context") =>
            {
                ErrorKind::ContextOverflow
            }
            s if s >= 500 => ErrorKind::Server,
            _ => ErrorKind::Request,
        };
        let what = match kind {
            ErrorKind::Auth => "the server refused the API key (set TADSL_LLM_API_KEY)",
            ErrorKind::Quota => "the account's quota is used up",
            ErrorKind::RateLimit => "the server is rate limiting",
            ErrorKind::ContextOverflow => "the prompt is longer than the model's context",
            ErrorKind::Server => "the server failed",
            _ => "the server rejected the request",
        };
        // llama-cpp-python reports request problems as 500: those never get better
        let hopeless = lower.contains("validation") || lower.contains("cannot use both");
        let mut retryable =
            matches!(status, 408 | 409 | 429) && kind != ErrorKind::Quota || (status >= 500 && !hopeless);
        match headers.get("x-should-retry").and_then(|v| v.to_str().ok()) {
            Some("true") => retryable = true,
            Some("false") => retryable = false,
            _ => {}
        }
        let detail = if message.is_empty() { String::new() } else { format!(": {}", clip(&message, 500)) };
        Error {
            kind,
            message: format!("{what} (HTTP {status}){detail}"),
            status: Some(status),
            retryable,
            retry_after: retry_after(headers),
            attempts: 0,
        }
    }
}

fn root_cause(e: &dyn std::error::Error) -> String {
    let mut cause = e;
    while let Some(next) = cause.source() {
        cause = next;
    }
    cause.to_string()
}

fn clip(s: &str, max: usize) -> String {
    let s: String = s.chars().filter(|c| !c.is_control() || *c == ' ').collect();
    if s.chars().count() <= max { s } else { format!("{}…", s.chars().take(max).collect::<String>()) }
}

/// (message, code, type) from any of the servers' error shapes.
fn read_body(body: &str) -> (String, String, String) {
    let text = |v: Option<&serde_json::Value>| match v {
        Some(serde_json::Value::String(s)) => s.clone(),
        Some(serde_json::Value::Null) | None => String::new(),
        Some(other) => other.to_string(),
    };
    match serde_json::from_str::<serde_json::Value>(body) {
        Ok(v) => {
            let inner = v.get("error").filter(|e| e.is_object()).unwrap_or(&v);
            let message = match (inner.get("message"), v.get("error"), v.get("detail")) {
                (Some(m), _, _) => text(Some(m)),
                (None, Some(serde_json::Value::String(s)), _) => s.clone(),
                (None, _, Some(d)) => text(Some(d)),
                _ => body.trim().to_string(),
            };
            (message, text(inner.get("code")), text(inner.get("type")))
        }
        Err(_) => (body.trim().to_string(), String::new(), String::new()),
    }
}

/// `retry-after-ms`, then `retry-after` in seconds.
fn retry_after(headers: &HeaderMap) -> Option<Duration> {
    let get = |name: &str| headers.get(name).and_then(|v| v.to_str().ok()).and_then(|v| v.trim().parse::<f64>().ok());
    let seconds = get("retry-after-ms").map(|ms| ms / 1000.0).or_else(|| get("retry-after"))?;
    (seconds.is_finite() && seconds >= 0.0).then(|| Duration::from_secs_f64(seconds.min(1e6)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn status(code: u16, body: &str, headers: &[(&'static str, &str)]) -> Error {
        let mut map = HeaderMap::new();
        for (k, v) in headers {
            map.insert(*k, v.parse().unwrap());
        }
        Error::status(code, &map, body)
    }

    #[test]
    fn every_servers_error_shape_is_read() {
        let openai = status(
            400,
            r#"{"error":{"message":"too long","type":"invalid_request_error","code":"context_length_exceeded"}}"#,
            &[],
        );
        assert_eq!((openai.kind, openai.retryable), (ErrorKind::ContextOverflow, false));
        let llama = status(
            400,
            r#"{"error":{"code":400,"message":"Failed to initialize samplers: failed to parse grammar","type":"invalid_request_error"}}"#,
            &[],
        );
        assert_eq!(llama.kind, ErrorKind::Request);
        assert!(llama.message.contains("failed to parse grammar"), "{}", llama.message);
        let vllm = status(400, r#"{"object":"error","message":"bad","type":"BadRequestError","code":400}"#, &[]);
        assert!(vllm.message.ends_with(": bad"));
        let fastapi = status(422, r#"{"detail":[{"msg":"field required"}]}"#, &[]);
        assert!(fastapi.message.contains("field required"));
        let plain = status(502, "<html>bad gateway</html>", &[]);
        assert_eq!((plain.kind, plain.retryable), (ErrorKind::Server, true));
        let validation =
            status(500, r#"{"error":{"message":"1 validation error","type":"internal_server_error"}}"#, &[]);
        assert!(!validation.retryable);
    }

    #[test]
    fn rate_limits_wait_as_told_and_quota_is_final() {
        let limited = status(429, "{}", &[("retry-after", "2")]);
        assert_eq!(
            (limited.kind, limited.retryable, limited.retry_after),
            (ErrorKind::RateLimit, true, Some(Duration::from_secs(2)))
        );
        let ms = status(429, "{}", &[("retry-after-ms", "250"), ("retry-after", "9")]);
        assert_eq!(ms.retry_after, Some(Duration::from_millis(250)));
        let quota =
            status(429, r#"{"error":{"message":"You exceeded your current quota","code":"insufficient_quota"}}"#, &[]);
        assert_eq!((quota.kind, quota.retryable), (ErrorKind::Quota, false));
        let told = status(400, "{}", &[("x-should-retry", "true")]);
        assert!(told.retryable);
    }
}
