//! `tadslc check`: report every problem of every file, in the chosen format.

use crate::files::{self, Input};
use crate::{Format, Status};
use tad_check::{Checked, Class, Options};
use tad_db::Database;
use tad_diagnostics::render::{FileReport, human, json, sarif};
use tad_diagnostics::{Code, Diagnostic, Severity, Span};

/// Check one input through the database: a non-UTF-8 file is reported, then checked as
/// decoded.
pub fn diagnose_in(db: &mut Database, input: &Input) -> Checked {
    let path = input.path.clone().unwrap_or_else(|| std::path::PathBuf::from(&input.name));
    let file = db.set_file(path, input.text.clone());
    let mut checked = tad_db::check(db, file).clone();
    if let Some(at) = input.invalid_utf8 {
        // The lossy text has U+FFFD (3 bytes) where the invalid sequence was.
        checked.diagnostics.insert(
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
    checked
}

/// Every diagnostic of one input, with the default options.
pub fn diagnose(input: &Input) -> Vec<Diagnostic> {
    diagnose_in(&mut Database::new(Options::default()), input).diagnostics
}

pub fn run(paths: &[std::path::PathBuf], format: Format, deny_warnings: bool, color: bool, options: Options) -> Status {
    let (inputs, mut status) = files::load(paths);
    let mut db = Database::new(options);
    let mut checked: Vec<(Input, Checked)> = Vec::new();
    let (mut errors, mut warnings) = (0, 0);
    let mut classes = [0usize; 3];
    for input in inputs {
        let result = diagnose_in(&mut db, &input);
        errors += result.diagnostics.iter().filter(|d| d.severity == Severity::Error).count();
        warnings += result.diagnostics.iter().filter(|d| d.severity == Severity::Warning).count();
        if let Some(class) = result.class {
            classes[class as usize] += 1;
        }
        let report = FileReport { name: &input.name, text: &input.text, diagnostics: &result.diagnostics };
        match format {
            Format::Human => {
                eprint!("{}", human::render(&report, color));
                if let Some(class) = result.class.filter(|c| *c != Class::Complete) {
                    eprintln!("{}: {}", input.name, class.as_str());
                }
            }
            Format::Json => {
                let mut object = json::file_object(&report);
                object.insert("class".into(), result.class.map_or(serde_json::Value::Null, |c| c.as_str().into()));
                object.insert("refinement".into(), result.refinement.clone().into());
                println!("{}", serde_json::Value::Object(object));
            }
            Format::Sarif => {}
        }
        checked.push((input, result));
    }
    match format {
        Format::Sarif => {
            let reports: Vec<FileReport<'_>> = checked
                .iter()
                .map(|(input, result)| FileReport {
                    name: &input.name,
                    text: &input.text,
                    diagnostics: &result.diagnostics,
                })
                .collect();
            println!("{}", sarif::render(&reports, env!("CARGO_PKG_VERSION")));
        }
        Format::Human => eprintln!("{}", summary(checked.len(), errors, warnings, classes)),
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

fn summary(files: usize, errors: usize, warnings: usize, classes: [usize; 3]) -> String {
    let problems = match (errors, warnings) {
        (0, 0) => "no problems".to_string(),
        (e, 0) => plural(e, "error"),
        (0, w) => plural(w, "warning"),
        (e, w) => format!("{}, {}", plural(e, "error"), plural(w, "warning")),
    };
    let names = ["complete", "incomplete", "non_scenario"];
    let classes: Vec<String> =
        classes.iter().zip(names).filter(|(n, _)| **n > 0).map(|(n, name)| format!("{n} {name}")).collect();
    if classes.is_empty() {
        format!("checked {}: {problems}", plural(files, "file"))
    } else {
        format!("checked {}: {problems}; scenarios: {}", plural(files, "file"), classes.join(", "))
    }
}
