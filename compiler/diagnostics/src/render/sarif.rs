//! `--format sarif`: one SARIF 2.1.0 log for a whole run, written as the files are checked.
//!
//! [`Stream`] writes the log in pieces, so a run over thousands of files holds one file's
//! results at a time: the head, each file's results as they come, then the artifacts and
//! the tool, whose rules are every code the run used, in the order of first use (a
//! result's `ruleIndex` is known when it is written). [`render`] is the same log as one
//! value. Related labels become `relatedLocations` and fixes become SARIF `fixes`.
//! Columns are declared as `unicodeCodePoints`, matching the JSON output.

use super::FileReport;
use crate::{Code, LineIndex, Severity, Span};
use serde_json::{Value, json};

/// The schema's URI, written once for [`Stream::HEAD`] and [`render`].
macro_rules! schema {
    () => {
        "https://json.schemastore.org/sarif-2.1.0.json"
    };
}

/// A SARIF log being written: [`Stream::HEAD`], then [`Stream::file`] for each file, then
/// [`Stream::end`].
#[derive(Default)]
pub struct Stream {
    /// The codes used so far, in the order of first use: the rules.
    rules: Vec<Code>,
    /// The artifacts so far, as the JSON array's elements (text is a small fraction of
    /// the memory a `Value` per file takes).
    artifacts: String,
    results: usize,
}

impl Stream {
    /// The log up to its first result.
    pub const HEAD: &'static str = concat!(
        r#"{"$schema":""#,
        schema!(),
        r#"","version":"2.1.0","#,
        r#""runs":[{"columnKind":"unicodeCodePoints","results":["#
    );

    /// The results of one file, to write after what was written before; its artifact
    /// (with `properties`, if not null) is kept for the end.
    pub fn file(&mut self, report: &FileReport<'_>, properties: Value) -> String {
        let mut text = String::new();
        for result in self.results_of(report) {
            if self.results > 0 {
                text.push(',');
            }
            self.results += 1;
            text.push_str(&result.to_string());
        }
        let mut artifact = json!({ "location": { "uri": uri(report.name) } });
        if !properties.is_null() {
            artifact["properties"] = properties;
        }
        if !self.artifacts.is_empty() {
            self.artifacts.push(',');
        }
        self.artifacts.push_str(&artifact.to_string());
        text
    }

    /// The rest of the log: the artifacts and the tool with its rules.
    pub fn end(self, tool_version: &str) -> String {
        format!(r#"],"artifacts":[{}],"tool":{}}}]}}"#, self.artifacts, tool(&self.rules, tool_version))
    }

    fn rule_index(&mut self, code: Code) -> usize {
        match self.rules.iter().position(|c| *c == code) {
            Some(i) => i,
            None => {
                self.rules.push(code);
                self.rules.len() - 1
            }
        }
    }

    fn results_of(&mut self, report: &FileReport<'_>) -> Vec<Value> {
        let index = LineIndex::new(report.text);
        let location = |span: Span| physical_location(report.name, report.text, &index, span);
        let mut results = Vec::new();
        for d in report.diagnostics {
            results.push(json!({
                "ruleId": d.code.as_str(),
                "ruleIndex": self.rule_index(d.code),
                "level": level(d.severity),
                "message": { "text": message_text(d) },
                "locations": [{ "physicalLocation": location(d.primary.span),
                                "message": { "text": d.primary.message } }],
                "relatedLocations": d.secondary.iter().enumerate().filter_map(|(i, l)| {
                    let source = report.source_of(l)?;
                    let at = if source.file == report.file {
                        location(l.span)
                    } else {
                        physical_location(source.name, source.text, &LineIndex::new(source.text), l.span)
                    };
                    Some(json!({ "id": i, "physicalLocation": at, "message": { "text": l.message } }))
                }).collect::<Vec<_>>(),
                "properties": { "payload": d.payload },
                "fixes": d.fixes.iter().map(|f| json!({
                    "description": { "text": d.help.clone().unwrap_or_else(|| "apply the suggested replacement".into()) },
                    "properties": { "applicability": f.applicability },
                    "artifactChanges": [{
                        "artifactLocation": { "uri": uri(report.name) },
                        "replacements": [{
                            "deletedRegion": region(report.text, &index, f.span),
                            "insertedContent": { "text": f.replacement },
                        }],
                    }],
                })).collect::<Vec<_>>(),
            }));
        }
        results
    }
}

/// The whole log of `reports` as one value (what [`Stream`] writes, read back).
pub fn render(reports: &[FileReport<'_>], tool_version: &str) -> Value {
    let mut stream = Stream::default();
    let results: Vec<Value> = reports.iter().flat_map(|r| stream.results_of(r)).collect();
    let artifacts: Vec<Value> = reports.iter().map(|r| json!({ "location": { "uri": uri(r.name) } })).collect();
    json!({
        "$schema": schema!(),
        "version": "2.1.0",
        "runs": [{
            "columnKind": "unicodeCodePoints",
            "results": results,
            "artifacts": artifacts,
            "tool": tool(&stream.rules, tool_version),
        }],
    })
}

fn tool(rules: &[Code], tool_version: &str) -> Value {
    json!({ "driver": {
        "name": "tadslc",
        "version": tool_version,
        "rules": rules.iter().map(|code| json!({
            "id": code.as_str(),
            "shortDescription": { "text": code.title() },
            "fullDescription": { "text": code.explanation() },
            "defaultConfiguration": { "level": level(code.severity()) },
        })).collect::<Vec<_>>(),
    }})
}

fn level(severity: Severity) -> &'static str {
    match severity {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Hint => "note",
    }
}

fn message_text(d: &crate::Diagnostic) -> String {
    match &d.help {
        Some(help) => format!("{}\nhelp: {help}", d.message),
        None => d.message.clone(),
    }
}

/// A relative URI for a path: forward slashes, spaces and `%` escaped.
fn uri(name: &str) -> String {
    let mut out = String::new();
    for c in name.replace('\\', "/").chars() {
        match c {
            ' ' => out.push_str("%20"),
            '%' => out.push_str("%25"),
            '#' => out.push_str("%23"),
            '?' => out.push_str("%3F"),
            c => out.push(c),
        }
    }
    out
}

fn region(text: &str, index: &LineIndex, span: Span) -> Value {
    let (start, end) = index.span_range(text, span);
    json!({
        "startLine": start.line,
        "startColumn": start.column,
        "endLine": end.line,
        "endColumn": end.column,
        "byteOffset": span.start,
        "byteLength": span.len(),
    })
}

fn physical_location(name: &str, text: &str, index: &LineIndex, span: Span) -> Value {
    json!({
        "artifactLocation": { "uri": uri(name) },
        "region": region(text, index, span),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Diagnostic;

    /// What the stream writes is the log `render` makes, whatever the split into files.
    #[test]
    fn the_stream_writes_the_rendered_log() {
        let d = |code, at: usize| Diagnostic::new(code, "m", Span::new(at, at + 1), "l");
        let (a, b) = (vec![d(Code::E0205, 0), d(Code::W0200, 2)], vec![d(Code::E0217, 1), d(Code::E0205, 3)]);
        let reports = [FileReport::new("a b.tad", "abcd", &a), FileReport::new("c.tad", "wxyz", &b)];
        let mut stream = Stream::default();
        let mut text = Stream::HEAD.to_string();
        for r in &reports {
            text.push_str(&stream.file(r, Value::Null));
        }
        text.push_str(&stream.end("1"));
        let streamed: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(streamed, render(&reports, "1"));
        let run = &streamed["runs"][0];
        let rules: Vec<&str> =
            run["tool"]["driver"]["rules"].as_array().unwrap().iter().map(|r| r["id"].as_str().unwrap()).collect();
        assert_eq!(rules, ["E0205", "W0200", "E0217"], "rules in the order of first use");
        let indexes: Vec<u64> =
            run["results"].as_array().unwrap().iter().map(|r| r["ruleIndex"].as_u64().unwrap()).collect();
        assert_eq!(indexes, [0, 1, 2, 0]);
        assert_eq!(run["artifacts"][0]["location"]["uri"], "a%20b.tad");
    }
}
