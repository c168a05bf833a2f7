//! What an actor does, as Scenic renders it: its behavior's declared `motion` checked
//! against the class it becomes (the motion and the speed themselves are the layout's,
//! `tad_layout::Facts`). Shared by the ego and the groups.

use tad_diagnostics::{Code, Span};
use tad_ir::{Behavior, Field, Motion, Named, Param, Scenario};

use super::report::{Annotate, Report, named, unsupported};
use crate::mapping::Class;

/// The motion of a written behavior for an actor of `class`, with what the program makes of
/// it: one without a motion, a U-turn, or a static object asked to move is approximated
/// (W0703). The motion an actor keeps is the layout's (`tad_layout::Facts`); this says
/// where Scenic renders it only approximately.
pub fn of(
    scenario: &Scenario,
    written: &Named<Behavior>,
    class: Class,
    at: Span,
    report: &mut Report,
) -> Option<Motion> {
    let entry = scenario.entries.resolved(written);
    let name = scenario.entries.name(written);
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
    motion
}

/// The approximations of a written behavior (see [`of`]), the nominal one of a choice.
pub fn approximate(scenario: &Scenario, behavior: &Field<Param<Named<Behavior>>>, class: Class, report: &mut Report) {
    if let (Some(param), Some(at)) = (behavior.given(), behavior.span()) {
        of(scenario, &param.nominal(), class, at, report);
    }
}

/// The motion of every behavior of a choice (`go_forward | turn_left`), each as [`of`]
/// approximates it; empty when the behavior is not a choice.
pub fn choices(
    scenario: &Scenario,
    behavior: &Field<Param<Named<Behavior>>>,
    class: Class,
    report: &mut Report,
) -> Vec<Option<Motion>> {
    let (Some(Param::Choice(options)), Some(at)) = (behavior.given(), behavior.span()) else { return Vec::new() };
    // the first is the nominal behavior, already approximated
    let mut motions = vec![of(scenario, &options[0], class, at, &mut Report::default())];
    for option in &options[1..] {
        motions.push(of(scenario, option, class, at, report));
    }
    motions
}

/// The payload's construct for a field of the ego (`ego.speed`) or of a group (`actor.speed`).
pub fn field(ego: bool, name: &str) -> String {
    if ego { format!("ego.{name}") } else { format!("actor.{name}") }
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
