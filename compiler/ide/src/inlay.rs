//! Inlay hints: what a written value is in the terms the simulator uses — a speed in m/s
//! when written in km/h or mph, and what a lane number means on the scenario's road
//! (spec §4.3: lanes count from 1 at the left of the ego's direction; negative numbers
//! are the oncoming lanes, `-1` nearest the centre line).
//!
//! The road's facts come from the checker's sources: `lanes` from the model, whether
//! there are oncoming lanes from the direction's declaration (`opposite_lanes`), and
//! whether the scenario counts lanes from 0 from `tad_check::lanes_counted_from_zero`.

use tad_syntax::model::{Attr, Known, Quantity, Val};
use tad_syntax::schema::{Unit, ValueType};

use crate::{Database, SourceFile, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum InlayKind {
    /// A value in other units (`20 mph` → `8.9 m/s`).
    Value,
    /// What a lane number means (`lane: -1` → `oncoming, nearest the centre`).
    Lane,
}

/// A hint shown at `offset` (after the text it explains).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InlayHint {
    pub offset: usize,
    pub label: String,
    pub kind: InlayKind,
    pub tooltip: Option<String>,
}

fn metres_per_second(value: &Val) -> Option<String> {
    let show = |q: &Quantity| format!("{:.1}", q.si());
    let other = |q: &Quantity| q.unit.measures() == ValueType::Speed && q.unit != Unit::MetresPerSecond;
    match value {
        Val::Quantity(q) if other(q) => Some(format!("= {} m/s", show(q))),
        Val::Range(low, high) if other(low) => Some(format!("= {}..{} m/s", show(low), show(high))),
        _ => None,
    }
}

/// The road as lane numbers see it.
struct Road {
    /// Lanes per direction, when stated.
    lanes: Option<i64>,
    /// `Some(false)` when the direction has no oncoming lanes.
    opposite: Option<bool>,
    /// Whether the scenario's lane numbers are counted from 0 (each means one more).
    from_zero: bool,
}

impl Road {
    /// What lane `n` is.
    fn lane(&self, n: i64) -> Option<String> {
        if self.from_zero && n >= 0 {
            let meant = Road { from_zero: false, ..*self }.lane(n + 1)?;
            return Some(format!("counted from 0: {meant}"));
        }
        let k = n.abs();
        let of = match self.lanes {
            Some(total) if k > total => return Some(format!("beyond the road's {total} lane{}", plural(total))),
            Some(1) => return Some(if n > 0 { "the only lane" } else { "the only oncoming lane" }.into()),
            Some(total) => format!("{k} of {total}"),
            None => format!("{k}"),
        };
        match n {
            0 => Some("lanes count from 1".into()),
            n if n < 0 && self.opposite == Some(false) => Some(format!("oncoming lane {k}, but the road is one-way")),
            1 => Some(format!("{of}, leftmost")),
            -1 => Some(format!("oncoming {of}, nearest the centre")),
            n if Some(k) == self.lanes => {
                Some(if n > 0 { format!("{of}, rightmost") } else { format!("oncoming {of}, outermost") })
            }
            n if n > 0 => Some(of),
            _ => Some(format!("oncoming {of}")),
        }
    }
}

fn plural(n: i64) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// The hints whose value overlaps `range`.
pub fn inlay_hints(db: &Database, file: SourceFile, range: Span) -> Vec<InlayHint> {
    let module = &tad_db::analyze(db, file).module;
    let Some(scenario) = &module.scenario else { return Vec::new() };
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    let lanes = scenario.attr("road", "lanes").and_then(Attr::integer).filter(|n| *n >= 1);
    let direction = scenario.attr("road", "direction").and_then(Attr::symbol);
    let opposite = direction.and_then(|d| vocabulary.get("direction", &d.name)).and_then(|e| e.flag("opposite_lanes"));
    let lane_attrs =
        scenario.section("ego").into_iter().flat_map(|s| &s.attrs).chain(scenario.actors.iter().flat_map(|g| &g.attrs));
    let indexes: Vec<i64> = lane_attrs.filter(|a| a.def.name == "lane").filter_map(Attr::integer).collect();
    let road = Road { lanes, opposite, from_zero: tad_check::lanes_counted_from_zero(&indexes, lanes) };

    let inside = |span: Span| span.end >= range.start && span.start <= range.end;
    let mut out = Vec::new();
    let mut visit = |attr: &Attr| {
        if !inside(attr.value_span) || attr.value_span.is_empty() {
            return;
        }
        let Known::Given(value) = &attr.value else { return };
        if let Some(label) = metres_per_second(value) {
            out.push(InlayHint {
                offset: attr.value_span.end,
                label,
                kind: InlayKind::Value,
                tooltip: Some("in SI units, as the runtime and the backends use it".into()),
            });
        }
        if attr.def.name == "lane"
            && let Val::Integer(n) = value
            && let Some(label) = road.lane(*n)
        {
            out.push(InlayHint {
                offset: attr.value_span.end,
                label,
                kind: InlayKind::Lane,
                tooltip: Some(
                    "lanes count from 1 at the left of the ego's direction; negative: oncoming, -1 nearest the centre"
                        .into(),
                ),
            });
        }
    };
    for section in &scenario.sections {
        section.attrs.iter().for_each(&mut visit);
    }
    for group in &scenario.actors {
        group.attrs.iter().for_each(&mut visit);
    }
    out.sort_by_key(|h| h.offset);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    fn hints(text: &str) -> Vec<String> {
        let (db, file) = testing::file(text);
        inlay_hints(&db, file, Span::new(0, text.len())).into_iter().map(|h| h.label).collect()
    }

    const ROAD: &str = "scenario demo {\n  road {\n    lanes: 3\n    direction: two_way\n  }\n  ego {\n    speed: 20 mph\n    lane: 3\n  }\n  actor a: car {\n    speed: 30..40 km/h\n    lane: -1\n  }\n  actor b: car {\n    speed: 5 m/s\n    lane: 1\n  }\n  actor c: car {\n    lane: -3\n  }\n  actor d: car {\n    lane: 2\n  }\n}\n";

    #[test]
    fn speeds_in_si_and_lanes_in_words() {
        assert_eq!(
            hints(ROAD),
            vec![
                "= 8.9 m/s",
                "3 of 3, rightmost",
                "= 8.3..11.1 m/s",
                "oncoming 1 of 3, nearest the centre",
                "1 of 3, leftmost",
                "oncoming 3 of 3, outermost",
                "2 of 3",
            ]
        );
        let (db, file) = testing::file(ROAD);
        let all = inlay_hints(&db, file, Span::new(0, ROAD.len()));
        let speed = ROAD.find("20 mph").unwrap();
        assert_eq!(all[0].offset, speed + "20 mph".len());
        assert_eq!((all[0].kind, all[1].kind), (InlayKind::Value, InlayKind::Lane));
    }

    #[test]
    fn only_inside_the_range() {
        let (db, file) = testing::file(ROAD);
        let at = ROAD.find("lane: -1").unwrap();
        let some = inlay_hints(&db, file, Span::new(at, at + 8));
        assert_eq!(some.len(), 1);
        assert_eq!(some[0].label, "oncoming 1 of 3, nearest the centre");
        assert!(inlay_hints(&db, file, Span::new(0, 10)).is_empty());
        assert!(inlay_hints(&db, file, Span::new(ROAD.len() + 10, ROAD.len() + 20)).is_empty());
    }

    #[test]
    fn the_road_decides_what_a_lane_is() {
        let one_way = hints("scenario demo {\n  road { direction: one_way }\n  ego { lane: -2 }\n}\n");
        assert_eq!(one_way, vec!["oncoming lane 2, but the road is one-way"]);
        assert_eq!(
            hints("scenario demo {\n  road { lanes: 2 }\n  ego { lane: 5 }\n}\n"),
            vec!["beyond the road's 2 lanes"]
        );
        assert_eq!(hints("scenario demo {\n  road { lanes: 1 }\n  ego { lane: 1 }\n}\n"), vec!["the only lane"]);
        assert_eq!(hints("scenario demo {\n  ego { lane: 2 }\n}\n"), vec!["2"]);
        // another tool's convention: lane 0 is the first lane, and every index means one more
        let from_zero =
            hints("scenario demo {\n  road { lanes: 2 }\n  ego { lane: 0 }\n  actor a: car { lane: 1 }\n}\n");
        assert_eq!(from_zero, vec!["counted from 0: 1 of 2, leftmost", "counted from 0: 2 of 2, rightmost"]);
    }

    #[test]
    fn non_ascii_yaml_and_broken_documents() {
        let text = "// météo ☀ 🚗\nscenario demo {\n  source { description: \"ça 🚦\" }\n  ego { speed: 36 km/h }\n}\n";
        let (db, file) = testing::file(text);
        let found = inlay_hints(&db, file, Span::new(0, text.len()));
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].label, "= 10.0 m/s");
        assert_eq!(&text[..found[0].offset], &text[..text.find(" }\n}").unwrap()]);

        let yaml = "road_network:\n  lane_number: 2\nactors:\n  ego_vehicle:\n    speed: 30 mph\n    lane_index: -1\n";
        let (db, file) = testing::with_language(yaml, crate::Language::Yaml);
        let labels: Vec<String> =
            inlay_hints(&db, file, Span::new(0, yaml.len())).into_iter().map(|h| h.label).collect();
        assert_eq!(labels, vec!["= 13.4 m/s", "oncoming 1 of 2, nearest the centre"]);

        for broken in [
            "scenario demo { ego { speed: 3",
            "scenario demo { ego { lane: ",
            "é",
            "scenario demo { road { lanes: -4 } ego { lane: -9 } }",
        ] {
            let (db, file) = testing::file(broken);
            let _ = inlay_hints(&db, file, Span::new(0, usize::MAX));
            let _ = inlay_hints(&db, file, Span::new(usize::MAX, 0));
        }
    }
}
