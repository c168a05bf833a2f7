//! Training examples: TRL's conversational form (`{"messages": [...]}`, the loss on the
//! last message, the assistant's) and its prompt/completion form (`{"prompt": [...],
//! "completion": [{"role": "assistant", ...}]}`), one JSON object a line.

use serde_json::Value;

/// One chat turn.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub role: String,
    pub content: String,
}

/// A prompt (system, user, … turns) and the assistant's answer the loss is taken on.
#[derive(Clone, Debug, PartialEq)]
pub struct Example {
    pub prompt: Vec<Message>,
    pub completion: String,
}

fn messages(value: &Value, what: &str) -> Result<Vec<Message>, String> {
    match value {
        // TRL's standard (non-conversational) form: a bare string is a user's turn
        Value::String(s) => Ok(vec![Message { role: "user".into(), content: s.clone() }]),
        Value::Array(items) => items
            .iter()
            .map(|m| {
                let role = m.get("role").and_then(Value::as_str);
                let content = m.get("content").and_then(Value::as_str);
                match (role, content) {
                    (Some(r), Some(c)) if ["system", "user", "assistant"].contains(&r) => {
                        Ok(Message { role: r.into(), content: c.into() })
                    }
                    _ => Err(format!(
                        "`{what}` holds a message without a system/user/assistant role and a string content"
                    )),
                }
            })
            .collect(),
        _ => Err(format!("`{what}` is not a list of messages")),
    }
}

impl Example {
    /// Reads one JSON object in either of TRL's chat forms.
    pub fn from_json(value: &Value) -> Result<Example, String> {
        if let Some(list) = value.get("messages") {
            let mut all = messages(list, "messages")?;
            let last = all.pop().filter(|m| m.role == "assistant").ok_or("the last message is not the assistant's")?;
            if all.is_empty() {
                return Err("no prompt before the assistant's message".into());
            }
            return Ok(Example { prompt: all, completion: last.content });
        }
        let (Some(prompt), Some(completion)) = (value.get("prompt"), value.get("completion")) else {
            return Err("neither `messages` nor `prompt` and `completion`".into());
        };
        let prompt = messages(prompt, "prompt")?;
        let completion = match completion {
            Value::String(s) => s.clone(),
            other => {
                let mut c = messages(other, "completion")?;
                match (c.pop(), c.is_empty()) {
                    (Some(m), true) if m.role == "assistant" => m.content,
                    _ => return Err("`completion` is not one assistant message".into()),
                }
            }
        };
        if prompt.is_empty() {
            return Err("the prompt is empty".into());
        }
        Ok(Example { prompt, completion })
    }
}

/// Reads a JSONL text: one example a non-blank line; an error names the line.
pub fn read_jsonl(text: &str) -> Result<Vec<Example>, String> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let value: Value = serde_json::from_str(line).map_err(|e| format!("line {}: not JSON: {e}", i + 1))?;
        out.push(Example::from_json(&value).map_err(|e| format!("line {}: {e}", i + 1))?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_forms_read() {
        let text = r#"{"messages":[{"role":"system","content":"s"},{"role":"user","content":"u"},{"role":"assistant","content":"a"}]}

{"prompt":[{"role":"user","content":"u"}],"completion":[{"role":"assistant","content":"a"}]}
"#;
        let examples = read_jsonl(text).unwrap();
        assert_eq!(examples.len(), 2);
        assert_eq!(examples[0].prompt.len(), 2);
        assert_eq!(examples[1].completion, "a");
        assert!(read_jsonl(r#"{"messages":[{"role":"user","content":"u"}]}"#).unwrap_err().starts_with("line 1"));
        assert!(read_jsonl("{\"prompt\": 3, \"completion\": \"a\"}").is_err());
        assert!(read_jsonl("not json").is_err());
    }
}
