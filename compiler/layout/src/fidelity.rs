//! What a run of a scenario must show for the scenario to keep its meaning
//! (`spec/layout.md` §7), checked on a [`Trace`]: every actor's pose at every step, from the
//! layout's own roll-out (`crate::predict`) or from a simulator (Scenic's Newtonian
//! simulator in the Scenic backend's fidelity suite).
//!
//! - **relations**: at the start, each group's first actor is where its position says,
//!   seen from its reference: in front or behind; left, right, or in the lane the layout
//!   gave it; facing the way the layout says (along, oncoming, from the left or the right,
//!   across);
//! - **no overlap**: no two actors other than the ego overlap in the first
//!   [`OVERLAP_WINDOW`] seconds, up to the ego's first contact (where an episode ends in the
//!   runtime and in SafeBench: what follows it is a consequence, not the scenario);
//! - **adversaries**: every group timed to a conflict comes within [`ADVERSARY_REACH`]
//!   metres of the ego.

use crate::geom::{Footprint, Pose, wrap};
use crate::{Facing, Layout};
use tad_ir::{GroupId, Longitudinal, Reference, Scenario};

/// Seconds from the start in which actors other than the ego must not overlap.
pub const OVERLAP_WINDOW: f64 = 3.0;
/// How near an adversary must come to the ego, m (footprint to footprint).
pub const ADVERSARY_REACH: f64 = 5.0;
/// Tolerances: lateral offset of a lane (m), heading (rad).
const LANE_TOLERANCE: f64 = 1.8;
const HEADING_TOLERANCE: f64 = 0.61;

/// One object of a trace: the ego (`group: None`) or a member of a group.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceObject {
    pub group: Option<GroupId>,
    pub index: usize,
    pub length: f64,
    pub width: f64,
}

/// Poses of every object at every step (`states[step][object]`), in a frame with `y` left
/// of `x` and yaw counter-clockwise from `+x`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    pub dt: f64,
    pub objects: Vec<TraceObject>,
    pub states: Vec<Vec<Pose>>,
}

impl Trace {
    fn find(&self, group: Option<GroupId>, index: usize) -> Option<usize> {
        self.objects.iter().position(|o| o.group == group && o.index == index)
    }

    fn footprint(&self, step: usize, k: usize) -> Footprint {
        let o = &self.objects[k];
        Footprint { pose: self.states[step][k], length: o.length, width: o.width }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RelationCheck {
    pub group: GroupId,
    pub holds: bool,
    /// What was measured, in the reference's frame: `x 12.3 m, y -3.5 m, heading 0°`.
    pub measured: String,
    /// What failed, when it did.
    pub failure: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Overlap {
    /// Trace object indexes.
    pub a: usize,
    pub b: usize,
    pub time: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Approach {
    pub group: GroupId,
    /// The smallest footprint distance to the ego, m, and when.
    pub distance: f64,
    pub time: f64,
    /// When it first touched the ego, s.
    pub contact: Option<f64>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Assessment {
    pub relations: Vec<RelationCheck>,
    /// Overlaps of actors other than the ego in the first [`OVERLAP_WINDOW`] seconds.
    pub overlaps: Vec<Overlap>,
    /// The first time any two actors (the ego too) overlap, and which.
    pub first_contact: Option<Overlap>,
    pub adversaries: Vec<Approach>,
}

impl Assessment {
    pub fn relations_hold(&self) -> bool {
        self.relations.iter().all(|r| r.holds)
    }

    pub fn adversaries_reach(&self) -> bool {
        self.adversaries.iter().all(|a| a.distance <= ADVERSARY_REACH)
    }

    pub fn holds(&self) -> bool {
        self.relations_hold() && self.overlaps.is_empty() && self.adversaries_reach()
    }
}

/// Where `b` is seen from `a`: `x` ahead, `y` to the left, in a frame midway between their
/// headings (one turned half round when they face opposite ways), so that a bend of the road
/// between them shifts neither side.
fn between(a: Pose, b: Pose) -> crate::geom::Vec2 {
    let delta = wrap(b.yaw - a.yaw);
    let along = if delta.abs() > std::f64::consts::FRAC_PI_2 { wrap(delta - std::f64::consts::PI) } else { delta };
    // only for actors along the same road: one crossing it is seen from `a` itself
    let turn = if along.abs() < 0.6 { along / 2.0 } else { 0.0 };
    Pose { position: a.position, yaw: a.yaw + turn }.local(b.position)
}

/// Check a trace of `scenario` laid out as `layout`.
pub fn assess(scenario: &Scenario, layout: &Layout, trace: &Trace) -> Assessment {
    let mut out = Assessment::default();
    if trace.states.is_empty() {
        return out;
    }
    let ego = trace.find(None, 0);
    // relations at the start
    for g in &layout.groups {
        let Some(first) = g.agents.first() else { continue };
        let Some(group) = scenario.group(g.group) else { continue };
        let Some(position) = group.position.given() else { continue };
        let (reference_agent, reference_object) = match &position.reference.value {
            Reference::Group(id) => (layout.group(*id).and_then(|r| r.agents.first()), trace.find(Some(*id), 0)),
            _ => (Some(&layout.ego), ego),
        };
        let (Some(reference_agent), Some(r), Some(k)) =
            (reference_agent, reference_object, trace.find(Some(g.group), 0))
        else {
            continue;
        };
        let relation = scenario.entries.resolved(&position.relation.value).map(|e| e.attrs);
        let (pr, pg) = (trace.states[0][r], trace.states[0][k]);
        let local = between(pr, pg);
        let heading = wrap(pg.yaw - pr.yaw);
        let expected_local = between(reference_agent.pose, first.pose);
        let expected_heading = wrap(first.pose.yaw - reference_agent.pose.yaw);
        let mut failures = Vec::new();
        let half = (trace.objects[r].length + trace.objects[k].length) / 2.0;
        match relation.and_then(|r| r.longitudinal) {
            Some(Longitudinal::Front) if local.x <= 0.5 => failures.push("not in front"),
            Some(Longitudinal::Behind) if local.x >= -0.5 => failures.push("not behind"),
            Some(Longitudinal::Same) if local.x.abs() > half + 3.0 => failures.push("not beside"),
            _ => {}
        }
        let crossing = matches!(first.facing, Facing::Across { .. });
        if !crossing {
            if first.station.arm == reference_agent.station.arm {
                // at a curb or on a shoulder the offset also depends on the real lane's width
                let tolerance = if first.place == crate::Place::Lane { LANE_TOLERANCE } else { LANE_TOLERANCE + 0.8 };
                if (local.y - expected_local.y).abs() > tolerance {
                    failures.push("not in its lane");
                }
            } else if local.y.signum() != expected_local.y.signum() && expected_local.y.abs() > 1.0 {
                failures.push("on the wrong side");
            }
        }
        if wrap(heading - expected_heading).abs() > HEADING_TOLERANCE {
            failures.push("facing the wrong way");
        }
        out.relations.push(RelationCheck {
            group: g.group,
            holds: failures.is_empty(),
            measured: format!("x {:.1} m, y {:.1} m, heading {:.0}°", local.x, local.y, heading.to_degrees()),
            failure: (!failures.is_empty()).then(|| {
                format!(
                    "{} (expected x {:.1} m, y {:.1} m, heading {:.0}°)",
                    failures.join(", "),
                    expected_local.x,
                    expected_local.y,
                    expected_heading.to_degrees()
                )
            }),
        });
    }
    // overlaps
    let window = (OVERLAP_WINDOW / trace.dt.max(1e-3)).round() as usize;
    let n = trace.objects.len();
    let mut seen = vec![false; n * n];
    // the step of the ego's first contact: later overlaps are not the scenario's
    let mut ego_hit: Option<usize> = None;
    for (step, _) in trace.states.iter().enumerate() {
        for a in 0..n {
            for b in a + 1..n {
                if !trace.footprint(step, a).overlaps(&trace.footprint(step, b)) {
                    continue;
                }
                let time = step as f64 * trace.dt;
                if out.first_contact.is_none() {
                    out.first_contact = Some(Overlap { a, b, time });
                }
                let with_ego = Some(a) == ego || Some(b) == ego;
                if with_ego {
                    ego_hit.get_or_insert(step);
                }
                let ended = ego_hit.is_some_and(|hit| step > hit);
                if step <= window && !with_ego && !ended && !seen[a * n + b] {
                    seen[a * n + b] = true;
                    out.overlaps.push(Overlap { a, b, time });
                }
            }
        }
    }
    // adversaries
    if let Some(e) = ego {
        for c in &layout.conflicts {
            let members: Vec<usize> = (0..n).filter(|&k| trace.objects[k].group == Some(c.group)).collect();
            let mut best = Approach { group: c.group, distance: f64::INFINITY, time: 0.0, contact: None };
            for (step, _) in trace.states.iter().enumerate() {
                let ego_box = trace.footprint(step, e);
                for &k in &members {
                    let d = ego_box.distance(&trace.footprint(step, k));
                    let time = step as f64 * trace.dt;
                    if d < best.distance {
                        best.distance = d;
                        best.time = time;
                    }
                    if d <= 0.0 && best.contact.is_none() {
                        best.contact = Some(time);
                    }
                }
            }
            out.adversaries.push(best);
        }
    }
    out
}
