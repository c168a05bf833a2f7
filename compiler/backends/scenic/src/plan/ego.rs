//! The ego vehicle: a `Car` of the actor type its `reference` declares (`reference ego {
//! actor_type: car }`) for its size and typical speed, its behavior's motion, its speed and
//! its lane (the middle lane when not given; never an opposite lane).

use tad_diagnostics::{Code, Span};
use tad_ir::{ActorType, Entry, Motion, Scenario};

use super::report::{Annotate, Report, unsupported};
use super::{ends, keyword, motion, nominal};
use crate::mapping::Class;

const WHO: &str = "the ego vehicle";

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
    let id = scenario.entries.reference_points.iter().find_map(|(_, e)| e.attrs.actor_type)?;
    scenario.entries.get(id)
}

pub fn plan(scenario: &Scenario, scenario_span: Span, report: &mut Report) -> EgoPlan {
    let ego = &scenario.ego;
    let section = keyword(ego.span, "ego", scenario_span);
    let kind = actor_type(scenario).map(|e| &e.attrs);
    let positive = |m: Option<tad_ir::Metres>| m.map(|m| m.0).filter(|v| *v > 0.0);
    let length = positive(kind.and_then(|k| k.length)).unwrap_or(4.5);
    let width = positive(kind.and_then(|k| k.width)).unwrap_or(1.8);
    let behavior_span = ego.behavior.span().unwrap_or(section);
    let (motion, behavior) = motion::of(scenario, &nominal(&ego.behavior), Class::Car, WHO, behavior_span, report);
    let motions = motion::choices(scenario, &ego.behavior, Class::Car, WHO, behavior_span, report);
    let typical = kind.and_then(|k| k.typical_speed).map_or(50.0 / 3.6, |s| s.0);
    let speed_range = ends(&ego.speed, |s| s.0.max(0.0)).filter(|(low, high)| low < high);
    // the layout keeps room for the fastest
    let fastest = ego.speed.clone().map(|p| p.max());
    let speed = motion::speed(&fastest, typical, behavior, WHO, section, report);
    let lane_span = ego.lane.span().unwrap_or(section);
    let lanes = scenario.road.lanes.get().filter(|n| *n >= 1).map(|n| n.min(1000));
    let lane = match ego.lane.get() {
        Some(lane) => lane.index(),
        None => {
            let lane = lanes.map_or(1, |n| (n + 1) / 2);
            report
                .warn(
                    Code::W0706,
                    "the lane of the ego vehicle is not given",
                    lane_span,
                    format!("lane {lane} chosen"),
                    unsupported("ego.lane", Some(format!("lane {lane}"))),
                )
                .note("the middle lane (the left one of the two middle lanes)");
            lane
        }
    };
    let lane = if lane < 0 {
        // The ego drives in its own direction: lane indexes are relative to it.
        report
            .warn(
                Code::W0703,
                "the ego vehicle cannot be in an opposite lane",
                lane_span,
                "lane 1 used",
                unsupported("ego.lane", Some("lane 1".into())),
            )
            .note("lane indexes are relative to the ego's direction of travel");
        1
    } else {
        lane
    };
    EgoPlan { length, width, speed, motion, lane, lane_span, behavior_span, speed_range, motions }
}
