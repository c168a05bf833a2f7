//! `--format sarif`: one SARIF 2.1.0 log for a whole run.
//!
//! Every code used in the run becomes a rule with its title and explanation; related
//! labels become `relatedLocations` and fixes become SARIF `fixes`. Columns are declared
//! as `unicodeCodePoints`, matching the JSON output.

use super::FileReport;
use crate::{Code, LineIndex, Severity, Span};
use serde_json::{Value, json};

pub fn render(reports: &[FileReport<'_>], tool_version: &str) -> Value {
    let mut rules: Vec<Code> = reports.iter().flat_map(|r| r.diagnostics.iter().map(|d| d.code)).collect();
    rules.sort();
    rules.dedup();
    let rule_index = |code: Code| rules.iter().position(|c| *c == code).unwrap_or(0);

    let mut results = Vec::new();
    for report in reports {
        let index = LineIndex::new(report.text);
        let location = |span: Span| physical_location(report.name, report.text, &index, span);
        for d in report.diagnostics {
            results.push(json!({
                "ruleId": d.code.as_str(),
                "ruleIndex": rule_index(d.code),
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
    }

    json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "tadslc",
                "version": tool_version,
                "rules": rules.iter().map(|code| json!({
                    "id": code.as_str(),
                    "shortDescription": { "text": code.title() },
                    "fullDescription": { "text": code.explanation() },
                    "defaultConfiguration": { "level": level(code.severity()) },
                })).collect::<Vec<_>>(),
            }},
            "columnKind": "unicodeCodePoints",
            "artifacts": reports.iter().map(|r| json!({ "location": { "uri": uri(r.name) } })).collect::<Vec<_>>(),
            "results": results,
        }],
    })
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
