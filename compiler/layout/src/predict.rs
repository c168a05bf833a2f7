//! A kinematic roll-out of a layout: the ego keeps its stated speed along its path; every
//! other actor waits for its start (delay, trigger, the ego's time to its conflict point),
//! then moves along its path at its speed, vehicles following whatever is ahead on their
//! path with the Intelligent Driver Model (`crate::idm`, the runtime's). Adversaries (groups
//! timed to a conflict) do not yield to the ego. It is what the layout promises, checked by
//! `crate::fidelity` without a simulator; the runtime is the real simulation.

use crate::fidelity::{Trace, TraceObject};
use crate::geom::{Pose, Vec2};
use crate::idm::IdmParams;
use crate::{Body, Layout};

const LOOKAHEAD: f64 = 60.0;

/// Roll the layout out for `steps` steps of `dt` seconds; step 0 is the start.
pub fn roll_out(layout: &Layout, steps: usize, dt: f64) -> Trace {
    let agents: Vec<&crate::Agent> = layout.agents().collect();
    let adversary: Vec<bool> = agents.iter().map(|a| a.group.is_some_and(|g| layout.conflict(g).is_some())).collect();
    let mut s: Vec<f64> = agents.iter().map(|a| a.path_start).collect();
    let mut v: Vec<f64> = agents.iter().map(|a| if a.moving { a.speed } else { 0.0 }).collect();
    let mut started: Vec<bool> = agents.iter().map(|a| a.group.is_none() || a.moving).collect();
    // a meeting's point as an arc of the ego's path, and the travel time it waits for
    let meets: Vec<Option<(f64, f64)>> =
        agents.iter().map(|a| a.start.meet.map(|m| (agents[0].path.project(m.point).0, m.travel))).collect();
    let objects = agents
        .iter()
        .map(|a| TraceObject { group: a.group, index: a.index, length: a.length, width: a.width })
        .collect();
    let mut states: Vec<Vec<Pose>> = Vec::with_capacity(steps + 1);
    let place = |k: usize, s: f64| -> Pose {
        let a = agents[k];
        if a.is_static() || a.path.length() == 0.0 || (s - a.path_start).abs() < 1e-9 {
            a.pose
        } else {
            let along = a.path.pose(s);
            if a.body == Body::Walker { Pose { yaw: a.pose.yaw, ..along } } else { along }
        }
    };
    states.push((0..agents.len()).map(|k| place(k, s[k])).collect());
    for step in 1..=steps {
        let t = step as f64 * dt;
        let current: Vec<Pose> = states.last().cloned().unwrap_or_default();
        let ego = current[0].position;
        for k in 0..agents.len() {
            let a = agents[k];
            if a.is_static() {
                continue;
            }
            if !started[k] {
                let due = t >= a.start.delay;
                let near = a.start.trigger.is_none_or(|d| ego.distance(current[k].position) <= d);
                // the ego's time to the point along its path, at its speed
                let met =
                    meets[k].is_none_or(|(at, travel)| tad_road::time_to(at - s[0], agents[0].speed) <= travel + 1e-9);
                if due && near && met {
                    started[k] = true;
                } else {
                    continue;
                }
            }
            if k == 0 || a.body != Body::Vehicle {
                v[k] = a.speed;
            } else {
                let leader = leader(&agents, &current, k, s[k], adversary[k]);
                let accel = IdmParams::default().accel(v[k], a.speed, leader);
                v[k] = (v[k] + accel * dt).max(0.0);
            }
            s[k] += v[k] * dt;
        }
        states.push((0..agents.len()).map(|k| place(k, s[k])).collect());
    }
    Trace { dt, objects, states }
}

/// The nearest actor ahead on `k`'s path within its corridor: (bumper gap, its speed along).
fn leader(agents: &[&crate::Agent], current: &[Pose], k: usize, s: f64, adversary: bool) -> Option<(f64, f64)> {
    let me = agents[k];
    let mut best: Option<(f64, f64)> = None;
    let mut ahead = 1.0;
    while ahead <= LOOKAHEAD {
        let p = me.path.pose(s + ahead);
        for (j, other) in agents.iter().enumerate() {
            if j == k || (adversary && j == 0) {
                continue;
            }
            let q = current[j].position;
            let reach = (me.width + other.width) / 2.0 + 0.2;
            if p.position.distance(q) <= reach.max(other.length / 2.0) && Pose::local(&p, q).y.abs() <= reach {
                let gap = ahead - (me.length + other.length.min(other.width.max(other.length))) / 2.0;
                let heading = Vec2::from_yaw(current[j].yaw).dot(Vec2::from_yaw(p.yaw));
                let speed = if other.is_static() { 0.0 } else { other.speed * heading.max(0.0) };
                if best.is_none_or(|(g, _)| gap < g) {
                    best = Some((gap, speed));
                }
            }
        }
        if best.is_some() {
            return best;
        }
        ahead += 1.0;
    }
    best
}
