//! The protocol end to end in process: capabilities, diagnostics on open and change,
//! positions in UTF-16 and UTF-8, settings, formatting and quick fixes.

mod common;

use common::{Client, codes, example, pos};
use serde_json::{Value, json};

const UNTITLED: &str = "file:///tmp/tadsl-protocol-test/untitled.tad";

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn capabilities_and_encoding_are_negotiated() {
    let (client, result) = Client::start(json!({}), Value::Null).await;
    let capabilities = &result["capabilities"];
    assert_eq!(capabilities["positionEncoding"], "utf-16");
    assert_eq!(capabilities["textDocumentSync"]["change"], 2, "incremental sync");
    for provider in [
        "hoverProvider",
        "completionProvider",
        "definitionProvider",
        "referencesProvider",
        "documentSymbolProvider",
        "documentFormattingProvider",
        "documentRangeFormattingProvider",
        "codeActionProvider",
        "renameProvider",
        "foldingRangeProvider",
        "semanticTokensProvider",
        "inlayHintProvider",
    ] {
        assert!(!capabilities[provider].is_null(), "{provider} missing");
    }
    assert_eq!(result["serverInfo"]["name"], "tadslc");
    client.shutdown().await;

    let (client, result) =
        Client::start(json!({"general": {"positionEncodings": ["utf-8", "utf-16"]}}), Value::Null).await;
    assert_eq!(result["capabilities"]["positionEncoding"], "utf-8");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_example_is_clean_and_complete() {
    let mut client = Client::default().await;
    let (uri, text) = example("examples/safety/right_turn.tad");
    client.open(&uri, "tad", &text).await;
    assert_eq!(client.diagnostics(&uri, 1).await, Vec::<Value>::new());
    let class = client.wait(|m| m["method"] == "tadsl/scenarioClass" && m["params"]["uri"] == uri).await;
    assert_eq!(class["params"]["class"], "complete");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn diagnostics_follow_changes_with_versions() {
    let mut client = Client::default().await;
    let (uri, text) = example("examples/safety/right_turn.tad");
    let broken = text.replace("weather: clear", "weather: sunny").replace("behavior: cross", "behavior: turn_left");
    client.open(&uri, "tad", &broken).await;
    let diagnostics = client.diagnostics(&uri, 1).await;
    let found = codes(&diagnostics);
    assert!(found.contains(&"W0401".to_string()) && found.contains(&"E0502".to_string()), "{found:?}");
    let alias = diagnostics.iter().find(|d| d["code"] == "W0401").unwrap();
    assert_eq!(alias["tags"], json!([2]), "an alias is a deprecated spelling");
    assert_eq!(alias["data"]["payload"]["kind"], "alias");
    assert_eq!(alias["data"]["class"], "invalid");
    assert_eq!(alias["source"], "tadsl");
    let line = broken.lines().position(|l| l.contains("sunny")).unwrap() as u64;
    assert_eq!(alias["range"]["start"]["line"], line);
    assert_eq!(alias["range"]["start"]["character"], 13);
    // the behaviour's diagnostic points at the stdlib for what the kind can do
    let behavior = diagnostics.iter().find(|d| d["code"] == "E0502").unwrap();
    assert!(behavior["message"].as_str().unwrap().contains("turn_left"), "{behavior}");

    // fix the behaviour by an incremental edit: the error goes, the alias stays
    // the second `turn_left` is the pedestrians'
    let at = broken.lines().enumerate().filter(|(_, l)| l.contains("behavior: turn_left")).nth(1).unwrap().0 as u32;
    let column = broken.lines().nth(at as usize).unwrap().find("turn_left").unwrap() as u32;
    let change = json!({"range": {"start": pos(at, column), "end": pos(at, column + 9)}, "text": "cross"});
    client
        .notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri, "version": 2}, "contentChanges": [change]}),
        )
        .await;
    let found = codes(&client.diagnostics(&uri, 2).await);
    assert_eq!(found, vec!["W0401"]);
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn columns_count_in_the_negotiated_encoding() {
    let text = "scenario demo {\n  source { description: \"Zürich 🚦\" region: zurichh }\n}\n";
    let line = text.lines().nth(1).unwrap();
    let before = &line[..line.find("zurichh").unwrap()];
    let utf16 = before.encode_utf16().count() as u64;
    let utf8 = before.len() as u64;
    assert_ne!(utf16, utf8);
    for (capabilities, column) in [(json!({}), utf16), (json!({"general": {"positionEncodings": ["utf-8"]}}), utf8)] {
        let (mut client, _) = Client::start(capabilities, Value::Null).await;
        client.open(UNTITLED, "tad", text).await;
        let diagnostics = client.diagnostics(UNTITLED, 1).await;
        let unknown = diagnostics.iter().find(|d| d["code"] == "E0400").expect("the unknown region");
        assert_eq!(unknown["range"]["start"], pos(1, column as u32));
        assert_eq!(unknown["range"]["end"], pos(1, column as u32 + 7));
        client.shutdown().await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn settings_change_the_rules() {
    let text = "scenario demo {\n  source { video: \"a.mp4\" }\n  environment {\n    weather: clear\n    time: daytime\n  }\n  actor follower: car {\n    behavior: move_forward\n    position: behind of ego\n    lane: 1\n  }\n}\n";
    let (mut client, _) = Client::start(json!({}), json!({"tadsl": {"profile": "default"}})).await;
    client.open(UNTITLED, "tad", text).await;
    assert!(!codes(&client.diagnostics(UNTITLED, 1).await).contains(&"E0510".to_string()));
    client.notify("workspace/didChangeConfiguration", json!({"settings": {"tadsl": {"profile": "dashcam"}}})).await;
    let again = client
        .wait(|m| {
            m["method"] == "textDocument/publishDiagnostics"
                && m["params"]["diagnostics"].as_array().is_some_and(|d| d.iter().any(|d| d["code"] == "E0510"))
        })
        .await;
    assert_eq!(again["params"]["uri"], UNTITLED);
    // a wrong setting is shown, not fatal
    client.notify("workspace/didChangeConfiguration", json!({"settings": {"tadsl": {"profile": "fast"}}})).await;
    let shown = client.wait(|m| m["method"] == "window/showMessage").await;
    assert!(shown["params"]["message"].as_str().unwrap().contains("fast"));
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn formatting_and_quick_fixes_edit_the_document() {
    let text = "scenario demo {\nenvironment {\n      weather: sunny\n  time:   daytime\n  }\n}\n";
    let mut client = Client::default().await;
    client.open(UNTITLED, "tad", text).await;
    let diagnostics = client.diagnostics(UNTITLED, 1).await;
    let edits = client
        .request(
            "textDocument/formatting",
            json!({"textDocument": {"uri": UNTITLED}, "options": {"tabSize": 2, "insertSpaces": true}}),
        )
        .await;
    let formatted = apply(text, &edits);
    assert_eq!(formatted, tad_syntax::format::format(text).unwrap());

    let alias = diagnostics.iter().find(|d| d["code"] == "W0401").unwrap().clone();
    let actions = client
        .request(
            "textDocument/codeAction",
            json!({"textDocument": {"uri": UNTITLED}, "range": alias["range"], "context": {"diagnostics": [alias]}}),
        )
        .await;
    let fix = actions.as_array().unwrap().iter().find(|a| a["kind"] == "quickfix").expect("a quick fix");
    assert_eq!(fix["title"], "Replace `sunny` with `clear`");
    assert_eq!(fix["isPreferred"], true);
    assert_eq!(fix["diagnostics"][0]["code"], "W0401");
    let edits = &fix["edit"]["changes"][UNTITLED];
    assert!(apply(text, edits).contains("weather: clear"));
    let all = actions.as_array().unwrap().iter().find(|a| a["kind"] == "source.fixAll");
    assert!(all.is_some(), "fix-all is offered: {actions}");
    // only quick fixes when asked for them
    let only = client
        .request(
            "textDocument/codeAction",
            json!({"textDocument": {"uri": UNTITLED}, "range": alias["range"], "context": {"diagnostics": [], "only": ["quickfix"]}}),
        )
        .await;
    assert!(only.as_array().unwrap().iter().all(|a| a["kind"] == "quickfix"));
    client.shutdown().await;
}

/// Apply protocol text edits (UTF-16 on ASCII text here) to `text`.
fn apply(text: &str, edits: &Value) -> String {
    let starts: Vec<usize> = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
    let offset = |p: &Value| {
        let line = p["line"].as_u64().unwrap() as usize;
        starts.get(line).map_or(text.len(), |s| s + p["character"].as_u64().unwrap() as usize)
    };
    let mut edits: Vec<(usize, usize, String)> = edits
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (offset(&e["range"]["start"]), offset(&e["range"]["end"]), e["newText"].as_str().unwrap().to_string()))
        .collect();
    edits.sort();
    let mut out = text.to_string();
    for (start, end, new) in edits.into_iter().rev() {
        out.replace_range(start..end, &new);
    }
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_edit_republishes_only_what_changed_and_a_used_module_rechecks_its_users() {
    let dir = std::env::temp_dir().join(format!("tadsl-protocol-modules-{}", std::process::id()));
    let module_uri = format!("file://{}/mine.tad", dir.display());
    let main_uri = format!("file://{}/main.tad", dir.display());
    let other_uri = format!("file://{}/other.tad", dir.display());
    let mut client = Client::default().await;
    client.open(&module_uri, "tad", "weather glum {\n  description: \"grey and low\"\n}\n").await;
    let scenario = "use mine\nscenario demo {\n  environment {\n    weather: glum\n    time: daytime\n  }\n}\n";
    client.open(&main_uri, "tad", scenario).await;
    client.open(&other_uri, "tad", "scenario other {\n  environment {\n    weather: clear\n  }\n}\n").await;
    let main = codes(&client.diagnostics(&main_uri, 1).await);
    assert!(!main.contains(&"E0400".to_string()), "the unsaved module declares `glum`: {main:?}");
    client.diagnostics(&other_uri, 1).await;
    // rename the declaration in the module: its user now has an unknown name
    let change = json!({"range": {"start": pos(0, 8), "end": pos(0, 12)}, "text": "gloom"});
    client
        .notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": module_uri, "version": 2}, "contentChanges": [change]}),
        )
        .await;
    let again = client
        .wait(|m| m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == main_uri.as_str())
        .await;
    let found = codes(again["params"]["diagnostics"].as_array().unwrap());
    assert!(found.contains(&"E0400".to_string()), "{found:?}");
    client.diagnostics(&module_uri, 2).await;
    // the unrelated document was not published again
    client
        .seen
        .retain(|m| m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == other_uri.as_str());
    assert!(client.seen.is_empty(), "{:?}", client.seen);
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn definition_opens_the_standard_library_read_only() {
    let mut client = Client::default().await;
    let (uri, text) = example("examples/safety/right_turn.tad");
    client.open(&uri, "tad", &text).await;
    let line = text.lines().position(|l| l.contains("4 pedestrian")).unwrap() as u32;
    let column = text.lines().nth(line as usize).unwrap().find("4 pedestrian").unwrap() as u32 + 4;
    let found = client
        .request("textDocument/definition", json!({"textDocument": {"uri": uri}, "position": pos(line, column)}))
        .await;
    let target = &found[0];
    let path = target["uri"].as_str().unwrap().strip_prefix("file://").unwrap().to_string();
    assert!(path.ends_with("/core.tad"), "{target}");
    let core = std::fs::read_to_string(&path).unwrap();
    assert!(std::fs::metadata(&path).unwrap().permissions().readonly());
    let at = target["range"]["start"]["line"].as_u64().unwrap() as usize;
    assert!(core.lines().nth(at).unwrap().starts_with("actor_type pedestrian"), "{}", core.lines().nth(at).unwrap());
    // opened in the editor it is the embedded module: no diagnostics, hover works
    client.open(target["uri"].as_str().unwrap(), "tad", &core).await;
    let hover = client
        .request(
            "textDocument/hover",
            json!({"textDocument": {"uri": target["uri"]}, "position": target["range"]["start"]}),
        )
        .await;
    assert!(hover["contents"]["value"].as_str().unwrap().contains("pedestrian"), "{hover}");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_feature_answers_with_content() {
    let snippets = json!({"textDocument": {"completion": {"completionItem": {"snippetSupport": true}}}});
    let (mut client, result) = Client::start(snippets, Value::Null).await;
    let legend = result["capabilities"]["semanticTokensProvider"]["legend"]["tokenTypes"].clone();
    let text = "scenario demo {\n  road {\n    lanes: 2\n  }\n  ego {\n    speed: 20 mph\n    lane: 2\n  }\n  actor lead: car {\n    position: front of ego\n  }\n  actor tail: bus {\n    position: behind of lead\n  }\n  \n}\n";
    client.open(UNTITLED, "tad", text).await;
    client.diagnostics(UNTITLED, 1).await;
    let doc = json!({"uri": UNTITLED});

    let symbols = client.request("textDocument/documentSymbol", json!({"textDocument": doc})).await;
    assert_eq!(symbols[0]["name"], "demo");
    assert_eq!(symbols[0]["children"].as_array().unwrap().len(), 4);

    let folds = client.request("textDocument/foldingRange", json!({"textDocument": doc})).await;
    assert_eq!(folds.as_array().unwrap().len(), 5, "{folds}");

    let whole = json!({"start": pos(0, 0), "end": pos(16, 0)});
    let hints = client.request("textDocument/inlayHint", json!({"textDocument": doc, "range": whole})).await;
    let labels: Vec<&str> = hints.as_array().unwrap().iter().filter_map(|h| h["label"].as_str()).collect();
    assert!(labels.contains(&"= 8.9 m/s") && labels.contains(&"2 of 2, rightmost"), "{labels:?}");

    let tokens = client.request("textDocument/semanticTokens/full", json!({"textDocument": doc})).await;
    let data: Vec<u64> = tokens["data"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    assert_eq!(&data[..3], &[0, 0, 8], "`scenario` first, 8 long");
    assert_eq!(legend[data[3] as usize], "keyword");

    let lead = pos(12, 24);
    let refs = client
        .request(
            "textDocument/references",
            json!({"textDocument": doc, "position": lead, "context": {"includeDeclaration": true}}),
        )
        .await;
    assert_eq!(refs.as_array().unwrap().len(), 2);
    let prepared = client.request("textDocument/prepareRename", json!({"textDocument": doc, "position": lead})).await;
    assert_eq!(prepared["start"], pos(12, 24));
    let edit = client
        .request("textDocument/rename", json!({"textDocument": doc, "position": lead, "newName": "leader"}))
        .await;
    assert_eq!(edit["changes"][UNTITLED].as_array().unwrap().len(), 2);
    let id = client
        .start_request("textDocument/rename", json!({"textDocument": doc, "position": lead, "newName": "tail"}))
        .await;
    let refused = client.response(id).await;
    assert!(refused["error"]["message"].as_str().unwrap().contains("already"), "{refused}");

    // a section completes as a snippet for a client that takes snippets
    let items = client.request("textDocument/completion", json!({"textDocument": doc, "position": pos(14, 2)})).await;
    let environment = items.as_array().unwrap().iter().find(|i| i["label"] == "environment").expect("environment");
    assert_eq!(environment["insertTextFormat"], 2);
    assert!(environment["textEdit"]["newText"].as_str().unwrap().contains("$0"));
    assert!(items.as_array().unwrap().iter().all(|i| i["label"] != "road"), "road is written already");

    let range = json!({"start": pos(2, 0), "end": pos(2, 5)});
    let formatted = client
        .request(
            "textDocument/rangeFormatting",
            json!({"textDocument": doc, "range": range, "options": {"tabSize": 2, "insertSpaces": true}}),
        )
        .await;
    assert!(formatted.as_array().is_some(), "{formatted}");
    client.shutdown().await;

    // without snippet support the same item is plain text
    let mut client = Client::default().await;
    client.open(UNTITLED, "tad", text).await;
    let items = client.request("textDocument/completion", json!({"textDocument": doc, "position": pos(14, 2)})).await;
    let environment = items.as_array().unwrap().iter().find(|i| i["label"] == "environment").unwrap();
    assert_eq!(environment["insertTextFormat"], 1);
    assert!(!environment["textEdit"]["newText"].as_str().unwrap().contains('$'));
    client.shutdown().await;
}
