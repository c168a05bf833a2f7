//! TAD's grammar in canonical layout, built from the schema (sections, fields, value
//! kinds, which fields take ranges or choices) and a vocabulary (every name field's
//! names as a closed set).
//!
//! It is the language `tadslc fmt` prints (`spec/language.md` §8): comment lines, `use`
//! lines, one scenario with its sections in canonical order, two-space indentation, one
//! field per line in the schema's order, each field at most once. A program in it parses;
//! the checker still judges its meaning (lanes against the road, behaviours against the
//! actor's kind, completeness). Numbers, names, strings and comment lines are bounded in
//! length, and lists and the groups in number, so that a decoder cannot run away inside one:
//! a small model otherwise repeats groups, list items or a sentence of a comment until its
//! token limit cuts the program short.

use tad_check::Vocabulary;
use tad_syntax::lexer::UNITS;
use tad_syntax::schema::{self, FieldDef, SectionDef, Unit, ValueType};

use crate::ir::{Expr, Grammar, alt, class, lit, not_class, opt, r, rep, seq, star};

/// The longest name a model may write (scenario and group names).
const NAME_MAX: u32 = 48;
/// Comment lines before the program.
const COMMENTS_MAX: u32 = 8;
/// Characters in a comment line after `//`.
const COMMENT_MAX: u32 = 120;
/// Characters in a string, and in a text block (a `source.description`, which answers need
/// not write: the benchmark's longest description has 642).
const STRING_MAX: u32 = 200;
const TEXT_MAX: u32 = 1000;
/// Actor groups in a scenario (the examples and the benchmark's truths have at most 5).
const GROUPS_MAX: u32 = 12;
/// Names in a list field (the examples and truths have at most 5).
const LIST_MAX: u32 = 8;

pub fn grammar(vocabulary: &Vocabulary, modules: &[String]) -> Grammar {
    let mut g = Grammar::default();
    let uses = if modules.is_empty() { opt(lit("\n")) } else { star(seq([lit("use "), r("module"), lit("\n")])) };
    g.rule(
        "file",
        seq([
            rep(r("comment"), 0, COMMENTS_MAX),
            uses,
            opt(lit("\n")),
            lit("scenario "),
            r("name"),
            lit(" {\n"),
            opt(r("source")),
            opt(r("environment")),
            opt(r("road")),
            opt(r("ego")),
            rep(r("actor"), 0, GROUPS_MAX),
            lit("}"),
            opt(lit("\n")),
        ]),
    );
    if !modules.is_empty() {
        g.rule("module", alt(modules.iter().map(|m| lit(m.clone()))));
    }
    let mut kinds: Vec<&'static str> = Vec::new();
    for section in schema::SECTIONS {
        g.rule(section.name, block(section, lit(format!("  {} {{\n", section.name)), "  ", &mut kinds));
    }
    let header = seq([
        lit("  actor "),
        r("name"),
        lit(": "),
        opt(seq([r("count"), lit(" ")])),
        alt([r(&kind_rule("actor_type")), lit("unspecified")]),
        lit(" {\n"),
    ]);
    g.rule("actor", block(&schema::ACTOR, header, "  ", &mut kinds));
    g.rule("count", alt([seq([r("int"), opt(seq([lit(".."), r("int")]))]), lit("unspecified")]));
    kinds.push("actor_type");
    kinds.push("relation");

    // one rule per field, named after its section
    for section in schema::SECTIONS.iter().copied().chain([&schema::ACTOR]) {
        for field in section.fields {
            g.rule(&field_rule(section, field), seq([lit(format!("    {}: ", field.name)), value(field), lit("\n")]));
        }
    }
    g.rule("position", seq([r(&kind_rule("relation")), lit(" of "), r("name")]));
    for unit_kind in [ValueType::Speed, ValueType::Duration, ValueType::Length] {
        let units: Vec<Expr> = UNITS
            .iter()
            .filter(|u| Unit::parse(u).is_some_and(|u| u.measures() == unit_kind))
            .map(|u| lit(*u))
            .collect();
        g.rule(&unit_rule(unit_kind), alt(units));
    }
    kinds.dedup();
    for kind in kinds {
        let names: Vec<Expr> = vocabulary.names(kind).into_iter().map(lit).collect();
        // a kind nothing declares still needs a rule; `none` is the one name every list takes
        let names = if names.is_empty() { vec![lit("none")] } else { names };
        g.rule(&kind_rule(kind), alt(names));
    }

    g.terminal("name", seq([class(&[('a', 'z'), ('A', 'Z'), ('_', '_')]), rep(r("name-char"), 0, NAME_MAX - 1)]));
    g.terminal("name-char", class(&[('a', 'z'), ('A', 'Z'), ('0', '9'), ('_', '_')]));
    g.terminal("int", seq([opt(lit("-")), rep(class(&[('0', '9')]), 1, 5)]));
    g.terminal(
        "number",
        seq([opt(lit("-")), rep(class(&[('0', '9')]), 1, 5), opt(seq([lit("."), rep(class(&[('0', '9')]), 1, 4)]))]),
    );
    g.terminal(
        "string",
        seq([
            lit("\""),
            rep(
                alt([
                    not_class(&['"', '\\', '\n']),
                    seq([lit("\\"), class(&[('"', '"'), ('\\', '\\'), ('n', 'n'), ('t', 't')])]),
                ]),
                0,
                STRING_MAX,
            ),
            lit("\""),
        ]),
    );
    g.terminal("text-block", seq([lit("\"\"\""), rep(not_class(&['"']), 0, TEXT_MAX), lit("\"\"\"")]));
    g.terminal("comment", seq([lit("//"), rep(not_class(&['\n']), 0, COMMENT_MAX), lit("\n")]));
    g
}

fn field_rule(section: &SectionDef, field: &FieldDef) -> String {
    format!("{}-{}", section.name, field.name.replace('_', "-"))
}

fn kind_rule(kind: &str) -> String {
    format!("{}-name", kind.replace('_', "-"))
}

fn unit_rule(kind: ValueType) -> String {
    format!("{}-unit", kind.describe().trim_start_matches("a ").replace(' ', "-"))
}

fn block(section: &SectionDef, head: Expr, indent: &str, kinds: &mut Vec<&'static str>) -> Expr {
    let mut items = vec![head];
    for field in section.fields {
        if let Some(kind) = field.vocabulary {
            kinds.push(kind);
        }
        items.push(opt(r(&field_rule(section, field))));
    }
    items.push(lit(format!("{indent}}}\n")));
    seq(items)
}

/// The values a field takes, `unspecified` among them.
fn value(field: &FieldDef) -> Expr {
    let given = match field.ty {
        ValueType::Symbol => {
            let name = r(&kind_rule(field.vocabulary.unwrap_or("none")));
            if field.param { seq([name.clone(), rep(seq([lit(" | "), name]), 0, 7)]) } else { name }
        }
        ValueType::SymbolList => {
            let name = r(&kind_rule(field.vocabulary.unwrap_or("none")));
            alt([lit("[]"), seq([lit("["), name.clone(), rep(seq([lit(", "), name]), 0, LIST_MAX - 1), lit("]")])])
        }
        ValueType::Integer => r("int"),
        ValueType::Speed | ValueType::Duration | ValueType::Length => {
            let unit = r(&unit_rule(field.ty));
            if field.param {
                seq([r("number"), opt(seq([lit(".."), r("number")])), lit(" "), unit])
            } else {
                seq([r("number"), lit(" "), unit])
            }
        }
        ValueType::Text => alt([r("string"), r("text-block")]),
        ValueType::Position => r("position"),
        ValueType::Flag => alt([lit("yes"), lit("no")]),
        ValueType::Choice(words) => alt(words.iter().map(|w| lit(*w))),
    };
    alt([given, lit("unspecified")])
}
