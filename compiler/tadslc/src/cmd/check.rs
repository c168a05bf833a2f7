//! `tadslc check`: report every problem of every file, in the chosen format.
//!
//! Each input is set in one database; a diagnostic whose label points into another file
//! (a used module, the prelude) is rendered with that file's text. A local module used by
//! an input and having errors is reported once, in its own file, after the inputs.

use std::path::PathBuf;

use crate::files::{self, Input, Search};
use crate::output::CliError;
use crate::{Status, err, errln, outln, plural};
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
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
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

/// One checked file, ready to render.
struct Checked1 {
    name: String,
    text: String,
    file: SourceFile,
    result: Checked,
}

/// Check every file `paths` name, then report. Every file is checked before anything is
/// reported, so the status is the whole run's even if the reader of the report stops
/// reading early (`spec/output.md`).
pub fn run(args: &Args, color: bool) -> Result<Status, CliError> {
    let Args { paths, format, deny_warnings, max_diagnostics: limit, rules } = args;
    let (format, deny_warnings, limit, options) = (*format, *deny_warnings, *limit, rules.options());
    // raised by unreadable paths, then by errors (and warnings with --deny-warnings)
    let mut status = Status::Ok;
    let (inputs, read) = files::load(paths, Search::Scenarios)?;
    status = status.max(read);
    let mut db = Database::new(options);
    let mut done: Vec<Checked1> = Vec::new();
    for input in &inputs {
        let file = register(&mut db, input);
        let result = checked(&db, file, input);
        done.push(Checked1 { name: input.name.clone(), text: input.text.clone(), file, result });
    }
    // local modules with errors of their own, each once, in their own file
    let inputs_files: Vec<SourceFile> = done.iter().map(|c| c.file).collect();
    let mut modules: Vec<SourceFile> = Vec::new();
    for c in &done {
        for m in db.local_modules(c.file) {
            if !inputs_files.contains(&m)
                && !modules.contains(&m)
                && tad_db::check(&db, m).diagnostics.iter().any(Diagnostic::is_error)
            {
                modules.push(m);
            }
        }
    }
    for m in modules {
        done.push(Checked1 {
            name: m.path(&db).display().to_string(),
            text: m.text(&db).clone(),
            file: m,
            result: tad_db::check(&db, m).clone(),
        });
    }

    let (mut errors, mut warnings) = (0, 0);
    let mut classes = [0usize; Class::ALL.len()];
    let mut hints = 0;
    for c in &done {
        errors += c.result.diagnostics.iter().filter(|d| d.severity == Severity::Error).count();
        warnings += c.result.diagnostics.iter().filter(|d| d.severity == Severity::Warning).count();
        hints += c.result.diagnostics.iter().filter(|d| d.severity == Severity::Hint).count();
        if let Some(class) = c.result.class {
            classes[class as usize] += 1;
        }
    }
    if errors > 0 || (deny_warnings && warnings > 0) {
        status = status.max(Status::Failed);
    }

    let mut sarif_reports = Vec::new();
    for c in &done {
        // a file with hundreds of problems: the first ones, and how many more
        let shown = if limit > 0 && c.result.diagnostics.len() > limit {
            &c.result.diagnostics[..limit]
        } else {
            &c.result.diagnostics[..]
        };
        let hidden = &c.result.diagnostics[shown.len()..];
        let related = related(&db, c.file, shown);
        let report = report(&c.name, &c.text, shown, &related);
        match format {
            Format::Human => {
                err!("{}", human::render(&report, color))?;
                if !hidden.is_empty() {
                    let errors = hidden.iter().filter(|d| d.is_error()).count();
                    errln!(
                        "{}: and {} ({}); `--max-diagnostics 0` shows all\n",
                        c.name,
                        plural(hidden.len(), "more diagnostic"),
                        plural(errors, "error")
                    )?;
                }
                if let Some(class) = c.result.class.filter(|c| *c != Class::Complete) {
                    errln!("{}: {}", c.name, class.as_str())?;
                }
            }
            Format::Json => {
                let mut object = json::file_object(&report);
                object.insert("class".into(), c.result.class.map_or(serde_json::Value::Null, |c| c.as_str().into()));
                let vocabulary = &tad_db::vocabulary(&db, c.file).vocabulary;
                // only what an otherwise valid scenario lacks is asked for
                let refinement = match c.result.class {
                    Some(Class::Incomplete) => tad_feedback::refinement(&c.result.diagnostics, vocabulary),
                    _ => Vec::new(),
                };
                object.insert("refinement".into(), refinement.into());
                object.insert("omitted".into(), hidden.len().into());
                outln!("{}", serde_json::Value::Object(object))?;
            }
            Format::Sarif => sarif_reports.push((
                c.name.clone(),
                c.text.clone(),
                shown.to_vec(),
                related.iter().map(|(n, t, f)| (n.clone(), t.to_string(), *f)).collect::<Vec<_>>(),
                hidden.len(),
            )),
        }
    }
    match format {
        Format::Sarif => {
            let reports: Vec<FileReport<'_>> = sarif_reports
                .iter()
                .map(|(name, text, diagnostics, related, _)| {
                    FileReport::new(name, text, diagnostics)
                        .with_related(related.iter().map(|(n, t, f)| Source { file: *f, name: n, text: t }).collect())
                })
                .collect();
            let mut log = sarif::render(&reports, env!("CARGO_PKG_VERSION"));
            // each artifact says its scenario's class and how many diagnostics were left out
            if let Some(artifacts) = log["runs"][0]["artifacts"].as_array_mut() {
                // one report per file checked, in the same order
                for ((artifact, c), (.., omitted)) in artifacts.iter_mut().zip(&done).zip(&sarif_reports) {
                    let class = c.result.class.map_or(serde_json::Value::Null, |c| c.as_str().into());
                    artifact["properties"] = serde_json::json!({ "class": class, "omitted": omitted });
                }
            }
            outln!("{log}")?;
        }
        // nothing was checked: the errors above say why
        Format::Human if inputs.is_empty() => {}
        Format::Human => errln!("{}", summary(inputs.len(), errors, warnings, hints, classes))?,
        Format::Json => {}
    }
    Ok(status)
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
