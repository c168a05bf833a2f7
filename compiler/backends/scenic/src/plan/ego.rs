//! The ego vehicle as the program renders it: a `Car` with the layout's size, motion,
//! speed and lane (`tad_layout::Layout::ego`, its facts), the speed range and choice of
//! behaviors Scenic samples, and where Scenic only approximates its behavior (W0703).

use tad_diagnostics::{Code, Span};
use tad_ir::{ActorType, Entry, Motion, Scenario};
use tad_layout::Layout;

use super::report::{Annotate, Report, unsupported};
use super::{ends, keyword, motion};
use crate::mapping::Class;

/// The ego vehicle, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct EgoPlan {
    pub length: f64,
    pub width: f64,
    /// m/s.
    pub speed: f64,
    pub motion: Option<Motion>,
    /// TAD lane index, at least 1.
    pub lane: i64,
    /// Where the lane is written (else the `ego` section).
    pub lane_span: Span,
    /// Where the behavior is written (else the `ego` section).
    pub behavior_span: Span,
    /// A speed range (m/s), sampled by Scenic.
    pub speed_range: Option<(f64, f64)>,
    /// The motions of a choice of behaviors, sampled by Scenic (empty: no choice).
    pub motions: Vec<Option<Motion>>,
}

/// The actor type the ego vehicle is: the first `reference` that declares one.
pub fn actor_type(scenario: &Scenario) -> Option<&Entry<ActorType>> {
    tad_layout::facts::ego_type(scenario)
}

pub fn plan(scenario: &Scenario, laid: &Layout, scenario_span: Span, report: &mut Report) -> EgoPlan {
    let ego = &scenario.ego;
    let section = keyword(ego.span, "ego", scenario_span);
    let behavior_span = ego.behavior.span().unwrap_or(section);
    motion::approximate(scenario, &ego.behavior, Class::Car, report);
    let motions = motion::choices(scenario, &ego.behavior, Class::Car, report);
    let speed_range = ends(&ego.speed, |s| s.0.max(0.0)).filter(|(low, high)| low < high);
    let lane_span = ego.lane.span().unwrap_or(section);
    if ego.lane.get().is_some_and(|lane| lane.index() < 0) {
        // The ego drives in its own direction: lane indexes are relative to it.
        report
            .warn(
                Code::W0703,
                "the ego vehicle cannot be in an opposite lane",
                lane_span,
                format!("lane {} used", laid.ego.lane),
                unsupported("ego.lane", Some(format!("lane {}", laid.ego.lane))),
            )
            .note("lane indexes are relative to the ego's direction of travel");
    }
    let facts = &laid.ego_facts;
    EgoPlan {
        length: facts.length,
        width: facts.width,
        speed: facts.speed,
        motion: facts.motion,
        lane: laid.ego.lane,
        lane_span,
        behavior_span,
        speed_range,
        motions,
    }
}
