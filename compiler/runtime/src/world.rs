//! The static world a program sets up: the layout's road (its lanes told apart point by
//! point, for lane invasions and off-road), the stop line of every arm, and the lights'
//! phase programs.
//!
//! Lanes are found geometrically from `tad_road::Road`, the same road the layout placed
//! everything on: on the ego's road (straight or curved) by the point's offset from the
//! centre line, on a junction's other arms by its offset in that arm's frame, and inside the
//! junction's box (or the roundabout's ring) as the junction itself, which has no markings.

use tad_bytecode::{Light, Phase};
use tad_road::geom::{Pose, Vec2};
use tad_road::road::CURVE_RADIUS;
use tad_road::{Arm, Road, Shape, Station};

/// Where a point is on the road.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spot {
    /// A driving lane of an arm (TAD's lane index; the ego's road is `Arm::Ego`).
    Lane(Arm, i64),
    /// Inside the junction.
    Junction,
    /// On no driving lane: the shoulder, a sidewalk, beyond the road.
    Off,
}

pub struct World {
    pub road: Road,
    /// Phase programs by arm (only a signalised junction has any).
    pub signals: Vec<(Arm, Vec<Phase>)>,
}

impl World {
    pub fn new(road: Road, signals: Vec<(Arm, Vec<Phase>)>) -> World {
        World { road, signals }
    }

    /// What the lights facing `arm`'s incoming traffic show at time `t`.
    pub fn light(&self, arm: Arm, t: f64) -> Light {
        let Some((_, phases)) = self.signals.iter().find(|(a, _)| *a == arm) else { return Light::Off };
        let cycle: f64 = phases.iter().map(|p| p.seconds.max(0.0)).sum();
        if cycle <= 0.0 {
            return phases.first().map_or(Light::Off, |p| p.light);
        }
        let mut at = t.rem_euclid(cycle);
        for p in phases {
            if at < p.seconds {
                return p.light;
            }
            at -= p.seconds;
        }
        phases.last().map_or(Light::Off, |p| p.light)
    }

    /// Every arm's light at `t`.
    pub fn lights(&self, t: f64) -> Vec<(Arm, Light)> {
        self.signals.iter().map(|(arm, _)| (*arm, self.light(*arm, t))).collect()
    }

    pub fn stop_signs(&self) -> bool {
        self.road.junction.as_ref().is_some_and(|j| j.stop_signs)
    }

    /// The centre of an incoming lane's stop line (with a junction).
    pub fn stop_line(&self, arm: Arm, lane: i64) -> Option<Vec2> {
        self.road.junction.as_ref()?;
        let along = if arm == Arm::Ego { self.road.approach } else { 0.0 };
        Some(self.road.lane_pose(Station { arm, along }, lane).position)
    }

    /// The lane (or junction) under a point.
    pub fn spot(&self, p: Vec2) -> Spot {
        let road = &self.road;
        let w = road.lane_width;
        if let Some(j) = &road.junction {
            let c = road.centre();
            let rel = p - c;
            let inside = if j.roundabout {
                let r = rel.length();
                r <= j.half && r >= (j.half * 0.75 - w * 0.75).max(0.0)
            } else {
                rel.x.abs() <= j.half && rel.y.abs() <= j.half
            };
            if inside {
                return Spot::Junction;
            }
            if j.roundabout && rel.length() < j.half {
                return Spot::Off; // the island
            }
            for &arm in &j.arms {
                let u = arm.outward();
                let along = rel.dot(u) - j.half;
                if along < 0.0 {
                    continue;
                }
                let lateral = rel.dot((-u).left());
                if let Some(lane) = lane_at(road, arm, lateral, w) {
                    return Spot::Lane(arm, lane);
                }
            }
            return Spot::Off;
        }
        let lateral = match road.shape {
            Shape::Curve { left } if p.x > 0.0 => {
                let sign = if left { 1.0 } else { -1.0 };
                let centre = Vec2::new(0.0, sign * CURVE_RADIUS);
                // only the bend's own half-plane: beyond it the road would go on
                sign * (CURVE_RADIUS - p.distance(centre))
            }
            _ => p.y,
        };
        lane_at(road, Arm::Ego, lateral, w).map_or(Spot::Off, |lane| Spot::Lane(Arm::Ego, lane))
    }

    /// Whether a point is on a driving lane or in the junction.
    pub fn on_road(&self, p: Vec2) -> bool {
        self.spot(p) != Spot::Off
    }

    /// The pose of a station on an arm, `lateral` left of its centre line.
    pub fn pose_at(&self, arm: Arm, along: f64, lane: i64, lateral: f64) -> Pose {
        self.road.pose_at(Station { arm, along }, lane, lateral)
    }
}

/// The lane `lateral` metres left of an arm's centre line lies in, if one does.
fn lane_at(road: &Road, arm: Arm, lateral: f64, w: f64) -> Option<i64> {
    let (incoming, outgoing) = road.arm_lanes(arm);
    if lateral <= 0.0 {
        let i = (-lateral / w).floor() as i64 + 1;
        (i <= i64::from(incoming)).then_some(i)
    } else {
        let j = (lateral / w).floor() as i64 + 1;
        (j <= i64::from(outgoing)).then_some(-j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tad_road::road::{Junction, LANE_WIDTH};

    pub(crate) fn crossroads(signalised: bool) -> Road {
        Road {
            shape: Shape::Junction { arms: 4, roundabout: false },
            lanes: 2,
            opposite: 1,
            cross_lanes: 1,
            lane_width: LANE_WIDTH,
            sidewalks: true,
            crosswalks: true,
            signal: None,
            junction: Some(Junction {
                arms: Arm::ALL.to_vec(),
                roundabout: false,
                half: 8.0,
                signalised,
                stop_signs: !signalised,
            }),
            approach: 30.0,
        }
    }

    #[test]
    fn points_fall_in_their_lanes() {
        let w = World::new(crossroads(false), vec![]);
        assert_eq!(w.spot(Vec2::new(5.0, -1.0)), Spot::Lane(Arm::Ego, 1));
        assert_eq!(w.spot(Vec2::new(5.0, -5.0)), Spot::Lane(Arm::Ego, 2));
        assert_eq!(w.spot(Vec2::new(5.0, 2.0)), Spot::Lane(Arm::Ego, -1));
        assert_eq!(w.spot(Vec2::new(5.0, 4.0)), Spot::Off, "one lane the other way");
        assert_eq!(w.spot(Vec2::new(5.0, -7.5)), Spot::Off);
        assert_eq!(w.spot(Vec2::new(38.0, 0.0)), Spot::Junction);
        // the left arm's incoming lane drives towards -y, on the arm's right: +x side
        let left_in = w.road.lane_pose(Station { arm: Arm::Left, along: 10.0 }, 1).position;
        assert_eq!(w.spot(left_in), Spot::Lane(Arm::Left, 1));
        let right_out = w.road.lane_pose(Station { arm: Arm::Right, along: 10.0 }, -1).position;
        assert_eq!(w.spot(right_out), Spot::Lane(Arm::Right, -1));
        assert!(w.stop_line(Arm::Ego, 1).is_some_and(|p| (p.x - 30.0).abs() < 1e-9));
    }

    #[test]
    fn a_curve_keeps_its_lanes() {
        let road = Road { shape: Shape::Curve { left: true }, junction: None, ..crossroads(false) };
        let w = World::new(road, vec![]);
        let p = w.road.ego_road(40.0, -1.75).position;
        assert_eq!(w.spot(p), Spot::Lane(Arm::Ego, 1));
        let p = w.road.ego_road(40.0, -9.0).position;
        assert_eq!(w.spot(p), Spot::Off);
    }

    #[test]
    fn phase_programs_cycle() {
        let phases = vec![
            Phase { light: Light::Green, seconds: 10.0 },
            Phase { light: Light::Yellow, seconds: 3.0 },
            Phase { light: Light::Red, seconds: 7.0 },
        ];
        let w = World::new(crossroads(true), vec![(Arm::Ego, phases)]);
        assert_eq!(w.light(Arm::Ego, 0.0), Light::Green);
        assert_eq!(w.light(Arm::Ego, 11.0), Light::Yellow);
        assert_eq!(w.light(Arm::Ego, 19.9), Light::Red);
        assert_eq!(w.light(Arm::Ego, 20.5), Light::Green);
        assert_eq!(w.light(Arm::Left, 0.0), Light::Off);
    }
}
