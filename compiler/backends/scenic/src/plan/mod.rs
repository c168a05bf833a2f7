//! From a resolved scenario (`tad_ir::Scenario`) to a plan of the Scenic program: the map
//! and what the ego's surroundings must have, and every actor with its class, blueprint,
//! size, lane, place along the lane, motion and speeds. The plan holds typed data only;
//! `crate::print` writes it as Scenic.
//!
//! Where everything stands is the layout's (`tad_layout`, `spec/layout.md`): its arm, lane,
//! station, facing, path and timing. This plan renders it on a CARLA map: only the ego's
//! place on the map is left to Scenic, among places the map table says have the road the
//! layout needs, and the room the layout keeps (its slack, an adversary's spread) is sampled.
//!
//! [`plan`] runs the steps in order, each in its own module with a typed result:
//!
//! 1. [`findings`]: the layout's findings (values it chose, arms the road lacks, capped
//!    groups) as the backend's diagnostics;
//! 2. [`ego`]: the ego vehicle as the layout decided it ([`ego::EgoPlan`]);
//! 3. [`road`]: what the road section asks of the map ([`road::RoadRequest`]);
//! 4. [`groups`]: every actor group's mapping and reference, with the layout's facts of it
//!    ([`groups::Resolved`]);
//! 5. [`choice`]: the road features in priority order and the map that keeps the most
//!    important ones ([`choice::Choice`]), moving actors into lanes the map has;
//! 6. [`layout`]: the stretch of road the layout needs, and capping groups to what the map has;
//! 7. [`actors`]: the objects of the program, with their identifiers;
//! 8. [`environment`]: CARLA's weather parameters, and the traffic light.
//!
//! Every step reads names through the IR's typed entries: what a name maps to is declared
//! with it in TAD (see `crate::mapping`).

pub mod actors;
pub mod choice;
pub mod ego;
pub mod environment;
pub mod findings;
pub mod groups;
pub mod layout;
pub mod motion;
pub mod report;
pub mod road;

use tad_diagnostics::{Diagnostic, Span};
use tad_ir::{Field, Motion, Param, ParamValue, Scenario, Signal};

use crate::EmitOptions;
use crate::mapping::Class;
use crate::maps::Needs;
use report::Report;

/// One object of the Scenic program.
#[derive(Clone, Debug, PartialEq)]
pub struct Actor {
    pub ident: String,
    pub class: Class,
    /// The CARLA blueprint.
    pub blueprint: String,
    /// The ego vehicle (`with rolename 'hero'`).
    pub is_ego: bool,
    /// An adversary (its group has a conflict with the ego in the layout): it keeps to its
    /// timing and does not brake for the ego (`with tadAdversary True`).
    pub adversary: bool,
    pub length: f64,
    pub width: f64,
    /// TAD lane index on its arm.
    pub lane: i64,
    /// The junction arm it stands on (`Ego`: the ego's road).
    pub arm: tad_layout::Arm,
    /// On the ego's road: metres along the ego's lane from the ego's centre. On another
    /// arm: metres before its stop line (outgoing lanes: after the junction).
    pub offset: f64,
    /// Where across its lane it stands: the layout's.
    pub place: tad_layout::Place,
    /// About to walk across the road: from its right-hand side (as the arm's incoming
    /// traffic, or the ego, sees it), and how much further from the road it stands.
    pub cross: Option<(bool, f64)>,
    /// What it does; `None` for a behavior that declares no motion.
    pub motion: Option<Motion>,
    /// The speed its behavior keeps, in m/s.
    pub target_speed: f64,
    /// The speed it starts at, in m/s (0 for actors that start at rest).
    pub initial_speed: f64,
    /// The parameters Scenic samples for it; shared by the actors of a group.
    pub params: Sampled,
}

/// What a Scenic program samples for an actor (its group's ranges and choices), each
/// `None` when fixed. Ranges are `(low, high)` in SI.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sampled {
    /// The name of the program's variables for this actor's group (`Ego`, `3`).
    pub tag: String,
    /// Speed range: its behavior keeps `tadSpeedTAG = Range(low, high)`.
    pub speed: Option<(f64, f64)>,
    /// The motions of a choice of behaviors (at least two), sampled with `DiscreteRange`.
    pub motions: Vec<Option<Motion>>,
    /// How much nearer its reference than `offset` it may be: `tadShiftTAG = Range(0, d)`,
    /// and the sign of "nearer" along the ego's lane.
    pub shift: Option<(f64, f64)>,
    /// Time before it starts its behavior.
    pub delay: Option<(f64, f64)>,
    /// It starts its behavior when the ego is within this distance.
    pub trigger: Option<(f64, f64)>,
    /// An adversary timed to meet the ego: its place varies by up to this much either way
    /// (`tadJitterTAG = Range(-j, j)`).
    pub jitter: Option<f64>,
    /// A written `offset` range: `tadOffsetTAG = Range(low, high)` added to its place (it
    /// replaces the shift and the jitter; a single offset is in the place already).
    pub offset: Option<(f64, f64)>,
    /// An adversary that waits for the ego (the layout's `Start::meet`), measured on the map:
    /// `TadMeet` with its own maneuver and the ego's.
    pub meet: Option<MeetPlan>,
    /// An adversary on another arm that the layout starts moving, on time for its conflict:
    /// its distance before the stop line measured again on the map's junction (`tadOnTime`).
    pub on_time: Option<OnTime>,
}

/// What `tadOnTime` needs to place an on-time adversary on the map: the arm and lane of
/// the group's first actor, its maneuver and the ego's (`mapping::maneuver` letters), the
/// distance within which their ways meet (as the layout's), and the layout's distance before
/// the stop line (kept where the map's ways do not meet).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnTime {
    pub arm: tad_layout::Arm,
    pub lane: i64,
    pub own: char,
    pub ego: char,
    pub reach: f64,
    pub before: f64,
}

/// The maneuvers (`mapping::maneuver` letters; `None`: straight ahead along its heading,
/// a walker or a road without a junction) whose ways `TadMeet` intersects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeetPlan {
    pub own: Option<char>,
    pub ego: Option<char>,
}

impl Sampled {
    /// Whether the actor starts at rest, waiting.
    pub fn waits(&self) -> bool {
        self.delay.is_some() || self.trigger.is_some() || self.meet.is_some()
    }
}

/// A range's or a value's ends, in SI.
pub(crate) fn ends<T: ParamValue + PartialOrd>(field: &Field<Param<T>>, si: impl Fn(&T) -> f64) -> Option<(f64, f64)> {
    field.given().map(|p| (si(&p.min()), si(&p.max())))
}

#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// What the source says about the group, for a comment.
    pub summary: String,
    pub actors: Vec<Actor>,
}

/// The traffic light the program holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub signal: Signal,
    /// The TAD light state it comes from.
    pub name: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    pub scenario: String,
    pub map: String,
    /// Whether the map is one the table describes.
    pub map_known: bool,
    pub needs: Needs,
    pub ego: Actor,
    pub ego_summary: String,
    pub groups: Vec<Group>,
    /// `carla.WeatherParameters` and what they stand for.
    pub weather: Vec<(&'static str, f64)>,
    pub weather_summary: String,
    pub light: Option<Light>,
    /// The road features asked for, and those left out, for comments.
    pub kept: Vec<String>,
    pub dropped: Vec<String>,
    /// The layout the program renders: laid out within the map's lanes when the map has
    /// fewer than the scenario uses.
    pub layout: tad_layout::Layout,
}

/// The span of a section's keyword (the section's span starts with it), or `fallback`.
pub(crate) fn keyword(section: Option<Span>, word: &str, fallback: Span) -> Span {
    section.map_or(fallback, |s| Span::new(s.start, s.start + word.len()))
}

pub(crate) fn kmh(speed: f64) -> String {
    format!("{:.0} km/h", speed * 3.6)
}

pub(crate) fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}

/// `a`, `` `a` and `b` ``, `` `a`, `b` and `c` ``.
pub(crate) fn list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.len() {
        0 => String::new(),
        1 => quoted[0].clone(),
        n => format!("{} and {}", quoted[..n - 1].join(", "), quoted[n - 1]),
    }
}

/// Steps 1 to 5 on a layout: its findings, the ego, the road's needs, the groups, the map
/// (`requested`, else chosen); `fitted`: the map the layout was laid out within.
fn decide(
    scenario: &Scenario,
    laid: &tad_layout::Layout,
    requested: Option<&str>,
    fitted: Option<&findings::Fitted>,
    report: &mut Report,
) -> (ego::EgoPlan, road::RoadRequest, Vec<groups::Resolved>, choice::Choice) {
    let scenario_span = scenario.name.as_ref().map_or(scenario.span, |n| n.span);
    let road_span = keyword(scenario.road.span, "road", scenario_span);
    findings::report(scenario, laid, fitted, report);
    let ego = ego::plan(scenario, laid, scenario_span, report);
    let road = road::request(scenario, road_span, report);
    let groups = groups::resolve(scenario, laid, report);
    let choice = choice::choose(&road, &ego, &groups, laid, requested, report);
    (ego, road, groups, choice)
}

/// The plan of `scenario`'s program, and the backend's diagnostics (unsorted).
pub fn plan(scenario: &Scenario, options: &EmitOptions) -> (Plan, Vec<Diagnostic>) {
    let mut report = Report::default();

    // the layout, then the map; when no map has every lane it uses, the layout again within
    // the closest map's lanes (it moves what that road lacks), and the map chosen on it
    let mut laid = tad_layout::lay_out(scenario);
    let mut first = Report::default();
    let (mut ego, mut road, mut groups, mut choice) = decide(scenario, &laid, options.map.as_deref(), None, &mut first);
    match choice.relayout.take() {
        None => report.diagnostics.extend(first.diagnostics),
        Some((map, limits)) => {
            laid = tad_layout::lay_out_within(scenario, Some(limits));
            let fitted = findings::Fitted { map: &map, limits };
            (ego, road, groups, choice) = decide(scenario, &laid, Some(&map), Some(&fitted), &mut report);
        }
    }
    let kept = if choice.map_known {
        layout::fit(scenario, &laid, &choice.needs, &choice.map, choice.junction, &mut report)
    } else {
        laid.groups.iter().map(|g| g.agents.len()).collect()
    };
    let mut needs = choice.needs.clone();
    layout::windows(&laid, &mut needs, choice.junction, Some(&kept));
    let actors = actors::build(scenario, &ego, &groups, &laid, &kept, choice.junction);
    // the window holds every actor the program places on the ego's road, sampled either way
    for a in actors.groups.iter().flat_map(|g| &g.actors).filter(|a| a.arm == tad_layout::Arm::Ego) {
        let reach = a.length.max(a.width) / 2.0 + a.params.jitter.unwrap_or(0.0) + 1.0;
        let shift = a.params.shift.map_or(0.0, |(s, _)| s);
        let (back, on) = a.params.offset.map_or((0.0, 0.0), |(low, high)| ((-low).max(0.0), high.max(0.0)));
        needs.ahead = needs.ahead.max((a.offset + reach + shift + on).ceil());
        needs.behind = needs.behind.max((reach + shift + back - a.offset).ceil());
    }
    let environment = environment::plan(scenario, &road, options.simulator, &mut report);

    let plan = Plan {
        scenario: scenario.name.as_ref().map_or_else(|| "scenario".to_string(), |n| n.value.clone()),
        map: choice.map,
        map_known: choice.map_known,
        needs,
        ego: actors.ego,
        ego_summary: actors.ego_summary,
        groups: actors.groups,
        weather: environment.weather,
        weather_summary: environment.summary,
        light: environment.light,
        kept: choice.kept,
        dropped: choice.dropped,
        layout: laid,
    };
    (plan, report.diagnostics)
}
