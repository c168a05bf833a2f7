//! Parsing the extracted YAML with serde_norway, turning its errors into located
//! diagnostics and recovering from them.
//!
//! Recovery keeps byte offsets unchanged: tabs used for indentation are read as single
//! spaces (W0300), and a line serde_norway stops at is blanked (replaced by spaces) and
//! the text parsed again, so one stray line of prose or a template placeholder does not
//! hide the rest of the answer. Every error is reported (E0301); the number of attempts is
//! bounded.

use crate::scan;
use serde_norway::Value;
use tad_diagnostics::{Code, Diagnostic, Payload, Span};

const MAX_ATTEMPTS: usize = 24;

/// Parse `text` (which starts at byte `base` of the file). Returns the text actually
/// parsed (same length, possibly with blanked lines) and its value, if any attempt parsed.
pub fn parse(text: &str, base: usize, diagnostics: &mut Vec<Diagnostic>) -> (String, Option<Value>) {
    let mut work = text.to_string();
    let (mut tabs_fixed, mut hashes_fixed) = (false, false);
    for _ in 0..MAX_ATTEMPTS {
        // the YAML reader takes quadratic time on deep flow nesting before it gives up
        if let Some(at) = too_deep(&work) {
            let span = rest_of_line(&work, at);
            diagnostics.push(snap(
                Diagnostic::new(
                    Code::E0301,
                    "invalid YAML: brackets nested too deeply",
                    Span::new(base + span.start, base + span.end),
                    format!("more than {MAX_DEPTH} levels"),
                )
                .with_help("a scenario needs two or three levels of nesting; remove the extra brackets")
                .with_payload(invalid("brackets nested too deeply")),
                text,
                base,
            ));
            let line = line_starts(&work).partition_point(|&s| s <= at).saturating_sub(1);
            if !blank_lines(&mut work, &[line]) {
                break;
            }
            continue;
        }
        let error = match serde_norway::from_str::<Value>(&work) {
            Ok(value) => return (work, Some(value)),
            Err(e) => e,
        };
        if !tabs_fixed {
            tabs_fixed = true;
            if let Some(first) = untab(&mut work) {
                diagnostics.push(
                    Diagnostic::new(
                        Code::W0300,
                        "tab used for indentation",
                        Span::new(base + first, base + first + 1),
                        "a tab",
                    )
                    .with_help("YAML indents with spaces only; each tab was read as one space")
                    .with_payload(Payload::WrongValue {
                        field: "indentation".into(),
                        expected: "spaces".into(),
                        found: "a tab".into(),
                    })
                    .with_note("most YAML readers, including the one TrafficAlign's pipeline uses, reject this file"),
                );
                continue;
            }
        }
        // `Cyclist #1:` is a key to its writer, a comment to YAML: read it as meant
        if !hashes_fixed {
            hashes_fixed = true;
            if unhash_keys(&mut work) {
                continue;
            }
        }
        let (diagnostic, blank) = describe(&work, base, &error);
        diagnostics.push(snap(diagnostic, text, base));
        if !blank_lines(&mut work, &blank) {
            break;
        }
    }
    (work, None)
}

/// The YAML reader's own nesting limit.
const MAX_DEPTH: usize = 128;

/// Where flow brackets first nest deeper than [`MAX_DEPTH`] (quotes are not tracked, so
/// this is an upper bound of the flow depth).
pub(crate) fn too_deep(text: &str) -> Option<usize> {
    let mut depth = 0usize;
    for (i, b) in text.bytes().enumerate() {
        match b {
            b'[' | b'{' => {
                depth += 1;
                if depth > MAX_DEPTH {
                    return Some(i);
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

/// Replace tabs in indentation with spaces; the offset of the first one replaced.
fn untab(text: &mut String) -> Option<usize> {
    let mut bytes = std::mem::take(text).into_bytes();
    let mut first = None;
    let mut at_line_start = true;
    for (i, b) in bytes.iter_mut().enumerate() {
        match *b {
            b'\n' => at_line_start = true,
            b'\t' if at_line_start => {
                first.get_or_insert(i);
                *b = b' ';
            }
            b' ' if at_line_start => {}
            b'-' if at_line_start => {}
            _ => at_line_start = false,
        }
    }
    *text = String::from_utf8(bytes).unwrap_or_default();
    first
}

/// Make a key written with ` #` in it (`Cyclist #1:`, where YAML starts a comment) one
/// key: each ` #` of the key loses its space (`#` after a character starts no comment),
/// and the spaces go before the key's colon, so that every offset after the line holds.
/// Lines that are comments, quoted, lists or flows are left alone; whether any changed.
fn unhash_keys(text: &mut String) -> bool {
    let mut changed = false;
    let lines: Vec<String> =
        text.split_inclusive('\n')
            .map(|line| {
                let body = line.trim_end_matches(['\n', '\r']);
                let indent = body.len() - body.trim_start_matches(' ').len();
                let content = &body[indent..];
                let Some(hash) = content.find(" #") else { return line.to_string() };
                // the key's colon: the first `:` after the `#` that ends the line or meets a space
                let colon = content[hash..].char_indices().map(|(i, _)| hash + i).find(|&i| {
                    content[i..].starts_with(':') && content[i + 1..].chars().next().is_none_or(|c| c == ' ')
                });
                let plain = !content.starts_with(['#', '"', '\'', '-', '{', '[', '&', '*', '!', '|', '>']);
                match colon.filter(|_| plain && !content[..hash].contains(':')) {
                    Some(colon) => {
                        let key = content[..colon].replace(" #", "#");
                        let pad = " ".repeat(colon - key.len());
                        changed = true;
                        format!("{}{key}{pad}{}{}", &body[..indent], &content[colon..], &line[body.len()..])
                    }
                    None => line.to_string(),
                }
            })
            .collect();
    if changed {
        *text = lines.concat();
    }
    changed
}

/// Blank the given lines (0-based); whether anything changed.
fn blank_lines(text: &mut String, lines: &[usize]) -> bool {
    let starts = line_starts(text);
    let mut bytes = std::mem::take(text).into_bytes();
    let mut changed = false;
    for &line in lines {
        let Some(&start) = starts.get(line) else { continue };
        let end = bytes[start..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |i| start + i);
        for b in &mut bytes[start..end] {
            if *b != b' ' && *b != b'\r' {
                *b = b' ';
                changed = true;
            }
        }
    }
    // whole lines of whole characters were replaced by ASCII: still UTF-8
    *text = String::from_utf8(bytes).unwrap_or_default();
    changed
}

fn line_starts(text: &str) -> Vec<usize> {
    let mut starts = vec![0];
    starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
    starts
}

/// Byte offset of a 1-based line and column (characters) as the YAML reader counts them:
/// it also breaks lines at `\r`, NEL, LS and PS. Clamped to the text.
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut current = 1;
    let mut chars = text.char_indices().peekable();
    while current < line {
        match chars.next() {
            None => return text.len(),
            Some((_, '\r')) => {
                if chars.peek().is_some_and(|&(_, c)| c == '\n') {
                    chars.next();
                }
                current += 1;
            }
            Some((_, '\n' | '\u{85}' | '\u{2028}' | '\u{2029}')) => current += 1,
            Some(_) => {}
        }
    }
    let mut offset = chars.peek().map_or(text.len(), |&(i, _)| i);
    for _ in 1..column {
        match chars.next() {
            Some((_, '\n' | '\r' | '\u{85}' | '\u{2028}' | '\u{2029}')) | None => break,
            Some((i, c)) => offset = i + c.len_utf8(),
        }
    }
    offset
}

/// What the YAML reader found wrong.
fn invalid(problem: &str) -> Payload {
    Payload::Syntax { expected: vec!["valid YAML".into()], found: Some(problem.to_string()) }
}

/// The primary position of an error: the reader's byte index when it is a character
/// boundary of the text, else its line and column.
fn error_offset(text: &str, error: &serde_norway::Error) -> Option<usize> {
    let location = error.location()?;
    let index = location.index();
    if index <= text.len() && text.is_char_boundary(index) && offset_of(text, location.line(), 1) <= index {
        Some(index)
    } else {
        Some(offset_of(text, location.line(), location.column()))
    }
}

/// Move every span of `d` (offsets of the file) onto character boundaries of `original`
/// (the text at `base`): blanked lines may have replaced multi-byte characters by spaces.
fn snap(mut d: Diagnostic, original: &str, base: usize) -> Diagnostic {
    let fix = |offset: usize| {
        let mut o = offset.saturating_sub(base).min(original.len());
        while !original.is_char_boundary(o) {
            o -= 1;
        }
        base + o
    };
    let span = |s: Span| Span::new(fix(s.start), fix(s.end).max(fix(s.start)));
    d.primary.span = span(d.primary.span);
    for label in &mut d.secondary {
        label.span = span(label.span);
    }
    for f in &mut d.fixes {
        f.span = span(f.span);
    }
    d
}

/// From `offset` to the end of its line's content (at least the character there).
fn rest_of_line(text: &str, offset: usize) -> Span {
    let rest = &text[offset.min(text.len())..];
    let line = &rest[..rest.find('\n').unwrap_or(rest.len())];
    let len = line.trim_end().len();
    Span::new(offset, offset + len)
}

/// `at line N column M` in a message.
fn position_in(text: &str) -> Option<(usize, usize)> {
    let i = text.find("at line ")?;
    let rest = &text[i + "at line ".len()..];
    let (line, rest) = rest.split_once(" column ")?;
    let column: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    Some((line.trim().parse().ok()?, column.parse().ok()?))
}

fn strip_positions(text: &str) -> String {
    let mut out = text.to_string();
    while let Some(i) = out.find(" at line ") {
        let rest = &out[i + " at line ".len()..];
        let Some(c) = rest.find(" column ") else { break };
        let digits = rest[c + " column ".len()..].chars().take_while(|c| c.is_ascii_digit()).count();
        let end = i + " at line ".len() + c + " column ".len() + digits;
        out.replace_range(i..end, "");
    }
    if let Some(i) = out.find(" at position ") {
        let digits = out[i + " at position ".len()..].chars().take_while(|c| c.is_ascii_digit()).count();
        out.replace_range(i..i + " at position ".len() + digits, "");
    }
    out
}

/// The diagnostic for one serde_norway error, and the lines (0-based) to blank to get past it.
fn describe(work: &str, base: usize, error: &serde_norway::Error) -> (Diagnostic, Vec<usize>) {
    let full = error.to_string();
    let (problem_text, context_text) = match full.split_once(", while ") {
        Some((p, c)) => (p.to_string(), Some(format!("while {c}"))),
        None => (full.clone(), None),
    };
    let problem = strip_positions(&problem_text);
    let line_of = |offset: usize| line_starts(work).partition_point(|&s| s <= offset).saturating_sub(1);

    if let Some(at) = problem.find("duplicate entry with key ") {
        let key = problem[at + "duplicate entry with key ".len()..].trim().trim_matches('"');
        let tree = scan::scan(work, 0);
        let mapping_at = error_offset(work, error);
        let candidates: Vec<(usize, usize, usize)> =
            tree.duplicates().into_iter().filter(|&(_, a, _)| tree.node(a).key == key).collect();
        let in_mapping = candidates.iter().copied().find(|&(m, _, _)| {
            let first = tree.node(m).children.first().map(|&c| tree.node(c).key_span.start);
            first.is_some() && first == mapping_at
        });
        if let Some((_, first, second)) = in_mapping.or(candidates.first().copied()) {
            let span = tree.node(second).key_span;
            let block = tree.block(second);
            let diagnostic = Diagnostic::new(
                Code::E0301,
                format!("invalid YAML: key `{key}` is given twice"),
                Span::new(base + span.start, base + span.end),
                "given again here",
            )
            .with_secondary(
                Span::new(base + tree.node(first).key_span.start, base + tree.node(first).key_span.end),
                "first given here",
            )
            .with_help("a mapping has each key once: keep one of the two")
            .with_payload(Payload::Duplicate {
                namespace: "key".into(),
                name: key.to_string(),
                earlier_module: None,
            });
            let lines = (line_of(block.start)..=line_of(block.end.saturating_sub(1).max(block.start))).collect();
            return (diagnostic, lines);
        }
    }

    if problem.contains("more than one document") {
        let mut seen_content = false;
        let mut markers = Vec::new();
        for (i, line) in work.lines().enumerate() {
            let t = line.trim_end();
            if t.starts_with("---") || t == "..." {
                if seen_content {
                    markers.push(i);
                }
            } else if !t.trim().is_empty() && !t.trim_start().starts_with('#') {
                seen_content = true;
            }
        }
        let at = markers.first().map_or(0, |&l| line_starts(work)[l]);
        let diagnostic = Diagnostic::new(
            Code::E0301,
            "invalid YAML: more than one document",
            Span::new(base + at, base + at + 3.min(work.len() - at)),
            "a second document starts here",
        )
        .with_help("give the whole scenario as one YAML document: remove the `---` separators")
        .with_payload(invalid("more than one document"));
        return (diagnostic, markers);
    }

    let location = error_offset(work, error);
    let context = context_text.as_ref().map(|c| {
        let at = position_in(c).map_or(0, |(l, col)| offset_of(work, l, col));
        (strip_positions(c), at)
    });
    // for a construct that never ended (a key without `:`, an open quote or bracket) the
    // place to show and to skip is where it started
    let started =
        context.as_ref().is_some_and(|(c, _)| c.starts_with("while scanning") || c.starts_with("while parsing a flow"));
    let (primary, secondary) = match (location, &context) {
        (_, Some((_, at))) if started => {
            let stop = |l: usize| {
                let label = if work[l.min(work.len())..].trim().is_empty() {
                    "the YAML ends here"
                } else {
                    "the YAML reader stopped here"
                };
                (l, label.to_string())
            };
            (Some(*at), location.filter(|l| l != at).map(stop))
        }
        (Some(l), Some((c, at))) => {
            let what = c.trim_start_matches("while ").replace("scanning ", "").replace("parsing ", "");
            (Some(l), (at != &l).then(|| (*at, format!("in {what} that starts here"))))
        }
        (l, _) => (l, None),
    };
    let span = primary.map_or(Span::new(0, 0), |p| rest_of_line(work, p));
    let construct = context.as_ref().map_or(String::new(), |(c, _)| {
        c.trim_start_matches("while ").replace("scanning ", "").replace("parsing ", "")
    });
    let label = match construct.as_str() {
        _ if !started => "here".to_string(),
        "a simple key" => "not a `key: value` line".to_string(),
        "a quoted scalar" => "this quoted string is never closed".to_string(),
        "a flow sequence" => "this `[` list is never closed".to_string(),
        "a flow mapping" => "this `{` mapping is never closed".to_string(),
        other => format!("{other} starts here"),
    };
    let mut diagnostic = Diagnostic::new(
        Code::E0301,
        format!("invalid YAML: {problem}"),
        Span::new(base + span.start, base + span.end),
        label,
    )
    .with_payload(invalid(&problem));
    if let Some((at, message)) = secondary {
        diagnostic = diagnostic.with_secondary(Span::new(base + at, base + at), message);
    }
    let help = if problem.contains("could not find expected ':'") {
        Some("every line of a mapping is `key: value`; remove this line if it is prose or a template placeholder")
    } else if problem.contains("mapping values are not allowed") {
        Some("a key must line up with the keys of its mapping, and a value that contains `: ` must be quoted")
    } else if problem.contains("did not find expected key") || problem.contains("did not find expected '-'") {
        Some("this line is not indented like the keys above it")
    } else if problem.contains("end of stream") && context.as_ref().is_some_and(|(c, _)| c.contains("quoted")) {
        Some("close the quoted string on this line")
    } else if problem.contains("did not find expected ',' or") {
        Some("close the list or mapping with its bracket on this line")
    } else if problem.contains("cannot start any token") {
        Some("quote the value, or remove the character")
    } else {
        None
    };
    if let Some(help) = help {
        diagnostic = diagnostic.with_help(help);
    }
    let lines = match primary {
        Some(p) => vec![line_of(p)],
        None => Vec::new(),
    };
    (diagnostic, lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(text: &str) -> (Option<Value>, Vec<Diagnostic>) {
        let mut d = Vec::new();
        let (_, v) = parse(text, 0, &mut d);
        (v, d)
    }

    fn line(text: &str, offset: usize) -> usize {
        text[..offset].matches('\n').count() + 1
    }

    #[test]
    fn a_stray_line_is_reported_and_skipped() {
        let text = "actors:\n    x:\n        type: car\n    ... (other actors if any) ...\n    y:\n        type: bus\n";
        let (v, d) = run(text);
        assert_eq!(d.len(), 1, "{d:?}");
        assert_eq!(line(text, d[0].primary.span.start), 4);
        let v = v.unwrap();
        assert!(v["actors"]["y"]["type"].as_str() == Some("bus"));
    }

    #[test]
    fn duplicates_tabs_and_documents() {
        let text = "environment:\n    weather: clear\n    weather: rainy\n";
        let (v, d) = run(text);
        assert_eq!(line(text, d[0].primary.span.start), 3);
        assert_eq!(v.unwrap()["environment"]["weather"].as_str(), Some("clear"));

        let text = "environment:\n\tweather: clear\n";
        let (v, d) = run(text);
        assert_eq!(d[0].code, Code::W0300);
        assert_eq!(v.unwrap()["environment"]["weather"].as_str(), Some("clear"));

        let text = "a: 1\n---\nb: 2\n";
        let (v, d) = run(text);
        assert_eq!(line(text, d[0].primary.span.start), 2);
        assert!(v.is_some());
    }

    #[test]
    fn unclosed_quotes_and_brackets_point_at_their_start() {
        let text = "a: 1\nb: \"open\nc: 2\n";
        let (_, d) = run(text);
        assert_eq!(line(text, d[0].primary.span.start), 2, "{d:?}");
        let text = "a: 1\nb: [x, y\nc: 2\n";
        let (_, d) = run(text);
        assert_eq!(line(text, d[0].primary.span.start), 2, "{d:?}");
    }
}
