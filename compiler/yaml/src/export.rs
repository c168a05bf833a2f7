//! A model written in TrafficAlign's YAML form, with extra keys for what that form lacks.

use crate::dialect::{self, Form, Place, Tad};
use crate::norm::{self, normalize};
use serde_norway::Value;
use tad_syntax::model::*;
use tad_syntax::schema::{Unit, ValueType};

const IN: &str = "    ";

/// Write the scenario of `module` in the paper's YAML form: `environment`,
/// `road_network` and `actors` (with `ego_vehicle` and one key per actor group), values in
/// the paper's spelling (`straight road`, `two-way`, `left front`, `30 km/h`). Everything
/// TAD has and that form lacks goes in extra keys, so [`crate::lower`] reads back the same
/// scenario: `scenario` (the name), `use`, a `source` block, and in `road_network`
/// `special_lanes`, `signs` (the full list when there is more than one sign; the paper's
/// `traffic_sign` holds one), `traffic`, `hazards`, `roadworks`, `emergency_vehicles` and
/// `roadside`. Absent fields are left out; `unspecified` is written `unspecified`.
///
/// `src` is the TAD text the model was lowered from: its leading comments become YAML
/// comments, and quantities keep their written form. Declarations are not exported.
pub fn export(module: &Module, src: &str) -> String {
    let mut out = String::new();
    for line in src.lines() {
        let t = line.trim();
        if let Some(comment) = t.strip_prefix("//") {
            if comment.chars().all(|c| printable(c) || c == '\t') {
                out.push_str(&format!("#{}\n", comment.trim_end()));
            }
        } else if !t.is_empty() {
            break;
        }
    }
    if !out.is_empty() {
        out.push('\n');
    }
    let Some(s) = &module.scenario else {
        out.push_str("{}\n");
        return out;
    };
    let w = Writer { src };
    for row in dialect::written(Place::Top) {
        match row.tad {
            Tad::ScenarioName => {
                if let Some(name) = &s.name {
                    out.push_str(&format!("{}: {}\n", row.key, scalar(&name.text)));
                }
            }
            Tad::Profile => out.push_str(&format!("{}: {}\n", row.key, crate::PROFILES[0])),
            Tad::Uses => {
                if !module.uses.is_empty() {
                    let paths: Vec<String> = module
                        .uses
                        .iter()
                        .map(|u| flow_item(&u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".")))
                        .collect();
                    out.push_str(&format!("{}: [{}]\n", row.key, paths.join(", ")));
                }
            }
            Tad::Block(place) => {
                if let Some(section) = place.section().and_then(|def| s.section(def.name)) {
                    out.push_str(&format!("{}:", row.key));
                    block(&mut out, &w.keys(place, &|field| section.attr(field), None, 1));
                }
            }
            Tad::Actors => w.actors(&mut out, row.key, s),
            Tad::Field(..) | Tad::Type | Tad::Count | Tad::Nothing => {}
        }
    }
    out
}

/// Append `: {}` for an empty mapping, else a line break and the body.
fn block(out: &mut String, body: &str) {
    if body.is_empty() {
        out.push_str(" {}\n");
    } else {
        out.push('\n');
        out.push_str(body);
    }
}

/// How a name is spelt in the paper's form.
#[derive(Clone, Copy, PartialEq)]
enum Spelling {
    Plain,
    RoadType,
    Direction,
}

struct Writer<'a> {
    src: &'a str,
}

impl Writer<'_> {
    /// The lines of the keys `export` writes at `place` (indented `depth` levels), for the
    /// fields `attr` finds; `group` is the actor group at an actor's place.
    fn keys<'m>(
        &self,
        place: Place,
        attr: &dyn Fn(&str) -> Option<&'m Attr>,
        group: Option<(&ActorGroup, &Scenario)>,
        depth: usize,
    ) -> String {
        let mut body = String::new();
        let mut line = |key: &str, value: String| body.push_str(&format!("{}{key}: {value}\n", IN.repeat(depth)));
        // a field an earlier key summarised, and the full value when the summary is not all of it
        let mut summarised: Option<(&str, Option<String>)> = None;
        for row in dialect::written(place) {
            if let Form::Fixed(value) = row.form {
                line(row.key, value.to_string());
                continue;
            }
            match (row.tad, group) {
                (Tad::Type, Some((actor, _))) => {
                    let kind = match &actor.kind.value {
                        Known::Given(kind) => self.name(Spelling::Plain, &kind.name),
                        Known::Unspecified => "unspecified".into(),
                    };
                    line(row.key, kind);
                }
                (Tad::Count, Some((actor, _))) => match &actor.count {
                    Some(Spanned { value: Known::Given(Count::Exactly(n)), .. }) => line(row.key, n.to_string()),
                    // the form import reads back as a range
                    Some(Spanned { value: Known::Given(Count::Between(low, high)), .. }) => {
                        line(row.key, format!("{low}-{high}"))
                    }
                    Some(Spanned { value: Known::Unspecified, .. }) => line(row.key, "unspecified".into()),
                    None => {}
                },
                (Tad::Field(_, field), _) => {
                    let Some(a) = attr(field) else { continue };
                    if let Some((done, full)) = &summarised
                        && *done == field
                    {
                        if let Some(full) = full {
                            line(row.key, full.clone());
                        }
                        continue;
                    }
                    let value = match row.form {
                        Form::SignSummary => {
                            let (single, full) = self.summary(&a.value);
                            summarised = Some((field, full));
                            single
                        }
                        Form::RoadType => self.symbol(Spelling::RoadType, &a.value),
                        Form::Direction => self.symbol(Spelling::Direction, &a.value),
                        Form::Relation | Form::Target => {
                            let (target, relation) = self.position(&a.value, group.map(|(_, s)| s));
                            if row.form == Form::Target { target } else { relation }
                        }
                        _ => match a.def.ty {
                            ValueType::SymbolList => self.symbols(&a.value),
                            ValueType::Integer => self.integer(&a.value),
                            ValueType::Speed | ValueType::Duration | ValueType::Length => self.quantity(a),
                            ValueType::Text => self.text(&a.value, depth),
                            _ => self.symbol(Spelling::Plain, &a.value),
                        },
                    };
                    line(row.key, value);
                }
                _ => {}
            }
        }
        body
    }

    /// `actors`: the ego vehicle first, then one key per actor group.
    fn actors(&self, out: &mut String, key: &str, s: &Scenario) {
        let ego = s.section("ego");
        if ego.is_none() && s.actors.is_empty() {
            // the paper's form always has `actors`; it also makes an empty scenario a scenario
            out.push_str(&format!("{key}: {{}}\n"));
            return;
        }
        out.push_str(&format!("{key}:\n"));
        if let Some(ego) = ego {
            out.push_str(&format!("{IN}{}:\n", dialect::EGO_KEY));
            out.push_str(&self.keys(Place::Ego, &|field| ego.attr(field), None, 2));
        }
        for actor in &s.actors {
            out.push_str(&format!("{IN}{}:\n", scalar(&actor.name.text)));
            out.push_str(&self.keys(Place::Actor, &|field| actor.attr(field), Some((actor, s)), 2));
        }
    }

    /// The paper's one-sign summary of a list of signs, and the full list when the summary
    /// does not hold it all.
    fn summary(&self, v: &Known<Val>) -> (String, Option<String>) {
        match v {
            Known::Unspecified => ("unspecified".to_string(), None),
            Known::Given(Val::Symbols(list)) => match list.as_slice() {
                [] => ("none".to_string(), None),
                [one] if one.name != "none" => (self.name(Spelling::Plain, &one.name), None),
                [first, ..] => (self.name(Spelling::Plain, &first.name), Some(self.symbols(v))),
            },
            other => (self.symbol(Spelling::Plain, other), None),
        }
    }

    /// A position as the paper's `position_target` and `position_relation`.
    fn position(&self, v: &Known<Val>, s: Option<&Scenario>) -> (String, String) {
        match v {
            Known::Given(Val::Position(p)) => {
                let target = if p.reference.name == "ego" {
                    dialect::EGO_KEY.to_string()
                } else if s.is_some_and(|s| s.actor(&p.reference.name).is_some()) {
                    scalar(&p.reference.name)
                } else {
                    self.name(Spelling::Plain, &p.reference.name)
                };
                (target, self.name(Spelling::Plain, &p.relation.name))
            }
            _ => ("unspecified".to_string(), "unspecified".to_string()),
        }
    }

    /// A name in the paper's spelling when that reads back as the same name, else as is.
    fn name(&self, field: Spelling, name: &str) -> String {
        let spaced = match (field, name) {
            (_, "t_intersection") => "t-intersection".to_string(),
            (_, "y_intersection") => "y-intersection".to_string(),
            (Spelling::Direction, _) => name.replace('_', "-"),
            _ => name.replace('_', " "),
        };
        let reads_back = normalize(&spaced) == name
            && !norm::is_unspecified(&spaced)
            && !norm::is_none_word(&spaced)
            && match field {
                Spelling::RoadType => {
                    norm::split_road_type(&spaced)
                        == norm::RoadTypeParts { road_type: Some(spaced.clone()), ..Default::default() }
                }
                _ => true,
            };
        if reads_back || name == "none" { flow_item(&spaced) } else { flow_item(name) }
    }

    fn symbol(&self, field: Spelling, v: &Known<Val>) -> String {
        match v {
            Known::Given(Val::Symbol(s)) => self.name(field, &s.name),
            other => self.other(other),
        }
    }

    fn symbols(&self, v: &Known<Val>) -> String {
        match v {
            Known::Given(Val::Symbols(list)) => {
                let items: Vec<String> = list.iter().map(|s| self.name(Spelling::Plain, &s.name)).collect();
                format!("[{}]", items.join(", "))
            }
            other => self.other(other),
        }
    }

    fn integer(&self, v: &Known<Val>) -> String {
        match v {
            Known::Given(Val::Integer(n)) => n.to_string(),
            other => self.other(other),
        }
    }

    fn quantity(&self, a: &Attr) -> String {
        if let Known::Given(Val::Range(low, high)) = &a.value {
            // the form import reads back as a range
            let number = crate::tad::number;
            return format!("{}-{} {}", number(low.value), number(high.value), high.unit.as_str());
        }
        let Known::Given(Val::Quantity(q)) = &a.value else { return self.other(&a.value) };
        let default = match q.unit {
            Unit::Seconds | Unit::Metres => q.unit,
            _ => Unit::KilometresPerHour,
        };
        if let Some(written) = self.src.get(a.value_span.start..a.value_span.end) {
            let written = written.split_whitespace().collect::<Vec<_>>().join(" ");
            if norm::parse_quantity(&written, default) == Some((q.value, q.unit)) && !written.contains(['#', ':']) {
                return written;
            }
        }
        format!("{} {}", crate::tad::number(q.value), q.unit.as_str())
    }

    fn text(&self, v: &Known<Val>, depth: usize) -> String {
        match v {
            Known::Given(Val::Text(t)) => text(t, depth),
            other => self.other(other),
        }
    }

    /// A value of an unexpected kind for its field: written as TAD would.
    fn other(&self, v: &Known<Val>) -> String {
        match v {
            Known::Unspecified => "unspecified".into(),
            Known::Given(Val::Text(t)) => quoted(t),
            Known::Given(Val::Symbol(s)) => flow_item(&s.name),
            other => quoted(&crate::tad::value(other, 0)),
        }
    }
}

/// A plain scalar when YAML (1.2, and 1.1 as Python's `yaml.safe_load` reads it) reads it
/// back as the same string, else a double-quoted one.
pub fn scalar(s: &str) -> String {
    const SPECIAL: &[&str] = &["y", "yes", "n", "no", "on", "off", "true", "false", "null", "~", "none"];
    let plain = !s.is_empty()
        && s.trim() == s
        && !SPECIAL.contains(&s.to_ascii_lowercase().as_str())
        && s.chars().all(|c| c.is_ascii_graphic() || c == ' ')
        && matches!(
            serde_norway::from_str::<Value>(&format!("k: {s}")),
            Ok(Value::Mapping(m)) if m.get("k").and_then(Value::as_str) == Some(s)
        );
    if plain { s.to_string() } else { quoted(s) }
}

/// A scalar that is also safe inside a flow list `[...]`.
fn flow_item(s: &str) -> String {
    if s.contains([',', '[', ']', '{', '}', '#', ':', '&', '*', '!', '|', '>', '\'', '"', '%', '@', '`']) {
        quoted(s)
    } else if s == "none" {
        s.to_string()
    } else {
        scalar(s)
    }
}

/// `s` as a YAML double-quoted scalar.
pub fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            '\0' => out.push_str("\\0"),
            c if printable(c) && !matches!(c, '\u{85}' | '\u{2028}' | '\u{2029}' | '\u{feff}') => out.push(c),
            c if (c as u32) <= 0xffff => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push_str(&format!("\\U{:08X}", c as u32)),
        }
    }
    out.push('"');
    out
}

/// YAML's printable characters.
fn printable(c: char) -> bool {
    matches!(c as u32, 0x20..=0x7e | 0x85 | 0xa0..=0xd7ff | 0xe000..=0xfffd | 0x10000..=0x10ffff)
}

/// Text: a literal block (`|-`) when one reads back exactly, else a quoted string.
fn text(t: &str, depth: usize) -> String {
    let indent = IN.repeat(depth + 1);
    let simple = t.contains('\n')
        && !t.starts_with([' ', '\n', '\t'])
        && !t.ends_with('\n')
        && t.chars()
            .all(|c| c == '\n' || (printable(c) && !matches!(c, '\u{85}' | '\u{2028}' | '\u{2029}' | '\u{feff}')))
        && t.lines().all(|l| l.trim_end() == l);
    if simple {
        let mut block = String::from("|-");
        for line in t.split('\n') {
            block.push('\n');
            if !line.is_empty() {
                block.push_str(&indent);
                block.push_str(line);
            }
        }
        let check = format!("k: {block}\n");
        if matches!(
            serde_norway::from_str::<Value>(&check),
            Ok(Value::Mapping(m)) if m.get("k").and_then(Value::as_str) == Some(t)
        ) {
            return block;
        }
    }
    quoted(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalars_are_quoted_when_yaml_would_misread_them() {
        assert_eq!(scalar("straight road"), "straight road");
        assert_eq!(scalar("yes"), "\"yes\"");
        assert_eq!(scalar("null"), "\"null\"");
        assert_eq!(scalar("a: b"), "\"a: b\"");
        assert_eq!(scalar("#x"), "\"#x\"");
        assert_eq!(quoted("say \"hi\"\n\u{1}\u{2028}"), "\"say \\\"hi\\\"\\n\\u0001\\u2028\"");
    }

    #[test]
    fn text_reads_back() {
        for t in ["one\ntwo", "a: b\n  c # d\n\nlast", "  leading", "trailing\n", "x\r\ny", "\"\"\"", "tab\there"] {
            let yaml = format!("k: {}\n", text(t, 0));
            let v: Value = serde_norway::from_str(&yaml).unwrap();
            assert_eq!(v["k"].as_str(), Some(t), "{yaml}");
        }
    }
}
