//! SafeBench's reward (`gym_carla/envs/carla_env.py::_get_reward`), step by step from the
//! runtime's records.

use std::ops::Deref;
use tad_layout::geom::Vec2;
use tad_metrics::StepRecord;
use tad_runtime::Scene;

/// Beyond this distance from the route the ego is out of its lane (`out_lane_thres`), m.
pub const OUT_OF_LANE: f64 = 4.0;

/// The reward's terms at one step, as SafeBench adds them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reward {
    /// −1 once the ego has collided.
    pub collision: f64,
    /// The ego's speed along the route, m/s.
    pub speed_lon: f64,
    /// −1 when `speed_lon` exceeds the desired speed (weighted 10).
    pub fast: f64,
    /// −1 when the ego is more than [`OUT_OF_LANE`] from the route.
    pub out: f64,
    /// −steer² (weighted 5), steer the applied control in `[−1, 1]`.
    pub steer: f64,
    /// −|steer|·speed_lon² (weighted 0.2), a lateral-acceleration penalty.
    pub lateral: f64,
}

impl Reward {
    /// `r = r_collision + lspeed_lon + 10·r_fast + r_out + 5·r_steer + 0.2·r_lat`.
    pub fn total(&self) -> f64 {
        self.collision + self.speed_lon + 10.0 * self.fast + self.out + 5.0 * self.steer + 0.2 * self.lateral
    }
}

/// Follows the ego along its route through an episode's records, so each step's arc is
/// found near the last one.
/// `S` is how the scene is held (`&Scene`, or `Arc<Scene>` for an environment).
pub struct Rewarder<S: Deref<Target = Scene>> {
    scene: S,
    desired: f64,
    arc: f64,
}

impl<S: Deref<Target = Scene>> Rewarder<S> {
    /// For an episode of `scene` whose ego wants `desired` m/s.
    pub fn new(scene: S, desired: f64) -> Rewarder<S> {
        let arc = scene.ego.start;
        Rewarder { scene, desired, arc }
    }

    /// The reward of the step that led to `record` with the applied normalised `steer`.
    /// The longitudinal speed is the speed times the cosine of the heading against the
    /// route's direction where the ego is (SafeBench: the velocity dotted with the lane's
    /// direction); the lateral distance is the record's distance to the route.
    pub fn step(&mut self, record: &StepRecord, steer: f64) -> Reward {
        let route = &self.scene.ego.route;
        let position = Vec2::new(record.position[0], record.position[1]);
        let (arc, _) = route.locate(position, self.arc, 10.0);
        self.arc = arc;
        let yaw = -record.yaw_deg.to_radians();
        let speed_lon = record.velocity * (yaw - route.pose(arc).yaw).cos();
        Reward {
            collision: if record.collision { -1.0 } else { 0.0 },
            speed_lon,
            fast: if speed_lon > self.desired { -1.0 } else { 0.0 },
            out: if record.distance_to_route > OUT_OF_LANE { -1.0 } else { 0.0 },
            steer: -steer * steer,
            lateral: -steer.abs() * speed_lon * speed_lon,
        }
    }
}
