//! A path the runtime follows: a polyline with cumulative arc lengths and a projection that
//! searches near a hint, so following a path costs the same whatever its length.

use tad_layout::geom::{Path, Pose, Vec2};

#[derive(Clone, Debug, Default)]
pub struct Track {
    points: Vec<Vec2>,
    arcs: Vec<f64>,
}

impl Track {
    pub fn new(path: &Path) -> Track {
        Track::from_points(path.points().iter().copied())
    }

    /// Through `points`, repeated ones dropped.
    pub fn from_points(points: impl IntoIterator<Item = Vec2>) -> Track {
        let mut t = Track::default();
        for p in points {
            match t.points.last() {
                Some(last) if last.distance(p) < 1e-6 => {}
                Some(last) => {
                    let arc = t.arcs.last().copied().unwrap_or(0.0) + last.distance(p);
                    t.points.push(p);
                    t.arcs.push(arc);
                }
                None => {
                    t.points.push(p);
                    t.arcs.push(0.0);
                }
            }
        }
        t
    }

    pub fn length(&self) -> f64 {
        self.arcs.last().copied().unwrap_or(0.0)
    }

    pub fn points(&self) -> &[Vec2] {
        &self.points
    }

    fn segment(&self, s: f64) -> usize {
        if self.points.len() < 2 {
            return 0;
        }
        let i = self.arcs.partition_point(|&a| a <= s);
        i.clamp(1, self.points.len() - 1) - 1
    }

    /// The pose at arc `s`, extrapolated straight beyond the ends.
    pub fn pose(&self, s: f64) -> Pose {
        match self.points.len() {
            0 => Pose::default(),
            1 => Pose { position: self.points[0], yaw: 0.0 },
            _ => {
                let i = self.segment(s);
                let (a, b) = (self.points[i], self.points[i + 1]);
                let along = (b - a) * (1.0 / (self.arcs[i + 1] - self.arcs[i]));
                Pose { position: a + along * (s - self.arcs[i]), yaw: along.yaw() }
            }
        }
    }

    /// The arc of the point nearest `p` among the segments within `window` metres of
    /// `hint`, with the signed distance (positive: `p` is left of the track).
    pub fn locate(&self, p: Vec2, hint: f64, window: f64) -> (f64, f64) {
        let n = self.points.len();
        if n < 2 {
            return (0.0, self.points.first().map_or(f64::INFINITY, |q| q.distance(p)));
        }
        let first = self.segment(hint - window);
        let last = self.segment(hint + window);
        let mut best = (hint, f64::INFINITY, 0.0);
        for i in first..=last {
            let (a, b) = (self.points[i], self.points[i + 1]);
            let ab = b - a;
            let len2 = ab.dot(ab);
            let mut t = (p - a).dot(ab) / len2;
            // beyond the ends the track goes on straight
            if !(i == 0 && t < 0.0 || i == n - 2 && t > 1.0) {
                t = t.clamp(0.0, 1.0);
            }
            let q = a + ab * t;
            let d = q.distance(p);
            if d < best.1 {
                let side = ab.cross(p - a);
                best = (self.arcs[i] + t * (self.arcs[i + 1] - self.arcs[i]), d, side);
            }
        }
        (best.0, if best.2 < 0.0 { -best.1 } else { best.1 })
    }

    /// [`Track::locate`] over the whole track.
    pub fn project(&self, p: Vec2) -> (f64, f64) {
        let half = self.length() / 2.0;
        self.locate(p, half, half + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_is_signed_and_extrapolates() {
        let t = Track::from_points([Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0), Vec2::new(10.0, 10.0)]);
        let (s, d) = t.locate(Vec2::new(5.0, 1.0), 5.0, 3.0);
        assert!((s - 5.0).abs() < 1e-9 && (d - 1.0).abs() < 1e-9);
        let (s, d) = t.locate(Vec2::new(11.0, 5.0), 15.0, 3.0);
        assert!((s - 15.0).abs() < 1e-9 && (d + 1.0).abs() < 1e-9, "right of the track: {d}");
        let (s, _) = t.project(Vec2::new(-4.0, 0.0));
        assert!((s + 4.0).abs() < 1e-9);
        assert!((t.pose(25.0).position.y - 15.0).abs() < 1e-9);
    }
}
