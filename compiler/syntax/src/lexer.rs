//! The lexer: source text to tokens, never failing.
//!
//! Built on logos. Every byte of input ends up in some token: text logos cannot match
//! becomes [`Token::Error`] with a diagnostic, so the parser always receives a complete
//! stream and recovers from lexical errors the same way as from syntax errors (lalrpop
//! recovers only from parser errors). Comments are returned beside the tokens, for the
//! formatter. Field keys (`weather:`) are one token, name and colon together: that keeps
//! the grammar LR(1) while values stay free of separators (`speed: 38 km/h lane: 2`).

use logos::Logos;
use tad_diagnostics::{Applicability, Code, Diagnostic, Payload, Span};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LexError {
    #[default]
    UnexpectedChar,
    UnterminatedString,
    UnterminatedTextBlock,
}

#[derive(Logos, Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[logos(error = LexError)]
#[logos(skip r"[ \t\r\n\f\u{FEFF}]+")]
pub enum Token {
    #[token("scenario")]
    Scenario,
    #[token("actor")]
    Actor,
    #[token("use")]
    Use,
    #[token("unspecified")]
    Unspecified,
    #[token("of")]
    Of,
    #[token("{")]
    LBrace,
    #[token("}")]
    RBrace,
    #[token("[")]
    LBracket,
    #[token("]")]
    RBracket,
    #[token(",")]
    Comma,
    #[token(".")]
    Dot,
    /// `..` between the bounds of a range (`30..40 km/h`).
    #[token("..")]
    DotDot,
    /// `|` between the names of a choice (`clear | cloudy`).
    #[token("|")]
    Pipe,
    #[token(":")]
    Colon,
    /// A field key: a name followed by `:` on the same line (`weather:`).
    #[regex(r"[A-Za-z_][A-Za-z0-9_]*[ \t]*:")]
    Key,
    #[regex(r"[A-Za-z_][A-Za-z0-9_]*")]
    Ident,
    #[regex(r"-?[0-9]+(\.[0-9]+)?")]
    Number,
    #[token("km/h")]
    #[token("mph")]
    #[token("m/s")]
    #[token("m", priority = 5)]
    #[token("s", priority = 5)]
    Unit,
    #[token("\"", lex_string)]
    Str,
    #[token("\"\"\"", lex_text_block)]
    TextBlock,
    #[regex(r"//[^\n]*", allow_greedy = true)]
    Comment,
    /// Text the lexer could not match; already reported.
    Error,
    /// A name directly followed by `{`: the head of a block (`road {`, `actor a: bus {`).
    /// Not produced by logos: [`lex`] turns such an [`Token::Ident`] into this, so that
    /// a stray name is never mistaken for the start of a section during error recovery.
    Head,
    /// The first name of a top-level item: the kind of a declaration (`weather` in
    /// `weather clear`). Marked by [`lex`] for the same reason as [`Token::Head`].
    DeclKind,
}

/// Every keyword of the language, with its token. A test round-trips each one.
pub const KEYWORDS: &[(&str, Token)] = &[
    ("scenario", Token::Scenario),
    ("actor", Token::Actor),
    ("use", Token::Use),
    ("unspecified", Token::Unspecified),
    ("of", Token::Of),
];

/// Every unit the lexer knows.
pub const UNITS: &[&str] = &["km/h", "mph", "m/s", "m", "s"];

/// `t` as a string literal that reads back as `t` (§2.4 of the language's escapes).
pub fn string_literal(t: &str) -> String {
    let mut out = String::with_capacity(t.len() + 2);
    out.push('"');
    for c in t.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn lex_string(lex: &mut logos::Lexer<'_, Token>) -> Result<(), LexError> {
    let rest = lex.remainder();
    let mut chars = rest.char_indices();
    while let Some((i, c)) = chars.next() {
        match c {
            '"' => {
                lex.bump(i + 1);
                return Ok(());
            }
            '\\' => match chars.next() {
                Some((_, '\n')) | None => {
                    lex.bump(i + 1);
                    return Err(LexError::UnterminatedString);
                }
                Some(_) => {}
            },
            '\n' => {
                lex.bump(i);
                return Err(LexError::UnterminatedString);
            }
            _ => {}
        }
    }
    lex.bump(rest.len());
    Err(LexError::UnterminatedString)
}

fn lex_text_block(lex: &mut logos::Lexer<'_, Token>) -> Result<(), LexError> {
    let rest = lex.remainder();
    match rest.find("\"\"\"") {
        Some(i) => {
            lex.bump(i + 3);
            Ok(())
        }
        None => {
            lex.bump(rest.len());
            Err(LexError::UnterminatedTextBlock)
        }
    }
}

/// A token with its byte range, as the parser consumes it.
pub type Spanned = (usize, Token, usize);

/// The result of lexing one text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lexed {
    /// Tokens without comments; lexical errors appear as [`Token::Error`].
    pub tokens: Vec<Spanned>,
    pub comments: Vec<Span>,
    pub diagnostics: Vec<Diagnostic>,
}

pub fn lex(src: &str) -> Lexed {
    let mut out = Lexed::default();
    let mut lexer = Token::lexer(src);
    // whether the last token is an unexpected-character error that may grow, and whether
    // it has grown past its first character
    let (mut merging, mut grown) = (false, false);
    while let Some(result) = lexer.next() {
        let span = lexer.span();
        let extends = merging
            && matches!(result, Err(LexError::UnexpectedChar))
            && out.tokens.last().is_some_and(|t| t.2 == span.start);
        if grown && !extends {
            name_run(src, &mut out);
            grown = false;
        }
        match result {
            Ok(Token::Comment) => out.comments.push(span.into()),
            Ok(token) => {
                merging = false;
                out.tokens.push((span.start, token, span.end));
            }
            // A run of unexpected characters is one token and one diagnostic.
            Err(_) if extends => {
                if let (Some(token), Some(d)) = (out.tokens.last_mut(), out.diagnostics.last_mut()) {
                    token.2 = span.end;
                    d.primary.span.end = span.end;
                    grown = true;
                }
            }
            Err(error) => {
                merging = error == LexError::UnexpectedChar;
                out.diagnostics.push(lex_error(src, span.clone().into(), error));
                out.tokens.push((span.start, Token::Error, span.end));
            }
        }
    }
    if grown {
        name_run(src, &mut out);
    }
    for i in 1..out.tokens.len() {
        if out.tokens[i].1 == Token::LBrace && out.tokens[i - 1].1 == Token::Ident {
            out.tokens[i - 1].1 = Token::Head;
        }
    }
    mark_declaration_kinds(&mut out.tokens);
    out
}

/// Characters of a run of unexpected ones that its message quotes.
const QUOTED: usize = 16;

/// Names the run of unexpected characters that the last token and diagnostic hold, once
/// it has ended: naming it at every character it grew by made a long run quadratic.
fn name_run(src: &str, out: &mut Lexed) {
    if let (Some(token), Some(d)) = (out.tokens.last(), out.diagnostics.last_mut()) {
        let run = &src[token.0..token.2];
        let count = run.chars().count();
        d.message = if count <= QUOTED {
            format!("unexpected characters `{}`", run.escape_debug())
        } else {
            // a long run is quoted by its start and counted
            let start: String = run.chars().take(QUOTED).collect();
            format!("unexpected characters `{}…` ({count} of them)", start.escape_debug())
        };
    }
}

/// Outside braces, items are flat (`use PATH`, `scenario NAME {...}`, `KIND NAME [{...}]`):
/// follow them and mark the first name of each declaration as [`Token::DeclKind`].
fn mark_declaration_kinds(tokens: &mut [Spanned]) {
    #[derive(PartialEq)]
    enum State {
        Item,
        UsePath,
        AfterPathName,
        Name,
    }
    let mut depth = 0usize;
    let mut state = State::Item;
    for token in tokens.iter_mut() {
        match token.1 {
            Token::LBrace => {
                depth += 1;
                state = State::Item;
                continue;
            }
            Token::RBrace => {
                depth = depth.saturating_sub(1);
                state = State::Item;
                continue;
            }
            _ if depth > 0 => continue,
            _ => {}
        }
        state = match (state, token.1) {
            (State::UsePath, Token::Ident) => State::AfterPathName,
            (State::AfterPathName, Token::Dot) => State::UsePath,
            (State::Name, Token::Ident | Token::Head) => State::Item,
            (_, Token::Use) => State::UsePath,
            (_, Token::Scenario) => State::Name,
            (_, Token::Ident) => {
                token.1 = Token::DeclKind;
                State::Name
            }
            _ => State::Item,
        };
    }
}

fn lex_error(src: &str, span: Span, error: LexError) -> Diagnostic {
    match error {
        LexError::UnexpectedChar => {
            let text = &src[span.start..span.end];
            let mut d = Diagnostic::new(
                Code::E0001,
                format!("unexpected character `{}`", text.escape_debug()),
                span,
                "not part of the language",
            )
            .with_payload(Payload::Syntax { expected: Vec::new(), found: Some(text.to_string()) });
            d = match text {
                "#" => d.with_help("comments start with `//`"),
                "=" => d.with_help("fields are written `name: value`").with_fix(
                    span,
                    ":",
                    Applicability::MachineApplicable,
                ),
                ";" => d.with_help("fields need no separator; remove the `;`").with_fix(
                    span,
                    "",
                    Applicability::MachineApplicable,
                ),
                "'" => d.with_help("strings use double quotes: `\"...\"`"),
                "/" => d.with_help("units are written `km/h`, `mph`, `m/s`, `m` or `s`"),
                "-" => d.with_help("a negative number is written with no space after `-`, e.g. `-1`"),
                _ if !text.is_ascii() => {
                    d.with_help("names are ASCII letters, digits and `_`; other text belongs in a string")
                }
                _ => d,
            };
            d
        }
        LexError::UnterminatedString => {
            Diagnostic::new(Code::E0002, "unterminated string", span, "this string has no closing `\"`")
                .with_payload(Payload::Syntax { expected: vec!["`\"`".into()], found: None })
                .with_help("close the string on the same line; use a `\"\"\"` text block for text over several lines")
        }
        LexError::UnterminatedTextBlock => Diagnostic::new(
            Code::E0003,
            "unterminated text block",
            Span::new(span.start, span.start + 3),
            "this text block is never closed",
        )
        .with_payload(Payload::Syntax { expected: vec!["`\"\"\"`".into()], found: None })
        .with_help("end the text block with `\"\"\"`"),
    }
}

fn escape_payload(found: &str) -> Payload {
    let expected = ["\\\"", "\\\\", "\\n", "\\t", "\\r", "\\u{...}"];
    Payload::Syntax { expected: expected.iter().map(|e| format!("`{e}`")).collect(), found: Some(found.to_string()) }
}

/// Decode the escapes of a string token (quotes included in `raw`). `offset` is the byte
/// offset of `raw` in the file, for diagnostics.
pub fn unescape(raw: &str, offset: usize, diagnostics: &mut Vec<Diagnostic>) -> String {
    let inner = raw.strip_prefix('"').unwrap_or(raw);
    let inner = inner.strip_suffix('"').unwrap_or(inner);
    let base = offset + 1;
    let mut out = String::with_capacity(inner.len());
    let mut chars = inner.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        let Some((j, e)) = chars.next() else {
            break;
        };
        match e {
            'n' => out.push('\n'),
            't' => out.push('\t'),
            'r' => out.push('\r'),
            '\\' => out.push('\\'),
            '"' => out.push('"'),
            'u' => {
                // \u{XXXX}
                let rest = &inner[j + 1..];
                let decoded = rest
                    .strip_prefix('{')
                    .and_then(|r| r.find('}').map(|end| &r[..end]))
                    .filter(|hex| (1..=6).contains(&hex.len()))
                    .and_then(|hex| u32::from_str_radix(hex, 16).ok().map(|v| (hex.len(), v)))
                    .and_then(|(len, v)| char::from_u32(v).map(|c| (len, c)));
                match decoded {
                    Some((len, c)) => {
                        out.push(c);
                        for _ in 0..len + 2 {
                            chars.next();
                        }
                    }
                    None => diagnostics.push(
                        Diagnostic::new(Code::E0004, "invalid unicode escape", Span::new(base + i, base + j + 1), "expected `\\u{...}` with 1 to 6 hex digits of a valid character")
                            .with_payload(escape_payload("\\u")),
                    ),
                }
            }
            other => diagnostics.push(
                Diagnostic::new(
                    Code::E0004,
                    format!("invalid escape `\\{}`", other.escape_debug()),
                    Span::new(base + i, base + j + other.len_utf8()),
                    "unknown escape",
                )
                .with_payload(escape_payload(&format!("\\{other}")))
                .with_help("valid escapes are `\\\"`, `\\\\`, `\\n`, `\\t`, `\\r` and `\\u{...}`; write `\\\\` for a backslash"),
            ),
        }
    }
    out
}

/// Bytes of leading spaces and tabs: indentation is ASCII, so cutting it off is always
/// on a character boundary (other whitespace, such as U+3000, is content).
fn indentation(line: &str) -> usize {
    line.len() - line.trim_start_matches([' ', '\t']).len()
}

/// The content of a `"""` text block: the line break after the opening quotes and the
/// indentation common to all non-blank lines are removed, as are trailing blank lines.
pub fn text_block_content(raw: &str) -> String {
    let inner = raw.strip_prefix("\"\"\"").unwrap_or(raw);
    let inner = inner.strip_suffix("\"\"\"").unwrap_or(inner);
    let inner = inner.strip_prefix("\r\n").or_else(|| inner.strip_prefix('\n')).unwrap_or(inner);
    let lines: Vec<&str> = inner.lines().collect();
    let indent = lines.iter().filter(|l| !l.trim().is_empty()).map(|l| indentation(l)).min().unwrap_or(0);
    let mut out: Vec<&str> =
        lines.iter().map(|l| if indentation(l) >= indent { &l[indent..] } else { l.trim_start() }).collect();
    while out.last().is_some_and(|l| l.trim().is_empty()) {
        out.pop();
    }
    out.iter().map(|l| l.trim_end()).collect::<Vec<_>>().join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(src: &str) -> Vec<Token> {
        lex(src).tokens.into_iter().map(|t| t.1).collect()
    }

    #[test]
    fn every_keyword_lexes_as_itself() {
        for (word, token) in KEYWORDS {
            assert_eq!(kinds(word), vec![*token], "{word}");
            // followed by a colon it is a field key
            assert_eq!(kinds(&format!("{word}:")), vec![Token::Key], "{word}:");
        }
        for unit in UNITS {
            assert_eq!(kinds(unit), vec![Token::Unit], "{unit}");
        }
    }

    #[test]
    fn keys_values_and_units() {
        use Token::*;
        assert_eq!(
            kinds("{ speed: 38 km/h lane : -2 kind: move_forward }"),
            vec![LBrace, Key, Number, Unit, Key, Number, Key, Ident, RBrace]
        );
        assert_eq!(
            kinds("30..40 km/h 2.5..3 m -1..1"),
            vec![Number, DotDot, Number, Unit, Number, DotDot, Number, Unit, Number, DotDot, Number]
        );
        assert_eq!(kinds("{ clear | cloudy }"), vec![LBrace, Ident, Pipe, Ident, RBrace]);
        assert_eq!(kinds("{ x\n: 1 }"), vec![LBrace, Ident, Colon, Number, RBrace]);
        assert_eq!(kinds("{ actor a: big bus {} }"), vec![LBrace, Actor, Key, Ident, Head, LBrace, RBrace, RBrace]);
        assert_eq!(
            kinds("use a.b weather wet weather clear { x: y } scenario s2 { road { k: v } }"),
            vec![
                Use, Ident, Dot, Ident, DeclKind, Ident, DeclKind, Head, LBrace, Key, Ident, RBrace, Scenario, Head,
                LBrace, Head, LBrace, Key, Ident, RBrace, RBrace
            ]
        );
    }

    #[test]
    fn comments_are_kept_aside() {
        let lexed = lex("a // one\n// two\nb");
        assert_eq!(lexed.tokens.len(), 2);
        assert_eq!(lexed.comments, vec![Span::new(2, 8), Span::new(9, 15)]);
    }

    #[test]
    fn strings_and_text_blocks() {
        use Token::*;
        assert_eq!(kinds(r#""a \" b" """x"y""""#), vec![Str, TextBlock]);
        let lexed = lex("\"open\nnext");
        assert_eq!(lexed.tokens[0].1, Error);
        assert_eq!(lexed.diagnostics[0].code, Code::E0002);
        let lexed = lex("x: \"\"\"never closed");
        assert_eq!(lexed.diagnostics[0].code, Code::E0003);
    }

    #[test]
    fn unexpected_characters_merge_into_one_error() {
        let lexed = lex("a $%^ b");
        assert_eq!(lexed.diagnostics.len(), 1);
        assert_eq!(lexed.diagnostics[0].primary.span, Span::new(2, 5));
        assert_eq!(lexed.tokens.iter().filter(|t| t.1 == Token::Error).count(), 1);
        let lexed = lex("é");
        assert_eq!(lexed.diagnostics[0].primary.span, Span::new(0, 2));
        assert_eq!(lexed.diagnostics[0].message, "unexpected character `é`");
        // the run's message names all of it, before a comment and at the end of the text
        let lexed = lex("a $% // c\n@@");
        let messages: Vec<&str> = lexed.diagnostics.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(messages, ["unexpected characters `$%`", "unexpected characters `@@`"]);
        // a long run is one token and one diagnostic (naming it at every character was
        // quadratic: 100,000 took 34 s)
        let lexed = lex(&"@".repeat(100_000));
        assert_eq!((lexed.tokens.len(), lexed.diagnostics.len()), (1, 1));
        assert_eq!(lexed.diagnostics[0].primary.span, Span::new(0, 100_000));
        // quoted by its start and counted, so the message does not grow with the run
        assert_eq!(
            lexed.diagnostics[0].message,
            format!("unexpected characters `{}…` (100000 of them)", "@".repeat(16))
        );
    }

    #[test]
    fn escapes() {
        let mut d = Vec::new();
        assert_eq!(unescape(r#""a\n\"\\\u{e9}""#, 0, &mut d), "a\n\"\\é");
        assert!(d.is_empty());
        unescape(r#""bad \q""#, 10, &mut d);
        assert_eq!(d[0].code, Code::E0004);
        assert_eq!(d[0].primary.span, Span::new(15, 17));
    }

    #[test]
    fn text_block_indentation_is_ascii() {
        // U+3000 is whitespace but not indentation: it stays, and nothing is cut mid-character
        let raw = "\"\"\"\n  x\n\u{3000}y\n\"\"\"";
        assert_eq!(text_block_content(raw), "  x\n\u{3000}y");
        let raw = "\"\"\"\n \u{3000}x\n  y\n\"\"\"";
        assert_eq!(text_block_content(raw), "\u{3000}x\n y");
    }

    #[test]
    fn text_blocks_are_dedented() {
        let raw = "\"\"\"\n    The ego vehicle\n      turns left.\n    \"\"\"";
        assert_eq!(text_block_content(raw), "The ego vehicle\n  turns left.");
    }
}
