//! `tadslc check`: report every problem of every file, in the chosen format.
//!
//! Each input is set in a database (a fresh one every [`BATCH`] files, so memory does not
//! grow with the directory) and reported as soon as it is checked; a diagnostic whose label
//! points into another file (a used module, the prelude) is rendered with that file's text.
//! A local module used by an input and having errors is reported once, in its own file,
//! after the inputs.

use std::path::PathBuf;

use crate::files::{self, Input, Search};
use crate::output::{CliError, Closed};
use crate::{Status, err, errln, out, outln, plural};
use tad_check::{Checked, Class, Options};
use tad_db::host::checked;
use tad_db::host::{diagnose_in, register};
use tad_db::{Database, SourceFile};
use tad_diagnostics::render::{FileReport, Source, human, json, sarif};
use tad_diagnostics::{Diagnostic, Severity};

/// `tadslc check`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Files or directories (searched recursively for *.tad, *.yaml and *.yml);
    /// `-` reads standard input
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Human)]
    pub format: Format,
    /// Treat warnings as errors for the exit code
    #[arg(long)]
    pub deny_warnings: bool,
    /// Show at most this many diagnostics per file, then how many more there are (0: all);
    /// in every format (JSON: `omitted`; SARIF: the artifact's `omitted` property)
    #[arg(long, value_name = "N", default_value_t = 50)]
    pub max_diagnostics: usize,
    #[command(flatten)]
    pub rules: Rules,
}

/// Output format of `check`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    #[default]
    Human,
    Json,
    Sarif,
}

/// Checking rules.
#[derive(clap::Args)]
pub struct Rules {
    /// Camera rules: `dashcam` applies TrafficAlign's extraction rules for dash-cam frames
    /// (nothing behind the ego); `auto` applies them to YAML answers and to scenarios whose
    /// `source` names a video, frame or time; `default` never
    #[arg(long, value_enum, default_value_t = ProfileArg::Auto)]
    pub profile: ProfileArg,
    /// The region of scenarios that state none (e.g. `yellowstone`): its vocabulary module
    /// is in scope
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: Option<String>,
    /// The essentials whose absence together makes a non-scenario
    #[arg(long, value_delimiter = ',', default_value = "weather,time,road")]
    pub non_scenario: Vec<EssentialArg>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ProfileArg {
    Auto,
    Default,
    Dashcam,
}

impl From<ProfileArg> for tad_check::Profile {
    fn from(arg: ProfileArg) -> Self {
        match arg {
            ProfileArg::Auto => tad_check::Profile::Auto,
            ProfileArg::Default => tad_check::Profile::Default,
            ProfileArg::Dashcam => tad_check::Profile::Dashcam,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EssentialArg {
    Weather,
    Time,
    Road,
    Ego,
    Actors,
}

impl Rules {
    pub fn options(&self) -> tad_check::Options {
        use tad_check::Essential;
        tad_check::Options {
            profile: self.profile.into(),
            region: self.region.clone(),
            answer: false,
            non_scenario: self
                .non_scenario
                .iter()
                .map(|e| match e {
                    EssentialArg::Weather => Essential::Weather,
                    EssentialArg::Time => Essential::Time,
                    EssentialArg::Road => Essential::Road,
                    EssentialArg::Ego => Essential::Ego,
                    EssentialArg::Actors => Essential::Actors,
                })
                .collect(),
        }
    }
}

/// Every diagnostic of one input, with the default options.
pub fn diagnose(input: &Input) -> Vec<Diagnostic> {
    diagnose_in(&mut Database::new(Options::default()), input).diagnostics
}

/// The files other than `own` that the labels of `diagnostics` point into.
pub fn related<'a>(
    db: &'a Database,
    own: SourceFile,
    diagnostics: &[Diagnostic],
) -> Vec<(String, &'a str, tad_diagnostics::FileId)> {
    let mut out: Vec<(String, &str, tad_diagnostics::FileId)> = Vec::new();
    for id in diagnostics.iter().flat_map(|d| d.files()) {
        if id == own.id(db) || out.iter().any(|(_, _, known)| *known == id) {
            continue;
        }
        if let Some(file) = db.file(id) {
            out.push((file.path(db).display().to_string(), file.text(db).as_str(), id));
        }
    }
    out
}

/// The report of one file, with the files its labels point into.
pub fn report<'a>(
    name: &'a str,
    text: &'a str,
    diagnostics: &'a [Diagnostic],
    related: &'a [(String, &'a str, tad_diagnostics::FileId)],
) -> FileReport<'a> {
    FileReport::new(name, text, diagnostics)
        .with_related(related.iter().map(|(name, text, file)| Source { file: *file, name, text }).collect())
}

/// The diagnostics `--max-diagnostics N` shows of a file's: the first `limit`, all with 0.
pub fn capped(all: &[Diagnostic], limit: usize) -> &[Diagnostic] {
    if limit > 0 { &all[..all.len().min(limit)] } else { all }
}

/// Files one database holds before the next one is started: a check of a large directory
/// holds this many files' analyses at a time, and reads the prelude once per batch. Each
/// file's result does not depend on the batch it is in.
const BATCH: usize = 256;

/// Check every file `paths` name, reporting each as it is checked. A reader who stops
/// reading early does not stop the check, so the status is the whole run's
/// (`spec/output.md`).
pub fn run(args: &Args, color: bool) -> Result<Status, CliError> {
    let Args { paths, format, deny_warnings, max_diagnostics: limit, rules } = args;
    let options = rules.options();
    // raised by unreadable paths, then by errors (and warnings with --deny-warnings)
    let mut status = Status::Ok;
    let (paths, errors) = tad_db::host::collect(paths, Search::Scenarios);
    for error in &errors {
        status = Status::Usage;
        errln!("error: {error}")?;
    }
    let mut reporter = Reporter { format: *format, color, limit: *limit, ..Reporter::default() };
    if *format == Format::Sarif {
        out!("{}", sarif::Stream::HEAD)?;
    }
    let inputs: std::collections::HashSet<PathBuf> = paths.iter().map(|p| canonical(p)).collect();
    // local modules used by an input and having errors of their own, each once: the file
    // (to tell it from the others) and its path as the input named it (to show)
    let mut modules: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut db = Database::new(options.clone());
    for (i, path) in paths.iter().enumerate() {
        if i > 0 && i % BATCH == 0 {
            db = Database::new(options.clone());
        }
        let input = match files::read(path) {
            Ok(input) => input,
            Err(e) => {
                status = Status::Usage;
                errln!("error: {e}")?;
                continue;
            }
        };
        let file = register(&mut db, &input);
        let result = checked(&db, file, &input);
        for m in db.local_modules(file) {
            let at = canonical(m.path(&db));
            if !inputs.contains(&at)
                && !modules.iter().any(|(known, _)| *known == at)
                && tad_db::check(&db, m).diagnostics.iter().any(Diagnostic::is_error)
            {
                modules.push((at, m.path(&db).clone()));
            }
        }
        reporter.files += 1;
        reporter.file(&db, &input.name, &input.text, file, &result)?;
    }
    // each in its own file, after the inputs
    let mut db = Database::new(options);
    for (_, path) in &modules {
        let Ok(input) = files::read(path) else { continue };
        let file = register(&mut db, &input);
        let result = tad_db::check(&db, file).clone();
        reporter.file(&db, &path.display().to_string(), &input.text, file, &result)?;
    }
    let Tally { errors, warnings, .. } = reporter.tally;
    if errors > 0 || (*deny_warnings && warnings > 0) {
        status = status.max(Status::Failed);
    }
    reporter.end()?;
    Ok(status)
}

/// A path as the file system names it, to tell whether two paths are one file.
fn canonical(path: &std::path::Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// What the summary counts.
#[derive(Default)]
struct Tally {
    errors: usize,
    warnings: usize,
    hints: usize,
    classes: [usize; Class::ALL.len()],
}

/// Writes each file's report as it comes, in the run's format, and what the run's end
/// says: the summary (human), the rest of the log (SARIF).
#[derive(Default)]
struct Reporter {
    format: Format,
    color: bool,
    limit: usize,
    /// The inputs read (not the modules reported after them).
    files: usize,
    tally: Tally,
    sarif: sarif::Stream,
}

impl Reporter {
    fn file(
        &mut self,
        db: &Database,
        name: &str,
        text: &str,
        file: SourceFile,
        result: &Checked,
    ) -> Result<(), Closed> {
        let all = &result.diagnostics;
        let count = |severity| all.iter().filter(|d| d.severity == severity).count();
        self.tally.errors += count(Severity::Error);
        self.tally.warnings += count(Severity::Warning);
        self.tally.hints += count(Severity::Hint);
        if let Some(class) = result.class {
            self.tally.classes[class as usize] += 1;
        }
        // a file with hundreds of problems: the first ones, and how many more
        let shown = capped(all, self.limit);
        let hidden = &all[shown.len()..];
        let related = related(db, file, shown);
        let report = report(name, text, shown, &related);
        let class = result.class.map_or(serde_json::Value::Null, |c| c.as_str().into());
        match self.format {
            Format::Human => {
                err!("{}", human::render(&report, self.color))?;
                if !hidden.is_empty() {
                    let errors = hidden.iter().filter(|d| d.is_error()).count();
                    errln!(
                        "{name}: and {} ({}); `--max-diagnostics 0` shows all\n",
                        plural(hidden.len(), "more diagnostic"),
                        plural(errors, "error")
                    )?;
                }
                if let Some(class) = result.class.filter(|c| *c != Class::Complete) {
                    errln!("{name}: {}", class.as_str())?;
                }
            }
            Format::Json => {
                let mut object = json::file_object(&report);
                object.insert("class".into(), class);
                let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
                // only what an otherwise valid scenario lacks is asked for
                let refinement = match result.class {
                    Some(Class::Incomplete) => tad_feedback::refinement(all, vocabulary),
                    _ => Vec::new(),
                };
                object.insert("refinement".into(), refinement.into());
                object.insert("omitted".into(), hidden.len().into());
                outln!("{}", serde_json::Value::Object(object))?;
            }
            // each artifact says its scenario's class and how many diagnostics were left out
            Format::Sarif => {
                let properties = serde_json::json!({ "class": class, "omitted": hidden.len() });
                out!("{}", self.sarif.file(&report, properties))?;
            }
        }
        Ok(())
    }

    fn end(self) -> Result<(), Closed> {
        let Tally { errors, warnings, hints, classes } = self.tally;
        match self.format {
            Format::Sarif => outln!("{}", self.sarif.end(env!("CARGO_PKG_VERSION"))),
            // nothing was checked: the errors above say why
            Format::Human if self.files == 0 => Ok(()),
            Format::Human => errln!("{}", summary(self.files, errors, warnings, hints, classes)),
            Format::Json => Ok(()),
        }
    }
}

fn summary(files: usize, errors: usize, warnings: usize, hints: usize, classes: [usize; Class::ALL.len()]) -> String {
    let mut problems = match (errors, warnings) {
        (0, 0) => "no problems".to_string(),
        (e, 0) => plural(e, "error"),
        (0, w) => plural(w, "warning"),
        (e, w) => format!("{}, {}", plural(e, "error"), plural(w, "warning")),
    };
    if hints > 0 {
        problems.push_str(&format!(" ({})", plural(hints, "hint")));
    }
    let classes: Vec<String> = classes
        .iter()
        .zip(Class::ALL)
        .filter(|(n, _)| **n > 0)
        .map(|(n, class)| format!("{n} {}", class.as_str()))
        .collect();
    if classes.is_empty() {
        format!("checked {}: {problems}", plural(files, "file"))
    } else {
        format!("checked {}: {problems}; scenarios: {}", plural(files, "file"), classes.join(", "))
    }
}
