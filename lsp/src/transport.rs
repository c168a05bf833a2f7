//! The framing in front of tower-lsp-server: every message the client sends is read and
//! checked here first, so no input can stop the server.
//!
//! tower-lsp-server answers a body that is not JSON-RPC with an error and then ends its
//! input stream (its framed reader stops after any decode error), which would leave the
//! client talking to a dead server. So this layer reads frames itself (`Content-Length`
//! headers, any other header ignored, a body of at most [`MAX_BODY`] bytes), passes on
//! those that are JSON-RPC messages unchanged, and answers the others itself: `-32700`
//! for a body that is not JSON, `-32600` for JSON that is no message (with the message's
//! id when it has one). Garbage between frames is skipped up to the next header. The
//! server's output goes through here too, whole frames at a time, so an answer written
//! here never splits one of the server's.

use serde_json::{Value, json};
use tokio::io::{AsyncBufReadExt, AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, BufReader};
use tokio::sync::mpsc;

/// The largest body accepted (a 10 MB document in JSON is well below it).
pub const MAX_BODY: usize = 256 << 20;

/// What one frame of input is.
#[derive(Debug, PartialEq)]
pub enum Checked {
    /// A JSON-RPC message, to pass on.
    Message,
    /// Not JSON-RPC: the error response to send back.
    Answer(Value),
}

/// Whether `body` is a JSON-RPC message; if not, the error to answer.
pub fn check(body: &[u8]) -> Checked {
    let Ok(value) = serde_json::from_slice::<Value>(body) else {
        return Checked::Answer(error(Value::Null, -32700, "Parse error: the body is not JSON"));
    };
    let id = value.get("id").cloned().filter(|id| id.is_string() || id.is_number()).unwrap_or(Value::Null);
    let Some(object) = value.as_object() else {
        return Checked::Answer(error(
            id,
            -32600,
            "Invalid request: expected one JSON-RPC object (batches are not supported)",
        ));
    };
    let version = object.get("jsonrpc").and_then(Value::as_str) == Some("2.0");
    let id_ok = object.get("id").is_none_or(|id| id.is_string() || id.is_number() || id.is_null());
    let request = object.get("method").is_some_and(Value::is_string)
        && object.get("params").is_none_or(|p| p.is_object() || p.is_array() || p.is_null());
    let response = object.contains_key("id") && (object.contains_key("result") || object.contains_key("error"));
    if version && id_ok && (request || response) {
        Checked::Message
    } else {
        Checked::Answer(error(id, -32600, "Invalid request: not a JSON-RPC 2.0 request, notification or response"))
    }
}

fn error(id: Value, code: i64, message: &str) -> Value {
    json!({ "jsonrpc": "2.0", "id": id, "error": { "code": code, "message": message } })
}

fn frame(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

/// One frame read from `input`: `Ok(None)` at the end, `Err(answer)` for a frame whose
/// headers could not be read (then the next header is searched for).
async fn read_frame<R: AsyncRead + Unpin>(input: &mut BufReader<R>) -> std::io::Result<Option<Result<Vec<u8>, Value>>> {
    let mut length: Option<usize> = None;
    let mut bad_header = false;
    let mut line = Vec::new();
    loop {
        line.clear();
        if input.read_until(b'\n', &mut line).await? == 0 {
            return Ok(None);
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\r', '\n']);
        if text.is_empty() {
            if length.is_some() || bad_header {
                break;
            }
            continue; // blank lines between frames
        }
        match text.split_once(':') {
            Some((name, value)) if name.trim().eq_ignore_ascii_case("content-length") => {
                match value.trim().parse::<usize>() {
                    Ok(n) if n <= MAX_BODY => length = Some(n),
                    _ => bad_header = true,
                }
            }
            Some(_) => {}
            None => bad_header = true,
        }
    }
    let Some(length) = length.filter(|_| !bad_header) else {
        return Ok(Some(Err(error(Value::Null, -32700, "Parse error: a frame without a valid Content-Length header"))));
    };
    let mut body = vec![0; length];
    input.read_exact(&mut body).await?;
    Ok(Some(Ok(body)))
}

/// Copy checked frames from `client` to `server`; answer bad ones on `answers`.
pub async fn filter_input<R, W>(client: R, mut server: W, answers: mpsc::UnboundedSender<Vec<u8>>)
where
    R: AsyncRead + Unpin,
    W: AsyncWrite + Unpin,
{
    let mut input = BufReader::with_capacity(1 << 16, client);
    loop {
        match read_frame(&mut input).await {
            Ok(Some(Ok(body))) => match check(&body) {
                Checked::Message => {
                    if server.write_all(&frame(&body)).await.is_err() {
                        break;
                    }
                }
                Checked::Answer(answer) => {
                    let _ = answers.send(frame(answer.to_string().as_bytes()));
                }
            },
            Ok(Some(Err(answer))) => {
                let _ = answers.send(frame(answer.to_string().as_bytes()));
            }
            // the client closed its end, or a frame was cut short
            Ok(None) | Err(_) => break,
        }
    }
    let _ = server.shutdown().await;
}

/// Copy the server's frames and the answers of [`filter_input`] to `client`, whole.
pub async fn merge_output<R, W>(server: R, mut client: W, mut answers: mpsc::UnboundedReceiver<Vec<u8>>)
where
    R: AsyncRead + Unpin,
    W: AsyncWrite + Unpin,
{
    let mut from_server = BufReader::with_capacity(1 << 16, server);
    let (mut server_open, mut answers_open) = (true, true);
    while server_open || answers_open {
        tokio::select! {
            frame_read = read_frame(&mut from_server), if server_open => match frame_read {
                Ok(Some(Ok(body))) => {
                    if client.write_all(&frame(&body)).await.is_err() || client.flush().await.is_err() {
                        return;
                    }
                }
                Ok(Some(Err(_))) => {}
                Ok(None) | Err(_) => server_open = false,
            },
            answer = answers.recv(), if answers_open => match answer {
                Some(bytes) if client.write_all(&bytes).await.is_err() || client.flush().await.is_err() => return,
                Some(_) => {}
                // the input has ended: only the server's last frames remain
                None => answers_open = false,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_pass_and_the_rest_is_answered() {
        assert_eq!(check(br#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{}}"#), Checked::Message);
        assert_eq!(check(br#"{"jsonrpc":"2.0","method":"initialized"}"#), Checked::Message);
        assert_eq!(check(br#"{"jsonrpc":"2.0","id":0,"result":null}"#), Checked::Message);
        let answer = |body: &[u8]| match check(body) {
            Checked::Answer(a) => (a["error"]["code"].as_i64().unwrap(), a["id"].clone()),
            Checked::Message => panic!("passed: {}", String::from_utf8_lossy(body)),
        };
        assert_eq!(answer(b"{bad"), (-32700, Value::Null));
        assert_eq!(answer(b"\xff\xfe"), (-32700, Value::Null));
        assert_eq!(answer(br#"{"jsonrpc":"2.0","id":7}"#), (-32600, json!(7)));
        assert_eq!(answer(br#"{"jsonrpc":"1.0","id":"a","method":"x"}"#), (-32600, json!("a")));
        assert_eq!(answer(br#"[{"jsonrpc":"2.0","method":"x"}]"#).0, -32600);
        assert_eq!(answer(br#"{"jsonrpc":"2.0","id":{"no":1},"method":"x"}"#), (-32600, Value::Null));
        assert_eq!(answer(br#"{"jsonrpc":"2.0","id":2,"method":"x","params":3}"#), (-32600, json!(2)));
    }

    #[tokio::test]
    async fn frames_are_read_through_garbage() {
        let input: &[u8] =
            b"garbage\r\n\r\nContent-Length: 2\r\nContent-Type: x\r\n\r\n{}\r\nContent-Length: nope\r\n\r\n";
        let mut reader = BufReader::new(input);
        assert!(matches!(read_frame(&mut reader).await, Ok(Some(Err(_)))), "a header line without a colon");
        assert_eq!(read_frame(&mut reader).await.unwrap(), Some(Ok(b"{}".to_vec())));
        assert!(matches!(read_frame(&mut reader).await, Ok(Some(Err(_)))));
        assert!(matches!(read_frame(&mut reader).await, Ok(None)));
    }
}
