//! Recognising a text that is not TAD: a README, a JSON or YAML file, prose.
//!
//! Reading such a text as TAD gives one syntax error after another, none of them useful.
//! A text is taken for something else when it does not begin like TAD (its first word
//! is not `scenario`, `use` or a declaration kind) and reading it gives many errors; it
//! is then named by what it looks like, with the first error kept as a note.

use crate::schema;
use tad_diagnostics::{Code, Diagnostic, LineIndex, Payload, Span};

/// Errors past which a text that does not begin like TAD is taken for something else.
const MANY: usize = 5;

pub fn not_tad(src: &str, diagnostics: &[Diagnostic]) -> Option<Diagnostic> {
    let errors: Vec<&Diagnostic> = diagnostics.iter().filter(|d| d.is_error()).collect();
    if errors.len() < MANY {
        return None;
    }
    if begins_like_tad(src) {
        return None;
    }
    let (start, first_line) = first_content(src)?;
    let looks = looks_like(src, first_line);
    let index = LineIndex::new(src);
    let first = errors[0];
    let at = index.line_col(src, first.primary.span.start);
    let end = start + first_line.trim_end().len();
    let mut d = Diagnostic::new(
        Code::E0007,
        format!("this is not a TAD source: it looks like {looks}"),
        Span::new(start, end),
        "TAD starts with `scenario NAME {`, `use` or a declaration",
    )
    .with_payload(Payload::WrongValue { field: "file".into(), expected: "a TAD source".into(), found: looks.into() })
    .with_note(format!(
        "read as TAD it gives {} errors; the first, at {}:{}: {}",
        errors.len(),
        at.line,
        at.column,
        first.message
    ));
    d = match looks {
        "YAML" => d.with_help("for a YAML scenario or an LLM answer, name the file `.yaml`, or run `tadslc import`"),
        _ => d.with_help("check `.tad` files, or a YAML answer named `.yaml`"),
    };
    Some(d)
}

/// Whether the first word of `src` that is not in a comment starts a TAD item (`scenario`,
/// `use`, a declaration kind).
pub fn begins_like_tad(src: &str) -> bool {
    let Some((_, first_line)) = first_content(src) else { return false };
    let word: String = first_line.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
    word == "scenario" || word == "use" || schema::declaration(&word).is_some()
}

/// The first line that is neither blank nor a `//` comment, and where it starts.
fn first_content(src: &str) -> Option<(usize, &str)> {
    let mut offset = 0;
    for line in src.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if !trimmed.trim().is_empty() && !trimmed.starts_with("//") {
            let start = offset + (line.len() - trimmed.len());
            return Some((start, trimmed.trim_end_matches(['\n', '\r'])));
        }
        offset += line.len();
    }
    None
}

fn looks_like(src: &str, first: &str) -> &'static str {
    let yaml_keys =
        src.lines().filter(|l| !l.starts_with(' ') && l.split_once(':').is_some_and(|(k, _)| is_key(k))).count();
    if first.starts_with('#') || first.starts_with("```") || src.contains("\n## ") {
        "Markdown"
    } else if first.starts_with('{') || first.starts_with('[') {
        "JSON"
    } else if first.starts_with('<') {
        "HTML or XML"
    } else if first.starts_with("---") || yaml_keys >= 2 {
        "YAML"
    } else {
        "plain text"
    }
}

fn is_key(text: &str) -> bool {
    !text.is_empty() && text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}
