//! The vocabulary a file sees: every declaration of the modules it uses, indexed by kind.
//!
//! Each module's declarations are indexed once, as a [`Layer`] (the database builds one
//! per module and reuses it for every file that uses the module). A file's
//! [`Vocabulary`] is a stack of shared layers — the prelude, then `use`d modules, then the
//! file itself — searched in order, so assembling it copies no declaration. A name
//! resolves exactly or through an alias; a name declared twice, or an alias that collides
//! with another name of the same kind, is a [`Conflict`] reported against the module that
//! declares the later one, and the earlier declaration wins.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::Arc;
use tad_diagnostics::{FileId, FileSpan, Span};
use tad_syntax::model::{Declaration, Module};

#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub name: String,
    pub declaration: Declaration,
    /// The module that declares it (`core`, `national_park`, or the file's own name).
    pub module: String,
    /// The file that declares it.
    pub file: FileId,
}

impl Entry {
    pub fn flag(&self, field: &str) -> Option<bool> {
        self.declaration.attr(field).and_then(|a| a.flag())
    }

    pub fn symbol(&self, field: &str) -> Option<&str> {
        self.declaration.attr(field).and_then(|a| a.symbol()).map(|s| s.name.as_str())
    }

    pub fn symbols(&self, field: &str) -> Option<Vec<&str>> {
        self.declaration.attr(field).and_then(|a| a.symbols()).map(|s| s.iter().map(|s| s.name.as_str()).collect())
    }

    /// A closed-set attribute (`lateral: left`) as its enum.
    pub fn choice<T: tad_syntax::schema::ClosedSet>(&self, field: &str) -> Option<T> {
        self.declaration.attr(field).and_then(|a| a.choice())
    }

    /// A speed attribute in m/s.
    pub fn speed(&self, field: &str) -> Option<f64> {
        self.declaration.attr(field).and_then(|a| a.quantity()).map(|q| q.si())
    }

    /// Where the name is declared.
    pub fn location(&self) -> FileSpan {
        FileSpan { file: self.file, span: self.declaration.name.span }
    }

    fn spellings(&self) -> impl Iterator<Item = &str> {
        let aliases = self.declaration.attr("aliases").and_then(|a| a.symbols()).unwrap_or(&[]);
        std::iter::once(self.name.as_str()).chain(aliases.iter().map(|a| a.name.as_str()))
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
struct Table {
    entries: Vec<Entry>,
    names: HashMap<String, usize>,
    aliases: HashMap<String, usize>,
}

impl Table {
    fn find(&self, name: &str) -> Option<usize> {
        self.names.get(name).or_else(|| self.aliases.get(name)).copied()
    }
}

/// The declarations of one module, indexed by kind, and the conflicts inside it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layer {
    module: String,
    kinds: BTreeMap<&'static str, Table>,
    conflicts: Vec<Conflict>,
}

impl Layer {
    /// Index the declarations of `module`, known as `name`, in `file`.
    pub fn build(name: &str, file: FileId, module: &Module) -> Layer {
        let mut layer = Layer { module: name.to_string(), ..Layer::default() };
        for declaration in &module.declarations {
            let kind = declaration.def.name;
            let table = layer.kinds.entry(kind).or_default();
            let decl_name = &declaration.name.text;
            if let Some(i) = table.find(decl_name) {
                let earlier = &table.entries[i];
                layer.conflicts.push(Conflict::name(kind, name, file, declaration, earlier));
                continue;
            }
            let index = table.entries.len();
            table.names.insert(decl_name.clone(), index);
            table.entries.push(Entry {
                name: decl_name.clone(),
                declaration: declaration.clone(),
                module: name.to_string(),
                file,
            });
            let aliases = declaration.attr("aliases").and_then(|a| a.symbols()).unwrap_or(&[]);
            for alias in aliases {
                if let Some(i) = table.find(&alias.name) {
                    let earlier = &table.entries[i];
                    layer.conflicts.push(Conflict::alias(
                        kind,
                        name,
                        &alias.name,
                        FileSpan { file, span: alias.span },
                        earlier,
                    ));
                } else {
                    table.aliases.insert(alias.name.clone(), index);
                }
            }
        }
        layer
    }

    pub fn module(&self) -> &str {
        &self.module
    }

    /// Conflicts between declarations of this module.
    pub fn conflicts(&self) -> &[Conflict] {
        &self.conflicts
    }

    pub fn is_empty(&self) -> bool {
        self.kinds.values().all(|t| t.entries.is_empty())
    }
}

/// The vocabulary one file sees: layers searched in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Vocabulary {
    layers: Vec<Arc<Layer>>,
    /// Modules out of scope (the other standard modules), consulted only to say where an
    /// unknown name is declared.
    elsewhere: Vec<Arc<Layer>>,
    /// Declarations of a later layer that an earlier one already has: (layer, kind, index).
    hidden: HashSet<(usize, &'static str, usize)>,
}

/// How a name resolved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lookup<'a> {
    Exact(&'a Entry),
    Alias(&'a Entry),
    Unknown,
}

impl<'a> Lookup<'a> {
    pub fn entry(self) -> Option<&'a Entry> {
        match self {
            Lookup::Exact(e) | Lookup::Alias(e) => Some(e),
            Lookup::Unknown => None,
        }
    }
}

/// A declaration of `module` that clashes with an earlier one.
#[derive(Clone, Debug, PartialEq)]
pub struct Conflict {
    pub kind: &'static str,
    pub name: String,
    /// The module and file of the later declaration, and where it is.
    pub module: String,
    pub at: FileSpan,
    pub message: String,
    /// The module of the earlier declaration, and where it is.
    pub earlier: String,
    pub earlier_at: FileSpan,
}

impl Conflict {
    fn name(kind: &'static str, module: &str, file: FileId, declaration: &Declaration, earlier: &Entry) -> Conflict {
        let name = &declaration.name.text;
        Conflict {
            kind,
            name: name.clone(),
            module: module.to_string(),
            at: FileSpan { file, span: declaration.name.span },
            message: if &earlier.name == name {
                format!("{kind} `{name}` is already declared")
            } else {
                format!("{kind} `{name}` is already an alias of `{}`", earlier.name)
            },
            earlier: earlier.module.clone(),
            earlier_at: earlier.location(),
        }
    }

    fn alias(kind: &'static str, module: &str, alias: &str, at: FileSpan, earlier: &Entry) -> Conflict {
        Conflict {
            kind,
            name: alias.to_string(),
            module: module.to_string(),
            at,
            message: format!("alias `{alias}` is already a {kind} name or alias (of `{}`)", earlier.name),
            earlier: earlier.module.clone(),
            earlier_at: earlier.location(),
        }
    }

    pub fn span(&self) -> Span {
        self.at.span
    }
}

impl Vocabulary {
    /// Stack `layers` in order; returns the conflicts between them (those inside a layer
    /// are the layer's own, see [`Layer::conflicts`]).
    pub fn layered(layers: Vec<Arc<Layer>>) -> (Vocabulary, Vec<Conflict>) {
        let mut hidden = HashSet::new();
        let mut conflicts = Vec::new();
        // the first layer has nothing before it to conflict with
        for (l, layer) in layers.iter().enumerate().skip(1) {
            for (kind, table) in &layer.kinds {
                for (i, entry) in table.entries.iter().enumerate() {
                    let earlier = layers[..l].iter().enumerate().find_map(|(k, earlier)| {
                        let t = earlier.kinds.get(kind)?;
                        let j = t.find(&entry.name)?;
                        (!hidden.contains(&(k, *kind, j))).then(|| &t.entries[j])
                    });
                    if let Some(earlier) = earlier {
                        conflicts.push(Conflict::name(kind, &layer.module, entry.file, &entry.declaration, earlier));
                        hidden.insert((l, *kind, i));
                        continue;
                    }
                    let aliases = entry.declaration.attr("aliases").and_then(|a| a.symbols()).unwrap_or(&[]);
                    for alias in aliases {
                        let taken = layers[..l].iter().find_map(|earlier| {
                            let t = earlier.kinds.get(kind)?;
                            t.find(&alias.name).map(|j| &t.entries[j])
                        });
                        if let Some(earlier) = taken {
                            let at = FileSpan { file: entry.file, span: alias.span };
                            conflicts.push(Conflict::alias(kind, &layer.module, &alias.name, at, earlier));
                        }
                    }
                }
            }
        }
        (Vocabulary { layers, hidden, elsewhere: Vec::new() }, conflicts)
    }

    /// Index the declarations of `modules`, in order, as one layer each (for callers
    /// without a database). Conflicts inside and between modules are returned together.
    pub fn build<'m>(modules: impl IntoIterator<Item = (&'m str, &'m Module)>) -> (Vocabulary, Vec<Conflict>) {
        let layers: Vec<Arc<Layer>> =
            modules.into_iter().map(|(name, module)| Arc::new(Layer::build(name, FileId::UNSET, module))).collect();
        let mut conflicts: Vec<Conflict> = layers.iter().flat_map(|l| l.conflicts.iter().cloned()).collect();
        let (vocabulary, between) = Vocabulary::layered(layers);
        conflicts.extend(between);
        (vocabulary, conflicts)
    }

    /// The same vocabulary, told which modules out of scope to name for unknown names.
    pub fn with_elsewhere(mut self, elsewhere: Vec<Arc<Layer>>) -> Self {
        self.elsewhere = elsewhere;
        self
    }

    /// The module out of scope that declares `name` (or an alias of it) as a `kind`.
    pub fn declared_elsewhere(&self, kind: &str, name: &str) -> Option<&str> {
        self.elsewhere.iter().find(|l| l.kinds.get(kind).is_some_and(|t| t.find(name).is_some())).map(|l| l.module())
    }

    /// A name of `kind` as declared, as an alias, or as the plural of either (`pedestrians`,
    /// `buses`, `bodies`: answers name a group by its plural); a plural is another spelling.
    pub fn lookup(&self, kind: &str, name: &str) -> Lookup<'_> {
        match self.lookup_exact(kind, name) {
            Lookup::Unknown => singulars(name)
                .into_iter()
                .find_map(|singular| self.lookup_exact(kind, &singular).entry())
                .map_or(Lookup::Unknown, Lookup::Alias),
            found => found,
        }
    }

    fn lookup_exact(&self, kind: &str, name: &str) -> Lookup<'_> {
        for (l, layer) in self.layers.iter().enumerate() {
            let Some((kind, table)) = layer.kinds.get_key_value(kind) else { continue };
            if let Some(&i) = table.names.get(name)
                && !self.is_hidden(l, kind, i)
            {
                return Lookup::Exact(&table.entries[i]);
            }
            if let Some(&i) = table.aliases.get(name)
                && !self.is_hidden(l, kind, i)
            {
                return Lookup::Alias(&table.entries[i]);
            }
        }
        Lookup::Unknown
    }

    fn is_hidden(&self, layer: usize, kind: &'static str, index: usize) -> bool {
        !self.hidden.is_empty() && self.hidden.contains(&(layer, kind, index))
    }

    pub fn get(&self, kind: &str, name: &str) -> Option<&Entry> {
        self.lookup(kind, name).entry()
    }

    /// The entries of a kind, in declaration order (layer by layer).
    pub fn entries(&self, kind: &str) -> Vec<&Entry> {
        let mut out = Vec::new();
        for (l, layer) in self.layers.iter().enumerate() {
            let Some((kind, table)) = layer.kinds.get_key_value(kind) else { continue };
            out.extend(
                table
                    .entries
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| !self.hidden.contains(&(l, *kind, *i)))
                    .map(|(_, e)| e),
            );
        }
        out
    }

    /// The canonical names of a kind, in declaration order.
    pub fn names(&self, kind: &str) -> Vec<&str> {
        self.entries(kind).into_iter().map(|e| e.name.as_str()).collect()
    }

    /// The canonical names whose name or alias is within typo distance of `word`,
    /// closest first, at most `n`.
    pub fn candidates(&self, kind: &str, word: &str, n: usize) -> Vec<&str> {
        let entries = self.entries(kind);
        let spellings: Vec<(&str, &Entry)> = entries.iter().flat_map(|e| e.spellings().map(move |s| (s, *e))).collect();
        let mut out: Vec<&str> = Vec::new();
        for close in tad_syntax::suggest::ranked(word, spellings.iter().map(|(s, _)| *s), usize::MAX) {
            if let Some((_, entry)) = spellings.iter().find(|(s, _)| *s == close)
                && !out.contains(&entry.name.as_str())
            {
                out.push(entry.name.as_str());
            }
            if out.len() == n {
                break;
            }
        }
        out
    }
}

/// The singulars an English plural may have: `buses` → `buse`, `bus`; `bodies` → `body`;
/// `pedestrians` → `pedestrian`; for a compound, of its last word (`school_buses`).
fn singulars(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(stem) = name.strip_suffix("ies") {
        out.push(format!("{stem}y"));
    }
    if let Some(stem) = name.strip_suffix("es") {
        out.push(stem.to_string());
    }
    if let Some(stem) = name.strip_suffix('s').filter(|s| !s.ends_with('s')) {
        out.push(stem.to_string());
    }
    out.retain(|s| s.len() >= 2);
    out
}

#[cfg(test)]
mod tests {
    use super::singulars;

    #[test]
    fn plurals_have_their_singulars() {
        assert!(singulars("pedestrians").contains(&"pedestrian".to_string()));
        assert!(singulars("buses").contains(&"bus".to_string()));
        assert!(singulars("bodies").contains(&"body".to_string()));
        assert!(singulars("school_buses").contains(&"school_bus".to_string()));
        assert!(singulars("glass").is_empty());
    }
}
