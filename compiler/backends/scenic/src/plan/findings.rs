//! The layout's findings in the backend's words: a value the scenario leaves unsaid that
//! the layout chose (W0706), a group on a junction arm the road lacks (W0701), a group
//! larger than the layout places (W0702), a lane the chosen map lacks (W0701: the layout,
//! laid out within the map's lanes, moved it). The layout decides; this step only reports
//! it, so every target says the same choice.

use tad_diagnostics::{Code, Payload};
use tad_ir::Scenario;
use tad_layout::{Finding, Layout, Limits, MAX_GROUP};

use super::motion::field;
use super::plural;
use super::report::{Annotate, Report, unsupported};

/// Who a finding is about, as messages name it.
fn who(scenario: &Scenario, group: Option<tad_ir::GroupId>) -> Option<String> {
    match group {
        None => Some("the ego vehicle".to_string()),
        Some(id) => scenario.group(id).map(|g| format!("group `{}`", g.name)),
    }
}

/// The map a layout was fitted to: its name and lanes.
pub struct Fitted<'a> {
    pub map: &'a str,
    pub limits: Limits,
}

/// Every finding of `laid` as a diagnostic; `fitted`: the map it was laid out within.
pub fn report(scenario: &Scenario, laid: &Layout, fitted: Option<&Fitted>, report: &mut Report) {
    for finding in &laid.findings {
        match finding {
            Finding::Chosen(c) => {
                let Some(who) = who(scenario, c.group) else { continue };
                let words = if c.field == "count" { "number of actors" } else { c.field };
                report
                    .warn(
                        Code::W0706,
                        format!("the {words} of {who} is not given"),
                        c.span,
                        format!("{} chosen", c.value),
                        unsupported(field(c.group.is_none(), c.field), Some(c.value.clone())),
                    )
                    .note(c.rule);
            }
            Finding::NoArm { group, arm, span } => {
                let Some(who) = who(scenario, Some(*group)) else { continue };
                report
                    .warn(
                        Code::W0701,
                        format!("the junction has no {} arm for {who}", arm.as_str()),
                        *span,
                        "placed on the ego's road instead",
                        unsupported("actor.position", Some("the ego's road".into())),
                    )
                    .note("a three-way junction keeps the arms the ego and most groups need");
            }
            Finding::Capped { group, wanted, placed, span } => {
                let Some(who) = who(scenario, Some(*group)) else { continue };
                report
                    .warn(
                        Code::W0702,
                        format!("{who} is capped at {MAX_GROUP} actors"),
                        *span,
                        format!("{wanted} written"),
                        unsupported(format!("{wanted} actors in {who}"), Some(format!("{placed} actors"))),
                    )
                    .note(
                        "a Scenic scene with very many objects samples slowly and rarely fits on one stretch of road",
                    );
            }
            Finding::Moved { group, from, to, span } => {
                let (Some(who), Some(Fitted { map, limits })) = (who(scenario, *group), fitted) else { continue };
                let mut allowed: Vec<String> = (1..=limits.same).map(|l| format!("lane {l}")).collect();
                allowed.extend((1..=limits.other).map(|l| format!("lane -{l}")));
                report
                    .warn(
                        Code::W0701,
                        format!("{map} has no lane {from} for {who}"),
                        *span,
                        format!("placed in lane {to}"),
                        Payload::Incompatible { subject: map.to_string(), value: format!("lane {from}"), allowed },
                    )
                    .note(format!(
                        "no map has all the lanes the scenario uses; {map} has a road with {} in the ego's direction and {} in the other",
                        plural(limits.same as usize, "lane"),
                        plural(limits.other as usize, "lane")
                    ));
            }
        }
    }
}
