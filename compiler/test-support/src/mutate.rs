//! Seeded mutations of TAD texts, for robustness tests: byte edits, token edits and word
//! swaps. The same seed gives the same inputs on every machine (the IR's SplitMix64).

/// The IR's seeded generator (SplitMix64), with its helpers (`below`, `pick`, `chance`).
pub use tad_ir::{Rng as _, SplitMix64 as Rng};

/// Pieces that break TAD in telling ways: brackets, quotes, units, keywords, odd characters.
pub const SNIPPETS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    ".",
    "\"",
    "\"\"\"",
    "//",
    "\n",
    " ",
    "-",
    "0",
    "-7",
    "km/h",
    "mph",
    "unspecified",
    "of",
    "actor",
    "scenario",
    "use",
    "x:",
    "ego",
    "actor x: car {",
    "é",
    "\u{0}",
    "\u{FEFF}",
    "1.5",
    "99999999999999999999999",
    "\\",
    "\\u{",
    "\r\n",
];

/// One to four byte edits: a deletion, a snippet, a random byte, a copied chunk, a changed
/// byte (invalid UTF-8 is decoded lossily).
pub fn bytes(rng: &mut Rng, text: &str) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(bytes.len() + 1);
        match rng.below(5) {
            0 if !bytes.is_empty() => {
                let end = (at + 1 + rng.below(8)).min(bytes.len());
                bytes.drain(at.min(end)..end);
            }
            1 => {
                let snippet = rng.pick(SNIPPETS).as_bytes();
                bytes.splice(at..at, snippet.iter().copied());
            }
            2 => bytes.insert(at, rng.below(256) as u8),
            3 if !bytes.is_empty() => {
                let from = rng.below(bytes.len());
                let end = (from + rng.below(40)).min(bytes.len());
                let chunk: Vec<u8> = bytes[from..end].to_vec();
                bytes.splice(at..at, chunk);
            }
            _ if at < bytes.len() => bytes[at] = rng.below(128) as u8,
            _ => {}
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// One to three token edits (a token removed, repeated, swapped with the next, or a snippet
/// inserted), the tokens then joined by spaces or line breaks.
pub fn tokens(rng: &mut Rng, text: &str) -> String {
    let lexed = tad_syntax::lexer::lex(text);
    let mut pieces: Vec<String> = lexed.tokens.iter().map(|t| text[t.0..t.2].to_string()).collect();
    for _ in 0..1 + rng.below(3) {
        let at = rng.below(pieces.len() + 1);
        match rng.below(4) {
            0 if at < pieces.len() => {
                pieces.remove(at);
            }
            1 if !pieces.is_empty() => {
                let from = rng.below(pieces.len());
                pieces.insert(at, pieces[from].clone());
            }
            2 if at + 1 < pieces.len() => pieces.swap(at, at + 1),
            _ => pieces.insert(at, rng.pick(SNIPPETS).to_string()),
        }
    }
    let sep = if rng.chance(50) { " " } else { "\n" };
    pieces.join(sep)
}

/// One to three edits that keep most of the text: a deletion, a snippet, or one word
/// replaced by another word of the text (which points references at other groups, makes
/// cycles, unknown names and wrong kinds).
pub fn words(rng: &mut Rng, text: &str) -> String {
    let words: Vec<&str> =
        text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect();
    let mut out = text.to_string();
    for _ in 0..1 + rng.below(3) {
        let mut at = rng.below(out.len() + 1);
        while !out.is_char_boundary(at) {
            at -= 1;
        }
        match rng.below(4) {
            0 => {
                let end = (at + 1 + rng.below(12)).min(out.len());
                if out.is_char_boundary(end) {
                    out.replace_range(at..end, "");
                }
            }
            1 => {
                let snippet: &&str = rng.pick(SNIPPETS);
                out.insert_str(at, snippet);
            }
            _ if !words.is_empty() => {
                let (from, to) = (words[rng.below(words.len())], words[rng.below(words.len())]);
                if let Some(found) = out[at..].find(from) {
                    out.replace_range(at + found..at + found + from.len(), to);
                }
            }
            _ => {}
        }
    }
    out
}
