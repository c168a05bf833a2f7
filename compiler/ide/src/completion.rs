//! Completion: what may be written at the cursor, read from the text around it.
//!
//! While a person types, the document is rarely whole, so the context comes from the
//! lexer's tokens rather than the model: the blocks enclosing the cursor (a stack of their
//! heads: the scenario, a section, an actor group with its type, a declaration), and on
//! the cursor's line whether a `key:` comes before it (a value of that field), an `actor`
//! header, or `use`. What is offered comes from the schema (sections, fields, closed sets,
//! units by the quantity they measure) and from the vocabulary the file sees (names of the
//! field's kind; for a group's `behavior`, only those its actor kind performs, as the
//! checker's E0502 rule says). `insert` is LSP snippet syntax when it holds `$0`.
//!
//! YAML answers get no completion: they are written by models, not typed.

use std::collections::HashSet;

use tad_check::{Entry, Vocabulary};
use tad_syntax::lexer::{KEYWORDS, Token, UNITS};
use tad_syntax::schema::{self, DECLARATIONS, FieldDef, SectionDef, Unit, ValueType};

use crate::{Database, Language, SourceFile, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CompletionKind {
    /// A section (`road`, `ego`) or the `actor`/`scenario` keyword.
    Section,
    /// A field key (`weather:`).
    Field,
    /// A vocabulary name or a word of a closed set.
    Value,
    /// An actor group (a reference).
    Group,
    Unit,
    Module,
    Keyword,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Completion {
    pub label: String,
    pub kind: CompletionKind,
    /// A short line beside the label (the declaration kind and module, the field's type).
    pub detail: Option<String>,
    /// Markdown.
    pub documentation: Option<String>,
    /// The text inserted in place of `replace` (the label when `None`); snippet syntax
    /// when it holds `$0`.
    pub insert: Option<String>,
    /// The text the completion replaces: the word typed so far (empty at the cursor).
    pub replace: Span,
    /// Sorts before others (the best guesses of a context).
    pub preselect: bool,
}

/// A block around the cursor.
#[derive(Clone, Debug, PartialEq)]
enum Frame {
    Scenario,
    Section(String),
    /// An actor group: its name and type as written.
    Actor {
        name: String,
        kind: Option<String>,
    },
    Declaration(String),
    /// A block of something unknown.
    Other,
}

struct Open {
    frame: Frame,
    /// Index of the `{` token.
    at: usize,
}

fn is_word(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

pub fn completions(db: &Database, file: SourceFile, offset: usize) -> Vec<Completion> {
    if file.language(db) != Language::Tad {
        return Vec::new();
    }
    let text = file.text(db);
    let offset = crate::clamp(text, offset);
    let start = text[..offset].char_indices().rev().take_while(|(_, c)| is_word(*c)).last().map_or(offset, |(i, _)| i);
    let end = offset + text[offset..].chars().take_while(|c| is_word(*c)).map(char::len_utf8).sum::<usize>();
    let replace = Span::new(start, end);
    // inside a comment or a string: nothing
    let lexed = tad_syntax::lexer::lex(text);
    if lexed.comments.iter().any(|c| c.start < start && start <= c.end) {
        return Vec::new();
    }
    let tokens = &lexed.tokens;
    if tokens.iter().any(|(s, t, e)| matches!(t, Token::Str | Token::TextBlock) && *s < start && start < *e) {
        return Vec::new();
    }
    let before = tokens.partition_point(|(_, _, e)| *e <= start);
    let stack = frames(tokens, before);
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    // the tokens of this line before the word, after the last brace
    let line: Vec<(Token, &str)> = tokens[..before]
        .iter()
        .rev()
        .take_while(|(s, t, _)| *s >= line_start && !matches!(t, Token::LBrace | Token::RBrace))
        .map(|(s, t, e)| (*t, &text[*s..*e]))
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    let scope = tad_db::vocabulary(db, file);
    let context = Context { vocabulary: &scope.vocabulary, replace, tokens, stack: &stack, text };
    context.offer(&line)
}

/// The blocks open before token `before`, outermost first.
fn frames(tokens: &[(usize, Token, usize)], before: usize) -> Vec<Open> {
    let mut stack: Vec<Open> = Vec::new();
    let mut header_from = 0;
    for (i, (_, token, _)) in tokens[..before].iter().enumerate() {
        match token {
            Token::LBrace => {
                let header: Vec<Token> = tokens[header_from..i].iter().map(|t| t.1).collect();
                let frame = classify(&header);
                stack.push(Open { frame, at: i });
                header_from = i + 1;
            }
            Token::RBrace => {
                stack.pop();
                header_from = i + 1;
            }
            // a field ends a header: the next block's header starts after it
            Token::Key if !matches!(tokens.get(header_from).map(|t| t.1), Some(Token::Actor)) => {
                header_from = i;
            }
            _ => {}
        }
    }
    stack
}

fn classify(header: &[Token]) -> Frame {
    match header.first() {
        Some(Token::Scenario) => Frame::Scenario,
        Some(Token::Actor) => Frame::Actor { name: String::new(), kind: None },
        Some(Token::DeclKind) => Frame::Declaration(String::new()),
        Some(Token::Head) if header.len() == 1 => Frame::Section(String::new()),
        _ => Frame::Other,
    }
}

struct Context<'a> {
    vocabulary: &'a Vocabulary,
    replace: Span,
    tokens: &'a [(usize, Token, usize)],
    stack: &'a [Open],
    text: &'a str,
}

impl Context<'_> {
    fn word(&self, at: usize) -> &str {
        self.tokens.get(at).map_or("", |(s, _, e)| &self.text[*s..*e])
    }

    /// The frame of an open block with its names filled in from its header tokens.
    fn frame(&self, open: &Open) -> Frame {
        let header_end = open.at;
        let mut from = header_end;
        while from > 0 && !matches!(self.tokens[from - 1].1, Token::LBrace | Token::RBrace) {
            from -= 1;
            if matches!(self.tokens[from].1, Token::Scenario | Token::Actor | Token::DeclKind) {
                break;
            }
        }
        let header = &self.tokens[from..header_end];
        match &open.frame {
            Frame::Actor { .. } => {
                let name = header
                    .iter()
                    .find(|t| t.1 == Token::Key)
                    .map_or(String::new(), |t| self.text[t.0..t.2].trim_end_matches(':').trim().to_string());
                let kind = header
                    .iter()
                    .rev()
                    .find(|t| matches!(t.1, Token::Head | Token::Ident))
                    .map(|t| self.text[t.0..t.2].to_string());
                Frame::Actor { name, kind }
            }
            Frame::Section(_) => Frame::Section(self.word(header_end - 1).to_string()),
            Frame::Declaration(_) => Frame::Declaration(
                header
                    .iter()
                    .find(|t| t.1 == Token::DeclKind)
                    .map_or(String::new(), |t| self.text[t.0..t.2].to_string()),
            ),
            other => other.clone(),
        }
    }

    /// The keys already written directly in the block opened at token `open`.
    fn written_keys(&self, open: usize) -> HashSet<String> {
        let mut depth = 0usize;
        let mut keys = HashSet::new();
        for (s, token, e) in &self.tokens[open + 1..] {
            match token {
                Token::LBrace => depth += 1,
                Token::RBrace if depth == 0 => break,
                Token::RBrace => depth -= 1,
                Token::Key
                    if depth == 0 && *e <= self.replace.start
                        || (*token == Token::Key && depth == 0 && *s >= self.replace.end) =>
                {
                    keys.insert(self.text[*s..*e].trim_end_matches(':').trim().to_string());
                }
                Token::Head if depth == 0 => {
                    keys.insert(self.text[*s..*e].to_string());
                }
                _ => {}
            }
        }
        keys
    }

    fn item(&self, label: &str, kind: CompletionKind) -> Completion {
        Completion {
            label: label.to_string(),
            kind,
            detail: None,
            documentation: None,
            insert: None,
            replace: self.replace,
            preselect: false,
        }
    }

    fn offer(&self, line: &[(Token, &str)]) -> Vec<Completion> {
        let Some(open) = self.stack.last() else { return self.top_level(line) };
        let frame = self.frame(open);
        // an actor header on this line, not yet opened: `actor name: 3 |`
        if line.first().is_some_and(|t| t.0 == Token::Actor) {
            return if line.iter().any(|t| t.0 == Token::Key) { self.names("actor_type", None) } else { Vec::new() };
        }
        let key = line.iter().rposition(|t| t.0 == Token::Key);
        match (&frame, key) {
            (Frame::Scenario, None) => self.sections(open.at),
            (Frame::Section(name), None) => {
                schema::section(name).map_or_else(Vec::new, |def| self.fields(def, open.at))
            }
            (Frame::Actor { .. }, None) => self.fields(&schema::ACTOR, open.at),
            (Frame::Declaration(kind), None) => {
                schema::declaration(kind).map_or_else(Vec::new, |def| self.fields(def, open.at))
            }
            (_, Some(k)) => {
                let key = line[k].1.trim_end_matches(':').trim();
                let def = match &frame {
                    Frame::Section(name) => schema::section(name).and_then(|d| d.field(key)),
                    Frame::Actor { .. } => schema::ACTOR.field(key),
                    Frame::Declaration(kind) => schema::declaration(kind).and_then(|d| d.field(key)),
                    _ => None,
                };
                match def {
                    Some(def) => self.value(def, &frame, &line[k + 1..]),
                    None => Vec::new(),
                }
            }
            (Frame::Other, None) => Vec::new(),
        }
    }

    fn top_level(&self, line: &[(Token, &str)]) -> Vec<Completion> {
        if line.first().is_some_and(|t| t.0 == Token::Use) {
            return tad_db::stdlib::MODULES
                .iter()
                .map(|(name, _)| Completion {
                    detail: Some("standard module".into()),
                    ..self.item(name, CompletionKind::Module)
                })
                .collect();
        }
        if !line.is_empty() {
            return Vec::new();
        }
        let mut out = vec![
            Completion {
                detail: Some("the scenario".into()),
                insert: Some("scenario ${1:name} {\n  $0\n}".into()),
                preselect: true,
                ..self.item("scenario", CompletionKind::Keyword)
            },
            Completion {
                detail: Some("use a module".into()),
                insert: Some("use ".into()),
                ..self.item("use", CompletionKind::Keyword)
            },
        ];
        out.extend(DECLARATIONS.iter().map(|def| Completion {
            detail: Some("declaration kind".into()),
            documentation: Some(def.doc.to_string()),
            insert: Some(format!("{} ${{1:name}} {{\n  $0\n}}", def.name)),
            ..self.item(def.name, CompletionKind::Keyword)
        }));
        out
    }

    fn sections(&self, open: usize) -> Vec<Completion> {
        let written = self.written_keys(open);
        let mut out: Vec<Completion> = schema::SECTIONS
            .iter()
            .filter(|def| !written.contains(def.name))
            .map(|def| Completion {
                detail: Some("section".into()),
                documentation: Some(def.doc.to_string()),
                insert: Some(format!("{} {{\n  $0\n}}", def.name)),
                preselect: def.essential().next().is_some(),
                ..self.item(def.name, CompletionKind::Section)
            })
            .collect();
        out.push(Completion {
            detail: Some("an actor group".into()),
            documentation: Some(schema::ACTOR.doc.to_string()),
            insert: Some("actor ${1:name}: ${2:1} ${3:car} {\n  $0\n}".into()),
            ..self.item("actor", CompletionKind::Keyword)
        });
        out
    }

    fn fields(&self, def: &SectionDef, open: usize) -> Vec<Completion> {
        let written = self.written_keys(open);
        def.fields
            .iter()
            .filter(|f| !written.contains(f.name))
            .map(|f| Completion {
                detail: Some(field_detail(f)),
                documentation: Some(format!("{}\n\ne.g. `{}: {}`", f.doc, f.name, f.example)),
                insert: Some(format!("{}: ", f.name)),
                preselect: f.essential,
                ..self.item(f.name, CompletionKind::Field)
            })
            .collect()
    }

    fn value(&self, def: &FieldDef, frame: &Frame, after: &[(Token, &str)]) -> Vec<Completion> {
        let last = after.last().map(|t| t.0);
        let unspecified = || Completion {
            detail: Some("explicitly unknown".into()),
            ..self.item(KEYWORDS[3].0, CompletionKind::Keyword)
        };
        match def.ty {
            ValueType::Speed | ValueType::Length | ValueType::Duration => {
                if last == Some(Token::Number) {
                    return UNITS
                        .iter()
                        .filter(|u| Unit::parse(u).is_some_and(|unit| unit.measures() == def.ty))
                        .map(|u| Completion {
                            detail: Some(def.ty.describe().into()),
                            ..self.item(u, CompletionKind::Unit)
                        })
                        .collect();
                }
                if after.is_empty() { vec![unspecified()] } else { Vec::new() }
            }
            ValueType::Flag => ["yes", "no"].iter().map(|w| self.item(w, CompletionKind::Value)).collect(),
            ValueType::Choice(words) => words.iter().map(|w| self.item(w, CompletionKind::Value)).collect(),
            ValueType::Position => {
                if last == Some(Token::Of) {
                    return self.references(frame);
                }
                if after.is_empty() {
                    let mut out = self.names("relation", None);
                    out.push(unspecified());
                    return out;
                }
                if last == Some(Token::Ident) {
                    return vec![self.item("of", CompletionKind::Keyword)];
                }
                Vec::new()
            }
            ValueType::Symbol | ValueType::SymbolList => {
                let Some(kind) = def.vocabulary else { return Vec::new() };
                if def.ty == ValueType::Symbol && matches!(last, Some(Token::Ident)) {
                    return Vec::new();
                }
                let performer = match frame {
                    Frame::Actor { kind: Some(t), .. } if kind == "behavior" => Some(
                        self.vocabulary.get("actor_type", t).and_then(|e| e.symbol("kind")).unwrap_or("").to_string(),
                    ),
                    Frame::Section(s) if s == "ego" && kind == "behavior" => Some(tad_check::EGO_KIND.to_string()),
                    _ => None,
                };
                let mut out = self.names(kind, performer.as_deref());
                if def.ty == ValueType::Symbol && after.is_empty() {
                    out.push(unspecified());
                }
                out
            }
            ValueType::Integer | ValueType::Text => {
                if after.is_empty() {
                    vec![unspecified()]
                } else {
                    Vec::new()
                }
            }
        }
    }

    /// Names of `kind`; for behaviours, only those `performer` (an actor kind) performs.
    fn names(&self, kind: &str, performer: Option<&str>) -> Vec<Completion> {
        self.vocabulary
            .entries(kind)
            .into_iter()
            .filter(|e| performer.is_none_or(|p| p.is_empty() || tad_check::performs(e, p)))
            .map(|e| Completion {
                detail: Some(format!("{} · {}", kind.replace('_', " "), e.module)),
                documentation: documentation(e),
                ..self.item(&e.name, CompletionKind::Value)
            })
            .collect()
    }

    /// After `of`: the other groups, then `ego` and the road elements.
    fn references(&self, frame: &Frame) -> Vec<Completion> {
        let own = match frame {
            Frame::Actor { name, .. } => name.as_str(),
            _ => "",
        };
        let mut groups = Vec::new();
        let mut depth = 0usize;
        for (i, (s, token, e)) in self.tokens.iter().enumerate() {
            match token {
                Token::LBrace => depth += 1,
                Token::RBrace => depth = depth.saturating_sub(1),
                Token::Key if depth == 1 && i > 0 && self.tokens[i - 1].1 == Token::Actor => {
                    let name = self.text[*s..*e].trim_end_matches(':').trim();
                    if name != own && !groups.contains(&name) {
                        groups.push(name);
                    }
                }
                _ => {}
            }
        }
        let mut out: Vec<Completion> = groups
            .into_iter()
            .map(|g| Completion { detail: Some("actor group".into()), ..self.item(g, CompletionKind::Group) })
            .collect();
        out.extend(self.names("reference", None).into_iter().map(|c| Completion {
            preselect: true,
            kind: CompletionKind::Group,
            ..c
        }));
        out.extend(self.names("road_element", None));
        out
    }
}

fn field_detail(f: &FieldDef) -> String {
    let mut detail = f.ty.describe().to_string();
    if let Some(kind) = f.vocabulary {
        detail = format!("{detail} ({})", kind.replace('_', " "));
    }
    if f.essential {
        detail.push_str(" · essential");
    }
    detail
}

/// A vocabulary entry's description and the attributes that tell names apart.
pub(crate) fn documentation(entry: &Entry) -> Option<String> {
    let declaration = &entry.declaration;
    let mut parts = Vec::new();
    if let Some(text) = declaration.attr("description").and_then(|a| match &a.value {
        tad_syntax::model::Known::Given(tad_syntax::model::Val::Text(t)) => Some(t.clone()),
        _ => None,
    }) {
        parts.push(text);
    }
    let q = |field: &str| declaration.attr(field).and_then(|a| a.quantity());
    if let (Some(l), Some(w)) = (q("length"), q("width")) {
        let h = q("height").map_or(String::new(), |h| format!(" × {} m", h.value));
        parts.push(format!("{} × {} m{h}", l.value, w.value));
    }
    for field in ["typical_speed", "max_speed"] {
        if let Some(v) = q(field) {
            parts.push(format!("{}: {} {}", field.replace('_', " "), v.value, v.unit.as_str()));
        }
    }
    for field in ["kind", "motion", "lateral", "longitudinal"] {
        if let Some(v) = entry.symbol(field) {
            parts.push(format!("{field}: {v}"));
        }
    }
    if let Some(p) = entry.symbols("performers") {
        parts.push(format!("performed by {}", p.join(", ")));
    }
    if let Some(aliases) = entry.symbols("aliases").filter(|a| !a.is_empty()) {
        parts.push(format!("also written {}", aliases.join(", ")));
    }
    (!parts.is_empty()).then(|| parts.join("\n\n"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    fn labels(text: &str) -> Vec<String> {
        let (db, file, offset) = testing::cursor(text);
        completions(&db, file, offset).into_iter().map(|c| c.label).collect()
    }

    #[test]
    fn a_pedestrian_group_is_offered_only_what_pedestrians_do() {
        let text = "scenario demo {\n  actor walkers: 4 pedestrian {\n    behavior: $0\n  }\n}\n";
        let found = labels(text);
        assert!(found.contains(&"cross".to_string()), "{found:?}");
        assert!(!found.contains(&"turn_left".to_string()), "{found:?}");
        let text = "scenario demo {\n  actor taxi: 1 taxi {\n    behavior: tu$0\n  }\n}\n";
        let found = labels(text);
        assert!(found.contains(&"turn_left".to_string()) && !found.contains(&"walk".to_string()), "{found:?}");
        let text = "scenario demo {\n  ego {\n    behavior: $0\n  }\n}\n";
        assert!(labels(text).contains(&"move_forward".to_string()));
    }

    #[test]
    fn the_word_typed_so_far_is_replaced() {
        let text = "scenario demo {\n  environment {\n    weather: clo$0\n  }\n}\n";
        let (db, file, offset) = testing::cursor(text);
        let items = completions(&db, file, offset);
        let cloudy = items.iter().find(|c| c.label == "cloudy").expect("cloudy");
        assert_eq!(cloudy.replace, Span::new(offset - 3, offset));
        assert!(cloudy.detail.as_deref().unwrap().starts_with("weather"));
        assert!(!items.iter().any(|c| c.label == "daytime"), "only weather");
    }

    #[test]
    fn sections_and_fields_not_yet_written() {
        let text = "scenario demo {\n  environment {\n    weather: clear\n    $0\n  }\n}\n";
        let found = labels(text);
        assert_eq!(found, vec!["time".to_string()]);
        let text = "scenario demo {\n  road { lanes: 2 }\n  $0\n}\n";
        let found = labels(text);
        assert!(found.contains(&"environment".into()) && found.contains(&"actor".into()), "{found:?}");
        assert!(!found.contains(&"road".into()));
        let text = "scenario demo {\n  actor a: car {\n    lane: 1\n    $0\n  }\n}\n";
        let found = labels(text);
        assert!(found.contains(&"behavior".into()) && !found.contains(&"lane".into()), "{found:?}");
    }

    #[test]
    fn units_follow_numbers_and_references_follow_of() {
        let text = "scenario demo {\n  ego {\n    speed: 30 $0\n  }\n}\n";
        let found = labels(text);
        assert_eq!(found.len(), 3, "speed units: {found:?}");
        assert!(found.contains(&"km/h".into()) && !found.contains(&"m".into()));
        let text = "scenario demo {\n  actor a: car {\n    position: front of $0\n  }\n  actor b: bus {\n  }\n}\n";
        let found = labels(text);
        assert!(
            found.contains(&"b".into()) && found.contains(&"ego".into()) && !found.contains(&"a".into()),
            "{found:?}"
        );
        let text = "scenario demo {\n  actor a: car {\n    position: $0\n  }\n}\n";
        assert!(labels(text).contains(&"left_front".into()));
    }

    #[test]
    fn headers_top_level_and_modules() {
        let text = "scenario demo {\n  actor a: 3 $0\n}\n";
        assert!(labels(text).contains(&"sedan".into()));
        assert!(labels("$0").contains(&"scenario".into()));
        assert!(labels("use $0").contains(&"national_park".into()));
        // in a comment or a string: nothing
        assert!(labels("// weather: $0\n").is_empty());
        assert!(labels("scenario demo {\n  source { description: \"wea$0\" }\n}\n").is_empty());
    }

    #[test]
    fn non_ascii_before_the_cursor_and_every_offset_of_an_example() {
        let text = "// Zürich 🚦\nscenario demo {\n  source { description: \"é\" }\n  environment {\n    weather: $0\n  }\n}\n";
        assert!(labels(text).contains(&"rainy".into()));
        let example = include_str!("../../../examples/safety/right_turn.tad");
        let (db, file) = testing::file(example);
        for offset in 0..=example.len() + 2 {
            let _ = completions(&db, file, offset);
        }
        let (db, file) = testing::with_language("Scenario:\n  Environment:\n", Language::Yaml);
        assert!(completions(&db, file, 5).is_empty());
    }
}
