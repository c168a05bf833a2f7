//! Ego policies: what drives the ego in the runtime.
//!
//! Every policy sees an [`EgoView`] each step (SafeBench's four-feature observation and,
//! for rule-based drivers, the full state the runtime knows) and answers an [`Action`].

/// What the ego's driver sees at a step. Frame: the ego's, `x` forward, `y` left.
#[derive(Clone, Debug, PartialEq)]
pub struct EgoView {
    /// SafeBench's observation `[lateral_dis, -delta_yaw, speed, vehicle_front]` (CARLA's
    /// conventions: `lateral_dis` > 0 right of the route, `-delta_yaw` > 0 when the route
    /// turns right of the heading; see `obs`'s doc in the crate's spec).
    pub obs: [f64; 4],
    /// m/s.
    pub speed: f64,
    /// The speed the scenario states for the ego, m/s.
    pub desired_speed: f64,
    /// The route's point [`EgoView::lookahead`] metres ahead, in the ego's frame, m.
    pub target: [f64; 2],
    pub lookahead: f64,
    /// Front-to-rear axle distance, m.
    pub wheelbase: f64,
    /// The nearest actor ahead in the ego's corridor: (bumper-to-bumper gap m, its speed
    /// along the route m/s).
    pub leader: Option<(f64, f64)>,
    /// Distance from the ego's front to where it must stop (a stop line whose light is red
    /// or yellow, a stop sign it has not stopped at yet), m.
    pub stop: Option<f64>,
    /// Step length, s.
    pub dt: f64,
}

/// What the driver does: `accel` in m/s² (the runtime clamps it to `[-8, 3]`), `steer`
/// normalised to `[-1, 1]` of the maximum wheel angle, positive to the right (CARLA's sign).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Action {
    pub accel: f64,
    pub steer: f64,
}

pub trait EgoPolicy: Send {
    /// As the command line names it: `idm`, `naive`, `learned:PATH`.
    fn name(&self) -> &str;
    /// Called before each episode.
    fn reset(&mut self) {}
    fn act(&mut self, view: &EgoView) -> Action;
}
