//! Answers, read leniently: servers add fields of their own (`timings`, `reasoning_content`,
//! `system_fingerprint`), send `content: null`, or end a stream with a usage-only chunk.

use serde::Deserialize;

use crate::error::{Error, ErrorKind};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Usage {
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
}

impl Usage {
    pub fn add(&mut self, other: Usage) {
        self.prompt_tokens += other.prompt_tokens;
        self.completion_tokens += other.completion_tokens;
    }

    pub fn total(&self) -> u64 {
        self.prompt_tokens + self.completion_tokens
    }
}

/// Why the model stopped.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Finish {
    Stop,
    /// `max_tokens` was reached: the program is likely cut off.
    Length,
    ContentFilter,
    Other(String),
}

impl Finish {
    fn parse(s: Option<&str>) -> Finish {
        match s {
            Some("stop") | Some("eos") | None => Finish::Stop,
            Some("length") => Finish::Length,
            Some("content_filter") => Finish::ContentFilter,
            Some(other) => Finish::Other(other.chars().take(40).collect()),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Answer {
    pub text: String,
    pub finish: Finish,
    pub usage: Usage,
    /// The model the server says answered.
    pub model: String,
    pub attempts: u32,
}

#[derive(Deserialize, Default)]
struct RawUsage {
    #[serde(default)]
    prompt_tokens: Option<u64>,
    #[serde(default)]
    completion_tokens: Option<u64>,
}

impl From<RawUsage> for Usage {
    fn from(u: RawUsage) -> Usage {
        Usage { prompt_tokens: u.prompt_tokens.unwrap_or(0), completion_tokens: u.completion_tokens.unwrap_or(0) }
    }
}

#[derive(Deserialize)]
struct RawMessage {
    #[serde(default)]
    content: Option<String>,
    #[serde(default)]
    refusal: Option<String>,
}

#[derive(Deserialize)]
struct RawChoice {
    #[serde(default)]
    message: Option<RawMessage>,
    #[serde(default)]
    delta: Option<RawMessage>,
    #[serde(default)]
    finish_reason: Option<String>,
}

#[derive(Deserialize)]
struct RawAnswer {
    #[serde(default)]
    choices: Vec<RawChoice>,
    #[serde(default)]
    usage: Option<RawUsage>,
    #[serde(default)]
    model: Option<String>,
    #[serde(default)]
    error: Option<serde_json::Value>,
}

fn protocol(what: impl Into<String>) -> Error {
    Error::new(ErrorKind::Protocol, what)
}

fn server_error(error: &serde_json::Value) -> Error {
    let message = error.get("message").and_then(|m| m.as_str()).unwrap_or("no message");
    Error::new(
        ErrorKind::Server,
        format!("the server reported an error: {}", message.chars().take(500).collect::<String>()),
    )
}

/// A whole (non-streamed) answer.
pub(crate) fn parse(text: &str) -> Result<Answer, Error> {
    let raw: RawAnswer = serde_json::from_str(text)
        .map_err(|e| protocol(format!("the server's answer is not a chat completion ({e})")))?;
    if let Some(error) = &raw.error {
        return Err(server_error(error));
    }
    let choice = raw.choices.into_iter().next().ok_or_else(|| protocol("the server's answer has no choices"))?;
    let message = choice.message.ok_or_else(|| protocol("the server's answer has no message"))?;
    let text = match (message.content, message.refusal) {
        (Some(t), _) => t,
        (None, Some(refusal)) => return Err(Error::new(ErrorKind::Request, format!("the model refused: {refusal}"))),
        (None, None) => String::new(),
    };
    Ok(Answer {
        text,
        finish: Finish::parse(choice.finish_reason.as_deref()),
        usage: raw.usage.map(Usage::from).unwrap_or_default(),
        model: raw.model.unwrap_or_default(),
        attempts: 1,
    })
}

/// A streamed answer as its chunks arrive.
#[derive(Default)]
pub(crate) struct Streamed {
    text: String,
    finish: Option<String>,
    usage: Usage,
    model: String,
    chunks: usize,
}

impl Streamed {
    /// Takes one event; returns the text it adds.
    pub(crate) fn feed(&mut self, event: &str, data: &str) -> Result<String, Error> {
        if event == "error" {
            let value: serde_json::Value = serde_json::from_str(data).unwrap_or(serde_json::json!({ "message": data }));
            return Err(server_error(value.get("error").unwrap_or(&value)));
        }
        let raw: RawAnswer =
            serde_json::from_str(data).map_err(|e| protocol(format!("a streamed chunk is not JSON ({e})")))?;
        if let Some(error) = &raw.error {
            return Err(server_error(error));
        }
        self.chunks += 1;
        if let Some(model) = raw.model {
            self.model = model;
        }
        if let Some(usage) = raw.usage {
            self.usage = usage.into();
        }
        let mut added = String::new();
        for choice in raw.choices {
            if let Some(piece) = choice.delta.and_then(|d| d.content) {
                added.push_str(&piece);
            }
            if choice.finish_reason.is_some() {
                self.finish = choice.finish_reason;
            }
        }
        self.text.push_str(&added);
        Ok(added)
    }

    pub(crate) fn len(&self) -> usize {
        self.text.len()
    }

    pub(crate) fn finish(self) -> Result<Answer, Error> {
        if self.chunks == 0 {
            return Err(protocol("the stream ended before any chunk").retryable());
        }
        Ok(Answer {
            text: self.text,
            finish: Finish::parse(self.finish.as_deref()),
            usage: self.usage,
            model: self.model,
            attempts: 1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_with_extra_fields_and_null_content_are_read() {
        let a = parse(r#"{"id":"x","choices":[{"index":0,"message":{"role":"assistant","content":"scenario a {}","reasoning_content":null},"finish_reason":"length"}],"usage":{"prompt_tokens":81,"completion_tokens":40,"total_tokens":121},"timings":{}}"#).unwrap();
        assert_eq!((a.text.as_str(), a.finish, a.usage.total()), ("scenario a {}", Finish::Length, 121));
        assert!(parse("{}").is_err());
        assert!(parse("<html>").is_err());
        assert_eq!(parse(r#"{"choices":[{"message":{"content":null}}]}"#).unwrap().text, "");
    }

    #[test]
    fn a_stream_collects_deltas_and_the_usage_chunk() {
        let mut s = Streamed::default();
        s.feed("", r#"{"choices":[{"delta":{"role":"assistant","content":null}}]}"#).unwrap();
        assert_eq!(s.feed("", r#"{"choices":[{"delta":{"content":"scen"}}]}"#).unwrap(), "scen");
        s.feed("", r#"{"choices":[{"delta":{"content":"ario"},"finish_reason":"stop"}]}"#).unwrap();
        s.feed("", r#"{"choices":[],"usage":{"prompt_tokens":5,"completion_tokens":2}}"#).unwrap();
        let a = s.finish().unwrap();
        assert_eq!((a.text.as_str(), a.finish, a.usage.completion_tokens), ("scenario", Finish::Stop, 2));
        let mut broken = Streamed::default();
        assert!(broken.feed("", r#"{"error":{"message":"boom"}}"#).unwrap_err().message.contains("boom"));
        assert!(broken.feed("error", "overloaded").is_err());
    }
}
