//! `tad-ide` and `tad-diagnostics` values to protocol values, through a [`View`]: one
//! document at one version, the database it was read from, and where other files are.
//!
//! A diagnostic becomes one LSP diagnostic: the code, the message with its help and notes,
//! every secondary label as related information (in its own file: a used module, the
//! written stdlib), tags where a code means unneeded or deprecated text, and as `data` the
//! typed payload and the scenario's class, so a client can act without reading words.

use std::collections::HashMap;
use std::path::PathBuf;

use serde_json::json;
use tad_db::{Database, STDLIB_PREFIX, SourceFile};
use tad_diagnostics::{Code, Severity, Span};
use tad_ide::Location;
use tower_lsp_server::ls_types as lsp;
use tower_lsp_server::ls_types::Uri;

use crate::line_index::{Encoding, LineIndex};
use crate::workspace::Document;

/// Where the files a result may point into are, for a client.
#[derive(Clone, Debug, Default)]
pub struct Locator {
    pub open: HashMap<SourceFile, (Uri, std::sync::Arc<String>, std::sync::Arc<LineIndex>)>,
    pub stdlib_dir: Option<PathBuf>,
}

/// One document as a request sees it.
pub struct View {
    pub db: Database,
    pub doc: Document,
    pub encoding: Encoding,
    pub locator: Locator,
    /// Line indexes of other files (a used module, the stdlib), made once per view.
    pub indexes: std::cell::RefCell<HashMap<SourceFile, std::sync::Arc<LineIndex>>>,
}

impl View {
    pub fn new(db: Database, doc: Document, encoding: Encoding, locator: Locator) -> View {
        View { db, doc, encoding, locator, indexes: Default::default() }
    }

    pub fn offset(&self, position: lsp::Position) -> usize {
        self.doc.index.offset(&self.doc.text, position, self.encoding)
    }

    pub fn range(&self, span: Span) -> lsp::Range {
        self.doc.index.range(&self.doc.text, span, self.encoding)
    }

    pub fn span(&self, range: lsp::Range) -> Span {
        self.doc.index.span(&self.doc.text, range, self.encoding)
    }

    pub fn position(&self, offset: usize) -> lsp::Position {
        self.doc.index.position(&self.doc.text, offset, self.encoding)
    }

    /// A span of any file as a protocol location.
    pub fn location(&self, file: SourceFile, span: Span) -> Option<lsp::Location> {
        if file == self.doc.file {
            return Some(lsp::Location { uri: self.doc.uri.clone(), range: self.range(span) });
        }
        if let Some((uri, text, index)) = self.locator.open.get(&file) {
            return Some(lsp::Location { uri: uri.clone(), range: index.range(text, span, self.encoding) });
        }
        let uri = self.uri_of(file)?;
        let text = file.text(&self.db);
        let index =
            self.indexes.borrow_mut().entry(file).or_insert_with(|| std::sync::Arc::new(LineIndex::new(text))).clone();
        Some(lsp::Location { uri, range: index.range(text, span, self.encoding) })
    }

    pub fn ide_location(&self, location: Location) -> Option<lsp::Location> {
        self.location(location.file, location.span)
    }

    pub fn uri_of(&self, file: SourceFile) -> Option<Uri> {
        if file == self.doc.file {
            return Some(self.doc.uri.clone());
        }
        if let Some((uri, ..)) = self.locator.open.get(&file) {
            return Some(uri.clone());
        }
        let path = file.path(&self.db);
        match path.strip_prefix(STDLIB_PREFIX) {
            Ok(relative) => Uri::from_file_path(self.locator.stdlib_dir.as_ref()?.join(relative)),
            Err(_) if path.is_absolute() && path.is_file() => Uri::from_file_path(path),
            Err(_) => None,
        }
    }

    /// Edits to one file as protocol text edits.
    pub fn text_edits(&self, file: SourceFile, edits: &[tad_ide::Edit]) -> Option<(Uri, Vec<lsp::TextEdit>)> {
        let uri = self.uri_of(file)?;
        let edits = edits
            .iter()
            .filter_map(|e| Some(lsp::TextEdit { range: self.location(file, e.span)?.range, new_text: e.text.clone() }))
            .collect();
        Some((uri, edits))
    }
}

/// The tag a code's diagnostics carry: text that can go (an empty section, a name listed
/// twice) or an old spelling (an alias).
fn tags(code: Code) -> Option<Vec<lsp::DiagnosticTag>> {
    match code {
        Code::W0200 | Code::W0201 => Some(vec![lsp::DiagnosticTag::UNNECESSARY]),
        Code::W0401 => Some(vec![lsp::DiagnosticTag::DEPRECATED]),
        _ => None,
    }
}

pub fn diagnostic(view: &View, d: &tad_diagnostics::Diagnostic, class: Option<&str>) -> lsp::Diagnostic {
    let mut message = d.message.clone();
    if let Some(help) = &d.help {
        message.push_str(&format!("\nhelp: {help}"));
    }
    for note in &d.notes {
        message.push_str(&format!("\nnote: {note}"));
    }
    let related: Vec<lsp::DiagnosticRelatedInformation> = d
        .secondary
        .iter()
        .filter_map(|label| {
            let file = match label.file {
                Some(id) => view.db.file(id)?,
                None => view.doc.file,
            };
            Some(lsp::DiagnosticRelatedInformation {
                location: view.location(file, label.span)?,
                message: label.message.clone(),
            })
        })
        .collect();
    lsp::Diagnostic {
        range: view.range(d.primary.span),
        severity: Some(match d.severity {
            Severity::Error => lsp::DiagnosticSeverity::ERROR,
            Severity::Warning => lsp::DiagnosticSeverity::WARNING,
            Severity::Hint => lsp::DiagnosticSeverity::HINT,
        }),
        code: Some(lsp::NumberOrString::String(d.code.as_str().to_string())),
        code_description: None,
        source: Some("tadsl".to_string()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        tags: tags(d.code),
        data: Some(json!({
            "payload": serde_json::to_value(&d.payload).unwrap_or_default(),
            "class": class,
            "fixes": d.fixes.len(),
        })),
    }
}

pub fn severity_of(d: &lsp::Diagnostic) -> &'static str {
    match d.severity {
        Some(lsp::DiagnosticSeverity::ERROR) => "error",
        Some(lsp::DiagnosticSeverity::WARNING) => "warning",
        _ => "hint",
    }
}

pub fn symbol_kind(kind: tad_ide::outline::SymbolKind) -> lsp::SymbolKind {
    use tad_ide::outline::SymbolKind as K;
    match kind {
        K::Scenario => lsp::SymbolKind::MODULE,
        K::Section => lsp::SymbolKind::NAMESPACE,
        K::Group => lsp::SymbolKind::OBJECT,
        K::Field => lsp::SymbolKind::PROPERTY,
        K::Declaration => lsp::SymbolKind::ENUM_MEMBER,
        K::Module => lsp::SymbolKind::PACKAGE,
    }
}

#[allow(deprecated)] // `deprecated` is a required field of the protocol's struct
pub fn symbol(view: &View, s: &tad_ide::outline::Symbol) -> lsp::DocumentSymbol {
    let range = view.range(s.span);
    let mut selection_range = view.range(s.selection);
    // the protocol wants the selection inside the range
    if !s.span.contains(s.selection) {
        selection_range = range;
    }
    lsp::DocumentSymbol {
        name: if s.name.is_empty() { "<unnamed>".to_string() } else { s.name.clone() },
        detail: s.detail.clone(),
        kind: symbol_kind(s.kind),
        tags: None,
        deprecated: None,
        range,
        selection_range,
        children: (!s.children.is_empty()).then(|| s.children.iter().map(|c| symbol(view, c)).collect()),
    }
}

pub fn completion_kind(kind: tad_ide::completion::CompletionKind) -> lsp::CompletionItemKind {
    use tad_ide::completion::CompletionKind as K;
    match kind {
        K::Section => lsp::CompletionItemKind::MODULE,
        K::Field => lsp::CompletionItemKind::FIELD,
        K::Value => lsp::CompletionItemKind::ENUM_MEMBER,
        K::Group => lsp::CompletionItemKind::VARIABLE,
        K::Unit => lsp::CompletionItemKind::UNIT,
        K::Module => lsp::CompletionItemKind::MODULE,
        K::Keyword => lsp::CompletionItemKind::KEYWORD,
    }
}

/// The semantic token legend, in the order of `tad_ide::tokens::TokenKind::ALL` and
/// `Modifier::ALL`.
pub fn legend() -> lsp::SemanticTokensLegend {
    use tad_ide::tokens::{Modifier, TokenKind as K};
    let token_types = K::ALL
        .iter()
        .map(|k| match k {
            K::Keyword => lsp::SemanticTokenType::KEYWORD,
            K::Namespace => lsp::SemanticTokenType::NAMESPACE,
            K::Property => lsp::SemanticTokenType::PROPERTY,
            K::Variable => lsp::SemanticTokenType::VARIABLE,
            K::Type => lsp::SemanticTokenType::TYPE,
            K::EnumMember | K::Declaration => lsp::SemanticTokenType::ENUM_MEMBER,
            K::Number => lsp::SemanticTokenType::NUMBER,
            K::Unit => lsp::SemanticTokenType::new("unit"),
            K::String => lsp::SemanticTokenType::STRING,
            K::Comment => lsp::SemanticTokenType::COMMENT,
            K::Operator => lsp::SemanticTokenType::OPERATOR,
        })
        .collect();
    let token_modifiers = Modifier::ALL
        .iter()
        .map(|m| match m {
            Modifier::Declaration => lsp::SemanticTokenModifier::DECLARATION,
            Modifier::Deprecated => lsp::SemanticTokenModifier::DEPRECATED,
            Modifier::DefaultLibrary => lsp::SemanticTokenModifier::DEFAULT_LIBRARY,
        })
        .collect();
    lsp::SemanticTokensLegend { token_types, token_modifiers }
}

/// Tokens (sorted, one line each) in the protocol's relative encoding; only those inside
/// `range` when given.
pub fn semantic_tokens(view: &View, tokens: &[tad_ide::tokens::Token], range: Option<Span>) -> Vec<lsp::SemanticToken> {
    use tad_ide::tokens::TokenKind;
    let mut out = Vec::with_capacity(tokens.len());
    let (mut line, mut start) = (0u32, 0u32);
    for token in tokens {
        if range.is_some_and(|r| token.span.end < r.start || token.span.start > r.end) || token.span.is_empty() {
            continue;
        }
        let from = view.position(token.span.start);
        let to = view.position(token.span.end);
        if to.line != from.line || to.character <= from.character {
            continue;
        }
        let delta_line = from.line - line;
        let delta_start = if delta_line == 0 { from.character.saturating_sub(start) } else { from.character };
        if delta_line == 0 && from.character < start && !out.is_empty() {
            continue; // overlapping: keep the first
        }
        let kind = TokenKind::ALL.iter().position(|k| *k == token.kind).unwrap_or(0) as u32;
        out.push(lsp::SemanticToken {
            delta_line,
            delta_start,
            length: to.character - from.character,
            token_type: kind,
            token_modifiers_bitset: token.modifiers,
        });
        line = from.line;
        start = from.character;
    }
    out
}
