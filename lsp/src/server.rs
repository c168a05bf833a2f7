//! The protocol: one `LanguageServer` method per request, each converting positions,
//! calling `tad-ide` on a snapshot and converting the answer back.
//!
//! Concurrency (style.md §9): notifications apply their edit to the [`Workspace`] at once,
//! under a `std` mutex never held across an `.await`, so edits keep their order whatever
//! tower-lsp-server interleaves. Requests clone the database under the lock and answer on
//! a blocking thread; when an edit arrives meanwhile, salsa cancels the stale work and the
//! request answers `ContentModified`. Diagnostics come from one worker thread that always
//! checks the newest text of every document waiting for it, so a burst of changes costs
//! one check, not one per change; each publication carries its document's version.
//!
//! A panic in analysis (a bug) is caught, answered as an internal error and logged; the
//! server carries on.

use std::collections::BTreeSet;
use std::panic::AssertUnwindSafe;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

use serde_json::Value;
use tad_check::Options;
use tower_lsp_server::jsonrpc::{Error, ErrorCode, Result};
use tower_lsp_server::ls_types::notification::Notification;
use tower_lsp_server::ls_types::*;
use tower_lsp_server::{Client, LanguageServer};

use crate::convert::{self, View};
use crate::line_index::Encoding;
use crate::workspace::Workspace;

/// `tadsl/scenarioClass`: a document's completeness class after each check.
pub enum ScenarioClass {}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct ScenarioClassParams {
    pub uri: Uri,
    pub version: i32,
    /// `complete`, `incomplete`, `non_scenario`, `invalid`; `null` for a module.
    pub class: Option<String>,
}

impl Notification for ScenarioClass {
    type Params = ScenarioClassParams;
    const METHOD: &'static str = "tadsl/scenarioClass";
}

pub struct Server {
    client: Client,
    state: Arc<Mutex<Workspace>>,
    checks: Arc<Checks>,
    snippets: Mutex<bool>,
}

/// Documents waiting for a check, and the worker's stop flag.
#[derive(Default)]
struct Checks {
    queue: Mutex<(BTreeSet<String>, bool)>,
    ready: Condvar,
}

impl Checks {
    fn push(&self, uris: impl IntoIterator<Item = Uri>) {
        if let Ok(mut queue) = self.queue.lock() {
            queue.0.extend(uris.into_iter().map(|u| u.as_str().to_string()));
            self.ready.notify_one();
        }
    }

    fn stop(&self) {
        if let Ok(mut queue) = self.queue.lock() {
            queue.1 = true;
            self.ready.notify_one();
        }
    }

    /// The next batch; `None` once stopped.
    fn next(&self) -> Option<BTreeSet<String>> {
        let mut queue = self.queue.lock().ok()?;
        loop {
            if queue.1 {
                return None;
            }
            if !queue.0.is_empty() {
                return Some(std::mem::take(&mut queue.0));
            }
            queue = self.ready.wait(queue).ok()?;
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.checks.stop();
    }
}

fn lock(state: &Mutex<Workspace>) -> MutexGuard<'_, Workspace> {
    // a panic never happens under the lock (edits are total); recover the data if it did
    state.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn content_modified() -> Error {
    Error { code: ErrorCode::ContentModified, message: "the document changed; ask again".into(), data: None }
}

fn request_failed(message: impl Into<String>) -> Error {
    Error { code: ErrorCode::ServerError(-32803), message: message.into().into(), data: None }
}

impl Server {
    pub fn new(client: Client) -> Server {
        let state = Arc::new(Mutex::new(Workspace::new(Options::default())));
        let checks = Arc::new(Checks::default());
        let runtime = tokio::runtime::Handle::current();
        {
            let (state, checks, client) = (state.clone(), checks.clone(), client.clone());
            std::thread::Builder::new()
                .name("tadsl-check".into())
                .spawn(move || check_worker(&state, &checks, &client, &runtime))
                .ok();
        }
        Server { client, state, checks, snippets: Mutex::new(false) }
    }

    /// Answer from a snapshot of `uri`'s document on a blocking thread. `Ok(None)` for a
    /// document that is not open.
    async fn read<T: Send + 'static>(
        &self,
        uri: &Uri,
        f: impl FnOnce(&View) -> T + Send + 'static,
    ) -> Result<Option<T>> {
        let view = {
            let ws = lock(&self.state);
            let Some(doc) = ws.doc(uri) else { return Ok(None) };
            View::new(ws.snapshot(), doc.clone(), ws.encoding, ws.locator())
        };
        let task = tokio::task::spawn_blocking(move || {
            std::panic::catch_unwind(AssertUnwindSafe(|| tad_db::cancellable(AssertUnwindSafe(|| f(&view)))))
        });
        match task.await {
            Ok(Ok(Some(answer))) => Ok(Some(answer)),
            Ok(Ok(None)) => Err(content_modified()),
            Ok(Err(panic)) => {
                let what = panic_message(&panic);
                self.client.log_message(MessageType::ERROR, format!("tadsl: internal error: {what}")).await;
                Err(Error {
                    code: ErrorCode::InternalError,
                    message: format!("internal error: {what}").into(),
                    data: None,
                })
            }
            Err(_) => Err(Error::internal_error()),
        }
    }

    fn queue_all(&self) {
        let uris: Vec<Uri> = lock(&self.state).docs.keys().cloned().collect();
        self.checks.push(uris);
    }

    async fn apply_settings(&self, settings: &Value) {
        let problems = {
            let mut ws = lock(&self.state);
            let mut options = ws.options.clone();
            let problems = crate::config::apply(&mut options, settings);
            if options != ws.options {
                ws.set_options(options);
            }
            problems
        };
        self.queue_all();
        if !problems.is_empty() {
            self.client.show_message(MessageType::WARNING, format!("tadsl settings: {}", problems.join("; "))).await;
        }
    }
}

fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".to_string())
}

/// Check every queued document on a snapshot and publish; a batch cancelled by an edit
/// is dropped (the edit queued its documents again).
fn check_worker(state: &Mutex<Workspace>, checks: &Checks, client: &Client, runtime: &tokio::runtime::Handle) {
    // what each document last had published: a document whose version and diagnostics are
    // unchanged (another document was edited) is not published again
    let mut published: std::collections::HashMap<Uri, (i32, Vec<Diagnostic>)> = std::collections::HashMap::new();
    while let Some(batch) = checks.next() {
        let (views, closed): (Vec<View>, Vec<Uri>) = {
            let ws = lock(state);
            let db = ws.snapshot();
            let locator = ws.locator();
            let mut views = Vec::new();
            let mut closed = Vec::new();
            for key in &batch {
                let Ok(uri) = key.parse::<Uri>() else { continue };
                match ws.doc(&uri) {
                    Some(doc) if !doc.read_only => {
                        views.push(View::new(db.clone(), doc.clone(), ws.encoding, locator.clone()))
                    }
                    Some(_) => {}
                    None => closed.push(uri),
                }
            }
            (views, closed)
        };
        for uri in closed {
            published.remove(&uri);
        }
        // every snapshot is dropped before anything is published: an edit waiting for
        // them may hold the task that writes to the client
        let results: Vec<_> = views
            .into_iter()
            .map(|view| {
                let result = std::panic::catch_unwind(AssertUnwindSafe(|| {
                    tad_db::cancellable(AssertUnwindSafe(|| publishable(&view)))
                }));
                (view.doc.uri.clone(), view.doc.version, result)
            })
            .collect();
        for (uri, version, result) in results {
            match result {
                Ok(Some((diagnostics, class))) => {
                    if published.get(&uri).is_some_and(|(v, d)| *v == version && *d == diagnostics) {
                        continue;
                    }
                    published.insert(uri.clone(), (version, diagnostics.clone()));
                    runtime.block_on(async {
                        client.publish_diagnostics(uri.clone(), diagnostics, Some(version)).await;
                        client.send_notification::<ScenarioClass>(ScenarioClassParams { uri, version, class }).await;
                    })
                }
                Ok(None) => {}
                Err(panic) => {
                    let message = format!("tadsl: internal error checking {}: {}", uri.as_str(), panic_message(&panic));
                    runtime.block_on(client.log_message(MessageType::ERROR, message));
                }
            }
        }
    }
}

/// The document's diagnostics, as published, and its class.
fn publishable(view: &View) -> (Vec<Diagnostic>, Option<String>) {
    let file = view.doc.file;
    if file.language(&view.db) == tad_db::Language::Yaml && tad_yaml::dialect(file.text(&view.db)).is_none() {
        // YAML that is no scenario answer is none of our business
        return (Vec::new(), None);
    }
    let checked = tad_db::check(&view.db, file);
    let class = checked.class.map(|c| c.as_str().to_string());
    let id = file.id(&view.db);
    let diagnostics = checked
        .diagnostics
        .iter()
        .filter(|d| d.file == id)
        .map(|d| convert::diagnostic(view, d, class.as_deref()))
        .collect();
    (diagnostics, class)
}

/// A snippet as plain text: `${1:x}` → `x`, `$0`/`$1` dropped, `\$` → `$`.
fn plain(snippet: &str) -> String {
    let mut out = String::with_capacity(snippet.len());
    let mut chars = snippet.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' => out.extend(chars.next()),
            '$' if chars.peek() == Some(&'{') => {
                chars.next();
                while chars.peek().is_some_and(|c| c.is_ascii_digit()) {
                    chars.next();
                }
                if chars.peek() == Some(&':') {
                    chars.next();
                }
                for c in chars.by_ref() {
                    if c == '}' {
                        break;
                    }
                    out.push(c);
                }
            }
            '$' if chars.peek().is_some_and(|c| c.is_ascii_digit()) => {
                while chars.peek().is_some_and(|c| c.is_ascii_digit()) {
                    chars.next();
                }
            }
            c => out.push(c),
        }
    }
    out
}

fn is_snippet(text: &str) -> bool {
    text.contains("$0") || text.contains("${") || text.contains("$1")
}

impl LanguageServer for Server {
    async fn initialize(&self, params: InitializeParams) -> Result<InitializeResult> {
        let encodings =
            params.capabilities.general.as_ref().and_then(|g| g.position_encodings.clone()).unwrap_or_default();
        let encoding = if encodings.contains(&PositionEncodingKind::UTF8) { Encoding::Utf8 } else { Encoding::Utf16 };
        let snippets = params
            .capabilities
            .text_document
            .as_ref()
            .and_then(|t| t.completion.as_ref())
            .and_then(|c| c.completion_item.as_ref())
            .and_then(|i| i.snippet_support)
            .unwrap_or(false);
        if let Ok(mut s) = self.snippets.lock() {
            *s = snippets;
        }
        lock(&self.state).encoding = encoding;
        if let Some(settings) = &params.initialization_options {
            self.apply_settings(settings).await;
        }
        Ok(InitializeResult {
            capabilities: ServerCapabilities {
                position_encoding: Some(match encoding {
                    Encoding::Utf8 => PositionEncodingKind::UTF8,
                    Encoding::Utf16 => PositionEncodingKind::UTF16,
                }),
                text_document_sync: Some(TextDocumentSyncCapability::Options(TextDocumentSyncOptions {
                    open_close: Some(true),
                    change: Some(TextDocumentSyncKind::INCREMENTAL),
                    ..TextDocumentSyncOptions::default()
                })),
                hover_provider: Some(HoverProviderCapability::Simple(true)),
                completion_provider: Some(CompletionOptions {
                    trigger_characters: Some(vec![":".into(), " ".into(), ".".into()]),
                    ..CompletionOptions::default()
                }),
                definition_provider: Some(OneOf::Left(true)),
                references_provider: Some(OneOf::Left(true)),
                document_symbol_provider: Some(OneOf::Left(true)),
                document_formatting_provider: Some(OneOf::Left(true)),
                document_range_formatting_provider: Some(OneOf::Left(true)),
                code_action_provider: Some(CodeActionProviderCapability::Options(CodeActionOptions {
                    code_action_kinds: Some(vec![CodeActionKind::QUICKFIX, CodeActionKind::SOURCE_FIX_ALL]),
                    ..CodeActionOptions::default()
                })),
                rename_provider: Some(OneOf::Right(RenameOptions {
                    prepare_provider: Some(true),
                    work_done_progress_options: WorkDoneProgressOptions::default(),
                })),
                folding_range_provider: Some(FoldingRangeProviderCapability::Simple(true)),
                semantic_tokens_provider: Some(SemanticTokensServerCapabilities::SemanticTokensOptions(
                    SemanticTokensOptions {
                        legend: convert::legend(),
                        range: Some(true),
                        full: Some(SemanticTokensFullOptions::Bool(true)),
                        ..SemanticTokensOptions::default()
                    },
                )),
                inlay_hint_provider: Some(OneOf::Left(true)),
                ..ServerCapabilities::default()
            },
            server_info: Some(ServerInfo { name: "tadslc".into(), version: Some(env!("CARGO_PKG_VERSION").into()) }),
            offset_encoding: None,
        })
    }

    async fn initialized(&self, _: InitializedParams) {
        let client = self.client.clone();
        let state = self.state.clone();
        let checks = self.checks.clone();
        // pulled from a task, never awaited inside a notification handler (style.md §9)
        tokio::spawn(async move {
            let item = ConfigurationItem { scope_uri: None, section: Some("tadsl".into()) };
            if let Ok(values) = client.configuration(vec![item]).await
                && let Some(settings) = values.into_iter().next().filter(|v| !v.is_null())
            {
                let mut ws = lock(&state);
                let mut options = ws.options.clone();
                let problems = crate::config::apply(&mut options, &settings);
                if problems.is_empty() && options != ws.options {
                    ws.set_options(options);
                    checks.push(ws.docs.keys().cloned().collect::<Vec<_>>());
                }
            }
        });
    }

    async fn shutdown(&self) -> Result<()> {
        self.checks.stop();
        Ok(())
    }

    async fn did_open(&self, params: DidOpenTextDocumentParams) {
        let d = params.text_document;
        lock(&self.state).open(d.uri.clone(), &d.language_id, d.version, d.text);
        self.queue_all();
    }

    async fn did_change(&self, params: DidChangeTextDocumentParams) {
        let d = params.text_document;
        let known = lock(&self.state).change(&d.uri, d.version, params.content_changes).is_some();
        if known {
            self.queue_all();
        } else {
            self.client
                .log_message(MessageType::WARNING, format!("tadsl: change to a document not open: {}", d.uri.as_str()))
                .await;
        }
    }

    async fn did_close(&self, params: DidCloseTextDocumentParams) {
        let uri = params.text_document.uri;
        let closed = lock(&self.state).close(&uri).is_some();
        if closed {
            self.queue_all();
            // the worker forgets what it published for it
            self.checks.push([uri.clone()]);
            self.client.publish_diagnostics(uri, Vec::new(), None).await;
        }
    }

    async fn did_change_configuration(&self, params: DidChangeConfigurationParams) {
        self.apply_settings(&params.settings).await;
    }

    async fn hover(&self, params: HoverParams) -> Result<Option<Hover>> {
        let p = params.text_document_position_params;
        let answer = self
            .read(&p.text_document.uri, move |view| {
                let hover = tad_ide::hover::hover(&view.db, view.doc.file, view.offset(p.position))?;
                Some(Hover {
                    contents: HoverContents::Markup(MarkupContent {
                        kind: MarkupKind::Markdown,
                        value: hover.markdown,
                    }),
                    range: Some(view.range(hover.span)),
                })
            })
            .await?;
        Ok(answer.flatten())
    }

    async fn completion(&self, params: CompletionParams) -> Result<Option<CompletionResponse>> {
        let p = params.text_document_position;
        let snippets = self.snippets.lock().map(|s| *s).unwrap_or(false);
        let answer = self
            .read(&p.text_document.uri, move |view| {
                let items = tad_ide::completion::completions(&view.db, view.doc.file, view.offset(p.position));
                let range = |span| view.range(span);
                items
                    .into_iter()
                    .enumerate()
                    .map(|(i, c)| {
                        let text = c.insert.clone().unwrap_or_else(|| c.label.clone());
                        let snippet = snippets && is_snippet(&text);
                        let new_text = if is_snippet(&text) && !snippet { plain(&text) } else { text };
                        CompletionItem {
                            kind: Some(convert::completion_kind(c.kind)),
                            detail: c.detail.clone(),
                            documentation: c.documentation.clone().map(|value| {
                                Documentation::MarkupContent(MarkupContent { kind: MarkupKind::Markdown, value })
                            }),
                            preselect: c.preselect.then_some(true),
                            sort_text: Some(format!("{}{i:05}", if c.preselect { 0 } else { 1 })),
                            filter_text: Some(c.label.clone()),
                            insert_text_format: Some(if snippet {
                                InsertTextFormat::SNIPPET
                            } else {
                                InsertTextFormat::PLAIN_TEXT
                            }),
                            text_edit: Some(CompletionTextEdit::Edit(TextEdit { range: range(c.replace), new_text })),
                            label: c.label,
                            ..CompletionItem::default()
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .await?;
        Ok(answer.map(CompletionResponse::Array))
    }

    async fn goto_definition(&self, params: GotoDefinitionParams) -> Result<Option<GotoDefinitionResponse>> {
        let p = params.text_document_position_params;
        let answer = self
            .read(&p.text_document.uri, move |view| {
                let targets = tad_ide::navigate::definition(&view.db, view.doc.file, view.offset(p.position));
                let locations: Vec<Location> = targets.into_iter().filter_map(|l| view.ide_location(l)).collect();
                (!locations.is_empty()).then_some(GotoDefinitionResponse::Array(locations))
            })
            .await?;
        Ok(answer.flatten())
    }

    async fn references(&self, params: ReferenceParams) -> Result<Option<Vec<Location>>> {
        let p = params.text_document_position;
        let include = params.context.include_declaration;
        self.read(&p.text_document.uri, move |view| {
            let found = tad_ide::navigate::references(&view.db, view.doc.file, view.offset(p.position), include);
            found.into_iter().filter_map(|l| view.ide_location(l)).collect()
        })
        .await
    }

    async fn document_symbol(&self, params: DocumentSymbolParams) -> Result<Option<DocumentSymbolResponse>> {
        let answer = self
            .read(&params.text_document.uri, |view| {
                let symbols = tad_ide::outline::symbols(&view.db, view.doc.file);
                DocumentSymbolResponse::Nested(symbols.iter().map(|s| convert::symbol(view, s)).collect())
            })
            .await?;
        Ok(answer)
    }

    async fn formatting(&self, params: DocumentFormattingParams) -> Result<Option<Vec<TextEdit>>> {
        let answer = self
            .read(&params.text_document.uri, |view| {
                let edits = tad_ide::actions::format(&view.db, view.doc.file)?;
                Some(edits.into_iter().map(|e| TextEdit { range: view.range(e.span), new_text: e.text }).collect())
            })
            .await?;
        Ok(answer.flatten())
    }

    async fn range_formatting(&self, params: DocumentRangeFormattingParams) -> Result<Option<Vec<TextEdit>>> {
        let range = params.range;
        let answer = self
            .read(&params.text_document.uri, move |view| {
                let edits = tad_ide::actions::format_range(&view.db, view.doc.file, view.span(range))?;
                Some(edits.into_iter().map(|e| TextEdit { range: view.range(e.span), new_text: e.text }).collect())
            })
            .await?;
        Ok(answer.flatten())
    }

    async fn code_action(&self, params: CodeActionParams) -> Result<Option<CodeActionResponse>> {
        let range = params.range;
        let only = params.context.only.clone();
        let wants = move |kind: &CodeActionKind| {
            only.as_ref().is_none_or(|only| only.iter().any(|o| kind.as_str().starts_with(o.as_str())))
        };
        let answer = self
            .read(&params.text_document.uri, move |view| {
                let file = view.doc.file;
                let mut out: CodeActionResponse = Vec::new();
                let checked = tad_db::check(&view.db, file);
                let class = checked.class.map(|c| c.as_str());
                if wants(&CodeActionKind::QUICKFIX) {
                    for action in tad_ide::actions::code_actions(&view.db, file, view.span(range)) {
                        let Some((uri, edits)) = view.text_edits(file, &action.edits) else { continue };
                        let diagnostic =
                            checked.diagnostics.get(action.diagnostic).map(|d| convert::diagnostic(view, d, class));
                        out.push(CodeActionOrCommand::CodeAction(CodeAction {
                            title: action.title,
                            kind: Some(CodeActionKind::QUICKFIX),
                            diagnostics: diagnostic.map(|d| vec![d]),
                            edit: Some(WorkspaceEdit {
                                changes: Some([(uri, edits)].into_iter().collect()),
                                ..WorkspaceEdit::default()
                            }),
                            is_preferred: action.preferred.then_some(true),
                            ..CodeAction::default()
                        }));
                    }
                }
                let all = tad_ide::actions::fix_all(&view.db, file);
                if wants(&CodeActionKind::SOURCE_FIX_ALL)
                    && !all.is_empty()
                    && let Some((uri, edits)) = view.text_edits(file, &all)
                {
                    out.push(CodeActionOrCommand::CodeAction(CodeAction {
                        title: format!("Apply every machine-applicable fix ({})", all.len()),
                        kind: Some(CodeActionKind::SOURCE_FIX_ALL),
                        edit: Some(WorkspaceEdit {
                            changes: Some([(uri, edits)].into_iter().collect()),
                            ..WorkspaceEdit::default()
                        }),
                        ..CodeAction::default()
                    }));
                }
                out
            })
            .await?;
        Ok(answer)
    }

    async fn prepare_rename(&self, params: TextDocumentPositionParams) -> Result<Option<PrepareRenameResponse>> {
        let position = params.position;
        let answer = self
            .read(&params.text_document.uri, move |view| {
                tad_ide::navigate::prepare_rename(&view.db, view.doc.file, view.offset(position))
                    .map(|span| view.range(span))
            })
            .await?;
        match answer {
            None => Ok(None),
            Some(Ok(range)) => Ok(Some(PrepareRenameResponse::Range(range))),
            Some(Err(why)) => Err(request_failed(why)),
        }
    }

    async fn rename(&self, params: RenameParams) -> Result<Option<WorkspaceEdit>> {
        let p = params.text_document_position;
        let new_name = params.new_name;
        let answer = self
            .read(&p.text_document.uri, move |view| {
                let edits = tad_ide::navigate::rename(&view.db, view.doc.file, view.offset(p.position), &new_name)?;
                let changes = edits.iter().filter_map(|(file, edits)| view.text_edits(*file, edits)).collect();
                Ok::<_, String>(WorkspaceEdit { changes: Some(changes), ..WorkspaceEdit::default() })
            })
            .await?;
        match answer {
            None => Ok(None),
            Some(Ok(edit)) => Ok(Some(edit)),
            Some(Err(why)) => Err(request_failed(why)),
        }
    }

    async fn folding_range(&self, params: FoldingRangeParams) -> Result<Option<Vec<FoldingRange>>> {
        self.read(&params.text_document.uri, |view| {
            tad_ide::outline::folding(&view.db, view.doc.file)
                .into_iter()
                .filter_map(|fold| {
                    let range = view.range(fold.span);
                    (range.end.line > range.start.line).then(|| FoldingRange {
                        start_line: range.start.line,
                        end_line: range.end.line,
                        kind: match fold.kind {
                            tad_ide::outline::FoldKind::Comment => Some(FoldingRangeKind::Comment),
                            tad_ide::outline::FoldKind::Block | tad_ide::outline::FoldKind::Text => {
                                Some(FoldingRangeKind::Region)
                            }
                        },
                        ..FoldingRange::default()
                    })
                })
                .collect()
        })
        .await
    }

    async fn semantic_tokens_full(&self, params: SemanticTokensParams) -> Result<Option<SemanticTokensResult>> {
        let answer = self
            .read(&params.text_document.uri, |view| {
                let tokens = tad_ide::tokens::tokens(&view.db, view.doc.file);
                SemanticTokensResult::Tokens(SemanticTokens {
                    result_id: None,
                    data: convert::semantic_tokens(view, &tokens, None),
                })
            })
            .await?;
        Ok(answer)
    }

    async fn semantic_tokens_range(
        &self,
        params: SemanticTokensRangeParams,
    ) -> Result<Option<SemanticTokensRangeResult>> {
        let range = params.range;
        let answer = self
            .read(&params.text_document.uri, move |view| {
                let tokens = tad_ide::tokens::tokens(&view.db, view.doc.file);
                let data = convert::semantic_tokens(view, &tokens, Some(view.span(range)));
                SemanticTokensRangeResult::Tokens(SemanticTokens { result_id: None, data })
            })
            .await?;
        Ok(answer)
    }

    async fn inlay_hint(&self, params: InlayHintParams) -> Result<Option<Vec<InlayHint>>> {
        let range = params.range;
        self.read(&params.text_document.uri, move |view| {
            tad_ide::inlay::inlay_hints(&view.db, view.doc.file, view.span(range))
                .into_iter()
                .map(|hint| InlayHint {
                    position: view.position(hint.offset),
                    label: InlayHintLabel::String(hint.label),
                    kind: Some(match hint.kind {
                        tad_ide::inlay::InlayKind::Value => InlayHintKind::TYPE,
                        tad_ide::inlay::InlayKind::Lane => InlayHintKind::PARAMETER,
                    }),
                    text_edits: None,
                    tooltip: hint.tooltip.map(InlayHintTooltip::String),
                    padding_left: Some(true),
                    padding_right: None,
                    data: None,
                })
                .collect()
        })
        .await
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snippets_become_plain_text() {
        assert_eq!(plain("road {\n  $0\n}"), "road {\n  \n}");
        assert_eq!(plain("actor ${1:name}: ${2:car} {\n  $0\n}"), "actor name: car {\n  \n}");
        assert_eq!(plain("cost \\$5"), "cost $5");
        assert!(is_snippet("a $0") && !is_snippet("weather: "));
    }
}
