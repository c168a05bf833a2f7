//! `--format json`: one JSON object per file (the CLI prints one per line).
//!
//! The shape is normative (`spec/output.md`): lines and columns are 1-based, columns count
//! characters, and byte offsets are 0-based. Each diagnostic carries its typed `payload`
//! and each fix its `applicability`; a label in another file names that file.

use super::FileReport;
use crate::{Diagnostic, LineIndex, Span};
use serde_json::{Map, Value, json};

/// The object for one file: `{"file", "diagnostics": [...]}`. Callers may add keys.
pub fn file_object(report: &FileReport<'_>) -> Map<String, Value> {
    let index = LineIndex::new(report.text);
    let mut object = Map::new();
    object.insert("file".into(), Value::String(report.name.to_string()));
    object.insert(
        "diagnostics".into(),
        Value::Array(report.diagnostics.iter().map(|d| diagnostic(d, report, &index)).collect()),
    );
    object
}

pub fn span(span: Span, text: &str, index: &LineIndex) -> Value {
    let (start, end) = index.span_range(text, span);
    json!({
        "start": { "line": start.line, "column": start.column },
        "end": { "line": end.line, "column": end.column },
        "byte_start": span.start,
        "byte_end": span.end,
    })
}

fn diagnostic(d: &Diagnostic, report: &FileReport<'_>, index: &LineIndex) -> Value {
    let text = report.text;
    json!({
        "code": d.code.as_str(),
        "severity": d.severity.as_str(),
        "message": d.message,
        "span": span(d.primary.span, text, index),
        "label": d.primary.message,
        "labels": d.secondary.iter().map(|l| {
            let mut object = Map::new();
            match report.source_of(l) {
                Some(source) if source.file == report.file => {
                    object.insert("span".into(), span(l.span, text, index));
                }
                Some(source) => {
                    object.insert("file".into(), source.name.into());
                    object.insert("span".into(), span(l.span, source.text, &LineIndex::new(source.text)));
                }
                None => {}
            }
            object.insert("message".into(), l.message.clone().into());
            Value::Object(object)
        }).collect::<Vec<_>>(),
        "notes": d.notes,
        "help": d.help,
        "payload": d.payload,
        "fixes": d.fixes.iter().map(|f| json!({
            "span": span(f.span, text, index),
            "replacement": f.replacement,
            "applicability": f.applicability,
        })).collect::<Vec<_>>(),
    })
}
