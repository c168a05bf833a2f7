//! What is at an offset: the one place that maps a position to a thing of the language,
//! shared by hover, navigation and rename.
//!
//! It reads the lowered model of `tad_db::analyze` (so it works alike on TAD files, on
//! stdlib modules and on YAML answers, whose model spans point into the YAML) and
//! resolves what it finds with the checker's own rules: names through
//! `Vocabulary::lookup` (aliases and plurals included), position references through
//! `tad_check::target` (a group, then `ego`, then a road element). A unit has no span of
//! its own in the model: it is the end of its quantity's text.

use tad_check::{Entry, Groups, Target, Vocabulary};
use tad_syntax::model::{Attr, Known, Module, Quantity, Symbol, Val};
use tad_syntax::schema::{self, FieldDef, SectionDef, Unit, ValueType};

use crate::{Database, SourceFile, Span};

/// A thing of the language under the cursor, with the span of its text.
#[derive(Clone, Debug, PartialEq)]
pub enum At {
    /// A section's name (`road`).
    Section { def: &'static SectionDef, span: Span },
    /// A field's key; `section` is the section, `actor` or the declaration kind.
    Field { def: &'static FieldDef, section: String, span: Span },
    /// A vocabulary name: in a value, an actor group's type, a declaration's name or one
    /// of its `aliases`. `entry` is what it resolves to in the file's vocabulary (the
    /// canonical name differs from `name` for an alias or a plural).
    Name { kind: String, name: String, span: Span, declared: bool, entry: Option<Box<Entry>> },
    /// A word of a closed set (`left` in a relation's `lateral`).
    Word { field: &'static FieldDef, word: String, span: Span },
    /// The number(s) of a quantity (`38` in `38 km/h`) or a range.
    Quantity { field: &'static FieldDef, value: Val, span: Span },
    /// The unit of a quantity (`km/h`).
    Unit { unit: Unit, span: Span },
    /// An actor group's name in its header; its index in the scenario.
    Group { index: usize, span: Span },
    /// The reference of a position (`ego`, a group's name, a road element), and what it
    /// names (`None`: nothing).
    Reference { name: String, span: Span, target: Option<Target> },
    /// A `use`d module's path, or the module a region declares.
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
            | At::Unit { span, .. }
            | At::Group { span, .. }
            | At::Reference { span, .. }
            | At::Module { span, .. }
            | At::DeclarationKind { span, .. } => *span,
        }
    }

    /// Whether a vocabulary name is written as an alias (or a plural) of its entry.
    pub fn is_alias(&self) -> bool {
        matches!(self, At::Name { name, entry: Some(entry), .. } if entry.name != *name)
    }
}

/// Whether `span` holds `offset` (its end included: a cursor right after a word is on it).
/// An empty span at 0 is a placeholder (a YAML answer's missing value), never a hit.
fn on(span: Span, offset: usize) -> bool {
    span.start <= offset && offset <= span.end && !(span.is_empty() && span.start == 0)
}

/// What is at `offset` in `file` (clamped into its text).
pub fn at(db: &Database, file: SourceFile, offset: usize) -> Option<At> {
    let text = file.text(db);
    let offset = crate::clamp(text, offset);
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    Finder { text, vocabulary, offset }.module(module)
}

struct Finder<'a> {
    text: &'a str,
    vocabulary: &'a Vocabulary,
    offset: usize,
}

impl Finder<'_> {
    fn on(&self, span: Span) -> bool {
        on(span, self.offset)
    }

    fn name(&self, kind: &str, symbol: &Symbol, declared: bool) -> At {
        At::Name {
            kind: kind.to_string(),
            name: symbol.name.clone(),
            span: symbol.span,
            declared,
            entry: self.vocabulary.get(kind, &symbol.name).cloned().map(Box::new),
        }
    }

    fn module(&self, module: &Module) -> Option<At> {
        for u in &module.uses {
            if let (Some(first), Some(last)) = (u.path.first(), u.path.last())
                && self.on(u.span)
            {
                let name = u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".");
                return Some(At::Module { name, span: first.span.to(last.span) });
            }
        }
        for declaration in &module.declarations {
            if !self.on(declaration.span) {
                continue;
            }
            let kind = declaration.def.name;
            if self.on(declaration.name.span) {
                let symbol = Symbol { name: declaration.name.text.clone(), span: declaration.name.span };
                return Some(self.name(kind, &symbol, true));
            }
            for attr in &declaration.attrs {
                if let Some(found) = self.attr(attr, kind) {
                    return Some(found);
                }
            }
            // the kind: from the declaration's start to its name
            if self.offset < declaration.name.span.start {
                let end = (declaration.span.start + kind.len()).min(declaration.name.span.start);
                return Some(At::DeclarationKind {
                    def: declaration.def,
                    span: Span::new(declaration.span.start, end),
                });
            }
        }
        let scenario = module.scenario.as_ref()?;
        for section in &scenario.sections {
            if self.on(section.name_span) {
                return Some(At::Section { def: section.def, span: section.name_span });
            }
            if self.on(section.span)
                && let Some(found) = section.attrs.iter().find_map(|a| self.attr(a, section.def.name))
            {
                return Some(found);
            }
        }
        let groups = Groups::new(scenario);
        for (index, group) in scenario.actors.iter().enumerate() {
            if self.on(group.name.span) {
                return Some(At::Group { index, span: group.name.span });
            }
            if let Known::Given(kind) = &group.kind.value
                && self.on(kind.span)
            {
                return Some(self.name("actor_type", kind, false));
            }
            if !self.on(group.span) {
                continue;
            }
            for attr in &group.attrs {
                if let Known::Given(Val::Position(p)) = &attr.value
                    && self.on(p.reference.span)
                {
                    let target = tad_check::target(&groups, self.vocabulary, &p.reference.name);
                    return Some(At::Reference { name: p.reference.name.clone(), span: p.reference.span, target });
                }
                if let Some(found) = self.attr(attr, "actor") {
                    return Some(found);
                }
            }
        }
        None
    }

    /// In one attribute of `section` (a section's name, `actor` or a declaration kind).
    fn attr(&self, attr: &Attr, section: &str) -> Option<At> {
        if self.on(attr.key_span) {
            return Some(At::Field { def: attr.def, section: section.to_string(), span: attr.key_span });
        }
        if !self.on(attr.value_span) {
            return None;
        }
        let Known::Given(value) = &attr.value else { return None };
        let symbols: Vec<&Symbol> = match value {
            Val::Position(p) => {
                return self.on(p.relation.span).then(|| self.name("relation", &p.relation, false));
            }
            Val::Quantity(Quantity { unit, .. }) | Val::Range(_, Quantity { unit, .. }) => {
                return Some(match self.unit_span(attr.value_span, *unit) {
                    Some(span) if self.offset >= span.start => At::Unit { unit: *unit, span },
                    Some(span) => At::Quantity {
                        field: attr.def,
                        value: value.clone(),
                        span: Span::new(attr.value_span.start, self.number_end(attr.value_span.start, span.start)),
                    },
                    None => At::Quantity { field: attr.def, value: value.clone(), span: attr.value_span },
                });
            }
            Val::Symbols(list) => list.iter().collect(),
            _ => value.names(),
        };
        let symbol = symbols.into_iter().find(|s| self.on(s.span))?;
        match (attr.def.ty, attr.def.vocabulary) {
            (ValueType::Choice(_), _) => {
                Some(At::Word { field: attr.def, word: symbol.name.clone(), span: symbol.span })
            }
            (_, Some(kind)) => Some(self.name(kind, symbol, false)),
            // a declaration's other spellings are names of its kind
            _ if attr.def.name == "aliases" && schema::declaration(section).is_some() => {
                Some(self.name(section, symbol, true))
            }
            // the standard module with a region's vocabulary
            _ if attr.def.name == "module" && section == "region" => {
                Some(At::Module { name: symbol.name.clone(), span: symbol.span })
            }
            _ => None,
        }
    }

    /// The unit's span at the end of a quantity's text (quotes and spaces around a YAML
    /// value skipped); `None` when the text does not end with it (a YAML answer may have
    /// written another spelling).
    fn unit_span(&self, value: Span, unit: Unit) -> Option<Span> {
        let written = self.text.get(value.start..value.end)?;
        let trimmed = written.trim_end_matches(['"', '\'', ' ', '\t']);
        let end = value.start + trimmed.len();
        let start = end.checked_sub(unit.as_str().len())?;
        (trimmed.ends_with(unit.as_str()) && start > value.start).then(|| Span::new(start, end))
    }

    /// The end of the number(s) before a unit at `unit`: the spaces between them trimmed.
    fn number_end(&self, start: usize, unit: usize) -> usize {
        self.text.get(start..unit).map_or(unit, |n| start + n.trim_end().len())
    }
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

    /// The text under what is found at the cursor.
    fn under(text: &str) -> String {
        let clean = text.replacen("$0", "", 1);
        at_cursor(text).map(|a| clean[a.span().start..a.span().end].to_string()).unwrap_or_default()
    }

    #[test]
    fn names_fields_sections_and_words() {
        let text = "scenario demo {\n  environment {\n    weather: sun$0ny\n  }\n}\n";
        let found = at_cursor(text).unwrap();
        assert!(found.is_alias());
        let At::Name { kind, name, entry, declared: false, .. } = found else { panic!("{found:?}") };
        assert_eq!((kind.as_str(), name.as_str(), entry.unwrap().name.as_str()), ("weather", "sunny", "clear"));
        assert_eq!(under(text), "sunny");

        let text = "scenario demo {\n  environment {\n    wea$0ther: clear\n  }\n}\n";
        assert!(
            matches!(at_cursor(text), Some(At::Field { def, section, .. }) if def.name == "weather" && section == "environment")
        );
        assert_eq!(under(text), "weather");
        let text = "scenario demo {\n  ro$0ad {\n    lanes: 2\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Section { def, .. }) if def.name == "road"));
        let text = "scenario demo {\n  road {\n    signs: [stop_sign, yi$0eld_sign]\n  }\n}\n";
        assert!(
            matches!(at_cursor(text), Some(At::Name { kind, name, .. }) if kind == "traffic_sign" && name == "yield_sign")
        );
        let text = "relation left_front {\n  lateral: le$0ft\n  longitudinal: front\n}\n";
        assert!(
            matches!(at_cursor(text), Some(At::Word { word, field, .. }) if word == "left" && field.name == "lateral")
        );
    }

    #[test]
    fn groups_types_relations_and_references() {
        let text = "scenario demo {\n  actor a$0b: 2 taxi {\n    position: front of ego\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Group { index: 0, .. })));
        assert_eq!(under(text), "ab");
        let text = "scenario demo {\n  actor ab: 2 ta$0xi {\n    position: front of ego\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { kind, entry: Some(_), .. }) if kind == "actor_type"));
        let text = "scenario demo {\n  actor crossing: 4 pedestrian$0s {\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { entry: Some(e), .. }) if e.name == "pedestrian"));
        let text = "scenario demo {\n  actor ab: 2 taxi {\n    position: front of e$0go\n  }\n}\n";
        assert_eq!(
            at_cursor(text).unwrap(),
            At::Reference {
                name: "ego".into(),
                span: Span::new(text.find("e$0go").unwrap(), text.find("e$0go").unwrap() + 3),
                target: Some(Target::Ego),
            }
        );
        let text = "scenario demo {\n  actor a: car { position: front of ego }\n  actor b: car {\n    position: behind of $0a\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Reference { target: Some(Target::Group(0)), .. })));
        let text = "scenario demo {\n  actor b: car {\n    position: front of junc$0tion\n  }\n}\n";
        assert!(
            matches!(at_cursor(text), Some(At::Reference { target: Some(Target::RoadElement(e)), .. }) if e == "intersection")
        );
        let text = "scenario demo {\n  actor b: car {\n    position: front of nob$0ody\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Reference { target: None, .. })));
        let text = "scenario demo {\n  actor ab: 2 taxi {\n    position: fr$0ont of ego\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { kind, .. }) if kind == "relation"));
    }

    #[test]
    fn numbers_and_their_units() {
        let text = "scenario demo {\n  ego {\n    speed: 3$00 mph\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Quantity { .. })));
        assert_eq!(under(text), "30");
        let text = "scenario demo {\n  ego {\n    speed: 30 mp$0h\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Unit { unit: Unit::MilesPerHour, .. })));
        assert_eq!(under(text), "mph");
        let text = "scenario demo {\n  actor a: car {\n    speed: 30..40 k$0m/h\n  }\n}\n";
        assert_eq!(under(text), "km/h");
        let text = "scenario demo {\n  actor a: car {\n    speed: 30..$040 km/h\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Quantity { value: Val::Range(..), .. })));
        assert_eq!(under(text), "30..40");
    }

    #[test]
    fn modules_and_declarations() {
        assert!(matches!(at_cursor("use national_p$0ark\n"), Some(At::Module { name, .. }) if name == "national_park"));
        assert_eq!(under("use national_p$0ark\nscenario demo {}\n"), "national_park");
        let text = "weather gl$0um {\n  cloudiness: 90\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { declared: true, entry: Some(_), .. })));
        let text = "weather glum {\n  aliases: [mi$0rk]\n}\n";
        assert!(
            matches!(at_cursor(text), Some(At::Name { declared: true, name, entry: Some(e), .. }) if name == "mirk" && e.name == "glum")
        );
        let text = "wea$0ther glum {\n  cloudiness: 90\n}\n";
        assert!(matches!(at_cursor(text), Some(At::DeclarationKind { def, .. }) if def.name == "weather"));
        assert_eq!(under(text), "weather");
        let text = "region somewhere {\n  module: national_pa$0rk\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Module { name, .. }) if name == "national_park"));
    }

    #[test]
    fn names_of_a_used_local_module() {
        struct Fs;
        impl tad_db::FileSystem for Fs {
            fn read(&self, path: &std::path::Path) -> Option<String> {
                (path == std::path::Path::new("/fixture/mine.tad"))
                    .then(|| "weather glum {\n  aliases: [mirk]\n}\n".to_string())
            }
        }
        let text = "use mine\nscenario demo {\n  environment {\n    weather: clear | mirk\n  }\n}\n";
        let mut db = Database::new(tad_check::Options::default());
        let file = db.set_source("/fixture/scenario.tad".into(), text.into(), crate::Language::Tad, &Fs);
        let found = at(&db, file, text.find("mirk").unwrap() + 1).unwrap();
        assert!(found.is_alias());
        let At::Name { entry: Some(entry), .. } = found else { panic!("{found:?}") };
        assert_eq!((entry.name.as_str(), entry.module.as_str()), ("glum", "mine"));
        assert_eq!(db.file(entry.file).unwrap().path(&db), std::path::Path::new("/fixture/mine.tad"));
        assert!(
            matches!(at(&db, file, 6), Some(At::Module { name, span }) if name == "mine" && span == Span::new(4, 8))
        );
    }

    #[test]
    fn stdlib_files_are_located_too() {
        let (db, _) = testing::file("");
        let core = db.standard_module("core").unwrap();
        let text = core.text(&db);
        let offset = text.find("actor_type pedestrian").unwrap() + "actor_type ped".len();
        assert!(matches!(at(&db, core, offset), Some(At::Name { name, declared: true, .. }) if name == "pedestrian"));
        // the kind it names, resolved in the module's own vocabulary
        let kind = offset + text[offset..].find("kind: pedestrian").unwrap() + "kind: p".len();
        let found = at(&db, core, kind);
        assert!(
            matches!(&found, Some(At::Name { kind, entry: Some(e), declared: false, .. }) if kind == "actor_kind" && e.file == core.id(&db)),
            "{found:?}"
        );
    }

    #[test]
    fn non_ascii_before_the_cursor() {
        let text = "// météo ☀ 🚗\nscenario demo {\n  source { description: \"ça roule 🚦\" }\n  environment {\n    weather: rai$0ny\n  }\n}\n";
        assert!(matches!(at_cursor(text), Some(At::Name { name, .. }) if name == "rainy"));
        assert_eq!(under(text), "rainy");
    }

    #[test]
    fn nothing_in_broken_text_or_past_the_end() {
        for broken in [
            "scenario demo { road { lanes: ",
            "// é🚗\nscenario demo {\n  environment { weather: clear }\n}\n",
            "actor : { position: of }",
            "use \nweather { aliases: [",
            "scenario demo { actor a: 3..x car { speed: 3 km/",
        ] {
            let (db, file) = testing::file(broken);
            for offset in 0..broken.len() + 5 {
                let _ = at(&db, file, offset);
            }
            assert_eq!(at(&db, file, usize::MAX), at(&db, file, broken.len()));
        }
        assert_eq!(at_cursor("$0"), None);
        assert_eq!(at_cursor("scenario demo {\n$0\n}\n"), None);
    }

    #[test]
    fn yaml_answers_have_spans_too() {
        let yaml = "Here it is:\n```yaml\nenvironment:\n  weather: sunny\n  time: day time\nroad_network:\n  lane_number: 2\nactors:\n  ego_vehicle:\n    speed: 30 mph\n    lane_index: 1\n  lead_car:\n    type: sedan\n    position_relation: front\n    position_target: ego_vehicle\n```\n";
        let (db, file) = testing::with_language(yaml, crate::Language::Yaml);
        let found = |needle: &str, plus: usize| at(&db, file, yaml.find(needle).unwrap() + plus);
        assert!(
            matches!(found("sunny", 2), Some(At::Name { kind, entry: Some(e), .. }) if kind == "weather" && e.name == "clear"),
            "{:?}",
            found("sunny", 2)
        );
        assert!(
            matches!(found("sedan", 1), Some(At::Name { kind, .. }) if kind == "actor_type"),
            "{:?}",
            found("sedan", 1)
        );
        assert!(matches!(found("lead_car", 1), Some(At::Group { index: 0, .. })), "{:?}", found("lead_car", 1));
        assert!(
            matches!(found("ego_vehicle\n```", 1), Some(At::Reference { target: Some(Target::Ego), .. })),
            "{:?}",
            found("ego_vehicle\n```", 1)
        );
        assert!(matches!(found("30 mph", 0), Some(At::Quantity { .. })), "{:?}", found("30 mph", 0));
    }
}
