//! The vocabulary a file sees: every declaration of the modules it uses, indexed by kind.
//!
//! Built from modules in order (the prelude, then `use`d modules, then the file itself).
//! A name resolves exactly or through an alias; a name declared twice, or an alias that
//! collides with another name of the same kind, is a conflict reported against the
//! module that declares the later one.

use std::collections::{BTreeMap, HashMap};
use tad_diagnostics::Span;
use tad_syntax::model::{Declaration, Module};

#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub name: String,
    pub declaration: Declaration,
    /// The module that declares it (`core`, `national_park`, or the file's own name).
    pub module: String,
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

    /// A speed attribute in m/s.
    pub fn speed(&self, field: &str) -> Option<f64> {
        self.declaration.attr(field).and_then(|a| a.quantity()).map(|q| q.si())
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
struct Table {
    entries: Vec<Entry>,
    names: HashMap<String, usize>,
    aliases: HashMap<String, usize>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Vocabulary {
    kinds: BTreeMap<&'static str, Table>,
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
    pub module: String,
    pub span: Span,
    pub message: String,
    pub earlier: String,
}

impl Vocabulary {
    /// Index the declarations of `modules`, in order.
    pub fn build<'m>(modules: impl IntoIterator<Item = (&'m str, &'m Module)>) -> (Vocabulary, Vec<Conflict>) {
        let mut vocabulary = Vocabulary::default();
        let mut conflicts = Vec::new();
        for (module_name, module) in modules {
            for declaration in &module.declarations {
                let kind = declaration.def.name;
                let table = vocabulary.kinds.entry(kind).or_default();
                let name = &declaration.name.text;
                if let Some(&i) = table.names.get(name).or_else(|| table.aliases.get(name)) {
                    let earlier = &table.entries[i];
                    conflicts.push(Conflict {
                        module: module_name.to_string(),
                        span: declaration.name.span,
                        message: if &earlier.name == name {
                            format!("{kind} `{name}` is already declared")
                        } else {
                            format!("{kind} `{name}` is already an alias of `{}`", earlier.name)
                        },
                        earlier: earlier.module.clone(),
                    });
                    continue;
                }
                let index = table.entries.len();
                table.names.insert(name.clone(), index);
                table.entries.push(Entry {
                    name: name.clone(),
                    declaration: declaration.clone(),
                    module: module_name.to_string(),
                });
                let aliases = declaration.attr("aliases").and_then(|a| a.symbols()).unwrap_or(&[]);
                for alias in aliases {
                    if let Some(&i) = table.names.get(&alias.name).or_else(|| table.aliases.get(&alias.name)) {
                        conflicts.push(Conflict {
                            module: module_name.to_string(),
                            span: alias.span,
                            message: format!(
                                "alias `{}` is already a {kind} name or alias (of `{}`)",
                                alias.name, table.entries[i].name
                            ),
                            earlier: table.entries[i].module.clone(),
                        });
                    } else {
                        table.aliases.insert(alias.name.clone(), index);
                    }
                }
            }
        }
        (vocabulary, conflicts)
    }

    pub fn lookup(&self, kind: &str, name: &str) -> Lookup<'_> {
        let Some(table) = self.kinds.get(kind) else { return Lookup::Unknown };
        if let Some(&i) = table.names.get(name) {
            Lookup::Exact(&table.entries[i])
        } else if let Some(&i) = table.aliases.get(name) {
            Lookup::Alias(&table.entries[i])
        } else {
            Lookup::Unknown
        }
    }

    pub fn get(&self, kind: &str, name: &str) -> Option<&Entry> {
        self.lookup(kind, name).entry()
    }

    /// The canonical names of a kind, in declaration order.
    pub fn names(&self, kind: &str) -> Vec<&str> {
        self.kinds.get(kind).map(|t| t.entries.iter().map(|e| e.name.as_str()).collect()).unwrap_or_default()
    }

    pub fn entries(&self, kind: &str) -> &[Entry] {
        self.kinds.get(kind).map_or(&[], |t| &t.entries)
    }

    /// The closest name or alias of `kind` to `word`, as the canonical name. Candidates
    /// are tried in declaration order, so ties resolve the same way every time.
    pub fn suggest(&self, kind: &str, word: &str) -> Option<&str> {
        let table = self.kinds.get(kind)?;
        let candidates = table.entries.iter().flat_map(|e| {
            let aliases = e.declaration.attr("aliases").and_then(|a| a.symbols()).unwrap_or(&[]);
            std::iter::once(e.name.as_str()).chain(aliases.iter().map(|a| a.name.as_str()))
        });
        let close = tad_syntax::suggest::closest(word, candidates)?;
        let index = table.names.get(close).or_else(|| table.aliases.get(close))?;
        Some(table.entries[*index].name.as_str())
    }
}
