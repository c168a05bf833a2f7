//! The prompts: versioned template files (`prompts/NAME.vN.txt`, embedded), rendered with
//! `{{name}}` variables into chat messages.
//!
//! A template has `## system`, `## example` and `## user` parts; the example goes after the
//! system text. What a prompt says about the language is rendered here from the schema and
//! the vocabulary in scope ([`vocabulary`]), and repair and refinement texts from the
//! diagnostics' payloads by `tad-feedback`: no list of names is written in a template.

use tad_check::Vocabulary;
use tad_llm::{Message, Role};
use tad_syntax::schema::{self, SectionDef, ValueType};

/// A prompt template: its name with version, and its text.
#[derive(Clone, Copy, Debug)]
pub struct Template {
    pub id: &'static str,
    text: &'static str,
}

macro_rules! template {
    ($name:ident, $id:literal) => {
        pub const $name: Template = Template { id: $id, text: include_str!(concat!("../prompts/", $id, ".txt")) };
    };
}

template!(DESCRIBE, "describe.v1");
template!(TRANSLATE, "translate.v9");
template!(GENERATE, "generate.v1");
template!(GENERATE_TUNED, "generate-tuned.v1");
template!(REPAIR, "repair.v1");
template!(REFINE, "refine.v1");
template!(REFINE_DESCRIPTION, "refine-description.v1");

pub const ALL: &[Template] = &[DESCRIBE, TRANSLATE, GENERATE, GENERATE_TUNED, REPAIR, REFINE, REFINE_DESCRIPTION];

/// The rendered parts of a template.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rendered {
    pub system: Option<String>,
    pub user: String,
}

impl Template {
    /// The template with `{{name}}` replaced by `vars`' values; unknown names are left out.
    pub fn render(&self, vars: &[(&str, &str)]) -> Rendered {
        let mut system = Vec::new();
        let mut user = Vec::new();
        let mut current: Option<&mut Vec<String>> = None;
        for line in self.text.lines() {
            match line.trim_end() {
                "## system" | "## example" => current = Some(&mut system),
                "## user" => current = Some(&mut user),
                _ => {
                    if let Some(target) = current.as_deref_mut() {
                        target.push(fill(line, vars));
                    }
                }
            }
        }
        let join = |lines: Vec<String>| lines.join("\n").trim().to_string();
        let system = join(system);
        Rendered { system: (!system.is_empty()).then_some(system), user: join(user) }
    }

    /// The template as messages: a system message (if any) and the user message.
    pub fn messages(&self, vars: &[(&str, &str)]) -> Vec<Message> {
        let rendered = self.render(vars);
        let mut out = Vec::new();
        if let Some(system) = rendered.system {
            out.push(Message::text(Role::System, system));
        }
        out.push(Message::text(Role::User, rendered.user));
        out
    }
}

fn fill(line: &str, vars: &[(&str, &str)]) -> String {
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find("{{") {
        let Some(len) = rest[start..].find("}}") else { break };
        out.push_str(&rest[..start]);
        let name = &rest[start + 2..start + len];
        out.push_str(vars.iter().find(|(n, _)| *n == name).map(|(_, v)| *v).unwrap_or(""));
        rest = &rest[start + len + 2..];
    }
    out.push_str(rest);
    out
}

/// Every section's fields and what they take, the names from `vocabulary`:
/// `road.type: straight_road, curve, ...`. Names a standard module declares follow the
/// prelude's, after the `use` line they need.
pub fn vocabulary(vocabulary: &Vocabulary) -> String {
    let mut out = Vec::new();
    let sections: Vec<&SectionDef> = schema::SECTIONS.iter().copied().filter(|s| s.name != "source").collect();
    for section in sections.into_iter().chain([&schema::ACTOR]) {
        for field in section.fields {
            let what = match (field.ty, field.vocabulary) {
                (ValueType::Symbol | ValueType::SymbolList, Some(kind)) => {
                    let names = names(vocabulary, kind);
                    if field.ty == ValueType::SymbolList { format!("a list of [{names}], [] for none") } else { names }
                }
                (ValueType::Choice(words), _) => words.join(", "),
                (ValueType::Position, _) => {
                    format!("RELATION of REFERENCE; relations: {}", names(vocabulary, "relation"))
                }
                (ty, _) => format!("{} (e.g. {})", ty.describe(), field.example),
            };
            let param = if field.param && matches!(field.ty, ValueType::Symbol) { "; or a choice a | b" } else { "" };
            let range = match field.param && !matches!(field.ty, ValueType::Symbol) {
                true => format!("; or a range {}", range_example(field.example)),
                false => String::new(),
            };
            out.push(format!("- {}.{}: {what}{param}{range}", section.name, field.name));
        }
    }
    out.push(format!("- actor header TYPE: {}", names(vocabulary, "actor_type")));
    out.join("\n")
}

/// A kind's canonical names: the prelude's, then each standard module's after
/// "with `use M`:".
fn names(vocabulary: &Vocabulary, kind: &str) -> String {
    let mut groups: Vec<(&str, Vec<&str>)> = Vec::new();
    for entry in vocabulary.entries(kind) {
        match groups.iter_mut().find(|(module, _)| *module == entry.module) {
            Some((_, names)) => names.push(&entry.name),
            None => groups.push((&entry.module, vec![&entry.name])),
        }
    }
    let shown = groups.iter().map(|(module, names)| match *module == tad_db::PRELUDE {
        true => names.join(", "),
        false => format!("with `use {module}`: {}", names.join(", ")),
    });
    shown.collect::<Vec<_>>().join("; ")
}

/// A range in the unit of a field's example (`15 m` gives `15..30 m`).
fn range_example(example: &str) -> String {
    let (number, unit) = example.split_once(' ').unwrap_or((example, ""));
    let twice = number.parse::<f64>().map(|n| n * 2.0).unwrap_or(0.0);
    format!("{number}..{twice} {unit}").trim_end().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn templates_render_their_variables_and_have_a_user_part() {
        for t in ALL {
            assert!(!t.render(&[]).user.is_empty(), "{} has no user part", t.id);
        }
        let r = REPAIR.render(&[("diagnostics", "E0500 3:5: unknown weather")]);
        assert!(r.system.is_none() && r.user.contains("E0500 3:5: unknown weather"));
        assert!(!TRANSLATE.render(&[]).system.unwrap().contains("{{"));
    }

    #[test]
    fn the_vocabulary_comes_from_declarations() {
        let (vocabulary, _) = tad_grammar::scope(Some("yellowstone")).unwrap();
        let text = super::vocabulary(&vocabulary);
        assert!(text.contains("- environment.weather: clear, cloudy"), "{text}");
        assert!(text.contains("bison"), "the region's module is in scope");
        assert!(text.contains("with `use national_park`: elk, bison"), "{text}");
        let (core, _) = tad_grammar::scope(Some("los_angeles")).unwrap();
        assert!(!super::vocabulary(&core).contains("bison"));
    }
}
