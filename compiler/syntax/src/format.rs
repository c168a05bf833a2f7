//! The formatter: one canonical layout for any file that parses.
//!
//! It prints the concrete tree and weaves the comments the lexer set aside back in by
//! position: a comment on the same line as the end of what was printed before it stays
//! a trailing comment; any other comment becomes a line of its own, before the next
//! construct, at the current indentation. A comment inside a construct that is printed
//! on one line (inside a list or a header, say) moves to the line before it. No comment is
//! ever dropped, and formatting a formatted file changes nothing (both are tested).
//!
//! Files with lexical or syntax errors are not formatted: their tree is incomplete.

use crate::cst::{self, Body, Entry, Item, Member, Name, Value};
use crate::lexer;
use crate::parse::{Parsed, parse};
use tad_diagnostics::{Diagnostic, LineIndex, Span};

const INDENT: &str = "  ";

/// Format `src`, or return its syntax errors.
pub fn format(src: &str) -> Result<String, Vec<Diagnostic>> {
    let parsed = parse(src);
    if parsed.has_errors() {
        // what `check` calls something else is one error here too (E0007)
        if let Some(not_tad) = crate::sniff::not_tad(src, &parsed.diagnostics) {
            return Err(vec![not_tad]);
        }
        return Err(parsed.diagnostics.into_iter().filter(Diagnostic::is_error).collect());
    }
    Ok(format_parsed(src, &parsed))
}

/// Format an error-free parse of `src`.
pub fn format_parsed(src: &str, parsed: &Parsed) -> String {
    let mut printer = Printer {
        src,
        index: LineIndex::new(src),
        comments: &parsed.comments,
        next: 0,
        out: String::with_capacity(src.len() + src.len() / 8),
        depth: 0,
        last_end: 0,
        line_open: false,
        block_start: true,
        force_blank: false,
    };
    printer.file(&parsed.file);
    printer.out
}

struct Printer<'a> {
    src: &'a str,
    index: LineIndex,
    comments: &'a [Span],
    next: usize,
    out: String,
    depth: usize,
    /// Source offset where the last printed construct or comment ends.
    last_end: usize,
    /// Whether the current output line may still be extended (by a trailing comment).
    line_open: bool,
    /// Nothing printed yet in the current block: no blank line before the first line.
    block_start: bool,
    /// The next line is preceded by a blank line.
    force_blank: bool,
}

impl Printer<'_> {
    fn text(&self, span: Span) -> &str {
        &self.src[span.start..span.end]
    }

    /// Print every comment that starts before `until`.
    fn comments_before(&mut self, until: usize) {
        while let Some(&c) = self.comments.get(self.next).filter(|c| c.start < until) {
            self.next += 1;
            let text = self.src[c.start..c.end].trim_end();
            let trailing = self.line_open
                && self.last_end <= c.start
                && self.index.line_of(self.last_end) == self.index.line_of(c.start)
                && !self.out.ends_with('\n');
            if trailing {
                self.out.push(' ');
            } else {
                self.new_line(c.start, true);
            }
            self.out.push_str(text);
            self.last_end = c.end;
        }
    }

    /// End the current line and start one for a construct at `start`, keeping one blank
    /// line where the source had at least one.
    fn new_line(&mut self, start: usize, allow_blank: bool) {
        if self.line_open {
            self.out.push('\n');
        }
        let gap = self.src.get(self.last_end..start).unwrap_or("");
        if self.force_blank || (allow_blank && !self.block_start && gap.matches('\n').count() >= 2) {
            self.out.push('\n');
        }
        self.force_blank = false;
        self.block_start = false;
        for _ in 0..self.depth {
            self.out.push_str(INDENT);
        }
        self.line_open = true;
    }

    /// Start the line of a construct spanning `span`; comments inside its first line
    /// (up to `head_end`) move before it.
    fn start(&mut self, span: Span, head_end: usize) {
        self.comments_before(span.start);
        self.comments_before(head_end);
        self.new_line(span.start, true);
    }

    fn file(&mut self, file: &cst::File) {
        for (index, item) in file.items.iter().enumerate() {
            match item {
                Item::Use(u) => {
                    self.start(u.span, u.span.end);
                    let path: Vec<&str> = u.path.iter().map(|n| n.text.as_str()).collect();
                    self.out.push_str("use ");
                    self.out.push_str(&path.join("."));
                    self.last_end = u.span.end;
                }
                Item::Scenario(s) => {
                    // a blank line separates the scenario from the items before it
                    self.force_blank = index > 0;
                    self.start(s.span, s.body.open.end);
                    self.out.push_str("scenario");
                    if let Some(name) = &s.name {
                        self.out.push(' ');
                        self.out.push_str(&name.text);
                    }
                    self.body(&s.body, |p, member| p.member(member));
                }
                Item::Declaration(d) => {
                    let head_end = d.body.as_ref().map_or(d.span.end, |b| b.open.end);
                    self.start(d.span, head_end);
                    let head = format!("{} {}", d.kind.text, d.name.text);
                    self.out.push_str(&head);
                    match &d.body {
                        Some(body) => self.body(body, |p, entry| p.entry(entry)),
                        None => self.last_end = d.span.end,
                    }
                }
                Item::Error(span) => self.verbatim(*span),
            }
        }
        self.comments_before(usize::MAX);
        if self.line_open {
            self.out.push('\n');
        }
    }

    fn verbatim(&mut self, span: Span) {
        self.start(span, span.start);
        let text = self.text(span).to_string();
        self.out.push_str(&text);
        self.last_end = span.end;
    }

    fn body<T>(&mut self, body: &Body<T>, mut item: impl FnMut(&mut Self, &T)) {
        self.out.push_str(" {");
        self.last_end = body.open.end;
        self.depth += 1;
        self.block_start = true;
        for it in &body.items {
            item(self, it);
        }
        self.comments_before(body.close.start);
        self.depth -= 1;
        self.new_line(body.close.start, false);
        self.out.push('}');
        self.last_end = body.close.end.max(self.last_end);
    }

    fn member(&mut self, member: &Member) {
        match member {
            Member::Section(section) => {
                self.start(section.span, section.body.open.end);
                let name = section.name.text.clone();
                self.out.push_str(&name);
                self.body(&section.body, |p, entry| p.entry(entry));
            }
            Member::Actor(actor) => {
                self.start(actor.span, actor.body.open.end);
                let mut head = format!("actor {}: ", actor.name.text);
                if let Some(count) = &actor.count {
                    head.push_str(&self.value_inline(count));
                    head.push(' ');
                }
                head.push_str(&self.value_inline(&actor.kind));
                self.out.push_str(&head);
                self.body(&actor.body, |p, entry| p.entry(entry));
            }
            Member::Error(span) => self.verbatim(*span),
        }
    }

    fn entry(&mut self, entry: &Entry) {
        match entry {
            Entry::Field(field) => {
                self.start(field.span, field.span.end);
                self.out.push_str(&field.key.text);
                self.out.push_str(": ");
                self.value(&field.value);
                self.last_end = field.span.end;
            }
            Entry::Error(span) => self.verbatim(*span),
        }
    }

    fn value(&mut self, value: &Value) {
        if let Value::TextBlock(span) = value {
            let content = lexer::text_block_content(self.text(*span));
            self.out.push_str("\"\"\"");
            for line in content.lines() {
                self.out.push('\n');
                if !line.is_empty() {
                    for _ in 0..=self.depth {
                        self.out.push_str(INDENT);
                    }
                    self.out.push_str(line);
                }
            }
            self.out.push('\n');
            for _ in 0..self.depth {
                self.out.push_str(INDENT);
            }
            self.out.push_str("\"\"\"");
        } else {
            let text = self.value_inline(value);
            self.out.push_str(&text);
        }
    }

    /// A value on one line (text blocks keep their source text).
    fn value_inline(&self, value: &Value) -> String {
        match value {
            Value::Unspecified(_) => "unspecified".into(),
            Value::Number { number, unit, .. } => match unit {
                Some(unit) => format!("{} {}", self.text(*number), self.text(*unit)),
                None => self.text(*number).into(),
            },
            Value::Range { low, high, .. } => {
                let bound = |b: &crate::cst::Bound| match b.unit {
                    Some(unit) => format!("{} {}", self.text(b.number), self.text(unit)),
                    None => self.text(b.number).to_string(),
                };
                match (low.unit, high.unit) {
                    // one unit for both ends is written once, after the range
                    (Some(a), Some(b)) if self.text(a) == self.text(b) => {
                        format!("{}..{} {}", self.text(low.number), self.text(high.number), self.text(b))
                    }
                    _ => format!("{}..{}", bound(low), bound(high)),
                }
            }
            Value::Choice { options, .. } => options.iter().map(|o| words_text(o)).collect::<Vec<_>>().join(" | "),
            Value::String(span) | Value::TextBlock(span) | Value::Error(span) => self.text(*span).into(),
            Value::Words(words) => words_text(words),
            Value::Position { relation, reference, .. } => {
                format!("{} of {}", words_text(relation), words_text(reference))
            }
            Value::List { items, .. } => {
                let items: Vec<String> = items.iter().map(|v| self.value_inline(v)).collect();
                format!("[{}]", items.join(", "))
            }
        }
    }
}

fn words_text(words: &[Name]) -> String {
    words.iter().map(|w| w.text.as_str()).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fmt(src: &str) -> String {
        format(src).unwrap_or_else(|e| panic!("{e:?}"))
    }

    #[test]
    fn canonical_layout() {
        let src = "use  national_park\nscenario demo{ environment{weather:clear time :daytime} \
                   actor a : 2 sedan {position: left_front  of ego lane:-1 speed:3.5 km/h} }";
        assert_eq!(
            fmt(src),
            "use national_park\n\nscenario demo {\n  environment {\n    weather: clear\n    time: daytime\n  }\n  \
             actor a: 2 sedan {\n    position: left_front of ego\n    lane: -1\n    speed: 3.5 km/h\n  }\n}\n"
        );
    }

    #[test]
    fn comments_stay_where_they_were() {
        let src = "// head\nscenario demo { // open\n  road { lanes: 2 // two\n    // before light\n    light: green\n  }\n  // end\n} // tail\n// last\n";
        let out = fmt(src);
        assert_eq!(
            out,
            "// head\nscenario demo { // open\n  road {\n    lanes: 2 // two\n    // before light\n    light: green\n  }\n  // end\n} // tail\n// last\n"
        );
        assert_eq!(fmt(&out), out);
    }

    #[test]
    fn comments_inside_a_line_move_before_it() {
        let src = "scenario demo {\n  road {\n    signs: [stop_sign, // first\n      yield_sign]\n  }\n}\n";
        let out = fmt(src);
        assert_eq!(out, "scenario demo {\n  road {\n    // first\n    signs: [stop_sign, yield_sign]\n  }\n}\n");
        assert_eq!(fmt(&out), out);
    }

    #[test]
    fn a_comment_stays_attached_to_the_scenario_after_it() {
        assert_eq!(fmt("// about\nscenario demo {\n}\n"), "// about\nscenario demo {\n}\n");
        assert_eq!(fmt("use x\n// about\nscenario demo {}"), "use x\n\n// about\nscenario demo {\n}\n");
    }

    #[test]
    fn blank_lines_are_kept_once() {
        let src = "scenario demo {\n\n  ego { lane: 1 }\n\n\n\n  road { lanes: 1 }\n\n}\n";
        assert_eq!(fmt(src), "scenario demo {\n  ego {\n    lane: 1\n  }\n\n  road {\n    lanes: 1\n  }\n}\n");
    }

    #[test]
    fn text_blocks_are_reindented_without_changing_their_value() {
        let src = "scenario demo { source { description: \"\"\"\n        line one\n          indented\n\"\"\" } }";
        let out = fmt(src);
        assert_eq!(
            out,
            "scenario demo {\n  source {\n    description: \"\"\"\n      line one\n        indented\n    \"\"\"\n  }\n}\n"
        );
        assert_eq!(fmt(&out), out);
    }

    #[test]
    fn ranges_and_choices_are_canonical() {
        let src = "scenario demo {\n  environment { weather: clear|cloudy   |  foggy }\n  actor a : 3 .. 5 pedestrian { speed: 3 km/h .. 5 km/h // slow\n distance: 15..25 m delay: 1.5 ..2 s }\n}\n";
        let out = fmt(src);
        assert_eq!(
            out,
            "scenario demo {\n  environment {\n    weather: clear | cloudy | foggy\n  }\n  actor a: 3..5 pedestrian {\n    speed: 3..5 km/h // slow\n    distance: 15..25 m\n    delay: 1.5..2 s\n  }\n}\n"
        );
        assert_eq!(fmt(&out), out);
    }

    #[test]
    fn syntax_errors_are_not_formatted() {
        assert!(format("scenario demo { road { lanes 2 } }").is_err());
    }
}
