//! The abstract road a scenario asks for: its shape (straight, a curve, a three- or
//! four-way junction, a roundabout), lanes per direction, sidewalks, crosswalks, stop
//! lines and the light, in a frame where the ego starts at the origin heading `+x`.
//!
//! Lanes follow TAD's convention: on the ego's road, lane `i > 0` drives with the ego and
//! lies `i - 0.5` lane widths right of the centre line; lane `-j` drives against it, `j -
//! 0.5` widths left of it. At a junction every [`Arm`] has incoming lanes (`i > 0`,
//! driving into the junction, counted from the centre line) and outgoing ones (`-j`). A
//! [`Station`] says where along the road something is: on the ego's arm, metres from the
//! ego's start along its road; on another arm, metres before that arm's stop line
//! (incoming lanes) or after the junction (outgoing lanes).

use crate::geom::{Path, Pose, Vec2, bezier};
use tad_ir::Signal;

/// Lane width, m.
pub const LANE_WIDTH: f64 = 3.5;
/// Sidewalk width, m.
pub const SIDEWALK_WIDTH: f64 = 2.0;
/// Radius of a curved road's centre line, m (a 30° bend every 31 m).
pub const CURVE_RADIUS: f64 = 60.0;
/// How far paths run before a start and after a junction, m: the scene's reach.
pub const RUN: f64 = tad_ir::SCENE_REACH;
/// Where an arm's crosswalk is: metres past its stop line, towards the junction's centre.
pub const CROSSWALK: f64 = 2.0;
/// How deep a crosswalk is, along the road, m.
pub const CROSSWALK_DEPTH: f64 = 2.5;
/// The radius of a roundabout's ring (where vehicles circle), as a fraction of [`Junction::half`].
pub const RING: f64 = 0.75;

/// A road of a junction, named from the ego's approach.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Arm {
    /// The ego's own road (with no junction, the whole road).
    Ego,
    /// The road to the ego's left: its incoming traffic drives towards the ego's right.
    Left,
    /// The road to the ego's right.
    Right,
    /// The road straight ahead across the junction: its incoming traffic comes towards the ego.
    Opposite,
}

impl Arm {
    pub const ALL: [Arm; 4] = [Arm::Ego, Arm::Left, Arm::Right, Arm::Opposite];

    pub fn as_str(self) -> &'static str {
        match self {
            Arm::Ego => "ego",
            Arm::Left => "left",
            Arm::Right => "right",
            Arm::Opposite => "opposite",
        }
    }

    /// From the junction's centre out along the arm.
    pub fn outward(self) -> Vec2 {
        match self {
            Arm::Ego => Vec2::new(-1.0, 0.0),
            Arm::Opposite => Vec2::new(1.0, 0.0),
            Arm::Left => Vec2::new(0.0, 1.0),
            Arm::Right => Vec2::new(0.0, -1.0),
        }
    }

    fn from_outward(u: Vec2) -> Arm {
        Arm::ALL.into_iter().max_by(|a, b| a.outward().dot(u).total_cmp(&b.outward().dot(u))).unwrap_or(Arm::Ego)
    }
}

/// What a vehicle does at the junction (or, with none, on the road).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Turn {
    Straight,
    Left,
    Right,
    UTurn,
}

impl Turn {
    /// The lane a vehicle in `lane` leaves by, onto an arm with `outgoing` lanes: its own
    /// going straight on, the innermost after a left turn or a U-turn, the outermost after a
    /// right turn.
    pub fn exit_lane(self, lane: i64, outgoing: u32) -> i64 {
        match self {
            Turn::Straight => lane.min(i64::from(outgoing.max(1))),
            Turn::Left | Turn::UTurn => 1,
            Turn::Right => i64::from(outgoing.max(1)),
        }
    }

    /// The arm a vehicle coming in on `arm` leaves by.
    pub fn exit(self, arm: Arm) -> Arm {
        let d = -arm.outward();
        match self {
            Turn::Straight => Arm::from_outward(d),
            Turn::Left => Arm::from_outward(d.left()),
            Turn::Right => Arm::from_outward(d.right()),
            Turn::UTurn => arm,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Straight,
    /// A bend of [`CURVE_RADIUS`] to the left or the right.
    Curve {
        left: bool,
    },
    Junction {
        arms: u8,
        roundabout: bool,
    },
}

/// Where along the road: see the module's header.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Station {
    pub arm: Arm,
    pub along: f64,
}

/// Which side of a road, as its incoming (or, for the ego's road, the ego's) traffic sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    Left,
    Right,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Junction {
    /// The arms that exist: the ego's and two or three others.
    pub arms: Vec<Arm>,
    pub roundabout: bool,
    /// From the centre to each stop line, m.
    pub half: f64,
    /// Traffic lights control it.
    pub signalised: bool,
    /// Stop signs on every arm.
    pub stop_signs: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Road {
    pub shape: Shape,
    /// Lanes in the ego's direction.
    pub lanes: u32,
    /// Lanes in the opposite direction (0: one-way).
    pub opposite: u32,
    /// Lanes each way on the crossing roads.
    pub cross_lanes: u32,
    pub lane_width: f64,
    pub sidewalks: bool,
    pub crosswalks: bool,
    /// What the light facing the ego shows.
    pub signal: Option<Signal>,
    pub junction: Option<Junction>,
    /// From the ego's start to its stop line, m (with a junction).
    pub approach: f64,
}

impl Road {
    /// The junction's centre.
    pub fn centre(&self) -> Vec2 {
        Vec2::new(self.approach + self.junction.as_ref().map_or(0.0, |j| j.half), 0.0)
    }

    pub fn has_arm(&self, arm: Arm) -> bool {
        arm == Arm::Ego || self.junction.as_ref().is_some_and(|j| j.arms.contains(&arm))
    }

    /// Lanes on an arm: (incoming, outgoing).
    pub fn arm_lanes(&self, arm: Arm) -> (u32, u32) {
        match arm {
            Arm::Ego => (self.lanes, self.opposite),
            Arm::Opposite => (self.opposite, self.lanes),
            Arm::Left | Arm::Right => (self.cross_lanes, self.cross_lanes),
        }
    }

    /// Lateral offset of a lane's centre, left of the ego road's centre line positive.
    pub fn lateral(&self, lane: i64) -> f64 {
        let w = self.lane_width;
        if lane > 0 { -(lane as f64 - 0.5) * w } else { (-lane as f64 - 0.5) * w }
    }

    /// The edge of the road on a side of the ego's road: `(lateral of the curb)`.
    pub fn curb(&self, side: Side) -> f64 {
        match side {
            Side::Right => -(self.lanes as f64) * self.lane_width,
            Side::Left => self.opposite as f64 * self.lane_width,
        }
    }

    /// A point of the ego's road: `x` metres along it from the ego's start, `y` left of
    /// its centre line.
    pub fn ego_road(&self, x: f64, y: f64) -> Pose {
        match self.shape {
            Shape::Curve { left } if x > 0.0 => {
                let r = CURVE_RADIUS;
                let (sign, y) = if left { (1.0, y) } else { (-1.0, -y) };
                let phi = x / r;
                let p = Vec2::new(phi.sin() * (r - y), r - phi.cos() * (r - y));
                Pose { position: Vec2::new(p.x, sign * p.y), yaw: sign * phi }
            }
            _ => Pose { position: Vec2::new(x, y), yaw: 0.0 },
        }
    }

    /// The pose of a lane's centre at a station; facing the lane's traffic.
    pub fn lane_pose(&self, station: Station, lane: i64) -> Pose {
        self.pose_at(station, lane, self.lateral(lane))
    }

    /// A point `lateral` metres left of the centre line (as the arm's incoming traffic sees
    /// it), at a station; facing along the lane `lane`'s traffic.
    pub fn pose_at(&self, station: Station, lane: i64, lateral: f64) -> Pose {
        match station.arm {
            Arm::Ego => {
                let p = self.ego_road(station.along, lateral);
                if lane < 0 { Pose { yaw: p.yaw + std::f64::consts::PI, ..p } } else { p }
            }
            arm => {
                let u = arm.outward();
                let d = -u;
                let half = self.junction.as_ref().map_or(0.0, |j| j.half);
                let position = self.centre() + u * (half + station.along) + d.left() * lateral;
                Pose { position, yaw: if lane < 0 { u.yaw() } else { d.yaw() } }
            }
        }
    }

    /// Where an arm meets the junction: the ego's stop line, or another arm's.
    pub fn edge(&self, arm: Arm) -> Station {
        Station { arm, along: if arm == Arm::Ego { self.approach } else { 0.0 } }
    }

    /// A station's distance before the arm's stop line (incoming lanes), or after the
    /// junction (outgoing lanes, given as a positive `along`).
    pub fn before_stop_line(&self, station: Station) -> f64 {
        match station.arm {
            Arm::Ego => self.approach - station.along,
            _ => station.along,
        }
    }

    /// The path of a vehicle in `lane` from `start` (metres before the stop line on its
    /// arm, or along the ego's road) taking `turn` at the junction; without a junction, along
    /// the lane. The path starts [`RUN`] metres behind the start; returns it with the arc
    /// length of the start.
    pub fn vehicle_path(&self, station: Station, lane: i64, turn: Turn) -> (Path, f64) {
        let Some(junction) = self.junction.as_ref().filter(|_| lane > 0) else {
            // along the lane, either way
            let points = sample(station.along - RUN, station.along + RUN, |x| {
                let s = if lane < 0 && station.arm == Arm::Ego { 2.0 * station.along - x } else { x };
                self.pose_at(Station { along: s, ..station }, lane, self.lateral(lane)).position
            });
            return (Path::new(points), RUN);
        };
        let arm = station.arm;
        let before = self.before_stop_line(station);
        let entry = self.lane_pose(self.edge(arm), lane);
        let d = Vec2::from_yaw(entry.yaw);
        let mut points: Vec<Vec2> = sample(-(before + RUN), 0.0, |t| entry.position + d * t);
        let exit_arm = turn.exit(arm);
        let (_, outgoing) = self.arm_lanes(exit_arm);
        let exit_lane = turn.exit_lane(lane, outgoing);
        let exit = self.pose_at(self.edge(exit_arm), -exit_lane, self.lateral(-exit_lane));
        let u = Vec2::from_yaw(exit.yaw);
        if junction.roundabout {
            let ring = Ring::of(self.centre(), junction.half * RING, entry.position, turn);
            let (on, off) = (ring.at(0.0), ring.at(ring.sweep));
            points.extend(bezier(entry.position, d, on, ring.tangent(0.0)));
            points.extend(ring.points());
            points.extend(bezier(off, ring.tangent(ring.sweep), exit.position, u));
        } else if turn == Turn::UTurn {
            let mid = self.centre() + d * (junction.half * 0.5);
            points.extend(bezier(entry.position, d, mid, d.left()));
            points.extend(bezier(mid, d.left(), exit.position, u));
        } else {
            points.extend(bezier(entry.position, d, exit.position, u));
        }
        points.extend(sample(0.0, RUN, |t| exit.position + u * t));
        (Path::new(points), RUN)
    }
}

/// Points every metre from `a` to `b` of `f`.
fn sample(a: f64, b: f64, f: impl Fn(f64) -> Vec2) -> Vec<Vec2> {
    let n = ((b - a).abs().ceil() as usize).clamp(1, 2000);
    (0..=n).map(|k| f(a + (b - a) * k as f64 / n as f64)).collect()
}

/// A vehicle's way round a roundabout's island: counter-clockwise on the circle of `radius`
/// about `centre`, from `start` (radians) through `sweep`. It joins the ring a little past
/// its entry's bearing and leaves it a little before its exit's, by a Bézier each way.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ring {
    pub centre: Vec2,
    pub radius: f64,
    pub start: f64,
    pub sweep: f64,
}

impl Ring {
    /// The ring of a vehicle entering at `entry` and taking `turn`.
    pub fn of(centre: Vec2, radius: f64, entry: Vec2, turn: Turn) -> Ring {
        let quarters = match turn {
            Turn::Right => 1.0,
            Turn::Straight => 2.0,
            Turn::Left => 3.0,
            Turn::UTurn => 4.0,
        };
        Ring {
            centre,
            radius,
            start: (entry - centre).yaw() + 0.35,
            sweep: quarters * std::f64::consts::FRAC_PI_2 - 0.7,
        }
    }

    /// The point `angle` radians into the ring.
    pub fn at(&self, angle: f64) -> Vec2 {
        self.centre + Vec2::from_yaw(self.start + angle) * self.radius
    }

    /// The direction of travel `angle` radians into the ring.
    pub fn tangent(&self, angle: f64) -> Vec2 {
        Vec2::from_yaw(self.start + angle).left()
    }

    /// Points every metre or so, strictly inside the arc.
    fn points(&self) -> Vec<Vec2> {
        let n = (self.sweep * self.radius).ceil().max(4.0) as usize;
        (1..n).map(|k| self.at(self.sweep * k as f64 / n as f64)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::wrap;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn crossroads() -> Road {
        Road {
            shape: Shape::Junction { arms: 4, roundabout: false },
            lanes: 2,
            opposite: 2,
            cross_lanes: 2,
            lane_width: LANE_WIDTH,
            sidewalks: true,
            crosswalks: true,
            signal: None,
            junction: Some(Junction {
                arms: Arm::ALL.to_vec(),
                roundabout: false,
                half: 8.0,
                signalised: false,
                stop_signs: false,
            }),
            approach: 20.0,
        }
    }

    #[test]
    fn arms_face_the_way_their_traffic_drives() {
        let road = crossroads();
        let left = road.lane_pose(Station { arm: Arm::Left, along: 10.0 }, 1);
        assert!((wrap(left.yaw) + FRAC_PI_2).abs() < 1e-9, "traffic from the left drives to the ego's right");
        assert!(left.position.y > 0.0 && left.position.x > road.approach);
        let right = road.lane_pose(Station { arm: Arm::Right, along: 10.0 }, 1);
        assert!((wrap(right.yaw) - FRAC_PI_2).abs() < 1e-9 && right.position.y < 0.0);
        let oncoming = road.lane_pose(Station { arm: Arm::Opposite, along: 5.0 }, 1);
        assert!((wrap(oncoming.yaw).abs() - PI).abs() < 1e-9);
        assert!(oncoming.position.y > 0.0, "oncoming lane 1 is left of the ego's centre line");
        assert_eq!(Turn::Left.exit(Arm::Ego), Arm::Left);
        assert_eq!(Turn::Right.exit(Arm::Ego), Arm::Right);
        assert_eq!(Turn::Left.exit(Arm::Left), Arm::Opposite);
        assert_eq!(Turn::Straight.exit(Arm::Right), Arm::Left);
    }

    #[test]
    fn a_left_turn_ends_on_the_left_arm_driving_away() {
        let road = crossroads();
        let (path, start) = road.vehicle_path(Station { arm: Arm::Ego, along: 0.0 }, 1, Turn::Left);
        assert!(path.pose(start).position.distance(Vec2::new(0.0, -1.75)) < 1e-6);
        let end = path.pose(path.length());
        assert!((wrap(end.yaw) - FRAC_PI_2).abs() < 1e-6 && end.position.y > 100.0);
        let (path, _) = road.vehicle_path(Station { arm: Arm::Ego, along: 0.0 }, 2, Turn::Right);
        let end = path.pose(path.length());
        assert!((wrap(end.yaw) + FRAC_PI_2).abs() < 1e-6 && end.position.y < -100.0);
    }

    #[test]
    fn a_curve_bends_the_ego_road() {
        let road = Road { shape: Shape::Curve { left: true }, junction: None, ..crossroads() };
        let p = road.ego_road(CURVE_RADIUS * FRAC_PI_2, 0.0);
        assert!((p.position.x - CURVE_RADIUS).abs() < 1e-9 && (p.position.y - CURVE_RADIUS).abs() < 1e-9);
        assert!((p.yaw - FRAC_PI_2).abs() < 1e-9);
    }
}
