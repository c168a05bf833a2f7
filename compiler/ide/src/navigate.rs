//! Go to definition, find references, rename.
//!
//! Definitions come from where the vocabulary says a name is declared (`Entry::file` and
//! the name's span: a stdlib file or a used local module) and from the scenario itself
//! (a group's header, the ego section). References are searched in the document's model:
//! a group's header and every `X of NAME` naming it; a vocabulary name's uses, alias or
//! not. Only groups can be renamed: names of the vocabulary are declarations shared by
//! every scenario, and the stdlib's are read-only.

use tad_check::Vocabulary;
use tad_syntax::lexer::{KEYWORDS, UNITS};
use tad_syntax::model::{Attr, Known, Module, Val};

use crate::locate::{At, at};
use crate::{Database, Edit, Location, SourceFile, Span, WorkspaceEdit};

fn group_index(module: &Module, name: &str) -> Option<usize> {
    module.scenario.as_ref()?.actors.iter().position(|g| g.name.text == name)
}

pub fn definition(db: &Database, file: SourceFile, offset: usize) -> Vec<Location> {
    let Some(found) = at(db, file, offset) else { return Vec::new() };
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    let here = |span| vec![Location { file, span }];
    match found {
        At::Reference { name, .. } => match group_index(module, &name) {
            Some(i) => here(module.scenario.as_ref().map_or(Span::default(), |s| s.actors[i].name.span)),
            None => {
                let ego = module.scenario.as_ref().and_then(|s| s.section("ego")).map(|s| s.name_span);
                match (ego, vocabulary.get("reference", &name)) {
                    (Some(span), Some(_)) => here(span),
                    _ => declared(db, vocabulary, "reference", &name)
                        .into_iter()
                        .chain(declared(db, vocabulary, "road_element", &name))
                        .collect(),
                }
            }
        },
        At::Name { kind, name, declared: false, .. } => declared(db, vocabulary, &kind, &name).into_iter().collect(),
        At::Name { span, declared: true, .. } => here(span),
        At::Group { span, .. } => here(span),
        At::Module { name, .. } => file
            .imports(db)
            .modules
            .get(&name)
            .map(|m| Location { file: *m, span: Span::new(0, 0) })
            .into_iter()
            .collect(),
        _ => Vec::new(),
    }
}

fn declared(db: &Database, vocabulary: &Vocabulary, kind: &str, name: &str) -> Option<Location> {
    let entry = vocabulary.get(kind, name)?;
    let at = entry.location();
    Some(Location { file: db.file(at.file)?, span: at.span })
}

/// Every symbol of the module with the vocabulary kind it is a name of.
pub(crate) fn symbols(module: &Module) -> Vec<(&str, &tad_syntax::model::Symbol)> {
    let mut out = Vec::new();
    fn from_attr<'m>(attr: &'m Attr, out: &mut Vec<(&'static str, &'m tad_syntax::model::Symbol)>) {
        let Known::Given(value) = &attr.value else { return };
        match value {
            Val::Position(p) => out.push(("relation", &p.relation)),
            Val::Symbols(list) => {
                if let Some(kind) = attr.def.vocabulary {
                    out.extend(list.iter().map(|s| (kind, s)));
                }
            }
            _ => {
                if let Some(kind) = attr.def.vocabulary {
                    out.extend(value.names().into_iter().map(|s| (kind, s)));
                }
            }
        }
    }
    for declaration in &module.declarations {
        for a in &declaration.attrs {
            from_attr(a, &mut out);
        }
    }
    if let Some(scenario) = &module.scenario {
        for section in &scenario.sections {
            for a in &section.attrs {
                from_attr(a, &mut out);
            }
        }
        for group in &scenario.actors {
            if let Known::Given(kind) = &group.kind.value {
                out.push(("actor_type", kind));
            }
            for a in &group.attrs {
                from_attr(a, &mut out);
            }
        }
    }
    out
}

/// The spans of a group's header name and of every reference to it.
fn group_spans(module: &Module, name: &str) -> Vec<Span> {
    let Some(scenario) = &module.scenario else { return Vec::new() };
    let mut out: Vec<Span> = scenario.actors.iter().filter(|g| g.name.text == name).map(|g| g.name.span).collect();
    for group in &scenario.actors {
        if let Some(Known::Given(Val::Position(p))) = group.attr("position").map(|a| &a.value)
            && p.reference.name == name
        {
            out.push(p.reference.span);
        }
    }
    out.sort_by_key(|s| s.start);
    out
}

pub fn references(db: &Database, file: SourceFile, offset: usize, include_declaration: bool) -> Vec<Location> {
    let Some(found) = at(db, file, offset) else { return Vec::new() };
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    let group = match &found {
        At::Group { index, .. } => {
            module.scenario.as_ref().and_then(|s| s.actors.get(*index)).map(|g| g.name.text.clone())
        }
        At::Reference { name, .. } if group_index(module, name).is_some() => Some(name.clone()),
        _ => None,
    };
    if let Some(name) = group {
        let header =
            module.scenario.as_ref().and_then(|s| s.actors.iter().find(|g| g.name.text == name)).map(|g| g.name.span);
        return group_spans(module, &name)
            .into_iter()
            .filter(|s| include_declaration || Some(*s) != header)
            .map(|span| Location { file, span })
            .collect();
    }
    let (kind, name) = match found {
        At::Name { kind, name, .. } => (kind, name),
        At::Reference { name, .. } => ("reference".to_string(), name),
        _ => return Vec::new(),
    };
    let Some(entry) = vocabulary.get(&kind, &name) else { return Vec::new() };
    let mut out: Vec<Location> = symbols(module)
        .into_iter()
        .filter(|(k, s)| {
            *k == kind && vocabulary.get(k, &s.name).is_some_and(|e| e.name == entry.name && e.file == entry.file)
        })
        .map(|(_, s)| Location { file, span: s.span })
        .collect();
    if let Some(scenario) = &module.scenario
        && kind == "reference"
    {
        for group in &scenario.actors {
            if let Some(Known::Given(Val::Position(p))) = group.attr("position").map(|a| &a.value)
                && vocabulary.get("reference", &p.reference.name).is_some_and(|e| e.name == entry.name)
            {
                out.push(Location { file, span: p.reference.span });
            }
        }
    }
    if include_declaration && let Some(at) = declared(db, vocabulary, &kind, &name) {
        out.insert(0, at);
    }
    out
}

/// The span of the name a rename at `offset` would change (a group's name or a reference
/// to it), or why there is nothing to rename there.
pub fn prepare_rename(db: &Database, file: SourceFile, offset: usize) -> Result<Span, String> {
    let module = &tad_db::analyze(db, file).module;
    match at(db, file, offset) {
        Some(At::Group { span, .. }) => Ok(span),
        Some(At::Reference { name, span }) if group_index(module, &name).is_some() => Ok(span),
        Some(At::Reference { .. }) => Err("`ego` and road elements are the language's own names".into()),
        Some(At::Name { kind, name, .. }) => {
            let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
            let from_stdlib = vocabulary
                .get(&kind, &name)
                .and_then(|e| db.file(e.file))
                .is_some_and(|f| f.path(db).starts_with(tad_db::STDLIB_PREFIX));
            Err(if from_stdlib {
                format!("`{name}` is declared in the standard library, which is read-only")
            } else {
                format!("only actor groups can be renamed; `{name}` is a {} declaration", kind.replace('_', " "))
            })
        }
        _ => Err("only actor groups can be renamed: put the cursor on a group's name".into()),
    }
}

pub fn rename(db: &Database, file: SourceFile, offset: usize, new_name: &str) -> Result<WorkspaceEdit, String> {
    let span = prepare_rename(db, file, offset)?;
    let text = file.text(db);
    let old = &text[span.start..span.end];
    let module = &tad_db::analyze(db, file).module;
    let valid = new_name.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && new_name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid {
        return Err(format!("`{new_name}` is not a name: letters, digits and `_`, not starting with a digit"));
    }
    if KEYWORDS.iter().any(|(k, _)| *k == new_name) || UNITS.contains(&new_name) || ["yes", "no"].contains(&new_name) {
        return Err(format!("`{new_name}` is a word of the language"));
    }
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    if vocabulary.get("reference", new_name).is_some() || vocabulary.get("road_element", new_name).is_some() {
        return Err(format!("`{new_name}` already names `ego` or a road element"));
    }
    if new_name != old && group_index(module, new_name).is_some() {
        return Err(format!("an actor group is already called `{new_name}`"));
    }
    let edits = group_spans(module, old).into_iter().map(|span| Edit { span, text: new_name.to_string() }).collect();
    Ok(vec![(file, edits)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    const TWO: &str = "scenario demo {\n  ego { lane: 1 }\n  actor lead: car {\n    position: front of ego\n  }\n  actor tail: bus {\n    position: behind of lead\n  }\n  actor side: bus {\n    position: left of lead\n  }\n}\n";

    #[test]
    fn references_go_to_their_group_and_names_to_the_stdlib() {
        let offset = TWO.find("behind of lead").unwrap() + 11;
        let (db, file) = testing::file(TWO);
        let found = definition(&db, file, offset);
        assert_eq!(
            found,
            vec![Location { file, span: Span::new(TWO.find("lead").unwrap(), TWO.find("lead").unwrap() + 4) }]
        );
        let bus = TWO.find("bus").unwrap() + 1;
        let found = definition(&db, file, bus);
        assert_eq!(found.len(), 1);
        let core = found[0].file;
        assert!(core.path(&db).starts_with(tad_db::STDLIB_PREFIX));
        assert!(core.text(&db)[found[0].span.start..].starts_with("bus"));
        // `ego` goes to the ego section
        let found = definition(&db, file, TWO.find("of ego").unwrap() + 4);
        assert_eq!(&TWO[found[0].span.start..found[0].span.end], "ego");
    }

    #[test]
    fn references_and_rename_of_a_group() {
        let (db, file) = testing::file(TWO);
        let at = TWO.find("lead").unwrap() + 1;
        assert_eq!(references(&db, file, at, true).len(), 3);
        assert_eq!(references(&db, file, at, false).len(), 2);
        let edit = rename(&db, file, at, "leader").unwrap();
        let renamed = crate::actions::apply(TWO, &edit[0].1);
        assert!(
            renamed.contains("actor leader: car")
                && renamed.contains("behind of leader")
                && renamed.contains("left of leader")
        );
        assert!(rename(&db, file, at, "tail").unwrap_err().contains("already"));
        assert!(rename(&db, file, at, "9x").is_err());
        assert!(rename(&db, file, at, "of").is_err());
        assert!(rename(&db, file, at, "ego").is_err());
        let bus = TWO.find("bus").unwrap() + 1;
        assert!(prepare_rename(&db, file, bus).unwrap_err().contains("read-only"));
    }

    #[test]
    fn uses_of_a_vocabulary_name_alias_or_not() {
        let text = "scenario demo {\n  actor a: bus {\n  }\n  actor b: coach {\n  }\n}\n";
        let (db, file) = testing::file(text);
        let bus = text.find("bus").unwrap();
        // `coach` is an alias of `bus` (or another type): either way the search is by entry
        let found = references(&db, file, bus, false);
        assert!(found.iter().any(|l| l.span.start == bus));
        let (db, file) = testing::file(TWO);
        let found = references(&db, file, TWO.find("bus").unwrap(), false);
        assert_eq!(found.len(), 2, "both buses");
        let with = references(&db, file, TWO.find("bus").unwrap(), true);
        assert_eq!(with.len(), 3, "and the declaration");
    }

    #[test]
    fn a_used_local_module_is_a_definition() {
        struct Fs;
        impl tad_db::FileSystem for Fs {
            fn read(&self, path: &std::path::Path) -> Option<String> {
                (path == std::path::Path::new("/fixture/mine.tad"))
                    .then(|| "weather glum {\n  cloudiness: 90\n}\n".to_string())
            }
        }
        let text = "use mine\nscenario demo {\n  environment {\n    weather: glum\n  }\n}\n";
        let mut db = Database::new(tad_check::Options::default());
        let file = db.set_source("/fixture/scenario.tad".into(), text.into(), crate::Language::Tad, &Fs);
        let found = definition(&db, file, text.find("glum").unwrap() + 1);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].file.path(&db), std::path::Path::new("/fixture/mine.tad"));
        let module = definition(&db, file, 5);
        assert_eq!(module[0].file, found[0].file);
        for offset in 0..text.len() + 3 {
            let _ =
                (definition(&db, file, offset), references(&db, file, offset, true), prepare_rename(&db, file, offset));
        }
    }
}
