//! Hover: a short Markdown account of what is under the cursor ([`crate::locate`]), from
//! the declarations the file sees and the schema — the same facts the checker uses — and,
//! when a diagnostic covers the cursor, its code, title and message.

use tad_syntax::model::{Known, Val};
use tad_syntax::schema::{FieldDef, Unit, ValueType};

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
            parts.push(format!("**{}** {}: {}", d.code.as_str(), d.code.title(), d.message));
            span = span.or(Some(s));
        }
    }
    (!parts.is_empty())
        .then(|| Hover { span: span.unwrap_or(Span::new(offset, offset)), markdown: parts.join("\n\n---\n\n") })
}

fn describe(db: &Database, file: SourceFile, found: &At) -> Option<String> {
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    Some(match found {
        At::Section { def, .. } => format!("```tad\n{}\n```\n{}", def.name, def.doc),
        At::DeclarationKind { def, .. } => format!("```tad\n{}\n```\ndeclaration kind: {}", def.name, def.doc),
        At::Field { def, section, .. } => field(def, section),
        At::Name { kind, name, .. } => {
            let Some(entry) = vocabulary.get(kind, name) else {
                return Some(format!("`{name}`: no {} of that name is in scope", kind.replace('_', " ")));
            };
            let mut out = format!("```tad\n{} {}\n```", kind, entry.name);
            if entry.name != *name {
                out.push_str(&format!("\n`{name}` is an alias of `{}`", entry.name));
            }
            if let Some(doc) = crate::completion::documentation(entry) {
                out.push_str(&format!("\n\n{doc}"));
            }
            let carla: Vec<String> =
                ["cloudiness", "precipitation", "wetness", "fog_density", "sun_altitude", "sun_azimuth"]
                    .iter()
                    .filter_map(|f| entry.declaration.attr(f).and_then(|a| a.integer()).map(|v| format!("{f} {v}")))
                    .collect();
            if !carla.is_empty() {
                out.push_str(&format!("\n\nCARLA: {}", carla.join(", ")));
            }
            if let Some(blueprint) = entry.declaration.attr("carla_blueprint").and_then(|a| match &a.value {
                Known::Given(Val::Text(t)) => Some(t.clone()),
                _ => None,
            }) {
                out.push_str(&format!("\n\nCARLA blueprint `{blueprint}`"));
            }
            if let Some(module) = entry.symbol("module") {
                out.push_str(&format!("\n\nits vocabulary: module `{module}`"));
            }
            out.push_str(&format!("\n\n*declared in module `{}`*", entry.module));
            out
        }
        At::Word { field, word, .. } => format!("`{word}`: one of {} for `{}`", quoted(field), field.name),
        At::Quantity { field, value, .. } => quantity(field, value),
        At::Group { index, .. } => group(db, file, *index)?,
        At::Reference { name, .. } => {
            let module = &tad_db::analyze(db, file).module;
            let scenario = module.scenario.as_ref()?;
            match scenario.actors.iter().position(|g| g.name.text == *name) {
                Some(index) => group(db, file, index)?,
                None if vocabulary.get("reference", name).is_some() => {
                    let lane = scenario.attr("ego", "lane").and_then(|a| a.integer());
                    let speed = scenario.attr("ego", "speed").and_then(|a| a.quantity());
                    let mut out = format!("```tad\nreference {name}\n```\nthe ego vehicle");
                    if let Some(lane) = lane {
                        out.push_str(&format!(", lane {lane}"));
                    }
                    if let Some(q) = speed {
                        out.push_str(&format!(", {} {}", q.value, q.unit.as_str()));
                    }
                    out
                }
                None => format!("`{name}`: no actor group, `ego` or road element of that name"),
            }
        }
        At::Module { name, .. } => {
            let imports = file.imports(db);
            match imports.modules.get(name) {
                Some(module) => format!("```tad\nuse {name}\n```\n{}", module.path(db).display()),
                None => format!("`{name}`: no such module"),
            }
        }
    })
}

fn quoted(field: &FieldDef) -> String {
    match field.ty {
        ValueType::Choice(words) => words.iter().map(|w| format!("`{w}`")).collect::<Vec<_>>().join(", "),
        _ => String::new(),
    }
}

fn field(def: &FieldDef, section: &str) -> String {
    let mut out = format!("```tad\n{section} {{ {}: {} }}\n```\n{}", def.name, def.example, def.doc);
    let mut facts = vec![def.ty.describe().to_string()];
    if let Some(kind) = def.vocabulary {
        facts.push(format!("names of `{kind}`"));
    }
    if def.essential {
        facts.push("essential: a complete scenario states it".into());
    }
    if def.param {
        facts.push("takes a range or a choice".into());
    }
    out.push_str(&format!("\n\n{}", facts.join(" · ")));
    out
}

fn si_unit(ty: ValueType) -> &'static str {
    match ty {
        ValueType::Speed => "m/s",
        ValueType::Length => "m",
        _ => "s",
    }
}

fn quantity(field: &FieldDef, value: &Val) -> String {
    let show = |q: &tad_syntax::model::Quantity| {
        let si = q.si();
        let unit = q.unit;
        let mut out = format!("{} {}", number(q.value), unit.as_str());
        if unit != Unit::MetresPerSecond && unit.measures() == ValueType::Speed {
            out.push_str(&format!(" = {} m/s", number(si)));
            if unit != Unit::KilometresPerHour {
                out.push_str(&format!(" = {} km/h", number(si * 3.6)));
            }
        }
        out
    };
    let body = match value {
        Val::Quantity(q) => show(q),
        Val::Range(low, high) => format!("between {} and {}, sampled per run", show(low), show(high)),
        _ => String::new(),
    };
    let unit = match value {
        Val::Quantity(q) | Val::Range(q, _) => q.unit,
        _ => Unit::Seconds,
    };
    format!(
        "`{}`: {body}\n\nunit `{}` is {} {}",
        field.name,
        unit.as_str(),
        number(unit.to_si()),
        si_unit(unit.measures())
    )
}

fn number(v: f64) -> String {
    let rounded = (v * 100.0).round() / 100.0;
    if rounded.fract() == 0.0 { format!("{rounded:.0}") } else { format!("{rounded}") }
}

fn group(db: &Database, file: SourceFile, index: usize) -> Option<String> {
    let module = &tad_db::analyze(db, file).module;
    let group = module.scenario.as_ref()?.actors.get(index)?;
    let count = group.count.as_ref().map_or("1".to_string(), |c| match &c.value {
        Known::Given(count) => count.to_string(),
        Known::Unspecified => "unspecified".into(),
    });
    let kind = group.kind.value.given().map_or("unspecified", |k| k.name.as_str());
    let mut out = format!("```tad\nactor {}: {count} {kind}\n```", group.name.text);
    let mut facts = Vec::new();
    if let Some(b) = group.attr("behavior").and_then(|a| a.symbol()) {
        facts.push(b.name.clone());
    }
    if let Some(q) = group.attr("speed").and_then(|a| a.quantity()) {
        facts.push(format!("{} {}", number(q.value), q.unit.as_str()));
    }
    if let Some(Known::Given(Val::Position(p))) = group.attr("position").map(|a| &a.value) {
        facts.push(format!("{} of {}", p.relation.name, p.reference.name));
    }
    if let Some(lane) = group.attr("lane").and_then(|a| a.integer()) {
        facts.push(format!("lane {lane}"));
    }
    if !facts.is_empty() {
        out.push_str(&format!("\n{}", facts.join(" · ")));
    }
    Some(out)
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
    fn vocabulary_names_show_their_declaration() {
        let md = hover_at("scenario demo {\n  actor walkers: 4 pede$0strian {\n  }\n}\n");
        assert!(md.contains("actor_type pedestrian"), "{md}");
        assert!(md.contains("declared in module `core`"), "{md}");
        let md = hover_at("scenario demo {\n  environment {\n    weather: sun$0ny\n  }\n}\n");
        assert!(md.contains("weather clear") && md.contains("alias of `clear`"), "{md}");
        assert!(md.contains("W0401"), "the alias's diagnostic is explained: {md}");
        assert!(md.contains("CARLA: cloudiness"), "{md}");
    }

    #[test]
    fn fields_quantities_and_references() {
        let md = hover_at("scenario demo {\n  ego {\n    spe$0ed: 20 mph\n  }\n}\n");
        assert!(md.contains("a speed") && md.contains("essential"), "{md}");
        let md = hover_at("scenario demo {\n  ego {\n    speed: 2$00 mph\n  }\n}\n");
        assert!(md.contains("20 mph = 8.94 m/s = 32.19 km/h"), "{md}");
        let text = "scenario demo {\n  ego { lane: 2 }\n  actor a: 3 taxi {\n    behavior: turn_left\n  }\n  actor b: car {\n    position: front of $0a\n  }\n}\n";
        let md = hover_at(text);
        assert!(md.contains("actor a: 3 taxi") && md.contains("turn_left"), "{md}");
        let md =
            hover_at("scenario demo {\n  ego { lane: 2 }\n  actor b: car {\n    position: front of eg$0o\n  }\n}\n");
        assert!(md.contains("the ego vehicle, lane 2"), "{md}");
    }

    #[test]
    fn a_diagnostic_alone_is_explained() {
        let md = hover_at("scenario demo {\n  environment {\n    wether$0: clear\n  }\n}\n");
        assert!(md.contains("E0203") && md.contains("unknown field"), "{md}");
    }

    #[test]
    fn broken_text_and_offsets_past_the_end() {
        let (db, file) = testing::file("// é🚗\nscenario demo { road { lanes: ");
        for offset in 0..60 {
            let _ = hover(&db, file, offset);
        }
    }
}
