//! What a client can throw at the server: malformed JSON-RPC, unknown methods, requests
//! for documents that are not open, cancellation, a 10 MB file, thousands of changes,
//! positions outside the text. Each test ends by checking the server still answers.

mod common;

use common::{Client, codes, example, pos};
use serde_json::{Value, json};

const URI: &str = "file:///tmp/tadsl-robustness-test/doc.tad";

async fn still_alive(client: &mut Client) {
    let (uri, text) = example("examples/paper/nl_to_dsl_example_1.tad");
    client.open(&uri, "tad", &text).await;
    let symbols = client.request("textDocument/documentSymbol", json!({"textDocument": {"uri": uri}})).await;
    assert!(symbols.is_array(), "{symbols}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn malformed_messages_are_answered_and_the_server_carries_on() {
    let mut client = Client::default().await;
    client.send_raw(b"Content-Length: 5\r\n\r\n{bad}").await;
    let error = client.wait(|m| m["error"]["code"] == -32700).await;
    assert_eq!(error["id"], Value::Null);
    // a message split over two writes, which is JSON but no request
    let body = br#"{"jsonrpc":"2.0","id":4}"#;
    client.send_raw(format!("Content-Length: {}\r\n\r\n", body.len()).as_bytes()).await;
    client.send_raw(&body[..10]).await;
    client.send_raw(&body[10..]).await;
    let error = client.wait(|m| m["error"]["code"] == -32600).await;
    assert_eq!(error["id"], 4, "an id-only object is no request");
    client.send_raw(b"no header at all\r\n\r\n").await;
    client.wait(|m| m["error"]["code"] == -32700).await;
    client.send(json!([{"jsonrpc": "2.0", "id": 5, "method": "shutdown"}])).await;
    client.wait(|m| m["error"]["code"] == -32600).await;
    let id = client.start_request("tadsl/noSuchMethod", json!({})).await;
    assert_eq!(client.response(id).await["error"]["code"], -32601);
    // wrong params for a known method
    let id = client.start_request("textDocument/hover", json!({"textDocument": 3})).await;
    assert_eq!(client.response(id).await["error"]["code"], -32602);
    client.notify("textDocument/didChange", json!({"nonsense": true})).await;
    client.notify("$/unknownNotification", json!({})).await;
    still_alive(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn requests_for_documents_not_open_get_empty_answers() {
    let mut client = Client::default().await;
    let doc = json!({"uri": "file:///nowhere/closed.tad"});
    for (method, params) in [
        ("textDocument/hover", json!({"textDocument": doc, "position": pos(0, 0)})),
        ("textDocument/completion", json!({"textDocument": doc, "position": pos(0, 0)})),
        ("textDocument/definition", json!({"textDocument": doc, "position": pos(0, 0)})),
        ("textDocument/formatting", json!({"textDocument": doc, "options": {"tabSize": 2, "insertSpaces": true}})),
        ("textDocument/semanticTokens/full", json!({"textDocument": doc})),
        ("textDocument/documentSymbol", json!({"textDocument": doc})),
    ] {
        assert_eq!(client.request(method, params).await, Value::Null, "{method}");
    }
    // a document opened then closed: its diagnostics are cleared and requests answer null
    client.open(URI, "tad", "scenario demo { road { lanes: x } }").await;
    assert!(!client.diagnostics(URI, 1).await.is_empty());
    client.notify("textDocument/didClose", json!({"textDocument": {"uri": URI}})).await;
    let cleared = client.wait(|m| m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == URI).await;
    assert_eq!(cleared["params"]["diagnostics"], json!([]));
    let hover =
        client.request("textDocument/hover", json!({"textDocument": {"uri": URI}, "position": pos(0, 0)})).await;
    assert_eq!(hover, Value::Null);
    // a change to a closed document is ignored
    client
        .notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": URI, "version": 9}, "contentChanges": [{"text": "x"}]}),
        )
        .await;
    still_alive(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn positions_outside_the_text_are_clamped() {
    let mut client = Client::default().await;
    let (_, text) = example("examples/safety/right_turn.tad");
    client.open(URI, "tad", &text).await;
    for position in [pos(9999, 0), pos(3, 9999), pos(u32::MAX, u32::MAX)] {
        for method in ["textDocument/hover", "textDocument/completion", "textDocument/definition"] {
            let id = client.start_request(method, json!({"textDocument": {"uri": URI}, "position": position})).await;
            let response = client.response(id).await;
            assert!(response.get("error").is_none(), "{method} at {position}: {response}");
        }
    }
    // an edit whose range is past the end appends
    let change = json!({"range": {"start": pos(9999, 0), "end": pos(9999, 5)}, "text": "// end\n"});
    client
        .notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": URI, "version": 2}, "contentChanges": [change]}),
        )
        .await;
    assert!(client.diagnostics(URI, 2).await.is_empty());
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_burst_of_changes_ends_with_the_last_version_checked() {
    let mut client = Client::default().await;
    let (_, text) = example("examples/safety/right_turn.tad");
    client.open(URI, "tad", &text).await;
    let line = text.lines().position(|l| l.contains("speed: 12 km/h")).unwrap() as u32;
    let column = text.lines().nth(line as usize).unwrap().find("12").unwrap() as u32;
    // 2,000 one-character edits, alternating a valid and an invalid speed
    let last = 2001;
    for version in 2..=last {
        let digit = if version % 2 == 0 { "x" } else { "1" };
        let change = json!({"range": {"start": pos(line, column), "end": pos(line, column + 1)}, "text": digit});
        client
            .notify(
                "textDocument/didChange",
                json!({"textDocument": {"uri": URI, "version": version}, "contentChanges": [change]}),
            )
            .await;
    }
    let final_diagnostics = client.diagnostics(URI, last).await;
    assert!(final_diagnostics.is_empty(), "the last text is valid: {:?}", codes(&final_diagnostics));
    // far fewer checks than changes were published (superseded work is dropped)
    let published = client.seen.iter().filter(|m| m["method"] == "textDocument/publishDiagnostics").count();
    assert!(published < 2000, "{published} publications for 2000 changes");
    // no publication for an older version arrives after the last one
    client.seen.clear();
    client
        .notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": URI, "version": last + 1}, "contentChanges": []}),
        )
        .await;
    client.diagnostics(URI, last + 1).await;
    for message in &client.seen {
        if message["method"] == "textDocument/publishDiagnostics" {
            assert!(message["params"]["version"].as_i64() >= Some(last), "a stale publication: {message}");
        }
    }
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_ten_megabyte_file_is_checked_and_requests_are_answered() {
    let mut client = Client::default().await;
    let (_, text) = example("examples/safety/right_turn.tad");
    let mut big = text.clone();
    let filler = "// a comment line to make the file large, with non-ASCII text: é 🚗\n";
    while big.len() < 10 << 20 {
        big.push_str(filler);
    }
    big.push_str("road { lanes: 2 }\n");
    client.open(URI, "tad", &big).await;
    let diagnostics = client.diagnostics(URI, 1).await;
    assert!(!diagnostics.is_empty(), "the stray section after the scenario is reported");
    let line = big.lines().count() as u32 - 1;
    let id = client
        .start_request("textDocument/hover", json!({"textDocument": {"uri": URI}, "position": pos(line, 2)}))
        .await;
    assert!(client.response(id).await.get("error").is_none());
    let id = client.start_request("textDocument/semanticTokens/full", json!({"textDocument": {"uri": URI}})).await;
    assert!(client.response(id).await.get("error").is_none());
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancelled_requests_are_answered() {
    let mut client = Client::default().await;
    let (_, text) = example("examples/safety/right_turn.tad");
    client.open(URI, "tad", &text).await;
    let id = client.start_request("textDocument/semanticTokens/full", json!({"textDocument": {"uri": URI}})).await;
    client.notify("$/cancelRequest", json!({"id": id})).await;
    let response = client.response(id).await;
    // answered either way: the result, or "cancelled" when the cancel came first
    assert!(response.get("result").is_some() || response["error"]["code"] == -32800, "{response}");
    still_alive(&mut client).await;
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn yaml_that_is_no_scenario_is_left_alone() {
    let mut client = Client::default().await;
    let uri = "file:///tmp/tadsl-robustness-test/workflow.yaml";
    client.open(uri, "yaml", "on: push\njobs:\n  build:\n    runs-on: ubuntu\n").await;
    assert!(client.diagnostics(uri, 1).await.is_empty());
    let answer = "file:///tmp/tadsl-robustness-test/answer.yaml";
    let yaml = "```yaml\nScenario:\n  Environment:\n    Weather: sunny\n    Time: day\n  Road Network:\n    Road Type: straight_road\n```\n";
    client.open(answer, "yaml", yaml).await;
    let diagnostics = client.diagnostics(answer, 1).await;
    assert!(!diagnostics.is_empty(), "a scenario answer is checked");
    client.shutdown().await;
}
