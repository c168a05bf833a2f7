//! A JSON Schema (draft 2020-12) of the YAML form as JSON, for servers whose structured
//! output takes a schema (OpenAI `response_format`, vLLM, SGLang, llama.cpp `json_schema`).
//!
//! Its keys are the ones `tad_yaml::export` writes (`tad_yaml::dialect::written`), each
//! value constrained by the key's form and its TAD field's kind; name fields take the
//! declared names in every spelling the YAML import reads back as the name (`straight_road`,
//! `straight road`, `two-way`). A JSON answer is YAML, so it goes through the same import
//! and checks as any YAML answer.

use serde_json::{Map, Value, json};
use tad_check::Vocabulary;
use tad_syntax::schema::{FieldDef, ValueType};
use tad_yaml::dialect::{self, Form, Key, Place, Tad};

const NAME_PATTERN: &str = "^[A-Za-z_][A-Za-z0-9_]*$";
const UNSPECIFIED: &str = "unspecified";

pub fn json_schema(vocabulary: &Vocabulary, title: &str) -> Value {
    let mut root = object(Place::Top, vocabulary);
    let root_map = root.as_object_mut().expect("an object schema");
    root_map.insert("$schema".into(), json!("https://json-schema.org/draft/2020-12/schema"));
    root_map.insert("title".into(), json!(title.lines().next().unwrap_or("TAD scenario")));
    root_map.insert("required".into(), json!(["environment", "road_network", "actors"]));
    root
}

fn object(place: Place, vocabulary: &Vocabulary) -> Value {
    let mut properties = Map::new();
    // an answer states no camera profile: it is judged as a dash-cam answer
    for key in dialect::written(place).into_iter().filter(|k| !matches!(k.tad, Tad::Profile)) {
        properties.insert(key.key.to_string(), value(key, vocabulary));
    }
    json!({ "type": "object", "properties": properties, "additionalProperties": false })
}

fn value(key: &Key, vocabulary: &Vocabulary) -> Value {
    if let Form::Fixed(v) = key.form {
        return json!({ "const": v });
    }
    match key.tad {
        Tad::Block(place) => object(place, vocabulary),
        Tad::Actors => json!({
            "type": "object",
            "properties": { (dialect::EGO_KEY): object(Place::Ego, vocabulary) },
            "required": [dialect::EGO_KEY],
            "additionalProperties": object(Place::Actor, vocabulary),
        }),
        Tad::ScenarioName => json!({ "type": "string", "pattern": NAME_PATTERN }),
        Tad::Uses => json!({ "type": "array", "items": { "type": "string", "pattern": "^[a-z_][a-z0-9_.]*$" } }),
        Tad::Type => names("actor_type", vocabulary),
        Tad::Count => json!({ "anyOf": [
            { "type": "integer", "minimum": 0 },
            { "type": "string", "pattern": "^[0-9]+ ?(-|\\.\\.) ?[0-9]+$" },
            { "const": UNSPECIFIED },
        ]}),
        Tad::Nothing => json!({ "type": "string" }),
        Tad::Profile => json!({ "enum": tad_yaml::PROFILES }),
        Tad::Field(..) => match (key.form, key.field()) {
            (Form::Relation, _) => names("relation", vocabulary),
            (Form::Target, _) => json!({ "type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_ -]*$" }),
            (Form::SignSummary, Some(field)) => {
                let mut schema = names(field.vocabulary.unwrap_or("traffic_sign"), vocabulary);
                add_name(&mut schema, "none");
                schema
            }
            (_, Some(field)) => field_value(field, vocabulary),
            (_, None) => json!({}),
        },
    }
}

fn field_value(field: &FieldDef, vocabulary: &Vocabulary) -> Value {
    let quantity = |units: &str| {
        let number = "-?[0-9]+(\\.[0-9]+)?";
        json!({ "anyOf": [
            { "type": "number" },
            { "type": "string", "pattern": format!("^{number}( ?-{number})? ?({units})?$") },
            { "const": UNSPECIFIED },
        ]})
    };
    match field.ty {
        ValueType::Symbol => {
            let kind = field.vocabulary.unwrap_or_default();
            let single = names(kind, vocabulary);
            if field.param {
                let words: Vec<String> = spellings(vocabulary, kind).iter().map(|s| regex_escape(s)).collect();
                let one = format!("(?:{})", words.join("|"));
                json!({ "anyOf": [single, { "type": "string", "pattern": format!("^{one}( \\| {one})+$") }] })
            } else {
                single
            }
        }
        ValueType::SymbolList => {
            let items = names(field.vocabulary.unwrap_or_default(), vocabulary);
            json!({ "anyOf": [{ "type": "array", "items": items }, { "const": UNSPECIFIED }] })
        }
        ValueType::Integer => json!({ "anyOf": [{ "type": "integer" }, { "const": UNSPECIFIED }] }),
        ValueType::Speed => quantity("km/h|mph|m/s"),
        ValueType::Duration => quantity("s"),
        ValueType::Length => quantity("m"),
        ValueType::Text | ValueType::Position => json!({ "type": "string" }),
        ValueType::Flag => json!({ "enum": ["yes", "no"] }),
        ValueType::Choice(words) => json!({ "enum": words }),
    }
}

/// Every spelling of every name of `kind` that reads back as the name.
fn spellings(vocabulary: &Vocabulary, kind: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for name in vocabulary.names(kind) {
        for spelt in [name.to_string(), name.replace('_', " "), name.replace('_', "-")] {
            if !out.contains(&spelt) {
                out.push(spelt);
            }
        }
    }
    out
}

fn names(kind: &str, vocabulary: &Vocabulary) -> Value {
    let mut all = spellings(vocabulary, kind);
    all.push(UNSPECIFIED.to_string());
    json!({ "enum": all })
}

fn add_name(schema: &mut Value, name: &str) {
    if let Some(Value::Array(list)) = schema.get_mut("enum") {
        list.push(json!(name));
    }
}

fn regex_escape(s: &str) -> String {
    s.chars().map(|c| if "\\.+*?()|[]{}^$".contains(c) { format!("\\{c}") } else { c.to_string() }).collect()
}
