//! What an actor does and how fast: its behavior's declared `motion`, checked against the
//! class it becomes, and its speed (written, else its type's typical speed capped by the
//! behavior's `max_speed`). Shared by the ego and the groups.

use tad_diagnostics::{Code, Span};
use tad_ir::{Behavior, ClosedSet, Entry, Field, Id, MetresPerSecond, Motion, Named, Param, Scenario};

use super::kmh;
use super::report::{Annotate, Report, named, unsupported};
use crate::mapping::Class;

/// The motion an actor of `class` gets when the scenario states no behavior: the layout's.
fn default_motion(class: Class) -> Motion {
    class.body().default_motion()
}

/// The first behavior of the vocabulary with `motion`: the one chosen for it.
fn behavior_with(scenario: &Scenario, motion: Motion) -> Option<Id<Behavior>> {
    scenario.entries.behaviors.iter().find(|(_, e)| e.attrs.motion == Some(motion)).map(|(id, _)| id)
}

/// The motion of `behavior` for an actor of `class`, and the behavior's entry (for its
/// `max_speed`). A behavior not given is the vocabulary's first of the class's default
/// motion (W0706); one without a motion, a U-turn, or a static object asked to move is
/// approximated (W0703). `span` is where a behavior not given is reported.
pub fn of<'s>(
    scenario: &'s Scenario,
    behavior: &Field<Named<Behavior>>,
    class: Class,
    who: &str,
    span: Span,
    report: &mut Report,
) -> (Option<Motion>, Option<&'s Entry<Behavior>>) {
    let Some(written) = behavior.given() else {
        let motion = default_motion(class);
        let chosen = behavior_with(scenario, motion);
        let name = chosen.map_or(motion.as_str(), |id| scenario.entries[id].name.as_str());
        report.warn(
            Code::W0706,
            format!("the behavior of {who} is not given"),
            span,
            format!("`{name}` chosen"),
            unsupported(field(who, "behavior"), Some(format!("`{name}`"))),
        );
        return (Some(motion), chosen.map(|id| &scenario.entries[id]));
    };
    let entry = scenario.entries.resolved(written);
    let name = scenario.entries.name(written);
    let at = behavior.span().unwrap_or(span);
    let motion = entry.and_then(|e| e.attrs.motion);
    match motion {
        None => {
            report
                .warn(
                    Code::W0703,
                    format!("behavior `{name}` has no Scenic mapping"),
                    at,
                    "approximated",
                    unsupported(named("behavior", name), Some("lane following".into())),
                )
                .note("it becomes lane following at the actor's speed (standing still at 0 km/h)");
        }
        Some(Motion::UTurn) => {
            report.warn(Code::W0703, "a U-turn has no Scenic mapping on these maps", at, "approximated", unsupported(named("behavior", name), Some("lane following".into())))
                .note("no junction of the CARLA maps offers a U-turn maneuver: the actor turns only where its lane has one and follows the lane otherwise");
        }
        Some(m) if class == Class::Debris && !matches!(m, Motion::Parked | Motion::Stop | Motion::Stand) => {
            report
                .warn(
                    Code::W0703,
                    format!("a static object cannot `{name}`"),
                    at,
                    "it stands still",
                    unsupported(named("behavior", name), Some("standing still".into())),
                )
                .note("static objects become Scenic `Debris`, which does not move");
        }
        _ => {}
    }
    (motion, entry)
}

/// The motion of every behavior of a choice (`go_forward | turn_left`), each as [`of`]
/// approximates it; empty when the behavior is not a choice.
pub fn choices(
    scenario: &Scenario,
    behavior: &Field<Param<Named<Behavior>>>,
    class: Class,
    who: &str,
    span: Span,
    report: &mut Report,
) -> Vec<Option<Motion>> {
    let (Some(Param::Choice(options)), Some(at)) = (behavior.given(), behavior.span()) else { return Vec::new() };
    // the first is the nominal behavior, already planned
    let mut motions =
        vec![of(scenario, &Field::Given(options[0].clone(), at), class, who, span, &mut Report::default()).0];
    for option in &options[1..] {
        motions.push(of(scenario, &Field::Given(option.clone(), at), class, who, span, report).0);
    }
    motions
}

/// The payload's construct for a field of the ego (`ego.speed`) or of a group (`actor.speed`).
pub fn field(who: &str, name: &str) -> String {
    if who == "the ego vehicle" { format!("ego.{name}") } else { format!("actor.{name}") }
}

/// The speed of an actor in m/s: written, else its type's `typical` speed, never above the
/// behavior's `max_speed` (W0706). `span` is where a speed not written is reported.
pub fn speed(
    written: &Field<MetresPerSecond>,
    typical: f64,
    behavior: Option<&Entry<Behavior>>,
    who: &str,
    span: Span,
    report: &mut Report,
) -> f64 {
    if let Some(speed) = written.get() {
        return speed.0.max(0.0);
    }
    let cap = behavior.and_then(|b| b.attrs.max_speed).map_or(f64::INFINITY, |s| s.0);
    let speed = typical.min(cap).max(0.0);
    report
        .warn(
            Code::W0706,
            format!("the speed of {who} is not given"),
            written.span().unwrap_or(span),
            format!("{} chosen", kmh(speed)),
            unsupported(field(who, "speed"), Some(kmh(speed))),
        )
        .note("the actor type's typical speed, capped by the behavior's `max_speed`");
    speed
}

/// Whether an actor starts moving at its speed (`with speed`), or at rest.
pub fn starts_moving(motion: Option<Motion>, class: Class) -> bool {
    class == Class::Car
        && matches!(
            motion,
            Some(
                Motion::Follow
                    | Motion::TurnLeft
                    | Motion::TurnRight
                    | Motion::UTurn
                    | Motion::ChangeLaneLeft
                    | Motion::ChangeLaneRight
                    | Motion::Overtake
                    | Motion::Yield
                    | Motion::Cross
                    | Motion::Walk
                    | Motion::Graze
            ) | None
        )
}
