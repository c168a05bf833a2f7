//! The motion models: a kinematic bicycle (reference point at the centre, as highway-env's
//! vehicles), pure-pursuit steering onto a track, and the Intelligent Driver Model for speed
//! (`/work/shared`'s runtime notes §4: Treiber, Hennecke and Helbing 2000).

use crate::track::Track;
use tad_layout::geom::{Pose, Vec2};

/// IDM parameters: maximum acceleration and comfortable deceleration (m/s²), time headway
/// (s), jam gap (m), acceleration exponent; hard braking is clipped at [`MAX_BRAKE`].
pub const IDM_A: f64 = 2.0;
pub const IDM_B: f64 = 3.0;
pub const IDM_T: f64 = 1.5;
pub const IDM_S0: f64 = 2.0;
pub const IDM_DELTA: i32 = 4;
pub const MAX_BRAKE: f64 = 8.0;
/// The largest wheel angle, rad (70°, CARLA's usual); the ego's normalised steer scales it.
pub const MAX_WHEEL: f64 = 1.2217;
/// Wheelbase as a share of a vehicle's length.
pub const WHEELBASE: f64 = 0.6;

/// IDM acceleration at speed `v` towards `v0`, behind a leader `(gap, its speed)`.
pub fn idm(v: f64, v0: f64, leader: Option<(f64, f64)>) -> f64 {
    let free = if v0 <= 0.01 { -1.0 } else { 1.0 - (v / v0).powi(IDM_DELTA) };
    let interaction = leader.map_or(0.0, |(gap, lead)| {
        let wanted = IDM_S0 + (v * IDM_T + v * (v - lead) / (2.0 * (IDM_A * IDM_B).sqrt())).max(0.0);
        (wanted / gap.max(0.1)).powi(2)
    });
    (IDM_A * (free - interaction)).clamp(-MAX_BRAKE, IDM_A)
}

/// A vehicle's kinematic state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kinematics {
    pub position: Vec2,
    pub yaw: f64,
    pub speed: f64,
}

impl Kinematics {
    pub fn pose(&self) -> Pose {
        Pose { position: self.position, yaw: self.yaw }
    }

    /// One step of the kinematic bicycle with wheel angle `wheel` (rad, left positive) and
    /// acceleration `accel`; speed never goes below zero (no reversing).
    pub fn bicycle(&mut self, wheelbase: f64, wheel: f64, accel: f64, dt: f64) {
        let beta = (0.5 * wheel.tan()).atan();
        let v = self.speed;
        self.position = self.position + Vec2::from_yaw(self.yaw + beta) * (v * dt);
        self.yaw = tad_layout::geom::wrap(self.yaw + v * beta.sin() / (wheelbase / 2.0) * dt);
        self.speed = (v + accel * dt).max(0.0);
    }
}

/// The wheel angle (rad, left positive) that steers a vehicle at `pose` onto `track` at arc
/// `s`, aiming at the point a speed-dependent distance ahead.
pub fn pursue(track: &Track, s: f64, pose: Pose, speed: f64, wheelbase: f64) -> f64 {
    let lookahead = lookahead(speed);
    let target = pose.local(track.pose(s + lookahead).position);
    let d2 = target.x * target.x + target.y * target.y;
    if d2 < 1e-9 {
        return 0.0;
    }
    let curvature = 2.0 * target.y / d2;
    (wheelbase * curvature).atan().clamp(-0.7, 0.7)
}

/// How far ahead pure pursuit aims, m.
pub fn lookahead(speed: f64) -> f64 {
    (0.6 * speed + 3.0).clamp(4.0, 20.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn idm_stops_behind_a_standing_leader() {
        let mut v: f64 = 10.0;
        let mut gap: f64 = 60.0;
        for _ in 0..400 {
            let a = idm(v, 12.0, Some((gap, 0.0)));
            gap -= v * 0.1;
            v = (v + a * 0.1).max(0.0);
        }
        assert!(v < 0.05 && gap > 1.0 && gap < 3.0, "stopped {gap:.2} m behind at {v:.2} m/s");
        assert!((idm(12.0, 12.0, None)).abs() < 1e-9);
    }

    #[test]
    fn pursuit_converges_onto_an_offset_track() {
        let track = Track::from_points([Vec2::new(-10.0, 0.0), Vec2::new(200.0, 0.0)]);
        let mut k = Kinematics { position: Vec2::new(0.0, -3.5), yaw: 0.0, speed: 10.0 };
        for _ in 0..100 {
            let (s, _) = track.locate(k.position, k.position.x + 10.0, 20.0);
            let wheel = pursue(&track, s, k.pose(), k.speed, 2.7);
            k.bicycle(2.7, wheel, 0.0, 0.1);
        }
        assert!(k.position.y.abs() < 0.1 && k.yaw.abs() < 0.02, "{k:?}");
    }
}
