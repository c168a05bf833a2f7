//! `tadslc import`: TrafficAlign's YAML form (and TrafficComposer's IR, or a whole LLM
//! answer around one) to canonical TAD.
//!
//! The YAML is read through the database, so every diagnostic, the checker's included,
//! points at a YAML line; the model is then printed as TAD in canonical form (aliases,
//! units and 0-based lanes corrected, then formatted). With errors the status is 1 and
//! `-o` writes no file (what was understood still goes to standard output without `-o`):
//! a `.tad` on disk is one that imported whole.
//!
//! The camera rules are `--profile`'s; under `auto` a YAML file that states its `profile`
//! (as `export` writes) is checked with it, and an answer that states none as a dash-cam
//! answer.

use std::path::{Path, PathBuf};

use tad_check::Options;
use tad_db::host::Input;
use tad_db::{Database, Language, RealFs};
use tad_diagnostics::render::{FileReport, human};
use tad_diagnostics::{Diagnostic, Severity};

use crate::output::{CliError, Closed};
use crate::{Status, err, errln, out, plural};

/// `tadslc import`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The YAML file or answer
    pub path: PathBuf,
    /// Where to write the TAD (default: standard output); nothing is written when the
    /// import has errors
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Camera rules: `auto` takes the file's own `profile` (what `export` writes), else the
    /// dash-cam rules of a model's answer; `default` never applies them; `dashcam` always
    #[arg(long, value_enum, default_value_t = super::check::ProfileArg::Auto)]
    pub profile: super::check::ProfileArg,
}

pub fn run(args: &Args, color: bool) -> Result<Status, CliError> {
    let (path, out) = (&args.path, args.output.as_deref());
    let input = tad_db::host::read(path).map_err(CliError::usage)?;
    let mut db = Database::new(Options { profile: args.profile.into(), ..Options::default() });
    let (text, diagnostics) = import(&mut db, &input);
    let errors = report(&input, &diagnostics, color)?;
    if errors == 0 {
        write_output(out, &text)?;
        return Ok(Status::Ok);
    }
    match out {
        Some(path) => errln!(
            "imported `{}` with {}: `{}` not written (without `-o` the TAD understood goes to standard output)",
            input.name,
            plural(errors, "error"),
            path.display()
        )?,
        None => {
            write_output(None, &text)?;
            errln!("imported `{}` with {}: the output lacks what they name", input.name, plural(errors, "error"))?
        }
    }
    Ok(Status::Failed)
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
    let canonical = super::fmt::canonicalize(db, &tad_input);
    let text = tad_syntax::format::format(&canonical).unwrap_or(canonical);
    (text, diagnostics)
}

/// The diagnostics on standard error; how many are errors.
pub(super) fn report(input: &Input, diagnostics: &[Diagnostic], color: bool) -> Result<usize, Closed> {
    err!("{}", human::render(&FileReport::new(&input.name, &input.text, diagnostics), color))?;
    Ok(diagnostics.iter().filter(|d| d.severity == Severity::Error).count())
}

/// `text` to `out`, or to standard output.
pub(super) fn write_output(out: Option<&Path>, text: &str) -> Result<(), CliError> {
    match out {
        None => Ok(out!("{text}")?),
        Some(path) => {
            std::fs::write(path, text)
                .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
            Ok(errln!("wrote `{}`", path.display())?)
        }
    }
}
