//! What TADSL says back to whoever wrote a scenario — an extractor, a language model —
//! in words, rendered from the diagnostics' typed payloads.
//!
//! The checker reports facts ([`Payload`]); this crate is the one place that turns them
//! into requests: [`refinement`] asks for what an incomplete scenario does not state (the
//! paper's refinement step), [`repair`] lists every problem compactly for a corrected
//! program. The vocabulary in the requests comes from the declarations in scope, never
//! from a list here.

use tad_check::Vocabulary;
use tad_diagnostics::{Diagnostic, Element, LineIndex, Payload};
use tad_syntax::schema::{self, SectionDef};

/// One request per missing essential attribute, in the order the checker found them.
pub fn refinement(diagnostics: &[Diagnostic], vocabulary: &Vocabulary) -> Vec<String> {
    let mut out = Vec::new();
    for d in diagnostics {
        let Payload::Missing { element, fields } = &d.payload else { continue };
        for field in fields {
            out.push(request(element, field, vocabulary));
        }
    }
    out
}

/// " (one of: a, b, c)" for a field whose names come from a vocabulary.
fn one_of(section: &SectionDef, field: &str, vocabulary: &Vocabulary) -> String {
    let Some(kind) = section.field(field).and_then(|f| f.vocabulary) else { return String::new() };
    let names = vocabulary.names(kind);
    if names.is_empty() { String::new() } else { format!(" (one of: {})", names.join(", ")) }
}

fn request(element: &Element, field: &str, vocabulary: &Vocabulary) -> String {
    match element {
        Element::Environment => {
            let what = if field == "time" { "the time of day" } else { "the weather" };
            format!("State {what}{}.", one_of(&schema::ENVIRONMENT, field, vocabulary))
        }
        Element::Road => match field {
            "lanes" => "State the number of lanes per direction.".to_string(),
            "direction" => {
                format!("State whether the road is one-way or two-way{}.", one_of(&schema::ROAD, field, vocabulary))
            }
            "type" => format!("State the road type{}.", one_of(&schema::ROAD, field, vocabulary)),
            other => format!("State the road's {other}{}.", one_of(&schema::ROAD, field, vocabulary)),
        },
        Element::Ego => match field {
            "behavior" => "State what the ego vehicle is doing (for example move_forward, turn_left, stopped).".into(),
            "speed" => "State the ego vehicle's speed in km/h.".into(),
            "lane" => "State the ego vehicle's lane index (1 is the leftmost lane in its direction).".into(),
            other => format!("State the ego vehicle's {other}."),
        },
        Element::Group { name } => match field {
            "type" => format!("State the type of actor group `{name}` (for example sedan, pedestrian, bus)."),
            "count" => format!("State how many actors group `{name}` has."),
            "behavior" => format!("State what actor group `{name}` is doing."),
            "position" => format!(
                "State where actor group `{name}` is relative to the ego vehicle (for example front, left_front, right)."
            ),
            "lane" => format!(
                "State the lane index of group `{name}` (1 is the leftmost lane in the ego's direction, -1 the leftmost of the opposite direction)."
            ),
            other => format!("State the {other} of actor group `{name}`."),
        },
    }
}

/// Every diagnostic of `text` as one line: `CODE line:column: message (fix: replacement)`,
/// for a request to correct a program.
pub fn repair(diagnostics: &[Diagnostic], text: &str) -> Vec<String> {
    let index = LineIndex::new(text);
    diagnostics
        .iter()
        .map(|d| {
            let at = index.line_col(text, d.primary.span.start);
            let mut line = format!("{} {}:{}: {}", d.code, at.line, at.column, d.message);
            if let Some(fix) = d.fixes.first() {
                line.push_str(&format!(" (fix: replace with `{}`)", fix.replacement));
            } else if let Some(help) = &d.help {
                line.push_str(&format!(" ({help})"));
            }
            line
        })
        .collect()
}
