//! The decoded program: set-up instructions (the road, signals, the ego, every actor),
//! then behaviour instructions run per actor, each actor with its own program counter.
//!
//! A behaviour instruction either returns at once (it sets what the actor does: `Drive`,
//! `Cross`, `Speed`, `ChangeLane`, `Stop`, `Signals`, `Mobil`) or blocks the actor's script
//! until it holds (`Wait`, `WaitNear`, `Meet`); the motion it set goes on meanwhile.

use tad_road::{Arm, Body, Facing, Place, Turn};

/// A parameter slot's index in [`Program::params`].
pub type Slot = u16;
/// An actor's index in the spawn order (0 is the first `Spawn`; the ego has none).
pub type ActorId = u16;
/// A path's index in [`Program::paths`].
pub type PathId = u16;

/// A number: `base`, plus the slot's sampled value when there is one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Value {
    pub base: f64,
    pub slot: Option<Slot>,
}

impl Value {
    pub const fn lit(base: f64) -> Value {
        Value { base, slot: None }
    }

    /// With the slots' values for this run (a missing slot counts 0).
    pub fn eval(&self, params: &[f64]) -> f64 {
        self.base + self.slot.and_then(|s| params.get(usize::from(s))).copied().unwrap_or(0.0)
    }
}

/// A value sampled per run, uniformly in `min..=max`; `default` is the nominal run's.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSlot {
    /// `group.what`: `slow_truck.shift`, `runner.spread`, `runner.speed`.
    pub name: String,
    pub min: f64,
    pub max: f64,
    pub default: f64,
}

/// A polyline in the road's frame (m; the ego starts at the origin heading `+x`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Polyline(pub Vec<[f64; 2]>);

impl Polyline {
    /// How far a dropped point may lie from the stored polyline, m.
    pub const TOLERANCE: f64 = 0.01;

    /// The form the `.tadc` format stores: every point rounded to whole millimetres, repeated
    /// points dropped, then every point within [`Polyline::TOLERANCE`] of the polyline
    /// through the points kept dropped (Douglas–Peucker; the ends are always kept).
    /// Idempotent: the canonical form of a canonical polyline is itself.
    /// A polyline with a non-finite coordinate is returned as it is (it is invalid anyway).
    pub fn canonical(&self) -> Polyline {
        if self.0.iter().flatten().any(|v| !v.is_finite()) {
            return self.clone();
        }
        let mut points: Vec<[f64; 2]> = Vec::with_capacity(self.0.len());
        for p in &self.0 {
            let q = [from_mm(to_mm(p[0])), from_mm(to_mm(p[1]))];
            if points.last() != Some(&q) {
                points.push(q);
            }
        }
        if points.len() <= 2 {
            return Polyline(points);
        }
        let mut keep = vec![false; points.len()];
        keep[0] = true;
        keep[points.len() - 1] = true;
        let mut stack = vec![(0, points.len() - 1)];
        while let Some((a, b)) = stack.pop() {
            let far = (a + 1..b)
                .map(|i| (i, segment_distance(points[i], points[a], points[b])))
                .max_by(|x, y| x.1.total_cmp(&y.1));
            if let Some((i, d)) = far
                && d > Self::TOLERANCE
            {
                keep[i] = true;
                stack.push((a, i));
                stack.push((i, b));
            }
        }
        Polyline(points.into_iter().zip(keep).filter(|(_, k)| *k).map(|(p, _)| p).collect())
    }

    /// Its length, m.
    pub fn length(&self) -> f64 {
        self.0.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum()
    }
}

/// A coordinate in whole millimetres, as the format stores it (saturating; a non-finite
/// one is `i64::MAX`, which the loader rejects as out of range).
pub(crate) fn to_mm(v: f64) -> i64 {
    if v.is_finite() { (v * 1000.0).round() as i64 } else { i64::MAX }
}

/// A coordinate from whole millimetres.
pub(crate) fn from_mm(mm: i64) -> f64 {
    mm as f64 / 1000.0
}

/// The distance from `p` to the segment `a`–`b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (abx, aby) = (b[0] - a[0], b[1] - a[1]);
    let len2 = abx * abx + aby * aby;
    let t = if len2 > 0.0 { (((p[0] - a[0]) * abx + (p[1] - a[1]) * aby) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a[0] + abx * t - p[0]).hypot(a[1] + aby * t - p[1])
}

/// What a light shows in a phase: the workspace's one light state (`tad_ir::Signal`).
pub use tad_ir::Signal as Light;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    pub light: Light,
    pub seconds: f64,
}

/// An actor's size, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Size {
    pub length: f64,
    pub width: f64,
    pub height: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Instr {
    // ── set-up, before step 0 ────────────────────────────────────────────────────────
    /// The road; exactly one, first. The runtime rebuilds `tad_road::Road` from it.
    Road(tad_road::Road),
    /// When a run ends: step length (s), steps, the ego's driven distance (m), time (s).
    Limits { dt: f64, max_steps: u32, max_distance: f64, timeout: f64 },
    /// The phase program of the lights facing an arm's incoming traffic; it repeats.
    Signal { arm: Arm, phases: Vec<Phase> },
    /// The ego: its vehicle, route (a path, the arc length of the start, the route's
    /// length from there) and the speed the scenario states (the policies' desired speed).
    Ego { class: String, size: Size, lane: i64, turn: Turn, path: PathId, start: f64, route_length: f64, speed: Value },
    /// One actor, standing (or moving at `speed` when `moving`) at a station on an arm.
    Spawn {
        actor: ActorId,
        /// The group's name and the actor's place in it.
        group: String,
        index: u16,
        body: Body,
        /// The vocabulary's name: `sedan`, `pedestrian`, `traffic_cone`.
        class: String,
        size: Size,
        arm: Arm,
        lane: i64,
        place: Place,
        /// The station's `along` (see `tad_road::Station`), sampled shifts included.
        along: Value,
        /// Left of the arm's centre line, m.
        lateral: f64,
        facing: Facing,
        /// Heading in the road's frame, radians from `+x`, counter-clockwise.
        yaw: f64,
        /// m/s at step 0 (0 when standing).
        speed: f64,
    },
    // ── behaviour, per actor, in program order ───────────────────────────────────────
    /// Block this actor's script for a time.
    Wait { actor: ActorId, seconds: Value },
    /// Block until the ego is within a distance of the actor, m.
    WaitNear { actor: ActorId, distance: Value },
    /// Block until the ego's time to `point` (its arc to the point's nearest on its route,
    /// at its speed) is `travel` seconds or less: the actor's own time to get there.
    Meet { actor: ActorId, point: [f64; 2], travel: Value },
    /// Drive its lane from where it stands at `speed`, taking `turn` at the junction ahead
    /// (the path is `Road::vehicle_path`, kept `lateral` off the lane's centre).
    Drive { actor: ActorId, speed: Value, turn: Turn },
    /// Drive or walk an explicit path (an overtake, a walk along the sidewalk).
    Follow { actor: ActorId, path: PathId, speed: Value },
    /// Walk straight ahead across the road at `speed`.
    Cross { actor: ActorId, speed: Value },
    /// Move to the lane `lanes` to the right (negative: left) of the current one.
    ChangeLane { actor: ActorId, lanes: i64 },
    /// A new target speed, m/s.
    Speed { actor: ActorId, speed: Value },
    /// Brake to a stop and stay.
    Stop { actor: ActorId },
    /// Obey (the default) or run red lights and stop signs.
    Signals { actor: ActorId, obey: bool },
    /// Let the runtime change lanes when it pays (MOBIL); off by default.
    Mobil { actor: ActorId, on: bool },
}

/// A decoded `.tadc` program.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Program {
    /// The scenario's name and the file it was built from.
    pub name: String,
    pub source: String,
    pub params: Vec<ParamSlot>,
    pub paths: Vec<Polyline>,
    pub code: Vec<Instr>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_canonical_form_drops_collinear_points_keeps_corners_and_is_idempotent() {
        // a straight run sampled every metre, a corner, a gentle arc
        let mut points: Vec<[f64; 2]> = (0..=100).map(|x| [f64::from(x), 0.004 * f64::from(x % 2)]).collect();
        points.extend((1..=50).map(|y| [100.0, f64::from(y)]));
        points.extend((1..=90).map(|k| {
            let a = f64::from(k).to_radians();
            [100.0 - 20.0 + 20.0 * a.cos(), 50.0 + 20.0 * a.sin()]
        }));
        let line = Polyline(points.clone());
        let c = line.canonical();
        assert!(c.0.len() < 50 && points.len() > 200, "{} points kept", c.0.len());
        assert_eq!(c.0.first(), Some(&[0.0, 0.0]));
        assert!(c.0.contains(&[100.0, 0.0]), "the corner is kept");
        assert_eq!(c.canonical(), c, "idempotent");
        for p in &points {
            let d = c.0.windows(2).map(|w| segment_distance(*p, w[0], w[1])).fold(f64::INFINITY, f64::min);
            assert!(d <= Polyline::TOLERANCE + 0.001, "{p:?} is {d} m off");
        }
        for q in c.0.iter().flatten() {
            assert_eq!(from_mm(to_mm(*q)), *q, "on the millimetre grid");
        }
        assert!((c.length() - line.length()).abs() < 0.1);
        // repeated points go; a non-finite polyline is left as it is
        assert_eq!(Polyline(vec![[1.0, 2.0], [1.0, 2.0], [1.0004, 2.0]]).canonical(), Polyline(vec![[1.0, 2.0]]));
        let bad = Polyline(vec![[f64::NAN, 0.0], [1.0, 0.0], [2.0, 0.0]]);
        assert_eq!(bad.canonical().0.len(), 3);
    }
}
