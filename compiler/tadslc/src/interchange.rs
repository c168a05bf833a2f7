//! `tadslc import` and `tadslc export`: TrafficAlign's YAML form (and TrafficComposer's
//! IR) to TAD and back.
//!
//! Import reads the YAML (possibly a whole LLM answer) through the database, so every
//! diagnostic, the checker's included, points at a YAML line; it then prints the model as
//! TAD in canonical form (aliases, units and 0-based lanes corrected, then formatted).
//! What was understood is written even when something was not: the errors say what is
//! missing, and the status is 1.

use crate::Status;
use crate::files::{self, Input};
use std::path::{Path, PathBuf};
use tad_check::Options;
use tad_db::{Database, Language, RealFs};
use tad_diagnostics::render::{FileReport, human};
use tad_diagnostics::{Diagnostic, Severity};

fn report(input: &Input, diagnostics: &[Diagnostic], color: bool) -> usize {
    eprint!("{}", human::render(&FileReport::new(&input.name, &input.text, diagnostics), color));
    diagnostics.iter().filter(|d| d.severity == Severity::Error).count()
}

fn write_output(out: Option<&Path>, text: &str) -> Status {
    match out {
        None => {
            print!("{text}");
            Status::Ok
        }
        Some(path) => match std::fs::write(path, text) {
            Ok(()) => {
                eprintln!("wrote {}", path.display());
                Status::Ok
            }
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", path.display());
                Status::Usage
            }
        },
    }
}

/// The TAD text for a YAML answer, and the diagnostics of the YAML.
pub fn import(db: &mut Database, input: &Input) -> (String, Vec<Diagnostic>) {
    // read as YAML whatever the extension (answers are often `.txt` or `.md`)
    let path = input.path.clone().unwrap_or_else(|| PathBuf::from(&input.name));
    let file = db.set_source(path.clone(), input.text.clone(), Language::Yaml, &RealFs);
    let diagnostics = tad_db::check(db, file).diagnostics.clone();
    let mut module = tad_db::analyze(db, file).module.clone();
    if let Some(scenario) = module.scenario.as_mut().filter(|s| s.name.is_none()) {
        let stem = path.file_stem().map_or("imported".into(), |s| s.to_string_lossy().into_owned());
        let stem = stem.trim_end_matches(".answer").to_string();
        scenario.name =
            Some(tad_syntax::cst::Name { text: tad_yaml::norm::identifier(&stem), span: Default::default() });
    }
    let tad = tad_yaml::to_tad(&module);
    // canonical names, units and lanes, checked as a TAD file beside the original
    let tad_input =
        Input { name: input.name.clone(), path: Some(path.with_extension("tad")), text: tad, invalid_utf8: None };
    let canonical = crate::fmt::canonicalize(db, &tad_input);
    let text = tad_syntax::format::format(&canonical).unwrap_or(canonical);
    (text, diagnostics)
}

/// Read one input, or say why not.
fn read(path: &Path) -> Result<Input, Status> {
    files::read(path).map_err(|e| {
        eprintln!("error: {e}");
        Status::Usage
    })
}

pub fn run_import(path: &Path, out: Option<&Path>, color: bool) -> Status {
    let input = match read(path) {
        Ok(input) => input,
        Err(status) => return status,
    };
    let mut db = Database::new(Options::default());
    let (text, diagnostics) = import(&mut db, &input);
    let errors = report(&input, &diagnostics, color);
    let status = write_output(out, &text);
    if errors > 0 {
        eprintln!(
            "imported `{}` with {errors} error{}: the output lacks what they name",
            input.name,
            if errors == 1 { "" } else { "s" }
        );
        return status.max(Status::Failed);
    }
    status
}

pub fn run_export(path: &Path, out: Option<&Path>, color: bool) -> Status {
    let input = match read(path) {
        Ok(input) => input,
        Err(status) => return status,
    };
    let mut db = Database::new(Options::default());
    let checked = crate::check::diagnose_in(&mut db, &input);
    if report(&input, &checked.diagnostics, color) > 0 {
        eprintln!("error: `{}` has errors; not exported", input.name);
        return Status::Failed;
    }
    let file = crate::check::register(&mut db, &input);
    let module = &tad_db::analyze(&db, file).module;
    write_output(out, &tad_yaml::export(module, &input.text))
}
