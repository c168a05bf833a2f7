//! A model printed as canonical TAD source.

use tad_syntax::model::*;
use tad_syntax::schema::{self, SectionDef};

const INDENT: &str = "  ";

/// Print `module` as TAD source in the layout of `tadslc fmt`: `use` items, then
/// declarations, then the scenario, separated by blank lines; sections in canonical order
/// (`source`, `environment`, `road`, `ego`), then actor groups in model order; fields in
/// schema order, one per line. Symbols print as their names, quantities as written (value
/// and unit), lists as `[a, b]`, positions as `rel of ref`, text as a `"""` block when it
/// has a line break and a block represents it exactly, else as an escaped string. A
/// scenario without a name is printed `scenario unnamed`. Comments are not in the model,
/// so none are printed.
pub fn to_tad(module: &Module) -> String {
    let mut groups: Vec<String> = Vec::new();
    if !module.uses.is_empty() {
        let mut out = String::new();
        for u in &module.uses {
            let path: Vec<&str> = u.path.iter().map(|n| n.text.as_str()).collect();
            out.push_str(&format!("use {}\n", path.join(".")));
        }
        groups.push(out);
    }
    if !module.declarations.is_empty() {
        let mut out = String::new();
        for d in &module.declarations {
            out.push_str(&format!("{} {}", d.def.name, d.name.text));
            if !d.attrs.is_empty() {
                out.push_str(" {\n");
                attrs(&mut out, d.def, &d.attrs, 1);
                out.push('}');
            }
            out.push('\n');
        }
        groups.push(out);
    }
    if let Some(s) = &module.scenario {
        groups.push(scenario(s));
    }
    groups.join("\n")
}

fn scenario(s: &Scenario) -> String {
    let mut out = format!("scenario {} {{\n", s.name.as_ref().map_or("unnamed", |n| n.text.as_str()));
    let mut sections: Vec<&Section> = s.sections.iter().collect();
    sections.sort_by_key(|sec| schema::SECTIONS.iter().position(|d| d.name == sec.def.name));
    for section in sections {
        out.push_str(&format!("{INDENT}{} {{\n", section.def.name));
        attrs(&mut out, section.def, &section.attrs, 2);
        out.push_str(&format!("{INDENT}}}\n"));
    }
    for actor in &s.actors {
        let mut head = format!("{INDENT}actor {}: ", actor.name.text);
        match &actor.count {
            Some(Spanned { value: Known::Given(n), .. }) => head.push_str(&format!("{n} ")),
            Some(Spanned { value: Known::Unspecified, .. }) => head.push_str("unspecified "),
            None => {}
        }
        match &actor.kind.value {
            Known::Given(kind) => head.push_str(&kind.name),
            Known::Unspecified => head.push_str("unspecified"),
        }
        out.push_str(&head);
        out.push_str(" {\n");
        attrs(&mut out, &schema::ACTOR, &actor.attrs, 2);
        out.push_str(&format!("{INDENT}}}\n"));
    }
    out.push_str("}\n");
    out
}

fn attrs(out: &mut String, def: &SectionDef, attrs: &[Attr], depth: usize) {
    let mut sorted: Vec<&Attr> = attrs.iter().collect();
    sorted.sort_by_key(|a| def.fields.iter().position(|f| f.name == a.def.name));
    for a in sorted {
        out.push_str(&INDENT.repeat(depth));
        out.push_str(a.def.name);
        out.push_str(": ");
        out.push_str(&value(&a.value, depth));
        out.push('\n');
    }
}

/// One value as TAD source; `depth` is the indentation of its field (for text blocks).
pub fn value(v: &Known<Val>, depth: usize) -> String {
    let Known::Given(v) = v else { return "unspecified".into() };
    match v {
        Val::Symbol(s) => s.name.clone(),
        Val::Symbols(list) => format!("[{}]", list.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")),
        Val::Integer(n) => n.to_string(),
        Val::Quantity(q) => format!("{} {}", number(q.value), q.unit.as_str()),
        Val::Text(t) => text(t, depth),
        Val::Position(p) => format!("{} of {}", p.relation.name, p.reference.name),
        Val::Flag(b) => (if *b { "yes" } else { "no" }).into(),
        Val::Range(low, high) => format!("{}..{} {}", number(low.value), number(high.value), high.unit.as_str()),
        Val::Choice(options) => options.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(" | "),
    }
}

/// A number as TAD writes it: the shortest decimal that reads back as the same value.
pub fn number(value: f64) -> String {
    format!("{value}")
}

fn text(t: &str, depth: usize) -> String {
    // (non-ASCII whitespace is kept out of blocks: the block reader measures indentation
    // in bytes)
    let ascii_space = !t.chars().any(|c| c.is_whitespace() && !c.is_ascii());
    if t.contains('\n') && !t.contains("\"\"\"") && ascii_space {
        let mut block = String::from("\"\"\"");
        for line in t.split('\n') {
            block.push('\n');
            if !line.is_empty() {
                block.push_str(&INDENT.repeat(depth + 1));
                block.push_str(line);
            }
        }
        block.push('\n');
        block.push_str(&INDENT.repeat(depth));
        block.push_str("\"\"\"");
        if tad_syntax::lexer::text_block_content(&block) == t {
            return block;
        }
    }
    escaped(t)
}

/// `t` as a TAD string literal.
pub fn escaped(t: &str) -> String {
    tad_syntax::lexer::string_literal(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_strings() {
        assert_eq!(number(38.0), "38");
        assert_eq!(number(3.5), "3.5");
        assert_eq!(number(-1.0), "-1");
        assert_eq!(escaped("a \"b\"\\\n\u{1}"), "\"a \\\"b\\\"\\\\\\n\\u{1}\"");
    }

    #[test]
    fn text_blocks_only_when_exact() {
        assert!(text("one\ntwo", 2).starts_with("\"\"\"\n      one\n      two\n    \"\"\""));
        assert!(text("one\ntwo\n", 2).starts_with('"'), "a trailing line break needs a string");
        assert!(text("  indented\n  both", 2).starts_with('"'));
        assert!(text("one", 2).starts_with('"'));
    }
}
