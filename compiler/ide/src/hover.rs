//! Hover: a short Markdown account of what is under the cursor ([`crate::locate`]), in the
//! manner of rust-analyzer: a code line naming the thing, then a few facts.
//!
//! The facts come from where the language keeps them — a vocabulary name's declaration
//! (its attributes, rendered generically in the schema's field order, so a new field
//! shows up without touching this module), the schema's docs for sections and fields,
//! `Unit` for units — and from the checker: a diagnostic covering the cursor adds its
//! code, title and message, so hovering an error explains it.

use tad_check::{Entry, Target};
use tad_syntax::model::{Attr, Declaration, Known, Quantity, Val};
use tad_syntax::schema::{FieldDef, SectionDef, Unit, ValueType};

use crate::locate::{At, at};
use crate::{Database, SourceFile, Span};

/// Markdown about the thing at an offset, and the span it covers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Hover {
    pub span: Span,
    pub markdown: String,
}

pub fn hover(db: &Database, file: SourceFile, offset: usize) -> Option<Hover> {
    let offset = crate::clamp(file.text(db), offset);
    let found = at(db, file, offset);
    let mut parts: Vec<String> = Vec::new();
    let mut span = found.as_ref().map(At::span);
    if let Some(found) = &found {
        parts.extend(describe(db, file, found));
    }
    // the diagnostics covering the cursor explain themselves
    let id = file.id(db);
    for d in tad_db::check(db, file).diagnostics.iter().filter(|d| d.file == id) {
        let s = d.primary.span;
        if s.start <= offset && offset <= s.end.max(s.start + 1) {
            let mut text = format!("**{}** {}: {}", d.code.as_str(), d.code.title(), d.message);
            if let Some(help) = &d.help {
                text.push_str(&format!("\n\nhelp: {help}"));
            }
            parts.push(text);
            span = span.or(Some(s));
        }
    }
    (!parts.is_empty())
        .then(|| Hover { span: span.unwrap_or(Span::new(offset, offset)), markdown: parts.join("\n\n---\n\n") })
}

fn code(line: &str) -> String {
    format!("```tad\n{line}\n```")
}

fn describe(db: &Database, file: SourceFile, found: &At) -> Option<String> {
    Some(match found {
        At::Section { def, .. } => section(def),
        At::DeclarationKind { def, .. } => {
            let fields: Vec<String> = own_fields(def).map(|f| format!("`{}`", f.name)).collect();
            format!("{}\ndeclaration kind: {}\n\nfields: {}", code(def.name), def.doc, fields.join(", "))
        }
        At::Field { def, section, .. } => field(def, section),
        At::Name { kind, name, entry, .. } => match entry {
            Some(entry) => self::entry(entry, name),
            None => format!("`{name}`: no {} of that name is in scope", kind.replace('_', " ")),
        },
        At::Word { field, word, .. } => {
            let words = match field.ty {
                ValueType::Choice(words) => words.iter().map(|w| format!("`{w}`")).collect::<Vec<_>>().join(", "),
                _ => String::new(),
            };
            format!("{}\n{}\n\none of {words}", code(word), field.doc)
        }
        At::Quantity { field, value, .. } => quantity(field, value),
        At::Unit { unit, .. } => format!(
            "{}\na unit of {}: 1 {} = {} {}",
            code(unit.as_str()),
            measure(unit.measures()),
            unit.as_str(),
            number(unit.to_si(), 5),
            si_unit(unit.measures())
        ),
        At::Group { index, .. } => group(db, file, *index)?,
        At::Reference { name, target, .. } => match target {
            Some(Target::Group(index)) => group(db, file, *index)?,
            Some(Target::Ego) => ego(db, file, name),
            Some(Target::RoadElement(_)) => {
                let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
                entry(vocabulary.get("road_element", name)?, name)
            }
            None => format!("`{name}`: no actor group, `ego` or road element of that name"),
        },
        At::Module { name, .. } => {
            let module = file.imports(db).modules.get(name).copied().or_else(|| db.standard_module(name));
            match module {
                Some(module) => {
                    let path = module.path(db);
                    let n = tad_db::analyze(db, module).module.declarations.len();
                    let origin =
                        if path.starts_with(tad_db::STDLIB_PREFIX) { "standard module" } else { "local module" };
                    format!("{}\n{origin} `{}` · {n} declarations", code(&format!("use {name}")), path.display())
                }
                None => format!("`{name}`: no such module"),
            }
        }
    })
}

/// The fields of a section or declaration kind, without those every declaration has.
fn own_fields(def: &SectionDef) -> impl Iterator<Item = &'static FieldDef> + '_ {
    def.fields.iter().filter(|f| !matches!(f.name, "aliases" | "description"))
}

fn section(def: &SectionDef) -> String {
    let mut out = format!("{}\n{}", code(def.name), def.doc);
    let essential: Vec<String> = def.essential().map(|f| format!("`{}`", f.name)).collect();
    if !essential.is_empty() {
        out.push_str(&format!("\n\nessential: {}", essential.join(", ")));
    }
    out
}

fn field(def: &FieldDef, section: &str) -> String {
    let mut out = format!("{}\n{}", code(&format!("{section} {{ {}: {} }}", def.name, def.example)), def.doc);
    let mut facts = vec![def.ty.describe().to_string()];
    if let Some(kind) = def.vocabulary {
        facts.push(format!("a `{kind}` name"));
    }
    if let ValueType::Choice(words) = def.ty {
        facts.push(format!("one of {}", words.iter().map(|w| format!("`{w}`")).collect::<Vec<_>>().join(", ")));
    }
    if def.essential {
        facts.push("essential: a complete scenario states it".into());
    }
    if def.param {
        facts.push("takes a parameter (a range or a choice)".into());
    }
    out.push_str(&format!("\n\n{}", facts.join(" · ")));
    out
}

/// A vocabulary entry, written as `written`.
fn entry(entry: &Entry, written: &str) -> String {
    let declaration = &entry.declaration;
    let mut parts = vec![code(&format!("{} {}", declaration.def.name, entry.name))];
    if entry.name != written {
        parts.push(format!("`{written}` is an alias of `{}`", entry.name));
    }
    if let Some(Known::Given(Val::Text(text))) = declaration.attr("description").map(|a| &a.value) {
        parts.push(text.clone());
    }
    let facts = facts(declaration);
    if !facts.is_empty() {
        // the attributes of a weather are CARLA's weather parameters
        let label = if declaration.def.name == "weather" { "CARLA: " } else { "" };
        parts.push(format!("{label}{}", facts.join(" · ")));
    }
    if let Some(aliases) = entry.symbols("aliases").filter(|a| !a.is_empty()) {
        parts.push(format!("also written {}", aliases.iter().map(|a| format!("`{a}`")).collect::<Vec<_>>().join(", ")));
    }
    parts.push(format!("*declared in module `{}`*", entry.module));
    parts.join("\n\n")
}

/// A declaration's attributes in its kind's field order; an actor type's size as one.
fn facts(declaration: &Declaration) -> Vec<String> {
    let quantity = |f: &str| declaration.attr(f).and_then(Attr::quantity);
    let mut out = Vec::new();
    let size = match (quantity("length"), quantity("width"), quantity("height")) {
        (Some(l), Some(w), Some(h)) => Some(format!("{} × {} × {} m (l × w × h)", si(l), si(w), si(h))),
        (Some(l), Some(w), None) => Some(format!("{} × {} m (l × w)", si(l), si(w))),
        _ => None,
    };
    for def in own_fields(declaration.def) {
        let in_size = matches!(def.name, "length" | "width" | "height") && size.is_some();
        if def.name == "carla_note" || in_size {
            if def.name == "length" {
                out.extend(size.clone());
            }
            continue;
        }
        if let Some(Known::Given(value)) = declaration.attr(def.name).map(|a| &a.value) {
            out.push(format!("{} {}", def.name.replace('_', " ").replace("carla", "CARLA"), value_text(value)));
        }
    }
    out
}

/// A value as a fact: speeds in km/h, lengths and durations in SI.
fn value_text(value: &Val) -> String {
    let names = |list: &[tad_syntax::model::Symbol], sep: &str| {
        if list.is_empty() {
            "none".to_string()
        } else {
            list.iter().map(|s| format!("`{}`", s.name)).collect::<Vec<_>>().join(sep)
        }
    };
    match value {
        Val::Symbol(s) => format!("`{}`", s.name),
        Val::Symbols(list) => names(list, ", "),
        Val::Choice(list) => names(list, " | "),
        Val::Integer(n) => n.to_string(),
        Val::Quantity(q) => human(*q),
        Val::Range(low, high) => format!("{}..{}", number(human_value(*low), 1), human(*high)),
        Val::Text(t) => format!("`{t}`"),
        Val::Position(p) => format!("`{} of {}`", p.relation.name, p.reference.name),
        Val::Flag(b) => (if *b { "yes" } else { "no" }).to_string(),
    }
}

/// A quantity in its usual unit: km/h for speeds, SI otherwise.
fn human(q: Quantity) -> String {
    let unit = if q.unit.measures() == ValueType::Speed { "km/h" } else { si_unit(q.unit.measures()) };
    format!("{} {unit}", number(human_value(q), 1))
}

fn human_value(q: Quantity) -> f64 {
    if q.unit.measures() == ValueType::Speed { q.si() * 3.6 } else { q.si() }
}

fn si(q: Quantity) -> String {
    number(q.si(), 2)
}

fn si_unit(ty: ValueType) -> &'static str {
    match ty {
        ValueType::Speed => "m/s",
        ValueType::Length => "m",
        _ => "s",
    }
}

fn measure(ty: ValueType) -> &'static str {
    match ty {
        ValueType::Speed => "speed",
        ValueType::Length => "length",
        _ => "time",
    }
}

fn quantity(field: &FieldDef, value: &Val) -> String {
    let show = |q: &Quantity| {
        let mut out = format!("{} {}", number(q.value, 2), q.unit.as_str());
        if q.unit.measures() == ValueType::Speed {
            if q.unit != Unit::MetresPerSecond {
                out.push_str(&format!(" = {} m/s", number(q.si(), 2)));
            }
            if q.unit != Unit::KilometresPerHour {
                out.push_str(&format!(" = {} km/h", number(q.si() * 3.6, 2)));
            }
        }
        out
    };
    let body = match value {
        Val::Quantity(q) => show(q),
        Val::Range(low, high) => format!("between {} and {}, one value per run", show(low), show(high)),
        _ => String::new(),
    };
    format!("`{}`: {body}", field.name)
}

/// `v` to at most `decimals` decimals, without trailing zeros.
fn number(v: f64, decimals: usize) -> String {
    let text = format!("{v:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

fn group(db: &Database, file: SourceFile, index: usize) -> Option<String> {
    let module = &tad_db::analyze(db, file).module;
    let group = module.scenario.as_ref()?.actors.get(index)?;
    let count = group.count.as_ref().map_or("1".to_string(), |c| match &c.value {
        Known::Given(count) => count.to_string(),
        Known::Unspecified => "unspecified".into(),
    });
    let kind = group.kind.value.given().map_or("unspecified", |k| k.name.as_str());
    let mut out = code(&format!("actor {}: {count} {kind}", group.name.text));
    let mut facts = Vec::new();
    for name in ["behavior", "speed", "position", "lane"] {
        if let Some(Known::Given(value)) = group.attr(name).map(|a| &a.value) {
            let text = match value {
                Val::Quantity(q) => format!("{} {}", number(q.value, 2), q.unit.as_str()),
                Val::Range(low, high) => {
                    format!("{}..{} {}", number(low.value, 2), number(high.value, 2), high.unit.as_str())
                }
                other => value_text(other),
            };
            facts.push(format!("{name} {text}"));
        }
    }
    if !facts.is_empty() {
        out.push_str(&format!("\n{}", facts.join(" · ")));
    }
    Some(out)
}

/// The ego vehicle as the scenario states it.
fn ego(db: &Database, file: SourceFile, written: &str) -> String {
    let module = &tad_db::analyze(db, file).module;
    let mut out = code(&format!("reference {written}"));
    out.push_str("\nthe ego vehicle");
    let ego = module.scenario.as_ref().and_then(|s| s.section("ego"));
    let mut facts = Vec::new();
    for name in ["behavior", "speed", "lane"] {
        if let Some(Known::Given(value)) = ego.and_then(|e| e.attr(name)).map(|a| &a.value) {
            let text = match value {
                Val::Quantity(q) => format!("{} {}", number(q.value, 2), q.unit.as_str()),
                other => value_text(other),
            };
            facts.push(format!("{name} {text}"));
        }
    }
    // what the vocabulary says of it (its actor type)
    if let Some(entry) = tad_db::vocabulary(db, file).vocabulary.get("reference", written) {
        facts.extend(self::facts(&entry.declaration));
    }
    if !facts.is_empty() {
        out.push_str(&format!("\n\n{}", facts.join(" · ")));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    fn hover_at(text: &str) -> String {
        let (db, file, offset) = testing::cursor(text);
        hover(&db, file, offset).map(|h| h.markdown).unwrap_or_default()
    }

    #[test]
    fn actor_types_show_size_and_speeds() {
        let text = "scenario demo {\n  actor crossing_pedestrians: 4 pede$0strian {\n  }\n}\n";
        let (db, file, offset) = testing::cursor(text);
        let found = hover(&db, file, offset).unwrap();
        let start = text.find("pede$0strian {").unwrap();
        assert_eq!(found.span, Span::new(start, start + "pedestrian".len()));
        let md = found.markdown;
        assert!(md.starts_with("```tad\nactor_type pedestrian\n```"), "{md}");
        assert!(md.contains("0.5 × 0.6 × 1.7 m (l × w × h)"), "{md}");
        assert!(md.contains("typical speed 5 km/h · max speed 25 km/h"), "{md}");
        assert!(md.contains("kind `pedestrian`") && md.contains("CARLA blueprint `walker.pedestrian.0001`"), "{md}");
        assert!(md.contains("also written `person`"), "{md}");
        assert!(md.contains("*declared in module `core`*"), "{md}");
        assert!(!md.contains("alias of"), "{md}");
    }

    #[test]
    fn aliases_weather_behaviors_relations_and_regions() {
        let md = hover_at("scenario demo {\n  environment {\n    weather: sun$0ny\n  }\n}\n");
        assert!(md.contains("weather clear") && md.contains("`sunny` is an alias of `clear`"), "{md}");
        assert!(md.contains("CARLA: cloudiness 10 · precipitation 0"), "{md}");
        assert!(md.contains("**W0401** "), "the alias's diagnostic is explained: {md}");
        let md = hover_at("scenario demo {\n  actor a: deer {\n    behavior: wal$0k\n  }\n}\n");
        assert!(md.contains("behavior walk") && md.contains("walk along the road"), "{md}");
        assert!(md.contains("performers `pedestrian`, `animal`") && md.contains("motion `walk`"), "{md}");
        let md = hover_at("scenario demo {\n  actor a: deer {\n    behavior: st$0and\n  }\n}\n");
        assert!(md.contains("max speed 0 km/h"), "{md}");
        let md = hover_at("scenario demo {\n  actor a: car {\n    position: left_fr$0ont of ego\n  }\n}\n");
        assert!(md.contains("relation left_front") && md.contains("lateral `left` · longitudinal `front`"), "{md}");
        let md = hover_at("scenario demo {\n  source {\n    region: yosem$0ite\n  }\n}\n");
        assert!(md.contains("module `national_park`"), "{md}");
    }

    #[test]
    fn sections_fields_words_and_declaration_kinds() {
        let md = hover_at("scenario demo {\n  ro$0ad { lanes: 2 }\n}\n");
        assert!(md.contains("the road network") && md.contains("essential: `type`, `lanes`, `direction`"), "{md}");
        let md = hover_at("scenario demo {\n  ego {\n    spe$0ed: 20 km/h\n  }\n}\n");
        assert!(md.contains("ego { speed: 30 km/h }") && md.contains("a speed"), "{md}");
        assert!(md.contains("essential") && md.contains("takes a parameter"), "{md}");
        let md = hover_at("relation sideways {\n  lateral: ri$0ght\n}\n");
        assert!(md.contains("across the road") && md.contains("one of `left`, `right`, `same`, `opposite`"), "{md}");
        let md = hover_at("weat$0her glum {\n  cloudiness: 90\n}\n");
        assert!(md.contains("declaration kind: a weather condition") && md.contains("`cloudiness`"), "{md}");
        // a declaration of this file, by its name or one of its aliases
        let md = hover_at("weather glum {\n  aliases: [mi$0rk]\n  cloudiness: 90\n}\n");
        assert!(md.contains("weather glum") && md.contains("alias of `glum`") && md.contains("cloudiness 90"), "{md}");
        assert!(md.contains("declared in module `scenario`"), "{md}");
    }

    #[test]
    fn quantities_and_units_in_si() {
        let md = hover_at("scenario demo {\n  ego {\n    speed: 2$00 mph\n  }\n}\n");
        assert!(md.contains("`speed`: 20 mph = 8.94 m/s = 32.19 km/h"), "{md}");
        assert!(md.contains("W0402"), "the unit's warning: {md}");
        let md = hover_at("scenario demo {\n  ego {\n    speed: 20 mp$0h\n  }\n}\n");
        assert!(md.contains("```tad\nmph\n```\na unit of speed: 1 mph = 0.44704 m/s"), "{md}");
        let md = hover_at("scenario demo {\n  actor a: car {\n    speed: 30..$040 km/h\n  }\n}\n");
        assert!(md.contains("between 30 km/h = 8.33 m/s and 40 km/h = 11.11 m/s"), "{md}");
        let md = hover_at("scenario demo {\n  actor a: car {\n    distance: 15 $0m\n  }\n}\n");
        assert!(md.contains("a unit of length: 1 m = 1 m"), "{md}");
    }

    #[test]
    fn references_name_their_group_the_ego_or_a_road_element() {
        let text = "scenario demo {\n  ego { lane: 2 }\n  actor a: 3 taxi {\n    behavior: turn_left\n  }\n  actor b: car {\n    position: front of $0a\n  }\n}\n";
        let md = hover_at(text);
        assert!(md.contains("actor a: 3 taxi") && md.contains("behavior `turn_left`"), "{md}");
        let md = hover_at(
            "scenario demo {\n  ego { lane: 2\n speed: 30 km/h }\n  actor b: car {\n    position: front of eg$0o\n  }\n}\n",
        );
        assert!(md.contains("the ego vehicle") && md.contains("speed 30 km/h · lane 2 · actor type `car`"), "{md}");
        let md = hover_at("scenario demo {\n  actor b: car {\n    position: front of junc$0tion\n  }\n}\n");
        assert!(md.contains("road_element intersection") && md.contains("alias of `intersection`"), "{md}");
        let md = hover_at("scenario demo {\n  actor b: car {\n    position: front of nob$0ody\n  }\n}\n");
        assert!(md.contains("no actor group") && md.contains("E0402"), "{md}");
    }

    #[test]
    fn a_diagnostic_alone_is_explained() {
        let md = hover_at("scenario demo {\n  environment {\n    wether$0: clear\n  }\n}\n");
        assert!(md.contains("**E0203** unknown field") && md.contains("help: did you mean `weather`?"), "{md}");
        let md = hover_at("scenario demo {\n  environment {\n    weather: cl$0aer\n  }\n}\n");
        assert!(md.contains("no weather of that name") && md.contains("**E0400**"), "{md}");
    }

    #[test]
    fn modules_standard_and_local() {
        let md = hover_at("use national_p$0ark\nscenario demo {}\n");
        assert!(md.contains("use national_park") && md.contains("standard module `<stdlib>"), "{md}");
        struct Fs;
        impl tad_db::FileSystem for Fs {
            fn read(&self, path: &std::path::Path) -> Option<String> {
                (path == std::path::Path::new("/fixture/mine.tad"))
                    .then(|| "weather glum {\n  description: \"grey and low\"\n  cloudiness: 90\n}\n".to_string())
            }
        }
        let text = "use mine\nscenario demo {\n  environment {\n    weather: glum\n  }\n}\n";
        let mut db = Database::new(tad_check::Options::default());
        let file = db.set_source("/fixture/scenario.tad".into(), text.into(), crate::Language::Tad, &Fs);
        let md = hover(&db, file, text.find("glum").unwrap()).unwrap().markdown;
        assert!(md.contains("grey and low") && md.contains("declared in module `mine`"), "{md}");
        let md = hover(&db, file, 5).unwrap().markdown;
        assert!(md.contains("local module `/fixture/mine.tad` · 1 declarations"), "{md}");
    }

    #[test]
    fn non_ascii_and_yaml_answers() {
        let md = hover_at(
            "// météo ☀ 🚗\nscenario demo {\n  source { description: \"ça 🚦\" }\n  ego {\n    speed: 3$00 km/h\n  }\n}\n",
        );
        assert!(md.contains("`speed`: 30 km/h = 8.33 m/s"), "{md}");
        let yaml = "environment:\n  weather: sunny\nactors:\n  lead_car:\n    type: sedan\n    speed: 30 mph\n";
        let (db, file) = testing::with_language(yaml, crate::Language::Yaml);
        let md = hover(&db, file, yaml.find("sunny").unwrap() + 1).unwrap().markdown;
        assert!(md.contains("weather clear") && md.contains("alias of `clear`"), "{md}");
        let md = hover(&db, file, yaml.find("lead_car").unwrap()).unwrap().markdown;
        assert!(md.contains("actor lead_car: 1 "), "{md}");
    }

    #[test]
    fn broken_text_and_offsets_past_the_end() {
        for text in ["// é🚗\nscenario demo { road { lanes: ", "actor : 3", "weather { cloudiness: ", "use"] {
            let (db, file) = testing::file(text);
            for offset in 0..text.len() + 3 {
                let _ = hover(&db, file, offset);
            }
            assert_eq!(hover(&db, file, usize::MAX), hover(&db, file, text.len()));
        }
        assert_eq!(hover_at("scenario demo {\n$0\n}\n"), "");
    }
}
