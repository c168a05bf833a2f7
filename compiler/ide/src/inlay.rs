//! Inlay hints: what a written value is in the terms the simulator uses — a speed in m/s
//! when written in km/h or mph, and what a lane number means on the scenario's road
//! (lanes count from 1 at the left of their direction; negative numbers are the oncoming
//! lanes, from the centre line out).

use tad_syntax::model::{Attr, Known, Val};
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
    let show = |q: &tad_syntax::model::Quantity| format!("{:.1}", q.si());
    match value {
        Val::Quantity(q) if q.unit.measures() == ValueType::Speed && q.unit != Unit::MetresPerSecond => {
            Some(format!("= {} m/s", show(q)))
        }
        Val::Range(low, high) if low.unit.measures() == ValueType::Speed && low.unit != Unit::MetresPerSecond => {
            Some(format!("= {}..{} m/s", show(low), show(high)))
        }
        _ => None,
    }
}

/// What lane `n` is on a road of `lanes` lanes each way (`None`: not stated).
fn lane(n: i64, lanes: Option<i64>, two_way: bool) -> Option<String> {
    let position = |k: i64, of: Option<i64>| match of {
        Some(1) => "the only lane".to_string(),
        Some(total) if k == 1 => format!("1 of {total}, leftmost"),
        Some(total) if k == total => format!("{k} of {total}, rightmost"),
        Some(total) if k > total => format!("{k}: beyond the {total} lanes"),
        Some(total) => format!("{k} of {total}"),
        None => format!("{k} from the left"),
    };
    match n {
        0 => None,
        n if n > 0 => Some(position(n, lanes)),
        n if !two_way => Some(format!("oncoming lane {}, but the road is one-way", -n)),
        -1 => Some("oncoming, nearest the centre".to_string()),
        n => Some(format!("oncoming, {} from the centre", -n)),
    }
}

/// The hints inside `range`.
pub fn inlay_hints(db: &Database, file: SourceFile, range: Span) -> Vec<InlayHint> {
    let module = &tad_db::analyze(db, file).module;
    let Some(scenario) = &module.scenario else { return Vec::new() };
    let lanes = scenario.attr("road", "lanes").and_then(Attr::integer);
    let two_way = scenario.attr("road", "direction").and_then(|a| a.symbol()).is_none_or(|d| d.name != "one_way");
    let inside = |span: Span| span.end >= range.start && span.start <= range.end;
    let mut out = Vec::new();
    let mut visit = |attr: &Attr| {
        if !inside(attr.value_span) {
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
            && let Some(label) = lane(*n, lanes, two_way)
        {
            out.push(InlayHint {
                offset: attr.value_span.end,
                label,
                kind: InlayKind::Lane,
                tooltip: Some("lanes count from 1 at the left of their direction; negative: oncoming".into()),
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

    #[test]
    fn speeds_in_si_and_lanes_in_words() {
        let text = "scenario demo {\n  road {\n    lanes: 3\n    direction: two_way\n  }\n  ego {\n    speed: 20 mph\n    lane: 3\n  }\n  actor a: car {\n    speed: 30..40 km/h\n    lane: -1\n  }\n  actor b: car {\n    speed: 5 m/s\n    lane: 1\n  }\n}\n";
        assert_eq!(
            hints(text),
            vec![
                "= 8.9 m/s",
                "3 of 3, rightmost",
                "= 8.3..11.1 m/s",
                "oncoming, nearest the centre",
                "1 of 3, leftmost"
            ]
        );
        // only inside the range
        let (db, file) = testing::file(text);
        let at = text.find("lane: -1").unwrap();
        let some = inlay_hints(&db, file, Span::new(at, at + 8));
        assert_eq!(some.len(), 1);
        assert!(
            hints("scenario demo {\n  road { direction: one_way }\n  ego { lane: -2 }\n}\n")[0].contains("one-way")
        );
        let _ = hints("scenario demo { ego { speed: 3");
        let _ = hints("// é🚗\nscenario demo { ego { speed: 30 km/h } }");
    }
}
