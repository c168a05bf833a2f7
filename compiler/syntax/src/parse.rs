//! The parser driver: lex, balance braces, run the lalrpop grammar, and turn every
//! recovered parse error into a located diagnostic in plain words.
//!
//! `parse` is total: it returns a tree for any input (possibly with error nodes) and
//! never panics. Errors caused by an earlier lexical error or by a brace this pass
//! closed are not reported twice.

use crate::cst::{Entry, Field, File, Item, Member, Value};
use crate::lexer::{self, Spanned, Token};
use crate::suggest;
use lalrpop_util::{ErrorRecovery, ParseError};
use tad_diagnostics::{Applicability, Code, Diagnostic, LineIndex, Payload, Span};

#[allow(clippy::all, clippy::pedantic, unused_parens, unused_qualifications)]
mod grammar {
    include!(concat!(env!("OUT_DIR"), "/grammar.rs"));
}

/// A parsed file: its tree, its comments (for the formatter) and what went wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct Parsed {
    pub file: File,
    pub comments: Vec<Span>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Parsed {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

pub fn parse(src: &str) -> Parsed {
    let lexed = lexer::lex(src);
    let mut diagnostics = lexed.diagnostics;
    let mut tokens = lexed.tokens;
    // An unterminated text block swallowed the rest of the file, closing braces included:
    // saying so once is enough.
    let swallowed = diagnostics.iter().any(|d| d.code == Code::E0003);
    close_braces(src, &mut tokens, &mut diagnostics, !swallowed);

    let mut errors = Vec::new();
    let stream = tokens.iter().map(|&t| Ok::<Spanned, ()>(t));
    let file = match grammar::FileParser::new().parse(src, &mut errors, stream) {
        Ok(file) => file,
        Err(error) => {
            errors.push(ErrorRecovery { error, dropped_tokens: Vec::new() });
            File::default()
        }
    };
    let mut file = file;
    let mut syntax: Vec<Diagnostic> = errors.into_iter().filter_map(|r| parse_error(src, &tokens, r.error)).collect();
    let missing_colons = split_words_at_line_breaks(src, &mut file);
    // What follows a missing `:` on its line is a consequence of it.
    let same_line = |a: usize, b: usize| !src[a.min(b)..a.max(b)].contains('\n');
    syntax.retain(|d| {
        !missing_colons.iter().any(|m| {
            d.primary.span.start > m.primary.span.start && same_line(d.primary.span.start, m.primary.span.start)
        })
    });
    drop_values_with_unknown_units(src, &mut file, &syntax);
    diagnostics.extend(missing_colons);
    diagnostics.extend(syntax);
    Parsed { file, comments: lexed.comments, diagnostics }
}

/// Words of a value that continue on the next line are almost always the next field
/// with its `:` forgotten (`weather: clear` / `time daytime`). Report that, and cut the
/// value at the line break, so the rest is not taken as one long name.
fn split_words_at_line_breaks(src: &str, file: &mut File) -> Vec<Diagnostic> {
    let mut diagnostics = Vec::new();
    let mut split = |words: &mut Vec<crate::cst::Name>| {
        let Some(i) = (1..words.len()).find(|&i| src[words[i - 1].span.end..words[i].span.start].contains('\n')) else {
            return;
        };
        let key = &words[i];
        diagnostics.push(
            Diagnostic::new(
                Code::E0103,
                format!("missing `:` after `{}`", key.text),
                key.span,
                "a field name needs a `:`",
            )
            .with_help(format!("write `{}: ...`", key.text))
            .with_payload(Payload::Syntax { expected: vec!["`:`".into()], found: Some(key.text.clone()) })
            .with_fix(Span::new(key.span.end, key.span.end), ":", Applicability::MachineApplicable),
        );
        words.truncate(i);
    };
    for field in fields_mut(file) {
        match &mut field.value {
            Value::Words(words) => split(words),
            Value::Position { reference, span, .. } => {
                split(reference);
                span.end = crate::cst::words_span(reference).end;
            }
            _ => {}
        }
        field.span.end = field.value.span().end;
    }
    diagnostics
}

/// `speed: 30 kmh` is reported as an unknown unit; the value is then an error node, so it
/// is not reported again as a speed without a unit.
fn drop_values_with_unknown_units(src: &str, file: &mut File, syntax: &[Diagnostic]) {
    let units: Vec<Span> = syntax
        .iter()
        .filter(|d| match &d.payload {
            Payload::Unknown { namespace, .. } => namespace == "unit",
            Payload::WrongValue { field, .. } => field == "number",
            _ => false,
        })
        .map(|d| d.primary.span)
        .collect();
    for field in fields_mut(file) {
        let (start, number) = match field.value {
            Value::Number { number, unit: None, .. } => (number, number),
            Value::Range { span, high: crate::cst::Bound { number, unit: None }, .. } => (span, number),
            _ => continue,
        };
        if let Some(bad) = units.iter().find(|u| u.start >= number.end && src[number.end..u.start].trim().is_empty()) {
            field.value = Value::Error(start.to(*bad));
        }
    }
}

/// Every field of every section and actor block.
fn fields_mut(file: &mut File) -> impl Iterator<Item = &mut Field> {
    let mut blocks: Vec<&mut Vec<Entry>> = Vec::new();
    for item in &mut file.items {
        match item {
            Item::Declaration(d) => blocks.extend(d.body.as_mut().map(|b| &mut b.items)),
            Item::Scenario(scenario) => {
                for member in &mut scenario.body.items {
                    match member {
                        Member::Section(section) => blocks.push(&mut section.body.items),
                        Member::Actor(actor) => blocks.push(&mut actor.body.items),
                        Member::Error(_) => {}
                    }
                }
            }
            Item::Use(_) | Item::Error(_) => {}
        }
    }
    blocks.into_iter().flatten().filter_map(|entry| match entry {
        Entry::Field(field) => Some(field),
        Entry::Error(_) => None,
    })
}

/// Report every `{` left open at the end of the file and close it with an empty `}`
/// token there, so the tree keeps everything that was parsed.
fn close_braces(src: &str, tokens: &mut Vec<Spanned>, diagnostics: &mut Vec<Diagnostic>, report: bool) {
    let mut open: Vec<usize> = Vec::new();
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for &(start, token, _) in tokens.iter() {
        match token {
            Token::LBrace => open.push(start),
            Token::RBrace => pairs.extend(open.pop().map(|opened| (opened, start))),
            _ => {}
        }
    }
    if open.is_empty() {
        return;
    }
    let index = LineIndex::new(src);
    let indent = |offset: usize| {
        let start = index.line_start(index.line_of(offset));
        src[start..].len() - src[start..].trim_start_matches([' ', '\t']).len()
    };
    let line_leading = |offset: usize| src[index.line_start(index.line_of(offset))..offset].trim().is_empty();
    // A `{` that a later, less indented `}` closed: most likely the one missing its `}`.
    let suspect =
        pairs.iter().copied().find(|&(opened, closed)| line_leading(closed) && indent(opened) > indent(closed));
    let end = src.len();
    // thousands of open braces (a pasted or generated file) are one report, not one each
    let many = open.len() > MANY_UNCLOSED;
    for (i, &opened) in open.iter().enumerate().rev() {
        tokens.push((end, Token::RBrace, end));
        if many && i > 0 {
            continue;
        }
        let mut d =
            Diagnostic::new(Code::E0102, "unclosed `{`", Span::new(opened, opened + 1), "this `{` is never closed")
                .with_secondary(Span::new(end, end), "the file ends here");
        if let (0, Some((likely, closer))) = (i, suspect) {
            d = Diagnostic::new(
                Code::E0102,
                "unclosed `{`",
                Span::new(likely, likely + 1),
                "this `{` is probably missing its `}`",
            )
            .with_secondary(Span::new(closer, closer + 1), "this `}`, indented like an outer block, closes it instead")
            .with_secondary(Span::new(opened, opened + 1), "so this `{` is still open at the end of the file");
        }
        if many {
            let last = index.line_col(src, open[open.len() - 1]);
            d = d.with_note(format!(
                "{} `{{` in all are never closed, the last at {}:{}",
                open.len(),
                last.line,
                last.column
            ));
        }
        if report {
            diagnostics.push(
                d.with_help("add the missing `}`")
                    .with_payload(Payload::Syntax { expected: vec!["`}`".into()], found: None }),
            );
        }
    }
}

/// Unclosed braces past which only the first is reported, with their count.
const MANY_UNCLOSED: usize = 8;

fn parse_error(src: &str, tokens: &[Spanned], error: ParseError<usize, Token, ()>) -> Option<Diagnostic> {
    match error {
        ParseError::UnrecognizedToken { token: (start, token, end), expected } => {
            if token == Token::Error || (token == Token::RBrace && start == end) {
                return None; // reported by the lexer, or by `close_braces`
            }
            let next = tokens.iter().find(|t| t.0 >= end).map(|t| t.1);
            if next == Some(Token::Error) {
                return None; // `lanes = 2`: the lexer's report of `=` says what is wrong
            }
            let span = Span::new(start, end);
            let found = describe_token(src, token, span);
            let words = expected_list(&expected);
            let wanted = join_or(&words);
            let previous = tokens.iter().rev().find(|t| t.2 <= start).map(|t| t.1);
            let mut d = Diagnostic::new(
                Code::E0100,
                format!("expected {wanted}, found {found}"),
                span,
                format!("expected {wanted}"),
            )
            .with_payload(Payload::Syntax { expected: words, found: Some(found.clone()) });
            if previous == Some(Token::Number) && token == Token::Ident {
                let word = &src[start..end];
                d.message = format!("unknown unit `{word}`");
                d.primary.message = "not a unit".into();
                if word.starts_with(['e', 'E']) && word[1..].bytes().all(|b| b.is_ascii_digit()) && word.len() > 1 {
                    return Some(
                        Diagnostic::new(Code::E0100, "exponent notation is not supported", span, "an exponent")
                            .with_help("write the number in full, e.g. `1000` instead of `1e3`")
                            .with_payload(Payload::WrongValue {
                                field: "number".into(),
                                expected: "a number written in full".into(),
                                found: word.to_string(),
                            }),
                    );
                }
                let guess = match word {
                    "kmh" | "kph" | "kmph" | "km" => Some("km/h"),
                    "ms" | "mps" => Some("m/s"),
                    "sec" | "secs" | "seconds" => Some("s"),
                    "meter" | "meters" | "metre" | "metres" => Some("m"),
                    _ => suggest::closest(word, lexer::UNITS.iter().copied()),
                };
                let candidates = guess.map(|g| vec![g.to_string()]).unwrap_or_default();
                d = d.with_payload(Payload::Unknown {
                    namespace: "unit".into(),
                    name: word.to_string(),
                    candidates,
                    module: None,
                });
                d = match guess {
                    Some(unit) => d.with_help(format!("did you mean `{unit}`?")).with_fix(
                        span,
                        unit,
                        Applicability::MaybeIncorrect,
                    ),
                    None => d.with_help("units are `km/h`, `mph`, `m/s`, `m` and `s`"),
                };
            } else if token == Token::Key && expected.iter().any(|e| e == "\"actor\"") {
                d = d.with_help("fields belong inside a section, e.g. `environment { weather: clear }`");
            } else if token == Token::Unit && expected.iter().any(|e| e == "Ident" || e == "Head") {
                d = d.with_help(format!("`{}` is a unit and cannot be a name; choose another name", &src[start..end]));
            } else if token == Token::Head && expected.iter().any(|e| e == "Key") {
                d = d.with_help(format!(
                    "a block cannot be inside a section; is the `}}` of the section missing before `{}`?",
                    &src[start..end]
                ));
            } else if token == Token::Colon {
                d = d.with_help("a field is written `name: value`, the name and `:` on the same line");
            }
            Some(d)
        }
        ParseError::UnrecognizedEof { location, expected } => {
            let span = Span::new(location.min(src.len()), location.min(src.len()));
            let words = expected_list(&expected);
            let wanted = join_or(&words);
            Some(
                Diagnostic::new(
                    Code::E0101,
                    format!("unexpected end of file, expected {wanted}"),
                    span,
                    format!("expected {wanted}"),
                )
                .with_payload(Payload::Syntax { expected: words, found: None }),
            )
        }
        ParseError::ExtraToken { token: (start, token, end) } => {
            let span = Span::new(start, end);
            let found = describe_token(src, token, span);
            Some(
                Diagnostic::new(Code::E0100, format!("unexpected {found}"), span, "not expected here")
                    .with_payload(Payload::Syntax { expected: Vec::new(), found: Some(found) }),
            )
        }
        ParseError::InvalidToken { location } => Some(
            Diagnostic::new(Code::E0001, "invalid token", Span::new(location, location), "here")
                .with_payload(Payload::Syntax { expected: Vec::new(), found: None }),
        ),
        ParseError::User { .. } => None,
    }
}

fn describe_token(src: &str, token: Token, span: Span) -> String {
    let text = src.get(span.start..span.end).unwrap_or("");
    match token {
        Token::Key => format!("field name `{}`", text.trim_end_matches(':').trim_end()),
        Token::Str => "a string".into(),
        Token::TextBlock => "a text block".into(),
        Token::Number => format!("number `{text}`"),
        _ if span.is_empty() => "end of file".into(),
        _ => format!("`{text}`"),
    }
}

/// The grammar's expected terminals in plain words, most useful first.
fn expected_list(expected: &[String]) -> Vec<String> {
    const VALUE_STARTS: &[&str] = &["Number", "String", "TextBlock", "\"[\"", "Ident", "\"unspecified\"", "Invalid"];
    let is_value = expected.iter().any(|e| e == "Number") && expected.iter().any(|e| e == "\"[\"");
    let mut words: Vec<(u8, String)> = Vec::new();
    if is_value {
        words.push((2, "a value".into()));
    }
    for e in expected {
        // what continues a value into a range or a choice is not worth listing
        if (is_value && VALUE_STARTS.contains(&e.as_str())) || matches!(e.as_str(), "\"|\"" | "\"..\"") {
            continue;
        }
        let word = match e.as_str() {
            "\"}\"" => (0, "`}`".to_string()),
            "\"]\"" => (0, "`]`".to_string()),
            "Key" => (1, "a field name".to_string()),
            "Ident" => (3, "a name".to_string()),
            "Head" if expected.iter().any(|e| e == "\"actor\"") => (3, "a section".to_string()),
            "Head" => (3, "a name".to_string()),
            "DeclKind" => (3, "a declaration".to_string()),
            "Number" => (4, "a number".to_string()),
            "Unit" => (4, "a unit".to_string()),
            "String" => (4, "a string".to_string()),
            "TextBlock" => (4, "a text block".to_string()),
            "Invalid" => continue,
            quoted => (5, format!("`{}`", quoted.trim_matches('"'))),
        };
        words.push(word);
    }
    words.sort();
    words.dedup();
    words.into_iter().map(|(_, w)| w).collect()
}

/// The expected things in words: "`}` or a field name".
fn join_or(words: &[String]) -> String {
    match words {
        [] => "something else".into(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}
