//! A scripted OpenAI-compatible server on 127.0.0.1 for tests of the client, the repair
//! loop and the pipelines: each request is recorded and answered by a script (a closure
//! given the request's number and body), which may answer JSON, stream SSE, delay, send an
//! error status with headers, or drop the connection. Plain `std::net`, one thread per
//! connection.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use serde_json::{Value, json};

/// What the server does with one request.
#[derive(Clone, Debug)]
pub enum Reply {
    /// A status, extra headers and a body.
    Status(u16, Vec<(String, String)>, String),
    /// A chat completion whose message is this text.
    Chat(String),
    /// The text streamed as SSE chunks of a few characters, with a usage chunk.
    Stream(String),
    /// Wait, then reply.
    Delay(Duration, Box<Reply>),
    /// Close the connection without answering.
    Drop,
}

impl Reply {
    pub fn chat(text: impl Into<String>) -> Reply {
        Reply::Chat(text.into())
    }

    pub fn status(status: u16, body: &str) -> Reply {
        Reply::Status(status, Vec::new(), body.to_string())
    }

    pub fn with_header(self, name: &str, value: &str) -> Reply {
        match self {
            Reply::Status(s, mut h, b) => {
                h.push((name.to_string(), value.to_string()));
                Reply::Status(s, h, b)
            }
            other => other,
        }
    }
}

type Script = dyn Fn(usize, &Value) -> Reply + Send + Sync;

pub struct FakeLlm {
    pub base_url: String,
    requests: Arc<Mutex<Vec<Value>>>,
}

impl FakeLlm {
    /// A server answering request `n` (from 0) with `script(n, body)`.
    pub fn start(script: impl Fn(usize, &Value) -> Reply + Send + Sync + 'static) -> FakeLlm {
        let listener = TcpListener::bind("127.0.0.1:0").expect("a free port on 127.0.0.1");
        let base_url = format!("http://{}/v1", listener.local_addr().expect("an address"));
        let requests: Arc<Mutex<Vec<Value>>> = Arc::default();
        let script: Arc<Script> = Arc::new(script);
        let seen = requests.clone();
        std::thread::spawn(move || {
            for stream in listener.incoming() {
                let Ok(stream) = stream else { continue };
                let (seen, script) = (seen.clone(), script.clone());
                std::thread::spawn(move || serve(stream, &seen, &*script));
            }
        });
        FakeLlm { base_url, requests }
    }

    /// A server answering the replies in order (the last one again after the end).
    pub fn script(replies: Vec<Reply>) -> FakeLlm {
        FakeLlm::start(move |n, _| replies[n.min(replies.len() - 1)].clone())
    }

    /// The bodies of the requests so far.
    pub fn requests(&self) -> Vec<Value> {
        self.requests.lock().unwrap().clone()
    }
}

/// The text of the last user message of a request body.
pub fn last_user_text(body: &Value) -> String {
    let messages = body["messages"].as_array().cloned().unwrap_or_default();
    let last = messages.iter().rev().find(|m| m["role"] == "user").cloned().unwrap_or(Value::Null);
    match &last["content"] {
        Value::String(s) => s.clone(),
        Value::Array(parts) => parts.iter().filter_map(|p| p["text"].as_str()).collect::<Vec<_>>().join("\n"),
        _ => String::new(),
    }
}

fn serve(mut stream: TcpStream, seen: &Mutex<Vec<Value>>, script: &Script) {
    let mut reader = BufReader::new(stream.try_clone().expect("a clone of the stream"));
    let mut length = 0usize;
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).unwrap_or(0) == 0 {
            return;
        }
        if line == "\r\n" {
            break;
        }
        if let Some((name, value)) = line.split_once(':')
            && name.eq_ignore_ascii_case("content-length")
        {
            length = value.trim().parse().unwrap_or(0);
        }
    }
    let mut body = vec![0; length];
    if reader.read_exact(&mut body).is_err() {
        return;
    }
    let body: Value = serde_json::from_slice(&body).unwrap_or(Value::Null);
    let n = {
        let mut seen = seen.lock().unwrap();
        seen.push(body.clone());
        seen.len() - 1
    };
    let mut reply = script(n, &body);
    while let Reply::Delay(wait, next) = reply {
        std::thread::sleep(wait);
        reply = *next;
    }
    let (status, headers, text, content_type) = match reply {
        Reply::Drop | Reply::Delay(..) => return,
        Reply::Status(s, h, b) => (s, h, b, "application/json"),
        Reply::Chat(text) => {
            let completion = json!({
                "id": "chatcmpl-fake", "object": "chat.completion", "model": "fake",
                "choices": [{ "index": 0, "message": { "role": "assistant", "content": text }, "finish_reason": "stop" }],
                "usage": { "prompt_tokens": 100, "completion_tokens": text.len() / 4 + 1 },
            });
            (200, Vec::new(), completion.to_string(), "application/json")
        }
        Reply::Stream(text) => {
            let mut events = String::from(": keep-alive\n\n");
            events.push_str(&format!(
                "data: {}\n\n",
                json!({ "choices": [{ "delta": { "role": "assistant", "content": null } }] })
            ));
            let chars: Vec<char> = text.chars().collect();
            for piece in chars.chunks(7) {
                let piece: String = piece.iter().collect();
                events.push_str(&format!("data: {}\n\n", json!({ "choices": [{ "delta": { "content": piece } }] })));
            }
            events.push_str(&format!("data: {}\n\n", json!({ "choices": [{ "delta": {}, "finish_reason": "stop" }] })));
            events.push_str(&format!(
                "data: {}\n\n",
                json!({ "choices": [], "usage": { "prompt_tokens": 100, "completion_tokens": chars.len() / 4 + 1 } })
            ));
            events.push_str("data: [DONE]\n\n");
            (200, Vec::new(), events, "text/event-stream")
        }
    };
    let reason = match status {
        200 => "OK",
        429 => "Too Many Requests",
        500 => "Internal Server Error",
        _ => "Status",
    };
    let mut head = format!(
        "HTTP/1.1 {status} {reason}\r\ncontent-type: {content_type}\r\ncontent-length: {}\r\nconnection: close\r\n",
        text.len()
    );
    for (name, value) in headers {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str("\r\n");
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(text.as_bytes());
    let _ = stream.flush();
}
