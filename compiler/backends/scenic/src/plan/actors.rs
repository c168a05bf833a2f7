//! The objects of the program: the ego vehicle and one object per actor of every group,
//! each with a safe identifier (`crate::python::Names`), its class, blueprint, size, lane,
//! offset, place in the lane, motion and speeds.

use tad_ir::Scenario;

use super::ego::EgoPlan;
use super::groups::Resolved;
use super::layout::Layout;
use super::motion::starts_moving;
use super::{Actor, Group, Place, Sampled};
use crate::mapping::{self, Class};
use crate::python::Names;

/// The program's objects.
#[derive(Clone, Debug, PartialEq)]
pub struct Actors {
    pub ego: Actor,
    pub ego_summary: String,
    pub groups: Vec<Group>,
}

pub fn build(scenario: &Scenario, ego: &EgoPlan, groups: &[Resolved], layout: &Layout) -> Actors {
    let mut names = Names::default();
    names.reserve("ego");
    let ego_actor = Actor {
        ident: "ego".into(),
        class: Class::Car,
        blueprint: mapping::EGO_BLUEPRINT.to_string(),
        is_ego: true,
        length: ego.length,
        width: ego.width,
        lane: ego.lane,
        offset: 0.0,
        place: Place::Centre,
        across: false,
        motion: ego.motion,
        target_speed: ego.speed,
        initial_speed: if starts_moving(ego.motion, Class::Car) { ego.speed } else { 0.0 },
        params: Sampled {
            tag: "Ego".into(),
            speed: ego.speed_range,
            motions: ego.motions.clone(),
            ..Sampled::default()
        },
    };
    let mut out = Vec::new();
    for (i, g) in groups.iter().enumerate() {
        let mut actors = Vec::new();
        for (k, &offset) in layout.offsets[i].iter().enumerate() {
            let ident = if layout.counts[i] == 1 && g.count == 1 {
                names.fresh(&g.name)
            } else {
                names.fresh(&format!("{}_{}", g.name, k + 1))
            };
            let class = g.mapping.class;
            let params = Sampled {
                tag: (i + 1).to_string(),
                speed: g.speed_range,
                motions: g.motions.clone(),
                shift: g.distance.filter(|(low, high)| low < high).map(|(low, high)| (high - low, -layout.steps[i])),
                delay: g.delay,
                trigger: g.trigger,
            };
            actors.push(Actor {
                ident,
                class,
                blueprint: g.mapping.blueprint.clone(),
                is_ego: false,
                length: g.length,
                width: g.width,
                lane: g.lane,
                offset,
                place: g.place(),
                across: g.across(),
                motion: g.motion,
                target_speed: g.speed,
                initial_speed: if starts_moving(g.motion, class) && !params.waits() { g.speed } else { 0.0 },
                params,
            });
        }
        out.push(Group { summary: g.summary.clone(), actors });
    }
    Actors { ego: ego_actor, ego_summary: ego_summary(scenario, ego.lane), groups: out }
}

/// `ego vehicle: BEHAVIOR, SPEED, lane N`, for a comment.
fn ego_summary(scenario: &Scenario, lane: i64) -> String {
    let mut parts = Vec::new();
    if let Some(b) = scenario.ego.behavior.given() {
        let names: Vec<&str> = b.values().into_iter().map(|n| scenario.entries.name(n)).collect();
        parts.push(names.join(" | "));
    }
    if let Some(speed) = scenario.ego.speed.given() {
        parts.push(super::groups::speed_text(speed));
    }
    parts.push(format!("lane {lane}"));
    format!("ego vehicle: {}", parts.join(", "))
}
