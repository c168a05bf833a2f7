//! What is at an offset: the one place that maps a position to a thing of the language,
//! read from the lowered model of `tad_db::analyze` (so it works alike on TAD and on YAML
//! answers, whose model spans point into the YAML) and, for `use` paths, from the
//! concrete tree.

use tad_syntax::model::{Attr, Known, Module, Val};
use tad_syntax::schema::{self, FieldDef, SectionDef, ValueType};

use crate::{Database, SourceFile, Span};

/// A thing of the language under the cursor, with the span of its text.
#[derive(Clone, Debug, PartialEq)]
pub enum At {
    /// A section's name (`road`).
    Section { def: &'static SectionDef, span: Span },
    /// A field's key; `section` is the section, `actor` or the declaration kind.
    Field { def: &'static FieldDef, section: String, span: Span },
    /// A vocabulary name in a value, an actor group's type, or a declaration's name.
    Name { kind: String, name: String, span: Span, declared: bool },
    /// A word of a closed set (`left` in a relation's `lateral`).
    Word { field: &'static FieldDef, word: String, span: Span },
    /// A quantity (`38 km/h`) or a range.
    Quantity { field: &'static FieldDef, value: Val, span: Span },
    /// An actor group's name in its header; its index in the scenario.
    Group { index: usize, span: Span },
    /// The reference of a position (`ego`, a group's name).
    Reference { name: String, span: Span },
    /// A `use`d module's path.
    Module { name: String, span: Span },
    /// A declaration's kind (`weather` in `weather clear`).
    DeclarationKind { def: &'static SectionDef, span: Span },
}

impl At {
    pub fn span(&self) -> Span {
        match self {
            At::Section { span, .. }
            | At::Field { span, .. }
            | At::Name { span, .. }
            | At::Word { span, .. }
            | At::Quantity { span, .. }
            | At::Group { span, .. }
            | At::Reference { span, .. }
            | At::Module { span, .. }
            | At::DeclarationKind { span, .. } => *span,
        }
    }
}

/// Whether `span` holds `offset` (its end included: a cursor right after a word is on it).
fn on(span: Span, offset: usize) -> bool {
    span.start <= offset && offset <= span.end && !(span.is_empty() && span.start == 0 && offset > 0)
}

pub fn at(db: &Database, file: SourceFile, offset: usize) -> Option<At> {
    let text = file.text(db);
    let offset = crate::clamp(text, offset);
    let module = &tad_db::analyze(db, file).module;
    in_module(module, offset).or_else(|| in_uses(text, offset))
}

fn in_module(module: &Module, offset: usize) -> Option<At> {
    for declaration in &module.declarations {
        if !on(declaration.span, offset) {
            continue;
        }
        if on(declaration.name.span, offset) {
            return Some(At::Name {
                kind: declaration.def.name.to_string(),
                name: declaration.name.text.clone(),
                span: declaration.name.span,
                declared: true,
            });
        }
        for attr in &declaration.attrs {
            if let Some(found) = in_attr(attr, declaration.def.name, offset) {
                return Some(found);
            }
        }
        // the kind: from the declaration's start to its name
        if offset < declaration.name.span.start {
            let end = declaration.span.start + declaration.def.name.len();
            return Some(At::DeclarationKind { def: declaration.def, span: Span::new(declaration.span.start, end) });
        }
    }
    let scenario = module.scenario.as_ref()?;
    for section in &scenario.sections {
        if on(section.name_span, offset) {
            return Some(At::Section { def: section.def, span: section.name_span });
        }
        if !on(section.span, offset) {
            continue;
        }
        for attr in &section.attrs {
            if let Some(found) = in_attr(attr, section.def.name, offset) {
                return Some(found);
            }
        }
    }
    for (index, group) in scenario.actors.iter().enumerate() {
        if on(group.name.span, offset) {
            return Some(At::Group { index, span: group.name.span });
        }
        if on(group.kind.span, offset)
            && let Known::Given(kind) = &group.kind.value
        {
            return Some(At::Name {
                kind: "actor_type".into(),
                name: kind.name.clone(),
                span: kind.span,
                declared: false,
            });
        }
        if !on(group.span, offset) {
            continue;
        }
        for attr in &group.attrs {
            if let Some(found) = in_attr(attr, "actor", offset) {
                return Some(found);
            }
        }
    }
    None
}

fn in_attr(attr: &Attr, section: &str, offset: usize) -> Option<At> {
    if on(attr.key_span, offset) {
        return Some(At::Field { def: attr.def, section: section.to_string(), span: attr.key_span });
    }
    if !on(attr.value_span, offset) {
        return None;
    }
    let Known::Given(value) = &attr.value else { return None };
    match value {
        Val::Position(position) => {
            if on(position.relation.span, offset) {
                return Some(At::Name {
                    kind: "relation".into(),
                    name: position.relation.name.clone(),
                    span: position.relation.span,
                    declared: false,
                });
            }
            if on(position.reference.span, offset) {
                return Some(At::Reference { name: position.reference.name.clone(), span: position.reference.span });
            }
            None
        }
        Val::Quantity(_) | Val::Range(..) => {
            Some(At::Quantity { field: attr.def, value: value.clone(), span: attr.value_span })
        }
        Val::Symbol(_) | Val::Symbols(_) | Val::Choice(_) => {
            let symbols: Vec<&tad_syntax::model::Symbol> = match value {
                Val::Symbols(list) => list.iter().collect(),
                _ => value.names(),
            };
            let symbol = symbols.into_iter().find(|s| on(s.span, offset))?;
            match (attr.def.ty, attr.def.vocabulary) {
                (ValueType::Choice(_), _) => {
                    Some(At::Word { field: attr.def, word: symbol.name.clone(), span: symbol.span })
                }
                (_, Some(kind)) => Some(At::Name {
                    kind: kind.to_string(),
                    name: symbol.name.clone(),
                    span: symbol.span,
                    declared: false,
                }),
                _ => None,
            }
        }
        _ => None,
    }
}

/// A `use` path: from the concrete tree of the cursor's line (a `use` is one line; the
/// model keeps no paths' spans).
fn in_uses(text: &str, offset: usize) -> Option<At> {
    let start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let line = &text[start..end];
    if !line.trim_start().starts_with("use") {
        return None;
    }
    let parsed = tad_syntax::parse(line);
    parsed.file.items.iter().find_map(|item| match item {
        tad_syntax::cst::Item::Use(u) if on(u.span, offset - start) => {
            let first = u.path.first()?;
            let last = u.path.last()?;
            let name = u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".");
            let span = first.span.to(last.span);
            Some(At::Module { name, span: Span::new(span.start + start, span.end + start) })
        }
        _ => None,
    })
}

/// The section or declaration kind a field key belongs to, for messages.
pub fn owner(section: &str) -> Option<&'static SectionDef> {
    schema::section(section)
        .or_else(|| schema::declaration(section))
        .or_else(|| (section == "actor").then_some(&schema::ACTOR))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    fn at_cursor(text: &str) -> Option<At> {
        let (db, file, offset) = testing::cursor(text);
        at(&db, file, offset)
    }

    #[test]
    fn names_fields_groups_and_references() {
        let text = "scenario demo {\n  environment {\n    weather: sun$0ny\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { kind, name, .. }) if kind == "weather" && name == "sunny"));
        let text = "scenario demo {\n  environment {\n    wea$0ther: clear\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Field { def, .. }) if def.name == "weather"));
        let text = "scenario demo {\n  ro$0ad {\n    lanes: 2\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Section { def, .. }) if def.name == "road"));
        let text = "scenario demo {\n  actor a$0b: 2 taxi {\n    position: front of ego\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Group { index: 0, .. })));
        let text = "scenario demo {\n  actor ab: 2 ta$0xi {\n    position: front of ego\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { kind, .. }) if kind == "actor_type"));
        let text = "scenario demo {\n  actor ab: 2 taxi {\n    position: front of e$0go\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Reference { name, .. }) if name == "ego"));
        let text = "scenario demo {\n  actor ab: 2 taxi {\n    position: fr$0ont of ego\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { kind, .. }) if kind == "relation"));
        let text = "scenario demo {\n  ego {\n    speed: 3$00 mph\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Quantity { .. })));
        assert!(matches!(at_cursor("use national_p$0ark\n"), Some(At::Module { name, .. }) if name == "national_park"));
        assert!(matches!(at_cursor("weather gl$0um {\n  cloudiness: 90\n}\n"), Some(At::Name { declared: true, .. })));
    }

    #[test]
    fn nothing_in_broken_text_or_past_the_end() {
        let (db, file) = testing::file("scenario demo { road { lanes: ");
        for offset in 0..40 {
            let _ = at(&db, file, offset);
        }
        let (db, file) = testing::file("// é🚗\nscenario demo {\n  environment { weather: clear }\n}\n");
        for offset in 0..80 {
            let _ = at(&db, file, offset);
        }
    }

    #[test]
    fn yaml_answers_have_spans_too() {
        let yaml = "Scenario:\n  Environment:\n    Weather: sunny\n    Time: day\n";
        let (db, file) = testing::with_language(yaml, crate::Language::Yaml);
        let offset = yaml.find("sunny").unwrap() + 2;
        assert!(
            matches!(at(&db, file, offset), Some(At::Name { kind, .. }) if kind == "weather"),
            "{:?}",
            at(&db, file, offset)
        );
    }
}
