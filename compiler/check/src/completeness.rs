//! Completeness: TrafficAlign's semantic validation.
//!
//! The essential attributes are the schema's (`FieldDef::essential`: the environment's
//! weather and time; the road's type, lanes and direction; the ego's behavior, speed and
//! lane; every group's behavior, position and lane) plus a group's type and count when
//! its header says `unspecified`. An attribute is missing when absent or `unspecified`. A
//! scenario missing every essential group of `Options::non_scenario` (by default weather,
//! time and the road) is a non-scenario — a title card or a dashboard frame — to be
//! discarded; otherwise one missing anything is incomplete, to be refined; else complete.
//!
//! The checker states facts only: each missing element is a W0600 whose payload names the
//! element and its fields. The words of a refinement request are rendered from those
//! payloads elsewhere (`tad-feedback`), for whoever asks the extractor.

use crate::Options;
use tad_diagnostics::{Code, Diagnostic, Element, Payload, Span};
use tad_syntax::model::{Attr, Known, Scenario, Section};
use tad_syntax::schema::{self, SectionDef};

/// What the pipeline does with a scenario: keep it, refine it, discard it, or send it back
/// for repair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Class {
    /// No errors and every essential attribute stated: keep.
    Complete,
    /// No errors, but essential attributes missing: ask the extractor for them.
    Incomplete,
    /// Not a traffic scenario (a title card, a map): discard.
    NonScenario,
    /// Errors: send back for repair. Completeness is not judged.
    Invalid,
}

impl Class {
    pub const ALL: [Class; 4] = [Class::Complete, Class::Incomplete, Class::NonScenario, Class::Invalid];

    pub fn as_str(self) -> &'static str {
        match self {
            Class::Complete => "complete",
            Class::Incomplete => "incomplete",
            Class::NonScenario => "non_scenario",
            Class::Invalid => "invalid",
        }
    }

    /// The class of a scenario with `diagnostics` (all of them: syntax, structure,
    /// names, semantics), whose completeness alone gives `completeness`: any error makes
    /// it invalid.
    pub fn of(completeness: Class, diagnostics: &[Diagnostic]) -> Class {
        if diagnostics.iter().any(Diagnostic::is_error) { Class::Invalid } else { completeness }
    }
}

/// The groups of essential attributes a non-scenario rule is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Essential {
    Weather,
    Time,
    /// The road's essential fields, all of them.
    Road,
    /// The ego's essential fields, all of them.
    Ego,
    /// Any actor group.
    Actors,
}

impl Essential {
    pub const ALL: &'static [Essential] =
        &[Essential::Weather, Essential::Time, Essential::Road, Essential::Ego, Essential::Actors];

    pub fn as_str(self) -> &'static str {
        match self {
            Essential::Weather => "weather",
            Essential::Time => "time",
            Essential::Road => "road",
            Essential::Ego => "ego",
            Essential::Actors => "actors",
        }
    }

    pub fn parse(text: &str) -> Option<Essential> {
        Essential::ALL.iter().copied().find(|e| e.as_str() == text)
    }
}

fn present(attr: Option<&Attr>) -> bool {
    matches!(attr, Some(Attr { value: Known::Given(_), .. }))
}

/// The essential fields of `def` that `section` does not state.
fn absent(def: &SectionDef, section: Option<&Section>) -> Vec<String> {
    def.essential().filter(|f| !present(section.and_then(|s| s.attr(f.name)))).map(|f| f.name.to_string()).collect()
}

pub fn classify(scenario: &Scenario, options: &Options, prior: &[Diagnostic], out: &mut Vec<Diagnostic>) -> Class {
    let anchor = scenario.name.as_ref().map_or(Span::new(scenario.span.start, scenario.span.start + 8), |n| n.span);
    // A part with an error in it may state what could not be read; with an error in the
    // scenario outside its parts, a whole part may be lost. Neither is judged missing.
    let errors: Vec<Span> = prior.iter().filter(|d| d.is_error()).map(Diagnostic::span).collect();
    let damaged = |span: Span| errors.iter().any(|e| span.contains(*e));
    let parts: Vec<Span> =
        scenario.sections.iter().map(|s| s.span).chain(scenario.actors.iter().map(|g| g.span)).collect();
    let lost = errors.iter().any(|e| scenario.span.contains(*e) && !parts.iter().any(|p| p.contains(*e)));
    // (where to report, element, missing fields)
    let mut missing: Vec<(Span, Element, Vec<String>)> = Vec::new();
    for (def, element) in
        [(&schema::ENVIRONMENT, Element::Environment), (&schema::ROAD, Element::Road), (&schema::EGO, Element::Ego)]
    {
        let section = scenario.section(def.name);
        let judged = match section {
            Some(s) => !damaged(s.span),
            None => !lost,
        };
        let fields = absent(def, section);
        if judged && !fields.is_empty() {
            missing.push((section.map_or(anchor, |s| s.name_span), element, fields));
        }
    }
    for group in scenario.actors.iter().filter(|g| !damaged(g.span)) {
        let mut fields = Vec::new();
        if matches!(group.kind.value, Known::Unspecified) {
            fields.push("type".to_string());
        }
        if matches!(group.count.as_ref().map(|c| &c.value), Some(Known::Unspecified)) {
            fields.push("count".to_string());
        }
        fields.extend(schema::ACTOR.essential().filter(|f| !present(group.attr(f.name))).map(|f| f.name.to_string()));
        if !fields.is_empty() {
            missing.push((group.name.span, Element::Group { name: group.name.text.clone() }, fields));
        }
    }

    // a damaged section may state what could not be read: it is not gone
    let unread = |def: &SectionDef| scenario.section(def.name).is_some_and(|s| damaged(s.span));
    let none_of = |def: &SectionDef| !unread(def) && def.essential().all(|f| !present(scenario.attr(def.name, f.name)));
    let gone = |essential: Essential| match essential {
        Essential::Weather => !unread(&schema::ENVIRONMENT) && !present(scenario.attr("environment", "weather")),
        Essential::Time => !unread(&schema::ENVIRONMENT) && !present(scenario.attr("environment", "time")),
        Essential::Road => none_of(&schema::ROAD),
        Essential::Ego => none_of(&schema::EGO),
        Essential::Actors => scenario.actors.is_empty(),
    };
    if !lost && !options.non_scenario.is_empty() && options.non_scenario.iter().all(|e| gone(*e)) {
        let parts: Vec<&str> = options.non_scenario.iter().map(|e| e.as_str()).collect();
        out.push(
            Diagnostic::new(
                Code::W0601,
                "this does not describe a traffic scenario",
                anchor,
                format!("no {}", parts.join(", no ")),
            )
            .with_payload(Payload::NonScenario { absent: parts.iter().map(|p| p.to_string()).collect() })
            .with_note(
                "a frame without these is usually a title card, a map or a dashboard; it is classed `non_scenario`",
            ),
        );
        return Class::NonScenario;
    }
    if missing.is_empty() {
        return Class::Complete;
    }
    for (span, element, fields) in missing {
        let list: Vec<String> = fields.iter().map(|a| format!("`{a}`")).collect();
        let what = match &element {
            Element::Environment => "the environment".to_string(),
            Element::Road => "the road".to_string(),
            Element::Ego => "the ego vehicle".to_string(),
            Element::Group { name } => format!("group `{name}`"),
        };
        out.push(
            Diagnostic::new(Code::W0600, format!("{what} does not state its {}", join_and(&list)), span, "incomplete")
                .with_payload(Payload::Missing { element, fields })
                .with_help(
                    "state them, or write `unspecified` when the source does not say (it still counts as missing)",
                ),
        );
    }
    Class::Incomplete
}

fn join_and(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}
