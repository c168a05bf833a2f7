//! A corpus: the scenarios of a directory that count, each checked and resolved once.
//!
//! One predicate, [`counts`], says which checked files count (no errors: complete or
//! incomplete); `stats`, `compare`, `fit`, `gen`'s draws and every `eval` generator use it.
//! Facts the harness needs later (the region, the behaviour the fine-tuning split keys
//! on) are read here from the resolved IR, not from the text again.

use std::path::{Path, PathBuf};

use tad_base::plural;
use tad_check::Class;
use tad_db::{Database, Language, RealFs, SourceFile};
use tad_ir::{Field, Param};
use tad_stats::Features;

/// Whether a checked file counts as a scenario of a corpus: no errors, complete or not.
pub fn counts(class: Option<Class>) -> bool {
    matches!(class, Some(Class::Complete | Class::Incomplete))
}

/// One scenario of a corpus.
pub struct Item {
    /// The file's stem.
    pub name: String,
    /// Its TAD text (a YAML answer converted).
    pub tad: String,
    /// The region its `source` names.
    pub region: Option<String>,
    pub features: Features,
}

/// A file to read into a corpus: its path and text, as the host read them.
pub struct Source {
    pub path: PathBuf,
    pub text: String,
}

pub struct Corpus {
    pub name: String,
    pub items: Vec<Item>,
    /// Files that did not count: with errors, and not scenarios.
    pub invalid: usize,
    pub non_scenarios: usize,
}

impl Corpus {
    /// The sources that count, in order, named `name`.
    pub fn new(name: String, sources: Vec<Source>) -> Corpus {
        let mut db = Database::new(tad_check::Options::default());
        let mut corpus = Corpus { name, items: Vec::new(), invalid: 0, non_scenarios: 0 };
        for source in sources {
            let language = Language::guess(&source.path, &source.text);
            let stem = source.path.file_stem().map(|s| s.to_string_lossy().into_owned());
            let file = db.set_source(source.path.clone(), source.text.clone(), language, &RealFs);
            match tad_db::check(&db, file).class {
                class if counts(class) => {}
                Some(Class::Invalid) => {
                    corpus.invalid += 1;
                    continue;
                }
                _ => {
                    corpus.non_scenarios += 1;
                    continue;
                }
            }
            let Some(scenario) = tad_db::resolve(&db, file) else { continue };
            let tad = if language == Language::Yaml {
                tad_yaml::to_tad(&tad_db::analyze(&db, file).module)
            } else {
                source.text
            };
            let name = stem.unwrap_or_else(|| source.path.display().to_string());
            corpus.items.push(Item { region: region(scenario), features: Features::of(&name, scenario), name, tad });
        }
        corpus
    }

    /// Files that did not count.
    pub fn skipped(&self) -> usize {
        self.invalid + self.non_scenarios
    }

    /// The scenarios of each region their `source` names.
    pub fn by_region(&self) -> std::collections::BTreeMap<String, Vec<&Item>> {
        let mut by_region: std::collections::BTreeMap<String, Vec<&Item>> = Default::default();
        for item in &self.items {
            if let Some(region) = &item.region {
                by_region.entry(region.clone()).or_default().push(item);
            }
        }
        by_region
    }

    /// What a user should know about the files that did not count, if any did not.
    pub fn skipped_note(&self) -> Option<String> {
        (self.skipped() > 0).then(|| {
            format!(
                "corpus `{}`: {} skipped ({} with errors, {} not scenarios; `tadslc check` says why)",
                self.name,
                plural(self.skipped(), "file"),
                self.invalid,
                self.non_scenarios
            )
        })
    }
}

/// A corpus's name: its directory's or file's name.
pub fn name_of(path: &Path) -> String {
    let base = if path.is_dir() { path.file_name() } else { path.file_stem() };
    base.map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string())
}

/// Every scenario under `paths` (files, or directories searched for `.tad` and `.yaml`)
/// that counts, as one corpus named after the first path; and why the paths that could
/// not be read were not.
pub fn read(paths: &[PathBuf]) -> (Corpus, Vec<String>) {
    let name = paths.first().map(|p| name_of(p)).unwrap_or_default();
    let (inputs, errors) = tad_db::host::load(paths, tad_db::host::Search::Scenarios);
    let sources = inputs
        .into_iter()
        .map(|input| Source { path: input.path.unwrap_or_else(|| PathBuf::from(input.name)), text: input.text })
        .collect();
    (Corpus::new(name, sources), errors)
}

/// Corpora named apart: a second `a` becomes `a#2`.
pub fn unique_names(corpora: &mut [Corpus]) {
    for i in 0..corpora.len() {
        let taken = corpora[..i].iter().filter(|c| c.name == corpora[i].name).count();
        if taken > 0 {
            corpora[i].name = format!("{}#{}", corpora[i].name, taken + 1);
        }
    }
}

/// The texts among `texts` that count, each registered in `db` as `dir/NAME.tad`.
pub fn counting(db: &mut Database, dir: &str, texts: Vec<(String, String)>) -> Vec<(String, String)> {
    texts
        .into_iter()
        .filter(|(name, text)| {
            let path = PathBuf::from(dir).join(format!("{name}.tad"));
            let file = db.set_source(path, text.clone(), Language::Tad, &RealFs);
            counts(tad_db::check(db, file).class)
        })
        .collect()
}

/// The region a scenario's `source` names.
pub fn region(scenario: &tad_ir::Scenario) -> Option<String> {
    let named = scenario.source.region.given()?;
    named.id()?;
    Some(scenario.entries.name(named).to_string())
}

/// A scenario's behaviour, the key of the fine-tuning split: its first actor group's
/// behaviour (the adversary of ChatScene's scenarios), else its ego's, else `none`. A
/// behaviour written as a choice or a parameter is no key.
pub fn behaviour(scenario: &tad_ir::Scenario) -> String {
    let name = |field: &Field<Param<tad_ir::Named<tad_ir::Behavior>>>| match field.given() {
        Some(Param::Fixed(named)) => Some(scenario.entries.name(named).to_string()),
        _ => None,
    };
    scenario
        .groups
        .first()
        .and_then(|g| name(&g.behavior))
        .or_else(|| name(&scenario.ego.behavior))
        .unwrap_or_else(|| "none".into())
}

/// [`behaviour`] of a file the database holds (`none` when it holds no scenario).
pub fn behaviour_of(db: &Database, file: SourceFile) -> String {
    tad_db::resolve(db, file).as_ref().map_or_else(|| "none".into(), behaviour)
}
