//! Completeness: TrafficAlign's semantic validation.
//!
//! Essential attributes: the environment's weather and time; the road's type, lanes and
//! direction; the ego's behavior, speed and lane; every group's type, count, behavior,
//! position and lane. An attribute is missing when absent or `unspecified`. A scenario
//! missing every essential group of `Options::non_scenario` (by default weather, time and
//! the road) is a non-scenario — a title card or a dashboard frame — to be discarded;
//! otherwise one missing anything is incomplete, to be refined; else complete. Each
//! missing attribute yields a concrete request for the extractor.

use crate::Options;
use crate::vocab::Vocabulary;
use tad_diagnostics::{Code, Diagnostic, Span};
use tad_syntax::model::{Attr, Known, Scenario};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Class {
    Complete,
    Incomplete,
    NonScenario,
}

impl Class {
    pub fn as_str(self) -> &'static str {
        match self {
            Class::Complete => "complete",
            Class::Incomplete => "incomplete",
            Class::NonScenario => "non_scenario",
        }
    }
}

/// The groups of essential attributes a non-scenario rule is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Essential {
    Weather,
    Time,
    /// The road's type, lanes and direction, all of them.
    Road,
    /// The ego's behavior, speed and lane, all of them.
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

fn one_of(vocabulary: &Vocabulary, kind: &str) -> String {
    let names = vocabulary.names(kind);
    if names.is_empty() { String::new() } else { format!(" (one of: {})", names.join(", ")) }
}

struct Missing {
    /// Where to report: the section or group name, or the scenario's name.
    span: Span,
    element: String,
    attributes: Vec<&'static str>,
}

pub fn classify(
    scenario: &Scenario,
    vocabulary: &Vocabulary,
    options: &Options,
    out: &mut Vec<Diagnostic>,
) -> (Class, Vec<String>) {
    let anchor = scenario.name.as_ref().map_or(Span::new(scenario.span.start, scenario.span.start + 8), |n| n.span);
    let mut missing: Vec<Missing> = Vec::new();
    let mut requests: Vec<String> = Vec::new();

    let mut section = |name: &str, fields: &[(&'static str, String)], element: &str, requests: &mut Vec<String>| {
        let s = scenario.section(name);
        let absent: Vec<&'static str> =
            fields.iter().filter(|(f, _)| !present(s.and_then(|s| s.attr(f)))).map(|(f, _)| *f).collect();
        for (f, request) in fields {
            if absent.contains(f) {
                requests.push(request.clone());
            }
        }
        if !absent.is_empty() {
            missing.push(Missing {
                span: s.map_or(anchor, |s| s.name_span),
                element: element.to_string(),
                attributes: absent,
            });
        }
    };
    section(
        "environment",
        &[
            ("weather", format!("State the weather{}.", one_of(vocabulary, "weather"))),
            ("time", format!("State the time of day{}.", one_of(vocabulary, "time_of_day"))),
        ],
        "the environment",
        &mut requests,
    );
    section(
        "road",
        &[
            ("type", format!("State the road type{}.", one_of(vocabulary, "road_type"))),
            ("lanes", "State the number of lanes per direction.".to_string()),
            ("direction", format!("State whether the road is one-way or two-way{}.", one_of(vocabulary, "direction"))),
        ],
        "the road",
        &mut requests,
    );
    section(
        "ego",
        &[
            (
                "behavior",
                "State what the ego vehicle is doing (for example go_forward, turn_left, stopped).".to_string(),
            ),
            ("speed", "State the ego vehicle's speed in km/h.".to_string()),
            ("lane", "State the ego vehicle's lane index (1 is the leftmost lane in its direction).".to_string()),
        ],
        "the ego vehicle",
        &mut requests,
    );
    for group in &scenario.actors {
        let name = &group.name.text;
        let mut absent = Vec::new();
        if matches!(group.kind.value, Known::Unspecified) {
            absent.push("type");
            requests.push(format!("State the type of actor group `{name}` (for example sedan, pedestrian, bus)."));
        }
        if matches!(group.count.as_ref().map(|c| &c.value), Some(Known::Unspecified)) {
            absent.push("count");
            requests.push(format!("State how many actors group `{name}` has."));
        }
        for (field, request) in [
            ("behavior", format!("State what actor group `{name}` is doing.")),
            (
                "position",
                format!(
                    "State where actor group `{name}` is relative to the ego vehicle (for example front, left_front, right)."
                ),
            ),
            (
                "lane",
                format!(
                    "State the lane index of group `{name}` (1 is the leftmost lane in the ego's direction, -1 the leftmost of the opposite direction)."
                ),
            ),
        ] {
            if !present(group.attr(field)) {
                absent.push(field);
                requests.push(request);
            }
        }
        if !absent.is_empty() {
            missing.push(Missing { span: group.name.span, element: format!("group `{name}`"), attributes: absent });
        }
    }

    let road = scenario.section("road");
    let ego = scenario.section("ego");
    let gone = |essential: Essential| match essential {
        Essential::Weather => !present(scenario.attr("environment", "weather")),
        Essential::Time => !present(scenario.attr("environment", "time")),
        Essential::Road => ["type", "lanes", "direction"].iter().all(|f| !present(road.and_then(|r| r.attr(f)))),
        Essential::Ego => ["behavior", "speed", "lane"].iter().all(|f| !present(ego.and_then(|e| e.attr(f)))),
        Essential::Actors => scenario.actors.is_empty(),
    };
    if !options.non_scenario.is_empty() && options.non_scenario.iter().all(|e| gone(*e)) {
        let parts: Vec<&str> = options.non_scenario.iter().map(|e| e.as_str()).collect();
        out.push(
            Diagnostic::new(
                Code::W0601,
                "this does not describe a traffic scenario",
                anchor,
                format!("no {}", parts.join(", no ")),
            )
            .with_note(
                "a frame without these is usually a title card, a map or a dashboard; it is classed `non_scenario`",
            ),
        );
        return (Class::NonScenario, Vec::new());
    }
    if missing.is_empty() {
        return (Class::Complete, Vec::new());
    }
    for m in &missing {
        let list: Vec<String> = m.attributes.iter().map(|a| format!("`{a}`")).collect();
        out.push(
            Diagnostic::new(
                Code::W0600,
                format!("{} does not state its {}", m.element, join_and(&list)),
                m.span,
                "incomplete",
            )
            .with_help("state them, or write `unspecified` when the source does not say (it still counts as missing)"),
        );
    }
    (Class::Incomplete, requests)
}

fn join_and(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}
