//! A chat request and its JSON body, with the constraint in the server's dialect.

use base64::Engine;
use serde_json::{Value, json};

use crate::config::{Config, Dialect};
use crate::error::{Error, ErrorKind};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    System,
    User,
    Assistant,
}

impl Role {
    pub fn name(self) -> &'static str {
        match self {
            Role::System => "system",
            Role::User => "user",
            Role::Assistant => "assistant",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Part {
    Text(String),
    /// An image sent inline as a `data:` URL.
    Image {
        mime: String,
        bytes: Vec<u8>,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub role: Role,
    pub parts: Vec<Part>,
}

impl Message {
    pub fn text(role: Role, text: impl Into<String>) -> Message {
        Message { role, parts: vec![Part::Text(text.into())] }
    }

    /// The text parts, joined (for transcripts).
    pub fn plain(&self) -> String {
        let texts: Vec<String> = self
            .parts
            .iter()
            .map(|p| match p {
                Part::Text(t) => t.clone(),
                Part::Image { mime, bytes } => format!("[image: {mime}, {} bytes]", bytes.len()),
            })
            .collect();
        texts.join("\n")
    }
}

/// What the decoder must follow.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Constraint {
    #[default]
    None,
    /// llama.cpp's GBNF.
    Gbnf(String),
    /// llguidance's Lark.
    Lark(String),
    /// A JSON Schema for a JSON answer.
    JsonSchema(Value),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub messages: Vec<Message>,
    pub max_tokens: u32,
    pub temperature: f64,
    pub seed: Option<u64>,
    pub constraint: Constraint,
    pub stream: bool,
}

impl Request {
    pub fn new(messages: Vec<Message>) -> Request {
        Request {
            messages,
            max_tokens: 1024,
            temperature: 0.0,
            seed: None,
            constraint: Constraint::None,
            stream: false,
        }
    }

    /// Requests the client would send wrong (some servers answer an empty request with
    /// their own default messages).
    pub(crate) fn validate(&self) -> Result<(), Error> {
        let wrong = |m: &str| Err(Error::new(ErrorKind::Request, m.to_string()));
        if self.messages.is_empty() {
            return wrong("a chat request needs at least one message");
        }
        if self.max_tokens == 0 {
            return wrong("max_tokens must be at least 1");
        }
        if !(0.0..=2.0).contains(&self.temperature) {
            return wrong("the temperature must be between 0 and 2");
        }
        Ok(())
    }
}

fn content(message: &Message) -> Value {
    match message.parts.as_slice() {
        [Part::Text(t)] => json!(t),
        parts => Value::Array(
            parts
                .iter()
                .map(|p| match p {
                    Part::Text(t) => json!({ "type": "text", "text": t }),
                    Part::Image { mime, bytes } => {
                        let data = base64::engine::general_purpose::STANDARD.encode(bytes);
                        json!({ "type": "image_url", "image_url": { "url": format!("data:{mime};base64,{data}"), "detail": "low" } })
                    }
                })
                .collect(),
        ),
    }
}

/// The JSON body for `config`'s server.
pub(crate) fn body(request: &Request, config: &Config) -> Value {
    let messages: Vec<Value> =
        request.messages.iter().map(|m| json!({ "role": m.role.name(), "content": content(m) })).collect();
    let mut body = json!({
        "model": config.model,
        "messages": messages,
        "temperature": request.temperature,
        "stream": request.stream,
    });
    let map = body.as_object_mut().expect("an object");
    map.insert(config.max_tokens_field.clone(), json!(request.max_tokens));
    if let Some(seed) = request.seed {
        map.insert("seed".into(), json!(seed));
    }
    if request.stream {
        map.insert("stream_options".into(), json!({ "include_usage": true }));
    }
    let schema_format = |schema: &Value| json!({ "type": "json_schema", "json_schema": { "name": "tad_scenario", "strict": false, "schema": schema } });
    match (&request.constraint, config.dialect) {
        (Constraint::None, _) => {}
        (Constraint::Gbnf(g) | Constraint::Lark(g), Dialect::Vllm) => {
            map.insert("structured_outputs".into(), json!({ "grammar": g }));
        }
        (Constraint::Gbnf(g) | Constraint::Lark(g), Dialect::VllmLegacy) => {
            map.insert("guided_grammar".into(), json!(g));
        }
        (Constraint::Gbnf(g), Dialect::Sglang) => {
            map.insert("ebnf".into(), json!(g));
        }
        (Constraint::Gbnf(g), Dialect::LlamaCpp) => {
            map.insert("grammar".into(), json!(g));
        }
        (Constraint::JsonSchema(s), Dialect::Vllm) => {
            map.insert("structured_outputs".into(), json!({ "json": s }));
        }
        (Constraint::JsonSchema(s), Dialect::VllmLegacy) => {
            map.insert("guided_json".into(), s.clone());
        }
        (Constraint::JsonSchema(s), Dialect::LlamaCpp) => {
            map.insert("json_schema".into(), s.clone());
        }
        (Constraint::JsonSchema(s), Dialect::OpenAi | Dialect::Sglang) => {
            map.insert("response_format".into(), schema_format(s));
        }
        // grammars a dialect has no field for are refused before a request is made
        (Constraint::Gbnf(_) | Constraint::Lark(_), _) => {}
    }
    body
}

/// Whether `dialect` carries `constraint`.
pub fn supports(dialect: Dialect, constraint: &Constraint) -> bool {
    match constraint {
        Constraint::None | Constraint::JsonSchema(_) => true,
        Constraint::Gbnf(_) => dialect != Dialect::OpenAi,
        Constraint::Lark(_) => matches!(dialect, Dialect::Vllm | Dialect::VllmLegacy),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constraints_go_where_each_server_reads_them() {
        let mut config = Config::new("http://x/v1", "m");
        let mut request = Request::new(vec![Message::text(Role::User, "hi")]);
        request.constraint = Constraint::Gbnf("root ::= \"a\"".into());
        let field = |config: &Config, request: &Request, key: &str| body(request, config).get(key).cloned();
        config.dialect = Dialect::LlamaCpp;
        assert_eq!(field(&config, &request, "grammar"), Some(json!("root ::= \"a\"")));
        config.dialect = Dialect::Sglang;
        assert!(field(&config, &request, "ebnf").is_some());
        config.dialect = Dialect::Vllm;
        assert_eq!(field(&config, &request, "structured_outputs"), Some(json!({ "grammar": "root ::= \"a\"" })));
        config.dialect = Dialect::OpenAi;
        assert!(!supports(config.dialect, &request.constraint));
        request.constraint = Constraint::JsonSchema(json!({ "type": "object" }));
        assert_eq!(field(&config, &request, "response_format").unwrap()["type"], "json_schema");
        config.max_tokens_field = "max_completion_tokens".into();
        assert_eq!(field(&config, &request, "max_completion_tokens"), Some(json!(1024)));
    }

    #[test]
    fn images_are_data_urls_and_plain_text_stays_a_string() {
        let config = Config::new("http://x/v1", "m");
        let message = Message {
            role: Role::User,
            parts: vec![Part::Text("describe".into()), Part::Image { mime: "image/jpeg".into(), bytes: vec![1, 2, 3] }],
        };
        let b = body(&Request::new(vec![Message::text(Role::System, "s"), message]), &config);
        assert_eq!(b["messages"][0]["content"], "s");
        assert_eq!(b["messages"][1]["content"][1]["image_url"]["url"], "data:image/jpeg;base64,AQID");
    }
}
