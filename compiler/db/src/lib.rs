//! The TADSL query database: the one place that turns files into checked results.
//!
//! Built on salsa 0.28 and the only crate that depends on it. No query touches the disk:
//! everything a query reads is an input the host (the CLI, the language server) sets.
//!
//! Inputs:
//! - [`SourceFile`]: a file's [`FileId`], path (its name in messages), text, [`Language`]
//!   (TAD, or a YAML answer read by `tad-yaml`: chosen by the host, not guessed from the
//!   path by a query) and [`Imports`] (the prelude it sees and the file each of its `use`s
//!   resolved to);
//! - [`Settings`]: the run's checker options.
//!
//! Queries, each reused until what it read changes:
//!
//! ```text
//! analyze(file) ──▶ declarations(file) ──▶ layer(file)          one module's vocabulary
//!     │                                        │
//!     │             scope(file): prelude + used modules (from Imports inputs only)
//!     │                                        ▼
//!     │                      vocabulary(file) = layers of scope(file) + layer(file)
//!     ▼                                        │
//!  check(file) ◀───────────────────────────────┘   + settings
//! ```
//!
//! So an edit that changes no declaration (a comment, a value in the scenario) re-runs
//! `analyze`, `declarations` and `check` of that file only; every module's layer and the
//! file's vocabulary are reused. Results are plain values with diagnostics inside (no
//! accumulators); every diagnostic carries the [`FileId`] of its file.
//!
//! Module resolution (done by the host, [`Database::set_source`]): `use a.b` is `a/b.tad`
//! in the using file's directory, read through a [`FileSystem`], else the standard module
//! `a.b` embedded from `stdlib/` at build time. Every file sees the prelude `core` unless
//! it is the prelude.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use tad_check::{Checked, Layer, Options, Vocabulary};
use tad_diagnostics::{Code, Diagnostic, FileId, FileSpan, Payload};
use tad_syntax::model::Module;

pub mod host;

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

/// The notation of a source text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Language {
    Tad,
    /// A YAML scenario in TrafficAlign's or TrafficComposer's form, possibly a whole LLM
    /// answer around one.
    Yaml,
}

impl Language {
    /// The language of a file for a host that has only its path and text: `.tad` is TAD
    /// and `.yaml`/`.yml` YAML; another file (a model's answer saved as `.txt` or `.md`) is
    /// a YAML answer when it holds a YAML scenario and does not begin like TAD.
    pub fn guess(path: &Path, text: &str) -> Language {
        let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match extension.as_deref() {
            Some("tad") => Language::Tad,
            Some("yaml" | "yml") => Language::Yaml,
            _ if tad_syntax::begins_like_tad(text) => Language::Tad,
            _ if tad_yaml::dialect(text).is_some() => Language::Yaml,
            _ => Language::Tad,
        }
    }
}

/// What a file's names refer to: the prelude it sees (none for the prelude itself) and
/// the file of each `use` that resolved.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Imports {
    pub prelude: Option<SourceFile>,
    pub modules: BTreeMap<String, SourceFile>,
}

#[salsa::input(debug)]
pub struct SourceFile {
    #[returns(copy)]
    pub id: FileId,
    #[returns(ref)]
    pub path: PathBuf,
    #[returns(ref)]
    pub text: String,
    #[returns(copy)]
    pub language: Language,
    #[returns(ref)]
    pub imports: Imports,
}

/// Options of a run, as an input so changing them re-checks exactly what depends on them.
#[salsa::input(debug)]
pub struct Settings {
    #[returns(ref)]
    pub options: Options,
}

#[salsa::db]
pub trait Db: salsa::Database {
    fn settings(&self) -> Settings;
    /// The embedded standard modules (fixed when the database is made).
    fn standard_modules(&self) -> Vec<SourceFile>;
}

/// A file parsed and lowered.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Analysis {
    pub module: Module,
    pub diagnostics: Vec<Diagnostic>,
    /// The camera profile a YAML file states for itself (`tad_yaml::PROFILES`).
    pub profile: Option<&'static str>,
}

/// The vocabulary a file sees, and the problems found gathering it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scope {
    pub vocabulary: Vocabulary,
    pub diagnostics: Vec<Diagnostic>,
}

fn stamp(diagnostics: impl IntoIterator<Item = Diagnostic>, file: FileId) -> Vec<Diagnostic> {
    diagnostics.into_iter().map(|d| d.in_file(file)).collect()
}

/// Parse and lower one file in its language. Either way the result is the same model,
/// with spans into the file's own text.
#[salsa::tracked(returns(ref))]
pub fn analyze(db: &dyn Db, file: SourceFile) -> Analysis {
    let (module, diagnostics, profile) = match file.language(db) {
        Language::Tad => {
            let (module, diagnostics) = tad_syntax::analyze(file.text(db));
            (module, diagnostics, None)
        }
        Language::Yaml => tad_yaml::lower_answer(file.text(db)),
    };
    Analysis { module, diagnostics: stamp(diagnostics, file.id(db)), profile }
}

/// The module name a file is known by.
pub fn module_name(path: &Path) -> String {
    path.file_stem().map_or_else(|| "<file>".to_string(), |s| s.to_string_lossy().into_owned())
}

/// The file's own declarations: unchanged by edits elsewhere in the file.
#[salsa::tracked(returns(ref))]
pub fn declarations(db: &dyn Db, file: SourceFile) -> Module {
    Module { declarations: analyze(db, file).module.declarations.clone(), ..Module::default() }
}

/// One module's vocabulary, built once and shared by every file that sees the module.
#[salsa::tracked(returns(clone))]
pub fn layer(db: &dyn Db, file: SourceFile) -> Arc<Layer> {
    Arc::new(Layer::build(&module_name(file.path(db)), file.id(db), declarations(db, file)))
}

/// The modules `file` sees, in order: the prelude, then every module it uses,
/// transitively, each once. Reads only [`Imports`] inputs.
#[salsa::tracked(returns(ref))]
pub fn scope(db: &dyn Db, file: SourceFile) -> Vec<SourceFile> {
    let mut order: Vec<SourceFile> = Vec::new();
    let prelude = file.imports(db).prelude;
    order.extend(prelude);
    let mut seen: Vec<SourceFile> = vec![file];
    seen.extend(prelude);
    let mut queue: Vec<SourceFile> = vec![file];
    let mut at = 0;
    while at < queue.len() {
        let current = queue[at];
        at += 1;
        for used in current.imports(db).modules.values() {
            if !seen.contains(used) {
                seen.push(*used);
                order.push(*used);
                queue.push(*used);
            }
        }
    }
    order
}

/// The vocabulary `file` sees: the layers of its scope, then its own.
#[salsa::tracked(returns(ref))]
pub fn vocabulary(db: &dyn Db, file: SourceFile) -> Scope {
    let own = layer(db, file);
    let in_scope = scope(db, file);
    let mut layers: Vec<Arc<Layer>> = in_scope.iter().map(|m| layer(db, *m)).collect();
    layers.push(own.clone());
    let (vocabulary, between) = Vocabulary::layered(layers);
    let elsewhere = db
        .standard_modules()
        .into_iter()
        .filter(|m| *m != file && !in_scope.contains(m))
        .map(|m| layer(db, m))
        .collect();
    let vocabulary = vocabulary.with_elsewhere(elsewhere);
    let id = file.id(db);
    let diagnostics = own
        .conflicts()
        .iter()
        .chain(between.iter().filter(|c| c.at.file == id))
        .map(|conflict| {
            Diagnostic::new(
                Code::E0405,
                conflict.message.clone(),
                conflict.span(),
                "conflicts with an earlier declaration",
            )
            .in_file(id)
            .with_payload(Payload::Duplicate {
                namespace: conflict.kind.to_string(),
                name: conflict.name.clone(),
                earlier_module: Some(conflict.earlier.clone()),
            })
            .with_secondary_in(
                conflict.earlier_at,
                format!("the earlier declaration, in module `{}`", conflict.earlier),
            )
            .with_help("use the existing name, or choose another")
        })
        .collect();
    Scope { vocabulary, diagnostics }
}

/// The problems of `file`'s `use`s: unresolved modules, and used modules with errors.
fn uses(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let id = file.id(db);
    let imports = file.imports(db);
    for u in &analyze(db, file).module.uses {
        let name: String = u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".");
        match imports.modules.get(&name) {
            Some(used) => {
                let errors: Vec<&Diagnostic> = analyze(db, *used).diagnostics.iter().filter(|d| d.is_error()).collect();
                if let Some(first) = errors.first() {
                    let n = errors.len();
                    out.push(
                        Diagnostic::new(
                            Code::E0404,
                            format!("module `{name}` has {n} error{}", if n == 1 { "" } else { "s" }),
                            u.span,
                            "used here",
                        )
                        .in_file(id)
                        .with_payload(Payload::ModuleErrors { module: name.clone(), errors: n })
                        .with_secondary_in(
                            FileSpan { file: used.id(db), span: first.primary.span },
                            format!("the first: {}", first.message),
                        )
                        .with_note(format!("its file is `{}`; its errors are reported there", used.path(db).display())),
                    );
                }
            }
            None => {
                let span = u.path.first().map_or(u.span, |f| f.span.to(u.path.last().map_or(f.span, |l| l.span)));
                let d = Diagnostic::new(Code::E0403, format!("no module `{name}`"), span, "not found").in_file(id);
                let known = stdlib::MODULES.iter().map(|(n, _)| *n);
                let (d, _) = tad_syntax::suggest::unknown(d, "module", &name, span, known);
                let dir = file.path(db).parent().map(|p| p.display().to_string()).unwrap_or_default();
                let standard: Vec<String> = stdlib::MODULES.iter().map(|(n, _)| format!("`{n}`")).collect();
                out.push(d.with_note(format!(
                    "modules are `NAME.tad` beside the file{}, or standard: {}",
                    if dir.is_empty() { String::new() } else { format!(" (in {dir})") },
                    standard.join(", ")
                )));
            }
        }
    }
    out
}

/// Every diagnostic of `file`, and its completeness class.
#[salsa::tracked(returns(ref))]
pub fn check(db: &dyn Db, file: SourceFile) -> Checked {
    let analysis = analyze(db, file);
    let scope = vocabulary(db, file);
    let mut options = db.settings().options(db).clone();
    if file.language(db) == Language::Yaml {
        // a YAML file is a dash-cam answer unless it states its profile (as `export` writes)
        let stated = analysis.profile;
        options.answer = stated.is_none();
        if options.profile == tad_check::Profile::Auto {
            options.profile = match stated {
                Some("default") => tad_check::Profile::Default,
                Some("dashcam") => tad_check::Profile::Dashcam,
                _ => tad_check::Profile::Auto,
            };
        }
    }
    let mut checked = tad_check::check(&analysis.module, &scope.vocabulary, &options, &analysis.diagnostics);
    checked.diagnostics = stamp(std::mem::take(&mut checked.diagnostics), file.id(db));
    checked.diagnostics.extend(analysis.diagnostics.iter().cloned());
    checked.diagnostics.extend(scope.diagnostics.iter().cloned());
    checked.diagnostics.extend(uses(db, file));
    tad_diagnostics::sort(&mut checked.diagnostics);
    checked.class = checked.class.map(|c| tad_check::Class::of(c, &checked.diagnostics));
    checked
}

/// Every standard module but the prelude, by name.
pub fn standard_modules() -> Vec<String> {
    stdlib::MODULES.iter().map(|(name, _)| name.to_string()).filter(|m| m != PRELUDE).collect()
}

/// The vocabulary a file that `use`s `modules` (standard ones) sees: the prelude's and theirs.
pub fn vocabulary_of(modules: &[String]) -> Vocabulary {
    let mut db = Database::new(Options::default());
    let text: String = modules.iter().map(|m| format!("use {m}\n")).collect();
    let file = db.set_file("<vocabulary>.tad".into(), text);
    vocabulary(&db, file).vocabulary.clone()
}

/// A region as a user names it (a canonical name or an alias), as its canonical name; an
/// unknown one is an error that lists the regions and suggests the nearest. Every
/// `--region` flag is read through this, so every command refuses the same names.
pub fn region(name: &str) -> Result<String, String> {
    let core = vocabulary_of(&[]);
    if let Some(entry) = core.get("region", name) {
        return Ok(entry.name.clone());
    }
    let near = core.candidates("region", name, 1);
    Err(format!(
        "unknown region `{name}`{} (the regions are: {})",
        near.first().map(|n| format!("; did you mean `{n}`?")).unwrap_or_default(),
        core.names("region").join(", ")
    ))
}

/// The standard module a region's scenarios see: the `module` its declaration names (the
/// one place the region → module map is read).
pub fn region_module(vocabulary: &tad_check::Vocabulary, region: &str) -> Option<String> {
    vocabulary.get("region", region).and_then(|r| r.symbol("module")).map(str::to_string)
}

/// The scenario of `file`, resolved: names to typed entries, quantities to SI, groups in
/// placement order. `None` when the file has no scenario. Every later stage (backends,
/// layout, runtime) reads this, never the string-keyed model.
#[salsa::tracked(returns(ref))]
pub fn resolve(db: &dyn Db, file: SourceFile) -> Option<tad_ir::Scenario> {
    tad_ir::resolve(&analyze(db, file).module, &vocabulary(db, file).vocabulary)
}

/// Run `f`, a reader of a database snapshot; `None` when a write cancelled it (salsa
/// unwinds the readers of inputs being set, so an edit never waits for stale work).
/// Other panics propagate.
pub fn cancellable<T>(f: impl FnOnce() -> T + std::panic::UnwindSafe) -> Option<T> {
    salsa::Cancelled::catch(f).ok()
}

/// Whether a source is the prelude's (embedded, or `stdlib/core.tad` checked from disk),
/// which must not see the prelude a second time.
fn is_prelude_source(path: &Path, text: &str) -> bool {
    module_name(path) == PRELUDE && stdlib::source(PRELUDE) == Some(text)
}

/// Where the host reads modules from.
pub trait FileSystem {
    /// The text of the file at `path`, if it is a readable file.
    fn read(&self, path: &Path) -> Option<String>;
}

/// The machine's file system.
pub struct RealFs;

impl FileSystem for RealFs {
    fn read(&self, path: &Path) -> Option<String> {
        if path.is_file() { std::fs::read_to_string(path).ok() } else { None }
    }
}

/// No file system: only the standard modules resolve.
pub struct NoFs;

impl FileSystem for NoFs {
    fn read(&self, _: &Path) -> Option<String> {
        None
    }
}

/// The database of one process: the host side registers files, resolves their `use`s
/// and sets the inputs; queries read only those.
#[salsa::db]
#[derive(Clone)]
pub struct Database {
    storage: salsa::Storage<Self>,
    files: HashMap<PathBuf, SourceFile>,
    by_id: Vec<SourceFile>,
    stdlib: BTreeMap<String, SourceFile>,
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
        let mut db = Database {
            storage,
            files: HashMap::new(),
            by_id: Vec::new(),
            stdlib: BTreeMap::new(),
            settings: None,
            log,
        };
        db.settings = Some(Settings::new(&db, options));
        for (name, text) in stdlib::MODULES {
            let path = Path::new(STDLIB_PREFIX).join(name.split('.').collect::<PathBuf>().with_extension("tad"));
            let file = db.register(path, text.to_string(), Language::Tad);
            db.stdlib.insert(name.to_string(), file);
        }
        for file in db.stdlib.values().copied().collect::<Vec<_>>() {
            db.resolve_imports(file, &NoFs, &mut Vec::new());
        }
        db
    }

    /// The queries executed since the last call (for a [`Database::logged`] database).
    pub fn take_log(&self) -> Vec<String> {
        self.log.as_ref().map(|l| l.lock().map(|mut l| std::mem::take(&mut *l)).unwrap_or_default()).unwrap_or_default()
    }

    /// Register (or replace the text of) the file at `path`, in the language its path and
    /// text suggest ([`Language::guess`]), resolving its modules on the machine's file
    /// system.
    pub fn set_file(&mut self, path: PathBuf, text: String) -> SourceFile {
        let language = Language::guess(&path, &text);
        self.set_source(path, text, language, &RealFs)
    }

    /// Register (or replace) a source: its text and language, and the files its `use`s
    /// resolve to through `fs` (each registered too, with its own modules).
    pub fn set_source(&mut self, path: PathBuf, text: String, language: Language, fs: &dyn FileSystem) -> SourceFile {
        use salsa::Setter;
        let file = match self.files.get(&path).copied() {
            Some(file) => {
                if file.text(self) != &text {
                    file.set_text(self).to(text);
                }
                if file.language(self) != language {
                    file.set_language(self).to(language);
                }
                file
            }
            None => self.register(path, text, language),
        };
        self.resolve_imports(file, fs, &mut Vec::new());
        file
    }

    fn register(&mut self, path: PathBuf, text: String, language: Language) -> SourceFile {
        let id = FileId(self.by_id.len() as u32);
        // the usual imports from the start, so a file without `use` needs no new revision
        let prelude = self.stdlib.get(PRELUDE).copied().filter(|_| !is_prelude_source(&path, &text));
        let imports = Imports { prelude, modules: BTreeMap::new() };
        let file = SourceFile::new(self, id, path.clone(), text, language, imports);
        self.files.insert(path, file);
        self.by_id.push(file);
        file
    }

    /// Set the imports of `file` from its `use`s, registering the modules they name.
    fn resolve_imports(&mut self, file: SourceFile, fs: &dyn FileSystem, visiting: &mut Vec<SourceFile>) {
        use salsa::Setter;
        if visiting.contains(&file) {
            return;
        }
        visiting.push(file);
        let path = file.path(self).clone();
        let is_stdlib = path.starts_with(STDLIB_PREFIX);
        let prelude = self
            .stdlib
            .get(PRELUDE)
            .copied()
            .filter(|p| *p != file && !is_prelude_source(file.path(self), file.text(self)));
        let module = &analyze(self, file).module;
        let mut names: Vec<String> =
            module.uses.iter().map(|u| u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".")).collect();
        // a scenario sees its region's own module: the region it states, else the run's
        let region = module.scenario.as_ref().and_then(|scenario| {
            let stated = scenario.attr("source", "region").and_then(|a| a.symbol()).map(|s| s.name.clone());
            stated.or_else(|| self.settings().options(self).region.clone())
        });
        let region_module = match (region, prelude) {
            (Some(region), Some(prelude)) => region_module(&vocabulary(self, prelude).vocabulary, &region),
            _ => None,
        };
        let mut modules = BTreeMap::new();
        if let Some(m) = region_module.filter(|m| !names.contains(m))
            && let Some(standard) = self.stdlib.get(&m).copied()
            && standard != file
        {
            modules.insert(m, standard);
        }
        names.retain(|n| !modules.contains_key(n));
        for name in names {
            let relative: PathBuf = name.split('.').collect::<PathBuf>().with_extension("tad");
            let local = if is_stdlib { None } else { path.parent().map(|dir| dir.join(&relative)) };
            let found = match local.as_ref().and_then(|candidate| fs.read(candidate).map(|t| (candidate.clone(), t))) {
                Some((candidate, text)) => Some(match self.files.get(&candidate).copied() {
                    Some(known) => {
                        if known.text(self) != &text {
                            known.set_text(self).to(text);
                        }
                        known
                    }
                    None => self.register(candidate, text, Language::Tad),
                }),
                None => self.stdlib.get(&name).copied(),
            };
            if let Some(used) = found {
                modules.insert(name, used);
                self.resolve_imports(used, fs, visiting);
            }
        }
        let imports = Imports { prelude, modules };
        if file.imports(self) != &imports {
            file.set_imports(self).to(imports);
        }
    }

    pub fn set_options(&mut self, options: Options) {
        use salsa::Setter;
        if let Some(settings) = self.settings {
            settings.set_options(self).to(options);
        }
    }

    /// The file with `id`.
    pub fn file(&self, id: FileId) -> Option<SourceFile> {
        self.by_id.get(id.0 as usize).copied()
    }

    /// The file registered at `path`.
    pub fn file_at(&self, path: &Path) -> Option<SourceFile> {
        self.files.get(path).copied()
    }

    /// The embedded standard module `name`.
    pub fn standard_module(&self, name: &str) -> Option<SourceFile> {
        self.stdlib.get(name).copied()
    }

    /// The local (not standard) modules `file` sees, in scope order.
    pub fn local_modules(&self, file: SourceFile) -> Vec<SourceFile> {
        scope(self, file).iter().copied().filter(|m| !m.path(self).starts_with(STDLIB_PREFIX)).collect()
    }
}

#[salsa::db]
impl Db for Database {
    fn settings(&self) -> Settings {
        self.settings.expect("set in Database::with_storage")
    }

    fn standard_modules(&self) -> Vec<SourceFile> {
        self.stdlib.values().copied().collect()
    }
}
