//! The motion models: a kinematic bicycle (reference point at the centre, as highway-env's
//! vehicles), pure-pursuit steering onto a track, and the Intelligent Driver Model for speed
//! (`tad_layout::idm::IdmParams`, the one IDM of the workspace, which the layout's roll-out follows with too).

use tad_road::geom::{Path, Pose, Vec2};

/// Wheelbase as a share of a vehicle's length.
pub const WHEELBASE: f64 = 0.6;

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
        self.yaw = tad_road::geom::wrap(self.yaw + v * beta.sin() / (wheelbase / 2.0) * dt);
        self.speed = (v + accel * dt).max(0.0);
    }
}

/// The wheel angle (rad, left positive) that steers a vehicle at `pose` onto `track` at arc
/// `s`, aiming at the point a speed-dependent distance ahead.
pub fn pursue(track: &Path, s: f64, pose: Pose, speed: f64, wheelbase: f64) -> f64 {
    let lookahead = lookahead(speed);
    let target = pose.local(track.pose(s + lookahead).position);
    let d2 = target.x * target.x + target.y * target.y;
    if d2 < 1e-9 {
        return 0.0;
    }
    let curvature = 2.0 * target.y / d2;
    (wheelbase * curvature).atan().clamp(-0.7, 0.7)
}

/// Lateral acceleration drivers keep to in curves, m/s².
pub const LATERAL_ACCEL: f64 = 2.5;

/// The highest speed for the track ahead of arc `s`: over the distance covered in 3 s (at
/// least 15 m), `sqrt(LATERAL_ACCEL / κ)` of its sharpest curvature κ, measured as the
/// heading's change over 2 m; infinite where it is straight.
pub fn curve_speed(track: &Path, s: f64, speed: f64) -> f64 {
    let reach = (3.0 * speed).max(15.0);
    let mut sharpest: f64 = 0.0;
    let mut x = s;
    while x < s + reach {
        let turn = tad_road::geom::wrap(track.pose(x + 2.0).yaw - track.pose(x).yaw).abs() / 2.0;
        sharpest = sharpest.max(turn);
        x += 1.0;
    }
    if sharpest < 1e-4 { f64::INFINITY } else { (LATERAL_ACCEL / sharpest).sqrt() }
}

/// The largest turn, rad, between a path's first heading and any other: no two headings of
/// the path differ by more than twice this.
pub fn bend(track: &Path) -> f64 {
    let mut headings = track.points().windows(2).map(|w| (w[1] - w[0]).yaw());
    let Some(first) = headings.next() else { return 0.0 };
    headings.map(|y| tad_road::geom::wrap(y - first).abs()).fold(0.0, f64::max)
}

/// [`curve_speed`] of a path whose [`bend`] is known: where no two headings differ by 1e-4
/// rad (and the turns it measures are half a difference), there is no curve to slow for.
pub fn curve_speed_knowing(track: &Path, bend: f64, s: f64, speed: f64) -> f64 {
    if bend < 0.5e-4 { f64::INFINITY } else { curve_speed(track, s, speed) }
}

/// How far ahead pure pursuit aims, m.
pub fn lookahead(speed: f64) -> f64 {
    (0.5 * speed + 2.5).clamp(3.5, 20.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_path_has_no_curve_speed_and_a_bend_has_one() {
        let lane = Path::new((0..=400).map(|k| Vec2::new(k as f64 * 0.999 - 200.0, -5.25 + k as f64 * 1e-9)));
        assert!(bend(&lane) < 1e-6);
        for s in [-10.0, 0.0, 150.0, 399.0, 420.0] {
            assert_eq!(curve_speed(&lane, s, 10.0), f64::INFINITY);
            assert_eq!(curve_speed_knowing(&lane, bend(&lane), s, 10.0), f64::INFINITY);
        }
        let corner =
            Path::new((0..=20).map(|k| Vec2::new(k as f64, 0.0)).chain((1..=20).map(|k| Vec2::new(20.0, k as f64))));
        assert!((bend(&corner) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(curve_speed_knowing(&corner, bend(&corner), 10.0, 5.0), curve_speed(&corner, 10.0, 5.0));
        assert!(curve_speed(&corner, 10.0, 5.0).is_finite());
        assert_eq!(bend(&Path::default()), 0.0);
    }

    #[test]
    fn pursuit_converges_onto_an_offset_track() {
        let track = Path::new([Vec2::new(-10.0, 0.0), Vec2::new(200.0, 0.0)]);
        let mut k = Kinematics { position: Vec2::new(0.0, -3.5), yaw: 0.0, speed: 10.0 };
        for _ in 0..100 {
            let (s, _) = track.locate(k.position, k.position.x + 10.0, 20.0);
            let wheel = pursue(&track, s, k.pose(), k.speed, 2.7);
            k.bicycle(2.7, wheel, 0.0, 0.1);
        }
        assert!(k.position.y.abs() < 0.1 && k.yaw.abs() < 0.02, "{k:?}");
    }
}
