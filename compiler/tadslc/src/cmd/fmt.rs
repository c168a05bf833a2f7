//! `tadslc fmt`: rewrite files in the canonical layout, or check that they are.

use crate::files::{self, Search};
use crate::output::CliError;
use crate::{Status, err, errln, out, plural};
use tad_diagnostics::render::{FileReport, human};

/// `tadslc fmt`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Files or directories (searched recursively for *.tad; YAML is skipped); `-`
    /// formats standard input to standard output
    #[arg(required = true)]
    pub paths: Vec<std::path::PathBuf>,
    /// Change nothing; exit 1 if any file is not formatted
    #[arg(long)]
    pub check: bool,
    /// Also replace aliases, non-canonical units and 0-based lane indexes by their
    /// canonical forms (the fixes of W0401, W0402 and W0403)
    #[arg(long)]
    pub canonicalize: bool,
    /// Show at most this many syntax errors per file that cannot be formatted, then how
    /// many more there are (0: all)
    #[arg(long, value_name = "N", default_value_t = 50)]
    pub max_diagnostics: usize,
}

/// The codes whose fixes `--canonicalize` applies (their machine-applicable ones).
pub const CANONICAL: &[tad_diagnostics::Code] =
    &[tad_diagnostics::Code::W0401, tad_diagnostics::Code::W0402, tad_diagnostics::Code::W0403];

/// `text` with every canonical-form fix applied (repeated until none is left, since a
/// fix can only be applied once its overlapping neighbours are).
pub fn canonicalize(db: &mut tad_db::Database, input: &files::Input) -> String {
    let mut text = input.text.clone();
    for _ in 0..8 {
        let probe = files::Input { text: text.clone(), ..input.clone() };
        let checked = tad_db::host::diagnose_in(db, &probe);
        let (fixed, applied) =
            tad_diagnostics::apply_fixes(&text, checked.diagnostics.iter().filter(|d| CANONICAL.contains(&d.code)));
        if applied == 0 {
            break;
        }
        text = fixed;
    }
    text
}

/// Format every `.tad` file `paths` name (directories are searched for `*.tad` only:
/// YAML is not TAD, and is skipped).
pub fn run(args: &Args, color: bool) -> Result<Status, CliError> {
    let Args { paths, check, canonicalize: canonical, max_diagnostics: limit } = args;
    let limit = *limit;
    let (check, canonical) = (*check, *canonical);
    let mut db = tad_db::Database::new(tad_check::Options::default());
    // raised by files that cannot be formatted or written, and by unformatted ones with --check
    let mut status = Status::Ok;
    let (inputs, read) = files::load(paths, Search::Tad)?;
    status = status.max(read);
    let mut unformatted = 0;
    for input in &inputs {
        if input.invalid_utf8.is_some() {
            status = status.max(Status::Failed);
            errln!("error: `{}` is not valid UTF-8; not formatted", input.name)?;
            continue;
        }
        let source = if canonical { canonicalize(&mut db, input) } else { input.text.clone() };
        let formatted = match tad_syntax::format::format(&source) {
            Ok(formatted) => formatted,
            Err(diagnostics) => {
                status = status.max(Status::Failed);
                let shown = super::check::capped(&diagnostics, limit);
                let report = FileReport::new(&input.name, &input.text, shown);
                err!("{}", human::render(&report, color))?;
                if shown.len() < diagnostics.len() {
                    let more = plural(diagnostics.len() - shown.len(), "more error");
                    errln!("{}: and {more}; `--max-diagnostics 0` shows all\n", input.name)?;
                }
                errln!("error: `{}` has syntax errors; not formatted", input.name)?;
                continue;
            }
        };
        let Some(target) = &input.path else {
            out!("{formatted}")?;
            continue;
        };
        if formatted == input.text {
            continue;
        }
        unformatted += 1;
        if check {
            status = status.max(Status::Failed);
            let line = first_difference(&input.text, &formatted);
            errln!("{}: not formatted (first difference at line {line})", input.name)?;
        } else if let Err(e) = write_atomically(target, &formatted) {
            status = Status::Usage;
            errln!("error: cannot write `{}`: {e}", input.name)?;
        } else {
            errln!("formatted {}", input.name)?;
        }
    }
    if check && unformatted > 0 {
        errln!(
            "{} would be reformatted ({} checked); run `tadslc fmt` on {}",
            plural(unformatted, "file"),
            inputs.len(),
            if unformatted == 1 { "it" } else { "them" }
        )?;
    }
    Ok(status)
}

fn first_difference(a: &str, b: &str) -> usize {
    a.lines().zip(b.lines()).position(|(x, y)| x != y).unwrap_or_else(|| a.lines().count().min(b.lines().count())) + 1
}

/// Write through a temporary file beside the target, so a failure never truncates it.
fn write_atomically(path: &std::path::Path, text: &str) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tadslc-fmt.tmp");
    let tmp = std::path::PathBuf::from(tmp);
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}
