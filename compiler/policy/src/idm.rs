//! The rule-based drivers: both keep to the route by pure pursuit on the view's target.
//! [`Idm`] follows the Intelligent Driver Model (Treiber, Hennecke, Helbing 2000) towards
//! the desired speed behind the leader and before a stop point (a red light's line, an
//! unserved stop sign), each a leader of its own; [`Naive`] holds one speed and sees
//! nothing.

use crate::{Action, EgoPolicy, EgoView, STANDING, pure_pursuit};
pub use tad_layout::idm::IdmParams;

/// Rule-based ego with full state: pure pursuit on the route and IDM towards the desired
/// speed (capped by the route's curves) behind the leader; a stop point (`EgoView::stop`) is a standing leader, so it
/// stops about `s0` short of it. At a stop sign the runtime clears `stop` once the ego
/// has stood; then it drives on. It never brakes into reverse.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Idm {
    pub params: IdmParams,
}

impl EgoPolicy for Idm {
    fn name(&self) -> &str {
        "idm"
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let obstacles = view.leader.into_iter().chain(view.stop.map(|d| (d, 0.0)));
        let accel = self.params.accel(view.speed, view.desired_speed.min(view.curve_speed), obstacles);
        Action { accel: no_reverse(accel, view), steer: pure_pursuit(view.target, view.wheelbase) }
    }
}

/// A driver that holds one speed along the route and ignores leaders, lights and signs:
/// the speed it has at its first step after [`EgoPolicy::reset`], or the desired speed if
/// it starts standing. It reaches that speed within IDM's comfortable limits
/// (`max_accel`, `comfort_decel`) and keeps it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Naive {
    pub params: IdmParams,
    hold: Option<f64>,
}

impl Naive {
    /// The speed it holds (`None` before its first step).
    pub fn hold(&self) -> Option<f64> {
        self.hold
    }
}

impl EgoPolicy for Naive {
    fn name(&self) -> &str {
        "naive"
    }

    fn reset(&mut self) {
        self.hold = None;
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let hold = *self.hold.get_or_insert(if view.speed >= STANDING { view.speed } else { view.desired_speed });
        let wanted = (hold - view.speed) / view.dt.max(1e-3);
        let accel = wanted.clamp(-self.params.comfort_decel, self.params.max_accel);
        Action { accel: no_reverse(accel, view), steer: pure_pursuit(view.target, view.wheelbase) }
    }
}

/// `accel` limited so that one step of it does not take the speed below zero.
fn no_reverse(accel: f64, view: &EgoView) -> f64 {
    if view.dt > 0.0 { accel.max(-view.speed.max(0.0) / view.dt) } else { accel }
}
