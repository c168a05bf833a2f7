//! A protocol client for the in-process tests: the real server (`tad_lsp::serve`, with
//! its framing layer) over an in-memory pipe, spoken to in framed JSON-RPC.

#![allow(dead_code)]

use std::time::Duration;

use serde_json::{Value, json};
use tokio::io::{AsyncBufReadExt, AsyncReadExt, AsyncWriteExt, BufReader, DuplexStream, ReadHalf, WriteHalf};

pub struct Client {
    write: WriteHalf<DuplexStream>,
    read: BufReader<ReadHalf<DuplexStream>>,
    next_id: i64,
    /// Messages read while waiting for something else.
    pub seen: Vec<Value>,
}

pub const WAIT: Duration = Duration::from_secs(20);

impl Client {
    /// A server, initialised with `capabilities` and `options`, and `initialized` sent.
    pub async fn start(capabilities: Value, options: Value) -> (Client, Value) {
        let (ours, theirs) = tokio::io::duplex(1 << 22);
        let (server_read, server_write) = tokio::io::split(theirs);
        tokio::spawn(tad_lsp::serve(server_read, server_write));
        let (read, write) = tokio::io::split(ours);
        let mut client = Client { write, read: BufReader::new(read), next_id: 1, seen: Vec::new() };
        let result =
            client.request("initialize", json!({"capabilities": capabilities, "initializationOptions": options})).await;
        client.notify("initialized", json!({})).await;
        (client, result)
    }

    pub async fn default() -> Client {
        Client::start(json!({}), json!({"tadsl": {"profile": "auto"}})).await.0
    }

    pub async fn send_raw(&mut self, bytes: &[u8]) {
        self.write.write_all(bytes).await.unwrap();
        self.write.flush().await.unwrap();
    }

    pub async fn send(&mut self, message: Value) {
        let body = message.to_string();
        self.send_raw(format!("Content-Length: {}\r\n\r\n{body}", body.len()).as_bytes()).await;
    }

    pub async fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({"jsonrpc": "2.0", "method": method, "params": params})).await;
    }

    /// Send a request and return its id, without waiting.
    pub async fn start_request(&mut self, method: &str, params: Value) -> i64 {
        let id = self.next_id;
        self.next_id += 1;
        self.send(json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params})).await;
        id
    }

    /// The whole response (result or error) to request `id`.
    pub async fn response(&mut self, id: i64) -> Value {
        self.wait(|m| m.get("id") == Some(&json!(id)) && m.get("method").is_none()).await
    }

    /// A request's result; panics on an error.
    pub async fn request(&mut self, method: &str, params: Value) -> Value {
        let id = self.start_request(method, params).await;
        let response = self.response(id).await;
        assert!(response.get("error").is_none(), "{method} failed: {response}");
        response["result"].clone()
    }

    async fn read_message(&mut self) -> Value {
        let mut length = 0;
        loop {
            let mut line = String::new();
            assert!(self.read.read_line(&mut line).await.unwrap() > 0, "the server closed its output");
            let line = line.trim();
            if line.is_empty() {
                break;
            }
            if let Some(value) = line.strip_prefix("Content-Length:") {
                length = value.trim().parse().unwrap();
            }
        }
        let mut body = vec![0; length];
        self.read.read_exact(&mut body).await.unwrap();
        let message: Value = serde_json::from_slice(&body).unwrap();
        // answer the server's requests (workspace/configuration) with nothing
        if message.get("method").is_some()
            && let Some(id) = message.get("id")
        {
            let reply = json!({"jsonrpc": "2.0", "id": id, "result": [null]});
            self.send(reply).await;
        }
        message
    }

    /// The first message (seen before or read now) that `pred` accepts; removed from `seen`.
    pub async fn wait(&mut self, pred: impl Fn(&Value) -> bool) -> Value {
        if let Some(i) = self.seen.iter().position(&pred) {
            return self.seen.remove(i);
        }
        let found = tokio::time::timeout(WAIT, async {
            loop {
                let message = self.read_message().await;
                if pred(&message) {
                    return message;
                }
                self.seen.push(message);
            }
        })
        .await;
        found.expect("no such message in time")
    }

    /// The diagnostics published for `uri` at `version`.
    pub async fn diagnostics(&mut self, uri: &str, version: i64) -> Vec<Value> {
        let message = self
            .wait(|m| {
                m["method"] == "textDocument/publishDiagnostics"
                    && m["params"]["uri"] == uri
                    && m["params"]["version"] == version
            })
            .await;
        message["params"]["diagnostics"].as_array().cloned().unwrap_or_default()
    }

    pub async fn open(&mut self, uri: &str, language: &str, text: &str) {
        let document = json!({"uri": uri, "languageId": language, "version": 1, "text": text});
        self.notify("textDocument/didOpen", json!({"textDocument": document})).await;
    }

    pub async fn shutdown(mut self) {
        self.request("shutdown", Value::Null).await;
        self.notify("exit", Value::Null).await;
    }
}

pub fn codes(diagnostics: &[Value]) -> Vec<String> {
    diagnostics.iter().map(|d| d["code"].as_str().unwrap_or("").to_string()).collect()
}

pub fn example(path: &str) -> (String, String) {
    let full = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path);
    let full = full.canonicalize().unwrap();
    (format!("file://{}", full.display()), std::fs::read_to_string(&full).unwrap())
}

pub fn pos(line: u32, character: u32) -> Value {
    json!({"line": line, "character": character})
}
