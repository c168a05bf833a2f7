//! Semantic tokens: the lexer's tokens, told apart by where they stand (a header, a key,
//! after `of`, in a `use` path) and by the model (which vocabulary a value's name belongs
//! to, whether it is written as an alias, whether the standard library declares it).
//! One pass over the tokens: linear in the document. YAML answers get none (their
//! highlighting is YAML's).

use std::collections::HashMap;

use tad_check::Lookup;
use tad_syntax::lexer::Token as Lexed;

use crate::{Database, Language, SourceFile, Span};

/// What a piece of text is, for highlighting. The language server's legend lists these
/// in the order of [`TokenKind::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TokenKind {
    Keyword,
    /// A section name or a declaration kind.
    Namespace,
    /// A field key.
    Property,
    /// An actor group's name or a reference to one (`ego` too).
    Variable,
    /// An actor type in a group's header.
    Type,
    /// A vocabulary name or a closed-set word in a value.
    EnumMember,
    /// A declaration's name.
    Declaration,
    Number,
    /// A unit (`km/h`).
    Unit,
    String,
    Comment,
    Operator,
}

impl TokenKind {
    pub const ALL: &'static [TokenKind] = &[
        TokenKind::Keyword,
        TokenKind::Namespace,
        TokenKind::Property,
        TokenKind::Variable,
        TokenKind::Type,
        TokenKind::EnumMember,
        TokenKind::Declaration,
        TokenKind::Number,
        TokenKind::Unit,
        TokenKind::String,
        TokenKind::Comment,
        TokenKind::Operator,
    ];
}

/// Modifiers, as bits; the legend lists them in the order of [`Modifier::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Modifier {
    /// Where a name is declared (a group's header, a declaration).
    Declaration,
    /// An alias of a vocabulary name (deprecated spelling).
    Deprecated,
    /// From the embedded standard library.
    DefaultLibrary,
}

impl Modifier {
    pub const ALL: &'static [Modifier] = &[Modifier::Declaration, Modifier::Deprecated, Modifier::DefaultLibrary];

    pub fn bit(self) -> u32 {
        1 << Modifier::ALL.iter().position(|m| *m == self).unwrap_or(0)
    }
}

/// One token: its span (on one line; a multi-line string or comment is split per line by
/// the producer), kind and modifier bits. Sorted by position, not overlapping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Token {
    pub span: Span,
    pub kind: TokenKind,
    pub modifiers: u32,
}

pub fn tokens(db: &Database, file: SourceFile) -> Vec<Token> {
    if file.language(db) != Language::Tad {
        return Vec::new();
    }
    let text = file.text(db);
    let lexed = tad_syntax::lexer::lex(text);
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    // the modifiers of each vocabulary name in a value, by its start
    let mut stdlib: HashMap<tad_diagnostics::FileId, bool> = HashMap::new();
    let mut names: HashMap<usize, u32> = HashMap::new();
    for (kind, symbol) in crate::navigate::symbols(module) {
        let lookup = vocabulary.lookup(kind, &symbol.name);
        let mut bits = 0;
        if matches!(lookup, Lookup::Alias(_)) {
            bits |= Modifier::Deprecated.bit();
        }
        if let Some(entry) = lookup.entry() {
            let from_stdlib = *stdlib
                .entry(entry.file)
                .or_insert_with(|| db.file(entry.file).is_some_and(|f| f.path(db).starts_with(tad_db::STDLIB_PREFIX)));
            if from_stdlib {
                bits |= Modifier::DefaultLibrary.bit();
            }
        }
        names.insert(symbol.span.start, bits);
    }
    let mut out: Vec<Token> = Vec::with_capacity(lexed.tokens.len() + lexed.comments.len());
    let push = |out: &mut Vec<Token>, start: usize, end: usize, kind: TokenKind, modifiers: u32| {
        // one token per line
        let mut from = start;
        for (i, _) in text[start..end].match_indices('\n') {
            let to = start + i;
            if to > from {
                out.push(Token { span: Span::new(from, to), kind, modifiers });
            }
            from = to + 1;
        }
        if end > from {
            out.push(Token { span: Span::new(from, end), kind, modifiers });
        }
    };
    let mut in_actor_header = false;
    let mut previous = None;
    for &(start, token, end) in &lexed.tokens {
        match token {
            Lexed::Scenario | Lexed::Use | Lexed::Unspecified | Lexed::Of => {
                push(&mut out, start, end, TokenKind::Keyword, 0)
            }
            Lexed::Actor => {
                in_actor_header = true;
                push(&mut out, start, end, TokenKind::Keyword, 0);
            }
            Lexed::Key => {
                let name_end = start + text[start..end].trim_end_matches(':').trim_end().len();
                if previous == Some(Lexed::Actor) {
                    push(&mut out, start, name_end, TokenKind::Variable, Modifier::Declaration.bit());
                } else {
                    push(&mut out, start, name_end, TokenKind::Property, 0);
                }
            }
            Lexed::Head | Lexed::Ident => {
                let (kind, modifiers) = match previous {
                    Some(Lexed::Scenario | Lexed::DeclKind) => (TokenKind::Declaration, Modifier::Declaration.bit()),
                    Some(Lexed::Use | Lexed::Dot) => (TokenKind::Namespace, 0),
                    Some(Lexed::Of) => (TokenKind::Variable, 0),
                    _ if in_actor_header => (TokenKind::Type, names.get(&start).copied().unwrap_or(0)),
                    _ if token == Lexed::Head => (TokenKind::Namespace, 0),
                    _ => (TokenKind::EnumMember, names.get(&start).copied().unwrap_or(0)),
                };
                push(&mut out, start, end, kind, modifiers);
            }
            Lexed::DeclKind => push(&mut out, start, end, TokenKind::Namespace, 0),
            Lexed::Number => push(&mut out, start, end, TokenKind::Number, 0),
            Lexed::Unit => push(&mut out, start, end, TokenKind::Unit, 0),
            Lexed::Str | Lexed::TextBlock => push(&mut out, start, end, TokenKind::String, 0),
            Lexed::DotDot | Lexed::Pipe => push(&mut out, start, end, TokenKind::Operator, 0),
            Lexed::LBrace | Lexed::RBrace => in_actor_header = false,
            _ => {}
        }
        previous = Some(token);
    }
    for comment in &lexed.comments {
        push(&mut out, comment.start, comment.end, TokenKind::Comment, 0);
    }
    out.sort_by_key(|t| t.span.start);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    fn kinds(text: &str) -> Vec<(String, TokenKind, u32)> {
        let (db, file) = testing::file(text);
        tokens(&db, file)
            .into_iter()
            .map(|t| (text[t.span.start..t.span.end].to_string(), t.kind, t.modifiers))
            .collect()
    }

    #[test]
    fn every_part_of_a_scenario() {
        let text = "// c\nscenario demo {\n  environment {\n    weather: sunny\n  }\n  actor lead: 2 taxi {\n    position: front of ego\n    speed: 30..40 km/h\n  }\n}\n";
        let found = kinds(text);
        let of = |word: &str| found.iter().find(|(w, ..)| w == word).map(|(_, k, m)| (*k, *m)).unwrap();
        let stdlib = Modifier::DefaultLibrary.bit();
        assert_eq!(of("// c").0, TokenKind::Comment);
        assert_eq!(of("scenario").0, TokenKind::Keyword);
        assert_eq!(of("demo"), (TokenKind::Declaration, Modifier::Declaration.bit()));
        assert_eq!(of("environment").0, TokenKind::Namespace);
        assert_eq!(of("weather").0, TokenKind::Property);
        assert_eq!(
            of("sunny"),
            (TokenKind::EnumMember, Modifier::Deprecated.bit() | stdlib),
            "an alias from the stdlib"
        );
        assert_eq!(of("lead"), (TokenKind::Variable, Modifier::Declaration.bit()));
        assert_eq!(of("2").0, TokenKind::Number);
        assert_eq!(of("taxi"), (TokenKind::Type, stdlib));
        assert_eq!(of("front"), (TokenKind::EnumMember, stdlib));
        assert_eq!(of("ego").0, TokenKind::Variable);
        assert_eq!(of("..").0, TokenKind::Operator);
        assert_eq!(of("km/h").0, TokenKind::Unit);
        // sorted, not overlapping
        let (db, file) = testing::file(text);
        let all = tokens(&db, file);
        assert!(all.windows(2).all(|w| w[0].span.end <= w[1].span.start));
    }

    #[test]
    fn text_blocks_are_split_per_line_and_broken_text_is_fine() {
        let text = "scenario demo {\n  source {\n    description: \"\"\"\n      é 🚗\n    \"\"\"\n  }\n}\n";
        let found = kinds(text);
        let strings: Vec<&String> = found.iter().filter(|(_, k, _)| *k == TokenKind::String).map(|(w, ..)| w).collect();
        assert_eq!(strings.len(), 3, "{strings:?}");
        assert!(strings.iter().all(|s| !s.contains('\n')));
        let _ = kinds("scenario { road { lanes: \"open");
        let (db, file) = testing::with_language("Scenario:\n  Environment:\n", Language::Yaml);
        assert!(tokens(&db, file).is_empty());
    }
}
