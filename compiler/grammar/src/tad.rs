//! TAD's grammar in canonical layout, built from the schema (sections, fields, value
//! kinds, which fields take ranges or choices) and a vocabulary (every name field's
//! names as a closed set).
//!
//! It is the language `tadslc fmt` prints (`spec/language.md` §8): comment lines, `use`
//! lines, one scenario with its sections in canonical order, two-space indentation, one
//! field per line in the schema's order, each field at most once. A program in it parses;
//! the checker still judges most of its meaning (lanes against the road's `lanes`,
//! references, completeness). Rules of meaning are here where what they depend on is
//! written first. The type comes before the behaviour: each actor kind has its own group
//! rule, whose behaviours are those the kind performs (`performers`; the ego's are a
//! vehicle's), so a cyclist cannot `stand` (E0502). The road comes before the ego and the
//! groups: a profile ([`Profile`]) of its direction and lane count keeps them out of
//! negative lanes on a one-way road (E0501) and within the road's lanes (E0500). A group's
//! count is at least 1 (E0509). Each would otherwise cost a repair round.
//!
//! Numbers, names, strings and comment lines are bounded in length, and lists and the
//! groups in number, so that a decoder cannot run away inside one: a small model otherwise
//! repeats groups, list items or a sentence of a comment until its token limit cuts the
//! program short.

use tad_check::{EGO_KIND, Vocabulary, performs};
use tad_syntax::lexer::UNITS;
use tad_syntax::schema::{self, FieldDef, SectionDef, Unit, ValueType};

use crate::ir::{Expr, Grammar, alt, class, lit, not_class, opt, r, rep, seq, star};

/// The longest name a model may write (scenario and group names).
const NAME_MAX: u32 = 48;
/// Comment lines before the program: a translation's list of road users, which may wrap
/// once. SmolLM2-135M, allowed eight, filled them with one road user repeated and ran out
/// of tokens before the program.
const COMMENTS_MAX: u32 = 2;
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
    // the road, the ego and the groups, as one of the profiles
    let profiles = profiles();
    let alternatives = profiles.iter().map(|p| {
        // a road stating its direction as one-way or its lanes is written; otherwise optional
        let road = if p.one_way || p.lanes.is_some() { r(&p.rule("road")) } else { opt(r(&p.rule("road"))) };
        seq([road, opt(r(&p.rule("ego"))), rep(r(&p.rule("actor")), 0, GROUPS_MAX)])
    });
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
            alt(alternatives),
            lit("}"),
            opt(lit("\n")),
        ]),
    );
    if !modules.is_empty() {
        g.rule("module", alt(modules.iter().map(|m| lit(m.clone()))));
    }
    for section in [&schema::SOURCE, &schema::ENVIRONMENT] {
        g.rule(section.name, block(section, section_head(section), |f| opt(r(&field_rule(section, f)))));
    }
    for profile in &profiles {
        road_and_ego(&mut g, profile);
        actors(&mut g, vocabulary, profile);
    }
    behaviors(&mut g, vocabulary);
    directions(&mut g, vocabulary);
    // a group has at least one actor (E0509)
    g.rule("count", alt([seq([r("count-int"), opt(seq([lit(".."), r("count-int")]))]), lit("unspecified")]));

    // one rule per field, named after its section
    let mut kinds: Vec<&'static str> = vec!["relation", BEHAVIOR];
    for section in schema::SECTIONS.iter().copied().chain([&schema::ACTOR]) {
        for field in section.fields.iter().filter(|f| !by_profile(section, f)) {
            kinds.extend(field.vocabulary);
            g.rule(&field_rule(section, field), field_line(field, &kind_rule(field.vocabulary.unwrap_or("none"))));
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
    let mut seen = std::collections::HashSet::new();
    kinds.retain(|k| seen.insert(*k));
    for kind in kinds {
        let names: Vec<Expr> = vocabulary.names(kind).into_iter().map(lit).collect();
        // a kind nothing declares still needs a rule; `none` is the one name every list takes
        let names = if names.is_empty() { vec![lit("none")] } else { names };
        g.rule(&kind_rule(kind), alt(names));
    }

    g.terminal("name", seq([class(&[('a', 'z'), ('A', 'Z'), ('_', '_')]), rep(r("name-char"), 0, NAME_MAX - 1)]));
    g.terminal("name-char", class(&[('a', 'z'), ('A', 'Z'), ('0', '9'), ('_', '_')]));
    g.terminal("count-int", seq([class(&[('1', '9')]), rep(class(&[('0', '9')]), 0, 4)]));
    g.terminal("lane-index-one-way", rep(class(&[('0', '9')]), 1, 5));
    // a lane count no profile names: more than LANES_PROFILED (0 and below are errors, E0500)
    g.terminal(
        "lanes-many",
        alt([
            class(&[((b'0' + LANES_PROFILED as u8 + 1) as char, '9')]),
            seq([class(&[('1', '9')]), rep(class(&[('0', '9')]), 1, 4)]),
        ]),
    );
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

/// The field whose names depend on who performs them.
const BEHAVIOR: &str = "behavior";
/// The field that takes a lane index.
const LANE: &str = "lane";
/// The road's field that counts its lanes.
const LANES: &str = "lanes";

/// The road's lane counts that have a profile of their own; a larger count (the truths
/// have at most 5) leaves the lanes unbounded.
const LANES_PROFILED: u32 = 6;

/// Which lanes the ego and the groups may be in, decided by the road's `direction` and
/// `lanes`: on a direction without opposite lanes (`one_way`) no lane is negative (E0501),
/// and with `lanes: N` stated a lane is within ±N and not 0 (E0500). Each profile has its
/// own road, ego and actor rules.
struct Profile {
    one_way: bool,
    /// The road's `lanes`, or `None` where it is not stated, `unspecified` or above
    /// [`LANES_PROFILED`].
    lanes: Option<u32>,
}

fn profiles() -> Vec<Profile> {
    let lanes = std::iter::once(None).chain((1..=LANES_PROFILED).map(Some));
    lanes.flat_map(|lanes| [false, true].map(|one_way| Profile { one_way, lanes })).collect()
}

impl Profile {
    /// `base`'s rule in this profile: `road`, `road-one-way`, `road-lanes-2`, ...
    fn rule(&self, base: &str) -> String {
        let mut name = base.to_string();
        if self.one_way {
            name.push_str("-one-way");
        }
        if let Some(n) = self.lanes {
            name.push_str(&format!("-lanes-{n}"));
        }
        name
    }

    /// A `lane:` line of this profile.
    fn lane(&self, field: &FieldDef) -> Expr {
        let index = match self.lanes {
            Some(n) => {
                let ahead = (1..=n).map(|i| lit(i.to_string()));
                let opposite = (1..=n).map(|i| lit(format!("-{i}"))).filter(|_| !self.one_way);
                alt(ahead.chain(opposite))
            }
            None if self.one_way => r("lane-index-one-way"),
            None => r("int"),
        };
        seq([lit(format!("    {}: ", field.name)), alt([index, lit("unspecified")]), lit("\n")])
    }

    /// The road's `lanes:` line in this profile, optional where it is not stated.
    fn lanes_line(&self, field: &FieldDef) -> Expr {
        match self.lanes {
            Some(n) => seq([lit(format!("    {}: ", field.name)), lit(n.to_string()), lit("\n")]),
            None => {
                opt(seq([lit(format!("    {}: ", field.name)), alt([r("lanes-many"), lit("unspecified")]), lit("\n")]))
            }
        }
    }
}

fn section_head(section: &SectionDef) -> Expr {
    lit(format!("  {} {{\n", section.name))
}

/// The profile's `road` (its `direction` one of the profile's, stated when one-way; its
/// `lanes` the profile's) and `ego` (a vehicle's behaviours, the profile's lanes).
fn road_and_ego(g: &mut Grammar, profile: &Profile) {
    let road = &schema::ROAD;
    g.rule(
        &profile.rule("road"),
        block(road, section_head(road), |f| match f.name {
            // stated, and only a direction without opposite lanes: not `unspecified`
            "direction" if profile.one_way => seq([lit("    direction: "), r("direction-one-way-name"), lit("\n")]),
            "direction" => opt(field_line(f, "direction-opposite-name")),
            LANES => profile.lanes_line(f),
            _ => opt(r(&field_rule(road, f))),
        }),
    );
    let ego = &schema::EGO;
    g.rule(
        &profile.rule("ego"),
        block(ego, section_head(ego), |f| match f.name {
            BEHAVIOR => opt(field_line(f, &behavior_rule(EGO_KIND))),
            LANE => opt(profile.lane(f)),
            _ => opt(r(&field_rule(ego, f))),
        }),
    );
}

/// Whether the profiles write this field themselves rather than share one rule for it.
fn by_profile(section: &SectionDef, field: &FieldDef) -> bool {
    matches!((section.name, field.name), ("road", "direction" | LANES) | ("ego" | "actor", BEHAVIOR | LANE))
}

/// `actor` in `profile`: one alternative per actor kind that has types, its types in the
/// header and its performers' behaviours in the block; types without a kind take any
/// behaviour. A group names its type: one of type `unspecified` is nothing the layout can
/// place, and a model that has nothing to write fills groups with it.
fn actors(g: &mut Grammar, vocabulary: &Vocabulary, profile: &Profile) {
    let types = vocabulary.entries("actor_type");
    let mut groups = Vec::new();
    for kind in vocabulary.names("actor_kind") {
        let of_kind: Vec<Expr> =
            types.iter().filter(|t| t.symbol("kind") == Some(kind)).map(|t| lit(&t.name)).collect();
        if !of_kind.is_empty() {
            groups.push((profile.rule(&format!("actor-{}", kind.replace('_', "-"))), alt(of_kind), Some(kind)));
        }
    }
    let kindless: Vec<Expr> = types
        .iter()
        .filter(|t| t.symbol("kind").is_none_or(|k| vocabulary.get("actor_kind", k).is_none()))
        .map(|t| lit(&t.name))
        .collect();
    if !kindless.is_empty() {
        groups.push((profile.rule("actor-any"), alt(kindless), None));
    }

    let actor = &schema::ACTOR;
    for (rule, names, kind) in &groups {
        let header =
            seq([lit("  actor "), r("name"), lit(": "), opt(seq([r("count"), lit(" ")])), names.clone(), lit(" {\n")]);
        let behaviors = kind.map_or_else(|| kind_rule(BEHAVIOR), behavior_rule);
        g.rule(
            rule,
            block(actor, header, |f| match f.name {
                BEHAVIOR => opt(field_line(f, &behaviors)),
                LANE => opt(profile.lane(f)),
                _ => opt(r(&field_rule(actor, f))),
            }),
        );
    }
    g.rule(&profile.rule("actor"), alt(groups.iter().map(|(rule, _, _)| r(rule))));
}

/// Each actor kind's behaviours, and the ego's: those the kind performs (`performers`).
fn behaviors(g: &mut Grammar, vocabulary: &Vocabulary) {
    let mut kinds = vocabulary.names("actor_kind");
    if !kinds.contains(&EGO_KIND) {
        kinds.push(EGO_KIND);
    }
    for kind in kinds {
        let names: Vec<Expr> =
            vocabulary.entries(BEHAVIOR).into_iter().filter(|b| performs(b, kind)).map(|b| lit(&b.name)).collect();
        let names = if names.is_empty() { vec![lit("none")] } else { names };
        g.rule(&behavior_rule(kind), alt(names));
    }
}

/// The directions with opposite lanes (or not saying), and those without.
fn directions(g: &mut Grammar, vocabulary: &Vocabulary) {
    let (one_way, opposite): (Vec<_>, Vec<_>) =
        vocabulary.entries("direction").into_iter().partition(|d| d.flag("opposite_lanes") == Some(false));
    for (rule, names) in [("direction-one-way-name", one_way), ("direction-opposite-name", opposite)] {
        let names: Vec<Expr> = names.into_iter().map(|d| lit(&d.name)).collect();
        g.rule(rule, alt(if names.is_empty() { vec![lit("none")] } else { names }));
    }
}

fn behavior_rule(kind: &str) -> String {
    format!("behavior-of-{}", kind.replace('_', "-"))
}

/// `    FIELD: VALUE` and a newline, names of a name field from the rule `names`.
fn field_line(field: &FieldDef, names: &str) -> Expr {
    seq([lit(format!("    {}: ", field.name)), value(field, names), lit("\n")])
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

/// A section's block: its head, each field in the schema's order as `field` gives it, and
/// the closing brace.
fn block(section: &SectionDef, head: Expr, field: impl Fn(&FieldDef) -> Expr) -> Expr {
    let mut items = vec![head];
    items.extend(section.fields.iter().map(field));
    items.push(lit("  }\n"));
    seq(items)
}

/// The values a field takes, `unspecified` among them; a name field's names from the rule
/// `names`.
fn value(field: &FieldDef, names: &str) -> Expr {
    let given = match field.ty {
        ValueType::Symbol => {
            let name = r(names);
            if field.param { seq([name.clone(), rep(seq([lit(" | "), name]), 0, 7)]) } else { name }
        }
        ValueType::SymbolList => {
            let name = r(names);
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
