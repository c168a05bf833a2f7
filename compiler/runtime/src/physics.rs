//! Collision detection with rapier3d: every actor is a kinematic body carrying a box the size
//! the vocabulary gives it; rapier's collision pipeline (broad phase, narrow phase, no
//! dynamics; the boxes are sensors, so only intersections are computed) reports when the
//! ego's box starts touching another. The runtime moves the
//! bodies itself, so nothing is integrated here.
//!
//! Only the ego's contacts matter, so rapier is asked as little as gives the same answer:
//! - the boxes of other actors are in a collision group that does not meet itself, so the
//!   broad phase makes no pairs of two non-ego boxes;
//! - a box that cannot reach the ego's (their centres farther apart than the two
//!   half-diagonals and a margin) is parked far away, moved only when it parks or comes near;
//! - a step in which no box can reach the ego's and the ego touches nothing is not handed to
//!   rapier at all (no new contact); most steps of most episodes are such steps.

use rapier3d::prelude::*;
use std::sync::mpsc::{Receiver, channel};

pub struct Physics {
    pipeline: CollisionPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    handles: Vec<RigidBodyHandle>,
    /// Each box's half-diagonal in the plane, m.
    radii: Vec<f64>,
    /// Whether each box stands at its parking place now.
    parked: Vec<bool>,
    /// The actors the ego touches now.
    touching: Vec<usize>,
    events: ChannelEventCollector,
    received: Receiver<CollisionEvent>,
    _forces: Receiver<ContactForceEvent>,
    _tears: Receiver<SoftBodyTearEvent>,
}

/// An actor's box: length, width, height (m).
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub length: f64,
    pub width: f64,
    pub height: f64,
}

impl Physics {
    /// One body per actor, in order; actor 0 is the ego, the only one whose contacts are
    /// reported.
    pub fn new(shapes: &[Shape]) -> Physics {
        let (send, received) = channel();
        let (force_send, forces) = channel();
        let (tear_send, tears) = channel();
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let mut handles = Vec::with_capacity(shapes.len());
        for (k, s) in shapes.iter().enumerate() {
            let body = bodies.insert(RigidBodyBuilder::kinematic_position_based().user_data(k as u128));
            let half = |x: f64| (x.max(0.1) / 2.0) as f32;
            let collider = ColliderBuilder::cuboid(half(s.length), half(s.width), half(s.height))
                .translation(Vector::new(0.0, 0.0, half(s.height)))
                .sensor(true)
                .active_collision_types(ActiveCollisionTypes::all())
                .collision_groups(if k == 0 { EGO } else { OTHERS })
                .active_events(if k == 0 { ActiveEvents::COLLISION_EVENTS } else { ActiveEvents::empty() })
                .user_data(k as u128);
            colliders.insert_with_parent(collider, body, &mut bodies);
            handles.push(body);
        }
        let radii = shapes.iter().map(|s| (s.length.max(0.1) / 2.0).hypot(s.width.max(0.1) / 2.0)).collect();
        Physics {
            radii,
            parked: vec![false; shapes.len()],
            touching: Vec::new(),
            pipeline: CollisionPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies,
            colliders,
            handles,
            events: ChannelEventCollector::new(send, force_send, tear_send),
            received,
            _forces: forces,
            _tears: tears,
        }
    }

    /// Move every actor to its pose `(x, y, yaw)` and return the actors the ego started
    /// touching.
    pub fn step(&mut self, poses: &[(f64, f64, f64)], hits: &mut Vec<usize>) {
        hits.clear();
        if self.touching.is_empty() && !self.anyone_near(poses) {
            return;
        }
        for (k, (&handle, &(x, y, yaw))) in self.handles.iter().zip(poses).enumerate() {
            let near = k == 0 || self.may_reach(poses[0], (x, y), k, PARK_MARGIN);
            if !near && self.parked[k] {
                continue;
            }
            self.parked[k] = !near;
            let (x, y) = if near { (x, y) } else { parking(k) };
            if let Some(body) = self.bodies.get_mut(handle) {
                let pose = Pose::new(Vector::new(x as f32, y as f32, 0.0), Vector::new(0.0, 0.0, yaw as f32));
                body.set_position(pose, true);
            }
        }
        self.pipeline.step(
            0.02,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &(),
            &self.events,
        );
        while let Ok(event) = self.received.try_recv() {
            let index = |h: ColliderHandle| self.colliders.get(h).map(|c| c.user_data as usize);
            let other = match (index(event.collider1()), index(event.collider2())) {
                (Some(0), Some(k)) | (Some(k), Some(0)) if k != 0 => k,
                _ => continue,
            };
            if event.started() {
                hits.push(other);
                self.touching.push(other);
            } else {
                self.touching.retain(|&k| k != other);
            }
        }
    }

    /// Whether some box may reach the ego's at `poses` (a margin of 0.5 m over the
    /// half-diagonals covers rapier's `f32` positions many times).
    fn anyone_near(&self, poses: &[(f64, f64, f64)]) -> bool {
        let Some(&ego) = poses.first() else { return false };
        poses.iter().enumerate().skip(1).any(|(k, &(x, y, _))| self.may_reach(ego, (x, y), k, 0.5))
    }

    /// Whether box `k` at `at` may reach the ego's at `ego`: their centres within the two
    /// half-diagonals and `margin`.
    fn may_reach(&self, ego: (f64, f64, f64), at: (f64, f64), k: usize, margin: f64) -> bool {
        let reach = self.radii[0] + self.radii[k] + margin;
        let (dx, dy) = (at.0 - ego.0, at.1 - ego.1);
        dx * dx + dy * dy <= reach * reach
    }
}

/// The ego's collision group: it meets the others'.
const EGO: InteractionGroups = InteractionGroups::new(Group::GROUP_1, Group::GROUP_2, InteractionTestMode::And);
/// Every other actor's group: it meets the ego's only.
const OTHERS: InteractionGroups = InteractionGroups::new(Group::GROUP_2, Group::GROUP_1, InteractionTestMode::And);
/// How much farther than it could reach the ego a box is parked, m: a box comes back from
/// its parking place only once it nears the ego, not at every step it wavers at the edge.
const PARK_MARGIN: f64 = 10.0;

/// Box `k`'s parking place: 1,000 km out from the origin and 100 m from every other (a
/// road is a few hundred metres across; `f32` holds positions there to 0.06 m).
fn parking(k: usize) -> (f64, f64) {
    (-1.0e6, 100.0 * k as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ego_touching_a_box_is_reported_once() {
        let car = Shape { length: 4.5, width: 1.8, height: 1.5 };
        let mut physics = Physics::new(&[car, car, Shape { length: 0.5, width: 0.5, height: 1.0 }]);
        let mut hits = Vec::new();
        physics.step(&[(0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        assert!(hits.is_empty());
        physics.step(&[(6.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        assert_eq!(hits, vec![1]);
        physics.step(&[(6.2, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        assert!(hits.is_empty(), "still touching: no new start");
        // rotated: a car across the ego's path, its box turned 90°
        physics.step(&[(0.0, 3.0, std::f64::consts::FRAC_PI_2), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        assert_eq!(hits, vec![2]);
        // far from everything: rapier is not asked, and nothing starts
        physics.step(&[(-50.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        assert!(hits.is_empty());
        // back at a box after steps away: a new start
        physics.step(&[(-50.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        physics.step(&[(6.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 5.0, 0.0)], &mut hits);
        assert_eq!(hits, vec![1]);
    }

    #[test]
    fn a_parked_box_that_comes_back_is_touched_and_others_never_pair() {
        let car = Shape { length: 4.5, width: 1.8, height: 1.5 };
        let mut physics = Physics::new(&[car, car, car, car]);
        let mut hits = Vec::new();
        // box 1 far off (parked), boxes 2 and 3 overlap each other beside the ego
        physics.step(&[(0.0, 0.0, 0.0), (200.0, 0.0, 0.0), (0.0, 4.0, 0.0), (1.0, 4.0, 0.0)], &mut hits);
        assert!(hits.is_empty());
        assert_eq!(physics.parked, [false, true, false, false]);
        // box 1 drives up to the ego in one step: its real pose is back in rapier
        physics.step(&[(0.0, 0.0, 0.0), (4.0, 0.0, 0.0), (0.0, 4.0, 0.0), (1.0, 4.0, 0.0)], &mut hits);
        assert_eq!(hits, vec![1]);
        assert!(physics.narrow_phase.intersection_pairs().all(|(a, b, _)| {
            let user = |h| physics.colliders.get(h).map(|c| c.user_data);
            user(a) == Some(0) || user(b) == Some(0)
        }));
    }
}
