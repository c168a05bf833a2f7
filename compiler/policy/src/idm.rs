//! The rule-based drivers: both keep to the route by pure pursuit on the view's target.
//! [`Idm`] follows the Intelligent Driver Model (Treiber, Hennecke, Helbing 2000) towards
//! the desired speed behind the leader and before a stop point (a red light's line, an
//! unserved stop sign), each a leader of its own; [`Naive`] holds one speed and sees
//! nothing.

use crate::{Action, EgoPolicy, EgoView, STANDING, pure_pursuit};

/// IDM's parameters (note §4.2's urban defaults).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdmParams {
    /// `a`, m/s².
    pub max_accel: f64,
    /// `b`, m/s².
    pub comfort_decel: f64,
    /// `T`, s.
    pub headway: f64,
    /// `s0`, m.
    pub jam_gap: f64,
    /// `δ`.
    pub delta: f64,
    /// The hardest braking allowed, m/s² (positive).
    pub max_decel: f64,
}

impl Default for IdmParams {
    fn default() -> Self {
        IdmParams { max_accel: 2.0, comfort_decel: 3.0, headway: 1.5, jam_gap: 2.0, delta: 4.0, max_decel: 8.0 }
    }
}

impl IdmParams {
    /// IDM's acceleration at speed `v` towards `v0`, behind each obstacle `(gap m, its
    /// speed m/s)`: `a·[1 − (v/v0)^δ − (s*/s)²]` with `s* = s0 + max(0, vT + vΔv/(2√(ab)))`,
    /// the least over the obstacles, within `[−max_decel, max_accel]`. A desired speed
    /// below [`STANDING`] asks to stand: the free-road term brakes at `b`.
    pub fn accel(&self, v: f64, v0: f64, obstacles: impl IntoIterator<Item = (f64, f64)>) -> f64 {
        let IdmParams { max_accel: a, comfort_decel: b, headway, jam_gap, delta, max_decel } = *self;
        let v = v.max(0.0);
        let free = if v0 >= STANDING {
            a * (1.0 - (v / v0).powf(delta))
        } else if v > 0.0 {
            -b
        } else {
            0.0
        };
        let interaction = obstacles
            .into_iter()
            .map(|(gap, lead)| {
                let wanted = jam_gap + (v * headway + v * (v - lead) / (2.0 * (a * b).sqrt())).max(0.0);
                a * (wanted / gap.max(0.01)).powi(2)
            })
            .fold(0.0, f64::max);
        (free - interaction).clamp(-max_decel, a)
    }
}

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
