//! Go to definition, find references, rename.
//!
//! Definitions come from where the vocabulary says a name is declared (`Entry::file` and
//! the name's span: a stdlib file or a used local module) and from the scenario itself
//! (a group's header, the ego section). References are searched in the document's model:
//! a group's header and every `X of NAME` naming it; a vocabulary name's uses, alias or
//! not, compared by the declaration they resolve to. Only groups can be renamed: names of
//! the vocabulary are declarations shared by every scenario, and the stdlib's are
//! read-only. A new name must lex as one plain name (so no keyword, no unit).

use tad_check::{Entry, Groups, Target, Vocabulary};
use tad_syntax::lexer::Token;
use tad_syntax::model::{Attr, Known, Module, Symbol, Val};

use crate::locate::{At, at};
use crate::{Database, Edit, Location, SourceFile, Span, WorkspaceEdit};

fn group_index(module: &Module, name: &str) -> Option<usize> {
    module.scenario.as_ref()?.actors.iter().position(|g| g.name.text == name)
}

/// Where an entry is declared.
fn declared(db: &Database, entry: &Entry) -> Option<Location> {
    let at = entry.location();
    Some(Location { file: db.file(at.file)?, span: at.span })
}

/// The vocabulary entry a position's reference resolves to (`ego`, a road element).
fn reference_entry<'v>(vocabulary: &'v Vocabulary, name: &str, target: Option<&Target>) -> Option<&'v Entry> {
    match target? {
        Target::Ego => vocabulary.get("reference", name),
        Target::RoadElement(_) => vocabulary.get("road_element", name),
        Target::Group(_) => None,
    }
}

pub fn definition(db: &Database, file: SourceFile, offset: usize) -> Vec<Location> {
    let Some(found) = at(db, file, offset) else { return Vec::new() };
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    let here = |span| vec![Location { file, span }];
    match found {
        At::Reference { target: Some(Target::Group(i)), .. } => {
            module.scenario.as_ref().and_then(|s| s.actors.get(i)).map_or_else(Vec::new, |g| here(g.name.span))
        }
        At::Reference { name, target, .. } => {
            // `ego`: the scenario's ego section when it has one, else its declaration
            let ego = module.scenario.as_ref().and_then(|s| s.section("ego")).map(|s| s.name_span);
            match (&target, ego) {
                (Some(Target::Ego), Some(span)) => here(span),
                _ => reference_entry(vocabulary, &name, target.as_ref())
                    .and_then(|e| declared(db, e))
                    .into_iter()
                    .collect(),
            }
        }
        At::Name { entry: Some(entry), .. } => declared(db, &entry).into_iter().collect(),
        At::Group { span, .. } => here(span),
        At::Module { name, .. } => file
            .imports(db)
            .modules
            .get(&name)
            .copied()
            .or_else(|| db.standard_module(&name))
            .map(|m| Location { file: m, span: Span::new(0, 0) })
            .into_iter()
            .collect(),
        _ => Vec::new(),
    }
}

/// Every symbol of the module with the vocabulary kind it is a name of (position
/// references excepted: they may name groups).
pub(crate) fn symbols(module: &Module) -> Vec<(&str, &Symbol)> {
    let mut out = Vec::new();
    fn from_attr<'m>(attr: &'m Attr, out: &mut Vec<(&'static str, &'m Symbol)>) {
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

/// The position references of the scenario, with what each names.
fn references_in(module: &Module, vocabulary: &Vocabulary) -> Vec<(Symbol, Option<Target>)> {
    let Some(scenario) = &module.scenario else { return Vec::new() };
    let groups = Groups::new(scenario);
    scenario
        .actors
        .iter()
        .flat_map(|g| &g.attrs)
        .filter_map(|a| match &a.value {
            Known::Given(Val::Position(p)) => {
                Some((p.reference.clone(), tad_check::target(&groups, vocabulary, &p.reference.name)))
            }
            _ => None,
        })
        .collect()
}

/// The spans of group `index`'s header name and of every reference to it.
fn group_spans(module: &Module, vocabulary: &Vocabulary, index: usize) -> Vec<Span> {
    let Some(group) = module.scenario.as_ref().and_then(|s| s.actors.get(index)) else { return Vec::new() };
    let mut out = vec![group.name.span];
    out.extend(
        references_in(module, vocabulary)
            .into_iter()
            .filter(|(_, t)| *t == Some(Target::Group(index)))
            .map(|(s, _)| s.span),
    );
    out.sort_by_key(|s| s.start);
    out
}

/// The group a cursor names: on its header or on a reference to it.
fn group_at(found: &At) -> Option<usize> {
    match found {
        At::Group { index, .. } | At::Reference { target: Some(Target::Group(index)), .. } => Some(*index),
        _ => None,
    }
}

pub fn references(db: &Database, file: SourceFile, offset: usize, include_declaration: bool) -> Vec<Location> {
    let Some(found) = at(db, file, offset) else { return Vec::new() };
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    if let Some(index) = group_at(&found) {
        let header = module.scenario.as_ref().and_then(|s| s.actors.get(index)).map(|g| g.name.span);
        return group_spans(module, vocabulary, index)
            .into_iter()
            .filter(|s| include_declaration || Some(*s) != header)
            .map(|span| Location { file, span })
            .collect();
    }
    let entry = match &found {
        At::Name { entry: Some(entry), .. } => entry.as_ref(),
        At::Reference { name, target, .. } => match reference_entry(vocabulary, name, target.as_ref()) {
            Some(entry) => entry,
            None => return Vec::new(),
        },
        _ => return Vec::new(),
    };
    let kind = entry.declaration.def.name;
    let same = |e: Option<&Entry>| e.is_some_and(|e| e.location() == entry.location());
    let mut spans: Vec<Span> = symbols(module)
        .into_iter()
        .filter(|(k, s)| *k == kind && same(vocabulary.get(k, &s.name)))
        .map(|(_, s)| s.span)
        .collect();
    spans.extend(
        references_in(module, vocabulary)
            .into_iter()
            .filter(|(s, t)| same(reference_entry(vocabulary, &s.name, t.as_ref())))
            .map(|(s, _)| s.span),
    );
    spans.sort_by_key(|s| s.start);
    let mut out: Vec<Location> = spans.into_iter().map(|span| Location { file, span }).collect();
    if include_declaration && let Some(at) = declared(db, entry) {
        out.insert(0, at);
    }
    out
}

/// The span of the name a rename at `offset` would change (a group's name or a reference
/// to it), or why there is nothing to rename there.
pub fn prepare_rename(db: &Database, file: SourceFile, offset: usize) -> Result<Span, String> {
    let found = at(db, file, offset);
    let read_only = |entry: &Entry| db.file(entry.file).is_some_and(|f| f.path(db).starts_with(tad_db::STDLIB_PREFIX));
    match found {
        Some(At::Group { span, .. } | At::Reference { target: Some(Target::Group(_)), span, .. }) => Ok(span),
        Some(At::Reference { name, target: Some(Target::Ego), .. }) => {
            Err(format!("`{name}` is the ego vehicle, a name of the language: only actor groups can be renamed"))
        }
        Some(At::Reference { name, target: None, .. }) => {
            Err(format!("`{name}` names no actor group: only actor groups can be renamed"))
        }
        Some(At::Name { name, entry: Some(entry), .. }) if read_only(&entry) => {
            Err(format!("`{name}` is declared in the standard library (module `{}`), which is read-only", entry.module))
        }
        Some(At::Reference { name, target: Some(Target::RoadElement(_)), .. }) => {
            Err(format!("`{name}` is a road element of the standard library, which is read-only"))
        }
        Some(At::Name { name, kind, .. }) => Err(format!(
            "only actor groups can be renamed; `{name}` is a {} name of the vocabulary",
            kind.replace('_', " ")
        )),
        _ => Err("only actor groups can be renamed: put the cursor on a group's name or a reference to it".into()),
    }
}

/// Why `name` cannot name an actor group, if it cannot: it must lex as one plain name.
fn invalid_name(name: &str) -> Option<String> {
    let tokens = tad_syntax::lexer::lex(name).tokens;
    match tokens.as_slice() {
        [(0, Token::Ident | Token::DeclKind | Token::Head, end)] if *end == name.len() => None,
        [(0, Token::Unit, end)] if *end == name.len() => Some(format!("`{name}` is a unit")),
        [(0, token, end)] if *end == name.len() && tad_syntax::lexer::KEYWORDS.iter().any(|(_, t)| t == token) => {
            Some(format!("`{name}` is a keyword"))
        }
        _ => Some(format!("`{name}` is not a name: letters, digits and `_`, not starting with a digit")),
    }
}

pub fn rename(db: &Database, file: SourceFile, offset: usize, new_name: &str) -> Result<WorkspaceEdit, String> {
    prepare_rename(db, file, offset)?;
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    let found = at(db, file, offset).ok_or("nothing to rename here")?;
    let index = group_at(&found).ok_or("only actor groups can be renamed")?;
    let old =
        module.scenario.as_ref().and_then(|s| s.actors.get(index)).map(|g| g.name.text.clone()).unwrap_or_default();
    if let Some(why) = invalid_name(new_name) {
        return Err(format!("cannot rename `{old}` to `{new_name}`: {why}"));
    }
    if vocabulary.get("reference", new_name).is_some() {
        return Err(format!("cannot rename `{old}` to `{new_name}`: `{new_name}` is the ego vehicle"));
    }
    if let Some(element) = vocabulary.get("road_element", new_name) {
        return Err(format!(
            "cannot rename `{old}` to `{new_name}`: `{new_name}` names the road element `{}`",
            element.name
        ));
    }
    if new_name != old && group_index(module, new_name).is_some() {
        return Err(format!("cannot rename `{old}` to `{new_name}`: an actor group is already called `{new_name}`"));
    }
    let spans = group_spans(module, vocabulary, index);
    // a YAML answer's group may have no written name of its own to replace
    let text = file.text(db);
    if spans.iter().any(|s| text.get(s.start..s.end) != Some(old.as_str())) {
        return Err(format!("`{old}` is not written as such everywhere in this file; rename it by hand"));
    }
    let edits = spans.into_iter().map(|span| Edit { span, text: new_name.to_string() }).collect();
    Ok(vec![(file, edits)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    const TWO: &str = "scenario demo {\n  ego { lane: 1 }\n  actor lead: car {\n    position: front of ego\n  }\n  actor tail: bus {\n    position: behind of lead\n  }\n  actor side: bus {\n    position: left of lead\n  }\n}\n";

    fn texts(db: &Database, found: &[Location]) -> Vec<String> {
        found.iter().map(|l| l.file.text(db)[l.span.start..l.span.end].to_string()).collect()
    }

    #[test]
    fn references_go_to_their_group_and_names_to_the_stdlib() {
        let offset = TWO.find("behind of lead").unwrap() + 11;
        let (db, file) = testing::file(TWO);
        let lead = TWO.find("lead").unwrap();
        assert_eq!(definition(&db, file, offset), vec![Location { file, span: Span::new(lead, lead + 4) }]);
        // an actor type, and the same through an alias
        for (text, name) in [(TWO, "bus"), ("scenario demo {\n  actor a: coach {\n  }\n}\n", "coach")] {
            let (db, file) = testing::file(text);
            let found = definition(&db, file, text.find(name).unwrap() + 1);
            assert_eq!(found.len(), 1);
            let core = found[0].file;
            assert_eq!(core, db.standard_module("core").unwrap());
            let line = &core.text(&db)[found[0].span.start - "actor_type ".len()..];
            assert!(line.starts_with("actor_type bus"), "{}", &line[..30]);
        }
        // `ego` goes to the ego section, or to its declaration without one
        let found = definition(&db, file, TWO.find("of ego").unwrap() + 4);
        assert_eq!(found[0].span.start, TWO.find("ego {").unwrap());
        let text = "scenario demo {\n  actor a: car {\n    position: front of ego_vehicle\n  }\n}\n";
        let (db2, file2) = testing::file(text);
        let found = definition(&db2, file2, text.find("ego_vehicle").unwrap());
        assert_eq!(texts(&db2, &found), vec!["ego"]);
        assert!(found[0].file.path(&db2).starts_with(tad_db::STDLIB_PREFIX));
        // a relation and a road element
        let text = "scenario demo {\n  actor a: car {\n    position: front_left of junction\n  }\n}\n";
        let (db3, file3) = testing::file(text);
        assert_eq!(texts(&db3, &definition(&db3, file3, text.find("front_left").unwrap())), vec!["left_front"]);
        assert_eq!(texts(&db3, &definition(&db3, file3, text.find("junction").unwrap())), vec!["intersection"]);
        // a standard module
        let text = "use national_park\nscenario demo {}\n";
        let (db4, file4) = testing::file(text);
        let found = definition(&db4, file4, 6);
        assert_eq!(
            found,
            vec![Location { file: db4.standard_module("national_park").unwrap(), span: Span::new(0, 0) }]
        );
    }

    #[test]
    fn references_and_rename_of_a_group() {
        let (db, file) = testing::file(TWO);
        let at = TWO.find("lead").unwrap() + 1;
        assert_eq!(references(&db, file, at, true).len(), 3);
        assert_eq!(references(&db, file, at, false).len(), 2);
        // from a reference too
        let from = TWO.find("left of lead").unwrap() + 9;
        assert_eq!(references(&db, file, from, true), references(&db, file, at, true));
        assert_eq!(prepare_rename(&db, file, from), Ok(Span::new(from - 1, from + 3)));
        let edit = rename(&db, file, from, "leader").unwrap();
        let renamed = crate::actions::apply(TWO, &edit[0].1);
        assert!(
            renamed.contains("actor leader: car")
                && renamed.contains("behind of leader")
                && renamed.contains("left of leader"),
            "{renamed}"
        );
        assert!(rename(&db, file, at, "tail").unwrap_err().contains("already called `tail`"));
        assert!(rename(&db, file, at, "9x").unwrap_err().contains("not a name"));
        assert!(rename(&db, file, at, "a b").unwrap_err().contains("not a name"));
        assert!(rename(&db, file, at, "").unwrap_err().contains("not a name"));
        assert!(rename(&db, file, at, "of").unwrap_err().contains("keyword"));
        assert!(rename(&db, file, at, "mph").unwrap_err().contains("unit"));
        assert!(rename(&db, file, at, "s").unwrap_err().contains("unit"));
        assert!(rename(&db, file, at, "ego").unwrap_err().contains("ego vehicle"));
        assert!(rename(&db, file, at, "intersection").unwrap_err().contains("road element"));
        assert!(rename(&db, file, at, "lead").is_ok(), "its own name");
        let bus = TWO.find("bus").unwrap() + 1;
        assert!(prepare_rename(&db, file, bus).unwrap_err().contains("read-only"));
        assert!(prepare_rename(&db, file, TWO.find("of ego").unwrap() + 4).unwrap_err().contains("ego vehicle"));
        assert!(prepare_rename(&db, file, 2).unwrap_err().contains("only actor groups"));
    }

    #[test]
    fn uses_of_a_vocabulary_name_alias_or_not() {
        let text = "scenario demo {\n  actor a: bus {\n  }\n  actor b: coach {\n  }\n  actor c: car {\n  }\n}\n";
        let (db, file) = testing::file(text);
        let found = references(&db, file, text.find("bus").unwrap(), false);
        assert_eq!(texts(&db, &found), vec!["bus", "coach"]);
        let (db, file) = testing::file(TWO);
        let found = references(&db, file, TWO.find("bus").unwrap(), false);
        assert_eq!(found.len(), 2, "both buses");
        let with = references(&db, file, TWO.find("bus").unwrap(), true);
        assert_eq!(with.len(), 3, "and the declaration");
        assert!(with[0].file.path(&db).starts_with(tad_db::STDLIB_PREFIX));
        // `ego`, written two ways
        let text = "scenario demo {\n  actor a: car { position: front of ego }\n  actor b: car { position: behind of ego_car }\n}\n";
        let (db, file) = testing::file(text);
        assert_eq!(texts(&db, &references(&db, file, text.find("ego }").unwrap(), false)), vec!["ego", "ego_car"]);
    }

    #[test]
    fn a_used_local_module_is_a_definition() {
        struct Fs;
        impl tad_db::FileSystem for Fs {
            fn read(&self, path: &std::path::Path) -> Option<String> {
                (path == std::path::Path::new("/fixture/mine.tad"))
                    .then(|| "weather glum {\n  aliases: [mirk]\n  cloudiness: 90\n}\n".to_string())
            }
        }
        let text = "use mine\nscenario demo {\n  environment {\n    weather: glum | mirk\n  }\n}\n";
        let mut db = Database::new(tad_check::Options::default());
        let file = db.set_source("/fixture/scenario.tad".into(), text.into(), crate::Language::Tad, &Fs);
        let found = definition(&db, file, text.find("glum").unwrap() + 1);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].file.path(&db), std::path::Path::new("/fixture/mine.tad"));
        assert_eq!(found[0].span, Span::new(8, 12));
        assert_eq!(definition(&db, file, text.find("mirk").unwrap()), found, "the alias too");
        let module = definition(&db, file, 5);
        assert_eq!(module, vec![Location { file: found[0].file, span: Span::new(0, 0) }]);
        let uses = references(&db, file, text.find("mirk").unwrap(), true);
        assert_eq!(texts(&db, &uses), vec!["glum", "glum", "mirk"]);
        let why = prepare_rename(&db, file, text.find("glum").unwrap()).unwrap_err();
        assert!(why.contains("only actor groups") && !why.contains("read-only"), "{why}");
        for offset in 0..text.len() + 3 {
            let _ =
                (definition(&db, file, offset), references(&db, file, offset, true), prepare_rename(&db, file, offset));
        }
    }

    /// Every position-based feature at every offset of the examples and of YAML answers:
    /// no panic, and every location's span is inside its file at character boundaries.
    #[test]
    fn every_offset_of_the_examples() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let mut files = Vec::new();
        for dir in ["examples/safety", "examples/regions", "tests/yaml/paper", "tests/yaml/answers"] {
            let Ok(entries) = std::fs::read_dir(root.join(dir)) else { continue };
            let paths = entries.flatten().map(|e| e.path());
            files.extend(paths.filter(|p| p.extension().is_some_and(|e| e == "tad" || e == "yaml")));
        }
        assert!(files.len() > 10, "{files:?}");
        for path in files {
            let text = std::fs::read_to_string(&path).unwrap();
            let language = tad_db::Language::guess(&path, &text);
            let (db, file) = testing::with_language(&text, language);
            let valid = |l: &Location| {
                let t = l.file.text(&db);
                l.span.start <= l.span.end && t.get(l.span.start..l.span.end).is_some()
            };
            for offset in (0..=text.len()).filter(|o| text.is_char_boundary(*o)) {
                assert!(definition(&db, file, offset).iter().all(valid), "{}:{offset}", path.display());
                assert!(references(&db, file, offset, true).iter().all(valid), "{}:{offset}", path.display());
                if let Ok(span) = prepare_rename(&db, file, offset) {
                    assert!(text.get(span.start..span.end).is_some());
                    let _ = rename(&db, file, offset, "renamed_group");
                }
                let _ = crate::hover::hover(&db, file, offset);
            }
            let _ = crate::inlay::inlay_hints(&db, file, Span::new(0, text.len()));
        }
    }

    #[test]
    fn non_ascii_yaml_and_broken_documents() {
        let text = "// voilà 🚗\nscenario demo {\n  source { description: \"çà 🚦\" }\n  actor lead: car {}\n  actor b: car {\n    position: behind of lead\n  }\n}\n";
        let (db, file) = testing::file(text);
        let at = text.rfind("lead").unwrap();
        assert_eq!(texts(&db, &definition(&db, file, at)), vec!["lead"]);
        let renamed =
            crate::actions::apply(text, &rename(&db, file, at, "première").map(|e| e[0].1.clone()).unwrap_or_default());
        assert_eq!(renamed, text, "a non-ASCII name is not a TAD name");
        let edit = rename(&db, file, at, "first").unwrap();
        assert!(crate::actions::apply(text, &edit[0].1).contains("behind of first"));

        let yaml = "actors:\n  lead_car:\n    type: sedan\n  other:\n    type: car\n    position_relation: behind\n    position_target: lead_car\n";
        let (db, file) = testing::with_language(yaml, crate::Language::Yaml);
        let found = definition(&db, file, yaml.rfind("lead_car").unwrap() + 2);
        assert_eq!(found, vec![Location { file, span: Span::new(10, 18) }]);
        let found = definition(&db, file, yaml.find("sedan").unwrap());
        assert!(found[0].file.path(&db).starts_with(tad_db::STDLIB_PREFIX));
        let edit = rename(&db, file, 11, "leader").unwrap();
        assert_eq!(edit[0].1.len(), 2);

        for broken in ["scenario demo { actor a: car { position: front of", "actor : { }", "use .\n", "é"] {
            let (db, file) = testing::file(broken);
            for offset in 0..broken.len() + 3 {
                let _ = (
                    definition(&db, file, offset),
                    references(&db, file, offset, true),
                    rename(&db, file, offset, "x"),
                );
            }
            assert!(definition(&db, file, usize::MAX).len() <= 1);
        }
    }
}
