//! Name resolution: every name in its field's vocabulary, references to groups and road
//! elements, aliases and units brought to their canonical form.

use crate::vocab::{Lookup, Vocabulary};
use std::collections::HashMap;
use tad_diagnostics::{Applicability, Code, Diagnostic, Payload, Span};
use tad_syntax::model::{Attr, Known, Scenario, Symbol, Val};
use tad_syntax::schema::{FieldDef, Unit};

/// What a group's position refers to.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    Ego,
    Group(usize),
    RoadElement(String),
}

/// Resolution results the later passes use, by actor group index.
#[derive(Debug, Default)]
pub struct Resolved {
    pub targets: HashMap<usize, Target>,
}

fn kind_label(kind: &str) -> String {
    kind.replace('_', " ")
}

/// Resolve `symbol` in `kind`: an unknown name is an error, an alias a warning with a fix.
pub fn resolve_symbol(vocabulary: &Vocabulary, kind: &str, field: &str, symbol: &Symbol, out: &mut Vec<Diagnostic>) {
    match vocabulary.lookup(kind, &symbol.name) {
        Lookup::Exact(_) => {}
        Lookup::Alias(entry) => out.push(
            Diagnostic::new(
                Code::W0401,
                format!("`{}` is another name for the {} `{}`", symbol.name, kind_label(kind), entry.name),
                symbol.span,
                "an alias",
            )
            .with_payload(Payload::Alias {
                namespace: kind.to_string(),
                written: symbol.name.clone(),
                canonical: entry.name.clone(),
            })
            .with_help(format!("write `{}`", entry.name))
            .with_fix(symbol.span, entry.name.clone(), Applicability::MachineApplicable),
        ),
        Lookup::Unknown => {
            let mut d = Diagnostic::new(
                Code::E0400,
                format!("unknown {} `{}`", kind_label(kind), symbol.name),
                symbol.span,
                format!("not {} `{field}` can take", tad_base::a(&kind_label(kind))),
            );
            let candidates = vocabulary.candidates(kind, &symbol.name, 5);
            // a name another standard module declares is not a typo
            let elsewhere = vocabulary.declared_elsewhere(kind, &symbol.name);
            if let (None, Some(guess)) = (elsewhere, candidates.first()) {
                d = d.with_help(format!("did you mean `{guess}`?")).with_fix(
                    symbol.span,
                    guess.to_string(),
                    Applicability::MaybeIncorrect,
                );
            }
            d = d.with_payload(Payload::Unknown {
                namespace: kind.to_string(),
                name: symbol.name.clone(),
                candidates: candidates.iter().map(|c| c.to_string()).collect(),
                module: elsewhere.map(str::to_string),
            });
            let names = vocabulary.names(kind);
            d = if let Some(module) = elsewhere {
                let regions: Vec<&str> = vocabulary
                    .entries("region")
                    .into_iter()
                    .filter(|r| r.symbol("module") == Some(module))
                    .map(|r| r.name.as_str())
                    .collect();
                let region = regions.first().map_or(String::new(), |r| {
                    format!(", or name the region (`source {{ region: {r} }}`, or `--region {r}`)")
                });
                d.with_help(format!(
                    "`{}` is declared in the standard module `{module}`: write `use {module}` at the top{region}",
                    symbol.name
                ))
                .with_fix(
                    Span { start: 0, end: 0 },
                    format!("use {module}\n"),
                    Applicability::MachineApplicable,
                )
            } else if names.is_empty() {
                d.with_note(format!("no {} is declared; is a `use` missing?", kind_label(kind)))
            } else if names.len() <= 12 {
                d.with_note(format!("the {} names are {}", kind_label(kind), quoted(&names)))
            } else {
                d.with_note(format!("declare it with `{kind} {} {{ ... }}` if it is new", symbol.name))
            };
            out.push(d);
        }
    }
}

pub fn quoted(names: &[&str]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}

/// Names in one attribute, by its field's vocabulary.
fn attr(vocabulary: &Vocabulary, attr: &Attr, out: &mut Vec<Diagnostic>) {
    let Known::Given(value) = &attr.value else { return };
    let def: &FieldDef = attr.def;
    match (value, def.vocabulary) {
        (Val::Symbol(symbol), Some(kind)) => resolve_symbol(vocabulary, kind, def.name, symbol, out),
        (Val::Symbols(symbols) | Val::Choice(symbols), Some(kind)) => {
            for symbol in symbols {
                resolve_symbol(vocabulary, kind, def.name, symbol, out);
            }
        }
        (Val::Quantity(q), _) if matches!(q.unit, Unit::MilesPerHour | Unit::MetresPerSecond) => {
            let kmh = q.si() * 3.6;
            let text = format_number(kmh);
            out.push(
                Diagnostic::new(
                    Code::W0402,
                    format!(
                        "speeds are written in km/h: {} {} is {text} km/h",
                        format_number(q.value),
                        q.unit.as_str()
                    ),
                    attr.value_span,
                    "not in km/h",
                )
                .with_payload(Payload::Alias {
                    namespace: "unit".into(),
                    written: format!("{} {}", format_number(q.value), q.unit.as_str()),
                    canonical: format!("{text} km/h"),
                })
                .with_help(format!("write `{text} km/h`"))
                .with_fix(attr.value_span, format!("{text} km/h"), Applicability::MachineApplicable),
            );
        }
        (Val::Range(low, high), _) if matches!(low.unit, Unit::MilesPerHour | Unit::MetresPerSecond) => {
            let (lo, hi) = (format_number(low.si() * 3.6), format_number(high.si() * 3.6));
            let written = format!("{}..{} {}", format_number(low.value), format_number(high.value), low.unit.as_str());
            out.push(
                Diagnostic::new(
                    Code::W0402,
                    format!("speeds are written in km/h: {written} is {lo}..{hi} km/h"),
                    attr.value_span,
                    "not in km/h",
                )
                .with_payload(Payload::Alias {
                    namespace: "unit".into(),
                    written,
                    canonical: format!("{lo}..{hi} km/h"),
                })
                .with_help(format!("write `{lo}..{hi} km/h`"))
                .with_fix(
                    attr.value_span,
                    format!("{lo}..{hi} km/h"),
                    Applicability::MachineApplicable,
                ),
            );
        }
        _ => {}
    }
}

/// A number to one decimal, without a trailing `.0`.
pub fn format_number(value: f64) -> String {
    let rounded = (value * 10.0).round() / 10.0;
    if rounded.fract() == 0.0 { format!("{}", rounded as i64) } else { format!("{rounded:.1}") }
}

/// Names inside the file's own declarations.
pub fn declarations(module: &tad_syntax::model::Module, vocabulary: &Vocabulary, out: &mut Vec<Diagnostic>) {
    for declaration in &module.declarations {
        for a in declaration.attrs.iter().filter(|a| a.def.name != "aliases") {
            attr(vocabulary, a, out);
        }
    }
}

/// Names in the scenario; returns what positions refer to.
pub fn scenario(scenario: &Scenario, vocabulary: &Vocabulary, out: &mut Vec<Diagnostic>) -> Resolved {
    let mut resolved = Resolved::default();
    let groups = Groups::new(scenario);
    for section in &scenario.sections {
        for a in &section.attrs {
            attr(vocabulary, a, out);
        }
    }
    for (index, group) in scenario.actors.iter().enumerate() {
        if let Known::Given(kind) = &group.kind.value {
            resolve_symbol(vocabulary, "actor_type", "type", kind, out);
        }
        for a in &group.attrs {
            attr(vocabulary, a, out);
            let Known::Given(Val::Position(position)) = &a.value else { continue };
            resolve_symbol(vocabulary, "relation", "position", &position.relation, out);
            if let Some(target) = reference(scenario, index, &groups, vocabulary, &position.reference, out) {
                resolved.targets.insert(index, target);
            }
        }
    }
    resolved
}

/// The actor groups of a scenario by name, built once for all its positions (a scenario
/// may have hundreds of groups).
pub struct Groups<'s>(HashMap<&'s str, usize>);

impl<'s> Groups<'s> {
    pub fn new(scenario: &'s Scenario) -> Self {
        let mut index = HashMap::with_capacity(scenario.actors.len());
        for (i, g) in scenario.actors.iter().enumerate() {
            // the first of a name wins, as a linear search would
            index.entry(g.name.text.as_str()).or_insert(i);
        }
        Groups(index)
    }
}

/// What a position's reference names, in this order: an actor group of the scenario, a
/// `reference` (`ego`) or a `road_element` (by name or alias); `None` for anything else.
pub fn target(groups: &Groups<'_>, vocabulary: &Vocabulary, name: &str) -> Option<Target> {
    if let Some(&i) = groups.0.get(name) {
        return Some(Target::Group(i));
    }
    if vocabulary.get("reference", name).is_some() {
        return Some(Target::Ego);
    }
    vocabulary.get("road_element", name).map(|entry| Target::RoadElement(entry.name.clone()))
}

/// The one group an unknown reference most likely means, and why, when a typo's distance
/// finds none: a reference is often the group described (`parked_suv` for the only `suv`
/// group, whatever it is called), or shares a word with one group's name (`lead` and
/// `lead_car`). Words are the name's `_`-separated parts; types compare by their canonical
/// names, so `suvs` finds `suv`. The group holding the position (`holder`) is not a
/// candidate: it cannot be placed relative to itself.
fn meant_group<'s>(
    scenario: &'s Scenario,
    holder: usize,
    vocabulary: &Vocabulary,
    name: &str,
) -> Option<(&'s str, String)> {
    let canonical = |word: &str| vocabulary.lookup("actor_type", word).entry().map(|e| e.name.clone());
    let words: Vec<&str> = name.split('_').filter(|w| !w.is_empty()).collect();
    let types: Vec<String> = words.iter().filter_map(|w| canonical(w)).collect();
    let only = |matching: Vec<(&'s str, String)>| <[_; 1]>::try_from(matching).ok().map(|[g]| g);
    let others = || scenario.actors.iter().enumerate().filter(move |(i, _)| *i != holder).map(|(_, g)| g);
    let of_type = others()
        .filter_map(|g| Some((g.name.text.as_str(), canonical(&g.kind.value.given()?.name)?)))
        .filter(|(_, kind)| types.contains(kind))
        .map(|(group, kind)| (group, format!("the only `{kind}` group")))
        .collect();
    only(of_type).or_else(|| {
        let sharing = others()
            .map(|g| g.name.text.as_str())
            .filter(|g| g.split('_').any(|w| !w.is_empty() && words.contains(&w)))
            .map(|g| (g, "the only group whose name shares a word with it".to_string()))
            .collect();
        only(sharing)
    })
}

/// A position's reference, reported when it names nothing and when written as an alias.
fn reference(
    scenario: &Scenario,
    holder: usize,
    groups: &Groups<'_>,
    vocabulary: &Vocabulary,
    symbol: &Symbol,
    out: &mut Vec<Diagnostic>,
) -> Option<Target> {
    if let Some(target) = target(groups, vocabulary, &symbol.name) {
        match target {
            Target::Group(_) => {}
            Target::Ego => resolve_symbol(vocabulary, "reference", "position", symbol, out),
            Target::RoadElement(_) => resolve_symbol(vocabulary, "road_element", "position", symbol, out),
        }
        return Some(target);
    }
    let groups: Vec<&str> = scenario.actors.iter().map(|g| g.name.text.as_str()).collect();
    let mut candidates: Vec<&str> = groups.clone();
    candidates.extend(vocabulary.names("reference"));
    candidates.extend(vocabulary.names("road_element"));
    let d = Diagnostic::new(
        Code::E0402,
        format!("unknown reference `{}`", symbol.name),
        symbol.span,
        "not `ego`, an actor group or a road element",
    );
    let (mut d, guessed) = tad_syntax::suggest::unknown(d, "reference", &symbol.name, symbol.span, candidates);
    if !guessed {
        d = match meant_group(scenario, holder, vocabulary, &symbol.name) {
            Some((group, why)) => d.with_help(format!("did you mean `{group}`, {why}?")).with_fix(
                symbol.span,
                group.to_string(),
                Applicability::MaybeIncorrect,
            ),
            None => d.with_help(format!(
                "declare an actor group `{}`, or place this one relative to `ego`, a road element or another group",
                symbol.name
            )),
        };
    }
    if !groups.is_empty() {
        d = d.with_note(format!("the actor groups are {}", quoted(&groups)));
    }
    out.push(d);
    None
}
