//! `tadslc check`: report every problem of every file, in the chosen format.

use crate::files::{self, Input};
use crate::{Format, Status};
use tad_diagnostics::render::{FileReport, human, json, sarif};
use tad_diagnostics::{Code, Diagnostic, Severity, Span};

/// Every diagnostic of one input: a non-UTF-8 file is reported, then checked as decoded.
pub fn diagnose(input: &Input) -> Vec<Diagnostic> {
    let (_, mut diagnostics) = tad_syntax::analyze(&input.text);
    if let Some(at) = input.invalid_utf8 {
        // The lossy text has U+FFFD (3 bytes) where the invalid sequence was.
        diagnostics.insert(
            0,
            Diagnostic::new(
                Code::E0006,
                "this file is not valid UTF-8",
                Span::new(at, at + 3),
                "invalid bytes start here",
            )
            .with_help("save the file as UTF-8"),
        );
    }
    diagnostics
}

pub fn run(paths: &[std::path::PathBuf], format: Format, deny_warnings: bool, color: bool) -> Status {
    let (files, io_errors) = files::collect(paths);
    let mut status = Status::Ok;
    for error in &io_errors {
        eprintln!("error: {error}");
        status = Status::Usage;
    }
    let mut checked: Vec<(Input, Vec<Diagnostic>)> = Vec::new();
    let (mut errors, mut warnings) = (0, 0);
    for path in &files {
        let input = match files::read(path) {
            Ok(input) => input,
            Err(e) => {
                eprintln!("error: {e}");
                status = Status::Usage;
                continue;
            }
        };
        let diagnostics = diagnose(&input);
        errors += diagnostics.iter().filter(|d| d.severity == Severity::Error).count();
        warnings += diagnostics.iter().filter(|d| d.severity == Severity::Warning).count();
        let report = FileReport { name: &input.name, text: &input.text, diagnostics: &diagnostics };
        match format {
            Format::Human => eprint!("{}", human::render(&report, color)),
            Format::Json => println!("{}", serde_json::Value::Object(json::file_object(&report))),
            Format::Sarif => {}
        }
        checked.push((input, diagnostics));
    }
    match format {
        Format::Sarif => {
            let reports: Vec<FileReport<'_>> = checked
                .iter()
                .map(|(input, diagnostics)| FileReport { name: &input.name, text: &input.text, diagnostics })
                .collect();
            println!("{}", sarif::render(&reports, env!("CARGO_PKG_VERSION")));
        }
        Format::Human => eprintln!("{}", summary(checked.len(), errors, warnings)),
        Format::Json => {}
    }
    if errors > 0 || (deny_warnings && warnings > 0) {
        status = status.max(Status::Failed);
    }
    status
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}

fn summary(files: usize, errors: usize, warnings: usize) -> String {
    let problems = match (errors, warnings) {
        (0, 0) => "no problems".to_string(),
        (e, 0) => plural(e, "error"),
        (0, w) => plural(w, "warning"),
        (e, w) => format!("{}, {}", plural(e, "error"), plural(w, "warning")),
    };
    format!("checked {}: {problems}", plural(files, "file"))
}
