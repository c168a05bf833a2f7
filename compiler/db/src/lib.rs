//! The TADSL query database: the one place that turns files into checked results.
//!
//! Built on salsa 0.28 and the only crate that depends on it. Inputs are [`SourceFile`]s
//! (a path and a text) and the run's [`Settings`]; tracked queries parse and lower a file
//! ([`analyze`]), gather the vocabulary it sees through the prelude and its `use`s
//! ([`vocabulary`]), and check it ([`check`]). Results are plain values with diagnostics
//! inside them (no accumulators), so they are reused whenever their inputs are unchanged.
//! The command line builds a database per run; the language server keeps one and sets
//! file texts as the editor changes them.
//!
//! A `.yaml`/`.yml` file is read by `tad-yaml` into the same model, so YAML answers are
//! checked by the same code and reported at their own lines.
//!
//! Module resolution: `use a.b` is `a/b.tad` in the using file's directory, else the
//! standard module `a.b` embedded from `stdlib/` at build time. Every file sees the
//! prelude `core` unless it is the prelude.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use tad_check::{Checked, Options, Vocabulary};
use tad_diagnostics::{Code, Diagnostic};
use tad_syntax::model::Module;

/// The standard modules, embedded at build time.
pub mod stdlib {
    include!(concat!(env!("OUT_DIR"), "/stdlib.rs"));

    pub fn source(name: &str) -> Option<&'static str> {
        MODULES.iter().find(|(n, _)| *n == name).map(|(_, text)| *text)
    }
}

/// The prefix of the virtual paths of embedded standard modules.
pub const STDLIB_PREFIX: &str = "<stdlib>";
/// The module every file sees.
pub const PRELUDE: &str = "core";

#[salsa::input(debug)]
pub struct SourceFile {
    #[returns(ref)]
    pub path: PathBuf,
    #[returns(ref)]
    pub text: String,
}

/// Options of a run, as an input so changing them re-checks exactly what depends on them.
#[salsa::input(debug)]
pub struct Settings {
    #[returns(ref)]
    pub options: Options,
}

#[salsa::db]
pub trait Db: salsa::Database {
    /// The file of module `name` (`a.b`) as `from` sees it, if there is one.
    fn module(&self, name: &str, from: SourceFile) -> Option<SourceFile>;
    fn settings(&self) -> Settings;
}

/// A file parsed and lowered.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Analysis {
    pub module: Module,
    pub diagnostics: Vec<Diagnostic>,
}

/// The vocabulary a file sees, and the problems found gathering it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scope {
    pub vocabulary: Vocabulary,
    pub diagnostics: Vec<Diagnostic>,
}

fn is_stdlib(path: &Path) -> bool {
    path.starts_with(STDLIB_PREFIX)
}

/// Whether a path is read as YAML (TrafficAlign's or TrafficComposer's form, possibly a
/// whole LLM answer) rather than TAD.
pub fn is_yaml(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"))
}

/// Parse and lower one file: TAD, or YAML by its extension. Either way the result is the
/// same model, with spans into the file's own text.
#[salsa::tracked(returns(ref))]
pub fn analyze(db: &dyn Db, file: SourceFile) -> Analysis {
    let (module, diagnostics) =
        if is_yaml(file.path(db)) { tad_yaml::lower(file.text(db)) } else { tad_syntax::analyze(file.text(db)) };
    Analysis { module, diagnostics }
}

/// The module name a file is known by.
fn module_name(path: &Path) -> String {
    path.file_stem().map_or_else(|| "<file>".to_string(), |s| s.to_string_lossy().into_owned())
}

/// Whether `file` is the prelude itself (embedded, or the source it was embedded from).
fn is_prelude(db: &dyn Db, file: SourceFile) -> bool {
    let path = file.path(db);
    if is_stdlib(path) {
        return module_name(path) == PRELUDE;
    }
    let on_disk = Path::new(stdlib::STDLIB_DIR).join(format!("{PRELUDE}.tad"));
    path.canonicalize().is_ok_and(|p| p == on_disk) || stdlib::source(PRELUDE) == Some(file.text(db).as_str())
}

/// The vocabulary `file` sees: the prelude, every module it uses (transitively, each
/// once), then its own declarations.
#[salsa::tracked(returns(ref))]
pub fn vocabulary(db: &dyn Db, file: SourceFile) -> Scope {
    let mut diagnostics = Vec::new();
    let mut order: Vec<(String, SourceFile)> = Vec::new();
    if !is_prelude(db, file)
        && let Some(prelude) = db.module(PRELUDE, file)
    {
        order.push((PRELUDE.to_string(), prelude));
    }
    // breadth-first through `use`, reporting only the file's own unresolved uses
    let mut queue: Vec<SourceFile> = vec![file];
    let mut seen: Vec<SourceFile> = vec![file];
    while let Some(current) = queue.pop() {
        for u in &analyze(db, current).module.uses {
            let name: String = u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".");
            match db.module(&name, current) {
                Some(used) if !seen.contains(&used) => {
                    seen.push(used);
                    if !is_prelude(db, used) {
                        order.push((name.clone(), used));
                    }
                    queue.push(used);
                    let errors = analyze(db, used).diagnostics.iter().filter(|d| d.is_error()).count();
                    if current == file && errors > 0 {
                        diagnostics.push(
                            Diagnostic::new(
                                Code::E0404,
                                format!("module `{name}` has {errors} error{}", if errors == 1 { "" } else { "s" }),
                                u.span,
                                "used here",
                            )
                            .with_note(format!("its file is {}; check it to see them", used.path(db).display())),
                        );
                    }
                }
                Some(_) => {}
                None if current == file => {
                    let span = u.path.first().map_or(u.span, |f| f.span.to(u.path.last().map_or(f.span, |l| l.span)));
                    let mut d = Diagnostic::new(Code::E0403, format!("no module `{name}`"), span, "not found");
                    let known = stdlib::MODULES.iter().map(|(n, _)| *n);
                    if let Some(guess) = tad_syntax::suggest::closest(&name, known) {
                        d = d.with_help(format!("did you mean `{guess}`?")).with_fix(span, guess.to_string());
                    }
                    let dir = file.path(db).parent().map(|p| p.display().to_string()).unwrap_or_default();
                    let standard: Vec<&str> = stdlib::MODULES.iter().map(|(n, _)| *n).collect();
                    diagnostics.push(d.with_note(format!(
                        "modules are `NAME.tad` beside the file{}, or standard: {}",
                        if dir.is_empty() { String::new() } else { format!(" (in {dir})") },
                        standard.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
                    )));
                }
                None => {}
            }
        }
    }
    let analyses: Vec<(String, &Module)> =
        order.iter().map(|(name, f)| (name.clone(), &analyze(db, *f).module)).collect();
    let own_name = module_name(file.path(db));
    let own = &analyze(db, file).module;
    let modules = analyses.iter().map(|(n, m)| (n.as_str(), *m)).chain([(own_name.as_str(), own)]);
    let (vocabulary, conflicts) = Vocabulary::build(modules);
    for conflict in conflicts.into_iter().filter(|c| c.module == own_name) {
        diagnostics.push(
            Diagnostic::new(Code::E0405, conflict.message, conflict.span, "conflicts with an earlier declaration")
                .with_note(format!("the earlier one is in module `{}`", conflict.earlier))
                .with_help("use the existing name, or choose another"),
        );
    }
    Scope { vocabulary, diagnostics }
}

/// Every diagnostic of `file`, its completeness class and refinement requests.
#[salsa::tracked(returns(ref))]
pub fn check(db: &dyn Db, file: SourceFile) -> Checked {
    let analysis = analyze(db, file);
    let scope = vocabulary(db, file);
    let options = db.settings().options(db);
    let mut checked = tad_check::check(&analysis.module, &scope.vocabulary, options);
    checked.diagnostics.extend(analysis.diagnostics.iter().cloned());
    checked.diagnostics.extend(scope.diagnostics.iter().cloned());
    tad_diagnostics::sort(&mut checked.diagnostics);
    checked
}

/// The database of one process: files are loaded on first use and kept.
#[salsa::db]
#[derive(Clone)]
pub struct Database {
    storage: salsa::Storage<Self>,
    files: Arc<Mutex<HashMap<PathBuf, SourceFile>>>,
    settings: Option<Settings>,
    log: Option<Arc<Mutex<Vec<String>>>>,
}

#[salsa::db]
impl salsa::Database for Database {}

impl Database {
    pub fn new(options: Options) -> Self {
        Self::with_storage(salsa::Storage::new(None), options, None)
    }

    /// A database that records which queries execute, to test reuse.
    pub fn logged(options: Options) -> Self {
        let log: Arc<Mutex<Vec<String>>> = Arc::default();
        let sink = log.clone();
        let storage = salsa::Storage::new(Some(Box::new(move |event: salsa::Event| {
            if let salsa::EventKind::WillExecute { database_key } = event.kind
                && let Ok(mut log) = sink.lock()
            {
                log.push(format!("{database_key:?}"));
            }
        })));
        Self::with_storage(storage, options, Some(log))
    }

    fn with_storage(storage: salsa::Storage<Self>, options: Options, log: Option<Arc<Mutex<Vec<String>>>>) -> Self {
        let mut db = Database { storage, files: Arc::default(), settings: None, log };
        db.settings = Some(Settings::new(&db, options));
        db
    }

    /// The queries executed since the last call (for a [`Database::logged`] database).
    pub fn take_log(&self) -> Vec<String> {
        self.log.as_ref().map(|l| l.lock().map(|mut l| std::mem::take(&mut *l)).unwrap_or_default()).unwrap_or_default()
    }

    /// Register (or replace the text of) the file at `path`.
    pub fn set_file(&mut self, path: PathBuf, text: String) -> SourceFile {
        use salsa::Setter;
        let existing = self.files.lock().ok().and_then(|files| files.get(&path).copied());
        match existing {
            Some(file) => {
                if file.text(self) != &text {
                    file.set_text(self).to(text);
                }
                file
            }
            None => {
                let file = SourceFile::new(self, path.clone(), text);
                if let Ok(mut files) = self.files.lock() {
                    files.insert(path, file);
                }
                file
            }
        }
    }

    pub fn set_options(&mut self, options: Options) {
        use salsa::Setter;
        if let Some(settings) = self.settings {
            settings.set_options(self).to(options);
        }
    }

    fn load(&self, path: PathBuf, text: impl FnOnce() -> Option<String>) -> Option<SourceFile> {
        let mut files = self.files.lock().ok()?;
        if let Some(file) = files.get(&path) {
            return Some(*file);
        }
        let file = SourceFile::new(self, path.clone(), text()?);
        files.insert(path, file);
        Some(file)
    }
}

#[salsa::db]
impl Db for Database {
    fn module(&self, name: &str, from: SourceFile) -> Option<SourceFile> {
        let relative: PathBuf = name.split('.').collect::<PathBuf>().with_extension("tad");
        let from_path = from.path(self);
        if !is_stdlib(from_path)
            && let Some(dir) = from_path.parent()
        {
            let candidate = dir.join(&relative);
            if candidate.is_file() {
                return self.load(candidate.clone(), || std::fs::read_to_string(&candidate).ok());
            }
        }
        let source = stdlib::source(name)?;
        self.load(Path::new(STDLIB_PREFIX).join(&relative), || Some(source.to_string()))
    }

    fn settings(&self) -> Settings {
        self.settings.expect("set in Database::with_storage")
    }
}
