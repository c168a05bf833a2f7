//! The layout's road as an OpenDRIVE road network (`spec/backends/openscenario.md` §2).
//!
//! The road frame is kept: the ego starts at the origin heading `+x`, so world coordinates
//! are the layout's. The ego's road is road 1, its reference line the layout's centre line
//! (a line, then the bend's arc), running with the ego up to its stop line. Every other arm
//! of a junction is a road whose reference line starts at the junction's edge and runs
//! outwards. Lanes keep TAD's numbering up to a sign: on the ego's road OpenDRIVE's lane
//! `-i` is TAD's lane `i` (driving with the reference line, on its right), on an arm road
//! the ids are TAD's (its incoming lanes run against the reference line, on its left).
//! Sidewalks are one more lane on each side.
//!
//! Inside the junction, one connecting road per incoming lane and turn carries the layout's
//! own path: the cubic Bézier of `tad_road::geom::bezier` as a `paramPoly3` (exactly), a
//! U-turn as two of them, a roundabout's path as a Bézier onto the ring, the ring's arc and a
//! Bézier off it. Every
//! lane gets the turns a lane of its place makes (straight on from every lane, left from
//! the innermost, right from the outermost) and every turn an actor of the layout takes.

use tad_layout::Layout;
use tad_road::geom::{Pose, Vec2, bezier_controls};
use tad_road::road::{CROSSWALK, CROSSWALK_DEPTH, RING, RUN, Ring, SIDEWALK_WIDTH};
use tad_road::{Arm, Road, Shape, Turn};

/// The junction's id; roads are numbered below it, connecting roads above.
pub const JUNCTION: u32 = 100;

/// The road of an arm: 1 for the ego's, then left, right, opposite.
pub fn arm_road(arm: Arm) -> u32 {
    match arm {
        Arm::Ego => 1,
        Arm::Left => 2,
        Arm::Right => 3,
        Arm::Opposite => 4,
    }
}

/// The OpenDRIVE lane id of TAD's lane `lane` on an arm's road.
pub fn lane_id(arm: Arm, lane: i64) -> i32 {
    let id = i32::try_from(lane.clamp(-99, 99)).unwrap_or(1);
    if arm == Arm::Ego { -id } else { id }
}

/// The shape of one piece of a reference line.
#[derive(Clone, Debug, PartialEq)]
pub enum Curve {
    Line,
    /// Curvature, 1/m (positive: to the left).
    Arc(f64),
    /// `u(p)`, `v(p)` in the piece's own frame, `p` from 0 to 1 over its length
    /// (`pRange="normalized"`); coefficients `a, b, c, d`.
    Poly3 {
        u: [f64; 4],
        v: [f64; 4],
    },
}

/// One piece of a road's reference line, from `s` on.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    pub s: f64,
    pub start: Pose,
    pub length: f64,
    pub curve: Curve,
}

impl Geometry {
    /// The pose `ds` metres into this piece (OpenDRIVE's definition: a `paramPoly3` at
    /// `p = ds / length`).
    pub fn pose(&self, ds: f64) -> Pose {
        let (x, y, heading) = match &self.curve {
            Curve::Line => (ds, 0.0, 0.0),
            Curve::Arc(k) if k.abs() < 1e-12 => (ds, 0.0, 0.0),
            Curve::Arc(k) => {
                let phi = ds * k;
                (phi.sin() / k, (1.0 - phi.cos()) / k, phi)
            }
            Curve::Poly3 { u, v } => {
                let p = if self.length > 0.0 { ds / self.length } else { 0.0 };
                let f = |c: &[f64; 4]| c[0] + p * (c[1] + p * (c[2] + p * c[3]));
                let df = |c: &[f64; 4]| c[1] + p * (2.0 * c[2] + p * 3.0 * c[3]);
                (f(u), f(v), df(v).atan2(df(u)))
            }
        };
        let e = Vec2::from_yaw(self.start.yaw);
        Pose { position: self.start.position + e * x + e.left() * y, yaw: self.start.yaw + heading }
    }

    /// The piece's end.
    pub fn end(&self) -> Pose {
        self.pose(self.length)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaneKind {
    Driving,
    Sidewalk,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Lane {
    pub id: i32,
    pub kind: LaneKind,
    pub width: f64,
    /// The lanes it continues from and into (connecting roads only).
    pub predecessor: Option<i32>,
    pub successor: Option<i32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contact {
    Start,
    End,
}

impl Contact {
    pub fn as_str(self) -> &'static str {
        match self {
            Contact::Start => "start",
            Contact::End => "end",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    Road { id: u32, contact: Contact },
    Junction(u32),
}

/// An OpenDRIVE signal on a road.
#[derive(Clone, Debug, PartialEq)]
pub struct Signal {
    pub id: u32,
    pub name: String,
    pub s: f64,
    pub t: f64,
    /// Whether it changes (a traffic light).
    pub dynamic: bool,
    /// `+`: for traffic driving with the reference line.
    pub along: bool,
    /// The German catalogue's type (StVO): 1000001 a light, 206 stop, 205 yield, 294 a stop line.
    pub kind: i64,
    pub height: f64,
    pub width: f64,
    /// The arm whose incoming traffic it faces.
    pub arm: Arm,
}

/// A crosswalk: a rectangle of the road, `from`..`to` along it (m from `s`, local `u`),
/// across `right`..`left` (t).
#[derive(Clone, Debug, PartialEq)]
pub struct Crosswalk {
    pub id: u32,
    pub s: f64,
    pub from: f64,
    pub to: f64,
    pub right: f64,
    pub left: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RoadDef {
    pub id: u32,
    pub name: String,
    /// The junction a connecting road belongs to.
    pub junction: Option<u32>,
    pub geometry: Vec<Geometry>,
    /// How far left of the reference line the centre lane is (connecting roads: half a lane,
    /// so that their one lane is centred on the path).
    pub lane_offset: f64,
    /// Ids 1, 2, … outwards.
    pub left: Vec<Lane>,
    /// Ids -1, -2, … outwards.
    pub right: Vec<Lane>,
    pub predecessor: Option<Link>,
    pub successor: Option<Link>,
    pub signals: Vec<Signal>,
    pub crosswalks: Vec<Crosswalk>,
    /// The arm this road is (not for connecting roads).
    pub arm: Option<Arm>,
    /// A connecting road: the incoming arm, its TAD lane and the turn.
    pub turn: Option<(Arm, i64, Turn)>,
}

impl RoadDef {
    pub fn length(&self) -> f64 {
        self.geometry.iter().map(|g| g.length).sum()
    }

    /// The reference line's pose at `s` (clamped to the road).
    pub fn pose(&self, s: f64) -> Pose {
        let s = s.clamp(0.0, self.length());
        let g = self.geometry.iter().rev().find(|g| g.s <= s + 1e-9).unwrap_or(&self.geometry[0]);
        g.pose(s - g.s)
    }

    /// The point `t` metres left of the reference line at `s`.
    pub fn point(&self, s: f64, t: f64) -> Vec2 {
        let p = self.pose(s);
        p.position + Vec2::from_yaw(p.yaw).left() * t
    }

    /// A lane's inner and outer edge, `t` (left positive); `None` for a lane it lacks.
    pub fn lane_span(&self, id: i32) -> Option<(f64, f64)> {
        let (lanes, sign) = if id > 0 { (&self.left, 1.0) } else { (&self.right, -1.0) };
        let k = usize::try_from(id.unsigned_abs()).ok()?.checked_sub(1)?;
        let inner: f64 = lanes.get(..k)?.iter().map(|l| l.width).sum();
        let width = lanes.get(k)?.width;
        Some((self.lane_offset + sign * inner, self.lane_offset + sign * (inner + width)))
    }

    /// A lane's centre, `t`.
    pub fn lane_centre(&self, id: i32) -> Option<f64> {
        self.lane_span(id).map(|(a, b)| (a + b) / 2.0)
    }

    /// The lane at `t` (the outermost one beyond the road) and the offset from its centre.
    pub fn lane_at(&self, t: f64) -> Option<(i32, f64)> {
        let ids = self.left.iter().chain(&self.right).map(|l| l.id);
        let best = ids
            .filter_map(|id| self.lane_span(id).map(|(a, b)| (id, a, b)))
            .min_by(|x, y| distance_to_span(t, x.1, x.2).total_cmp(&distance_to_span(t, y.1, y.2)))?;
        Some((best.0, t - (best.1 + best.2) / 2.0))
    }

    /// Where a point lies: `(s, t)` of its nearest reference point, when it is within the
    /// road's length (`None` before its start or past its end).
    pub fn locate(&self, p: Vec2) -> Option<(f64, f64)> {
        let length = self.length();
        let steps = (length / 0.5).ceil().clamp(1.0, 20_000.0) as usize;
        let near = (0..=steps)
            .map(|k| length * k as f64 / steps as f64)
            .min_by(|a, b| self.pose(*a).position.distance(p).total_cmp(&self.pose(*b).position.distance(p)))?;
        // refine by bisection on the along-track component
        let (mut lo, mut hi) = ((near - 0.5).max(0.0), (near + 0.5).min(length));
        for _ in 0..40 {
            let mid = (lo + hi) / 2.0;
            let pose = self.pose(mid);
            if (p - pose.position).dot(Vec2::from_yaw(pose.yaw)) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let s = (lo + hi) / 2.0;
        let pose = self.pose(s);
        let d = p - pose.position;
        let along = d.dot(Vec2::from_yaw(pose.yaw));
        (along.abs() < 0.05).then(|| (s, d.dot(Vec2::from_yaw(pose.yaw).left())))
    }
}

fn distance_to_span(t: f64, a: f64, b: f64) -> f64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    if t < lo {
        lo - t
    } else if t > hi {
        t - hi
    } else {
        0.0
    }
}

/// A junction connection: traffic from `incoming`'s lane `from` enters `connecting`.
#[derive(Clone, Debug, PartialEq)]
pub struct Connection {
    pub id: u32,
    pub incoming: u32,
    pub connecting: u32,
    pub from: i32,
}

/// One controller per arm of a signalised junction: the lights facing its incoming traffic.
#[derive(Clone, Debug, PartialEq)]
pub struct Controller {
    pub id: u32,
    pub arm: Arm,
    pub signals: Vec<u32>,
}

#[derive(Clone, Debug, PartialEq, Default)]
pub struct Network {
    pub roads: Vec<RoadDef>,
    pub connections: Vec<Connection>,
    pub controllers: Vec<Controller>,
    pub roundabout: bool,
}

impl Network {
    pub fn road(&self, id: u32) -> Option<&RoadDef> {
        self.roads.iter().find(|r| r.id == id)
    }

    pub fn has_junction(&self) -> bool {
        !self.connections.is_empty()
    }

    /// The connecting road a vehicle in TAD lane `lane` of `arm` takes for `turn`.
    pub fn connecting(&self, arm: Arm, lane: i64, turn: Turn) -> Option<&RoadDef> {
        self.roads.iter().find(|r| r.turn == Some((arm, lane, turn)))
    }

    /// Where a point of an arm is: its road, `s` and `t`; a point of no road is `None`.
    pub fn locate(&self, arm: Arm, p: Vec2) -> Option<(u32, f64, f64)> {
        let road = self.road(arm_road(arm))?;
        road.locate(p).map(|(s, t)| (road.id, s, t))
    }
}

/// The network of a layout's road, with connecting roads for every turn its actors take.
pub fn network(layout: &Layout) -> Network {
    let road = &layout.road;
    let mut net = Network { roundabout: road.junction.as_ref().is_some_and(|j| j.roundabout), ..Network::default() };
    let on_arm = |arm: Arm| layout.agents().filter(move |a| a.station.arm == arm).map(|a| a.station.along);
    net.roads.push(ego_road(road, on_arm(Arm::Ego)));
    if let Some(junction) = &road.junction {
        let mut arms = junction.arms.clone();
        arms.sort();
        arms.dedup();
        for &arm in arms.iter().filter(|a| **a != Arm::Ego) {
            let length = RUN + on_arm(arm).fold(0.0, f64::max);
            net.roads.push(arm_road_def(road, arm, length));
        }
        let taken: Vec<(Arm, i64, Turn)> = layout
            .agents()
            .filter(|a| a.lane > 0 && a.body == tad_road::Body::Vehicle)
            .map(|a| (a.station.arm, a.lane, a.turn))
            .collect();
        connecting_roads(&mut net, road, &arms, &taken);
        signals(&mut net, road, &arms);
    }
    crosswalks(&mut net, layout);
    net
}

/// A road's lanes on one side: `n` driving lanes, then a sidewalk when the road has them.
fn side(road: &Road, n: u32, sign: i32) -> Vec<Lane> {
    let lane = |k: i32, kind, width| Lane { id: sign * k, kind, width, predecessor: None, successor: None };
    let mut lanes: Vec<Lane> = (1..=n as i32).map(|k| lane(k, LaneKind::Driving, road.lane_width)).collect();
    if road.sidewalks {
        lanes.push(lane(n as i32 + 1, LaneKind::Sidewalk, SIDEWALK_WIDTH));
    }
    lanes
}

/// Road 1: the ego's, from `RUN` behind the rearmost actor to its stop line (with a
/// junction) or `RUN` past the foremost one (a bend stops after three quarters of a turn).
fn ego_road(road: &Road, along: impl Iterator<Item = f64>) -> RoadDef {
    let (lo, hi) = along.fold((0.0_f64, 0.0_f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let x0 = lo - RUN;
    let x1 = match road.shape {
        _ if road.junction.is_some() => road.approach,
        Shape::Curve { .. } => (hi + RUN).min(1.5 * std::f64::consts::PI * tad_road::road::CURVE_RADIUS),
        _ => hi + RUN,
    };
    let mut geometry = Vec::new();
    let line_end = match road.shape {
        Shape::Curve { .. } => 0.0_f64.min(x1),
        _ => x1,
    };
    geometry.push(Geometry {
        s: 0.0,
        start: Pose { position: Vec2::new(x0, 0.0), yaw: 0.0 },
        length: line_end - x0,
        curve: Curve::Line,
    });
    if let Shape::Curve { left } = road.shape
        && x1 > 0.0
    {
        let k = if left { 1.0 } else { -1.0 } / tad_road::road::CURVE_RADIUS;
        geometry.push(Geometry {
            s: -x0,
            start: Pose { position: Vec2::new(0.0, 0.0), yaw: 0.0 },
            length: x1,
            curve: Curve::Arc(k),
        });
    }
    RoadDef {
        id: arm_road(Arm::Ego),
        name: "ego".into(),
        junction: None,
        geometry,
        lane_offset: 0.0,
        left: side(road, road.opposite, 1),
        right: side(road, road.lanes, -1),
        predecessor: None,
        successor: road.junction.as_ref().map(|_| Link::Junction(JUNCTION)),
        signals: Vec::new(),
        crosswalks: Vec::new(),
        arm: Some(Arm::Ego),
        turn: None,
    }
}

/// An arm of the junction: from the junction's edge outwards, its incoming lanes on the left.
fn arm_road_def(road: &Road, arm: Arm, length: f64) -> RoadDef {
    let half = road.junction.as_ref().map_or(0.0, |j| j.half);
    let u = arm.outward();
    let (incoming, outgoing) = road.arm_lanes(arm);
    RoadDef {
        id: arm_road(arm),
        name: arm.as_str().into(),
        junction: None,
        geometry: vec![Geometry {
            s: 0.0,
            start: Pose { position: road.centre() + u * half, yaw: u.yaw() },
            length,
            curve: Curve::Line,
        }],
        lane_offset: 0.0,
        left: side(road, incoming, 1),
        right: side(road, outgoing, -1),
        predecessor: Some(Link::Junction(JUNCTION)),
        successor: None,
        signals: Vec::new(),
        crosswalks: Vec::new(),
        arm: Some(arm),
        turn: None,
    }
}

fn connecting_roads(net: &mut Network, road: &Road, arms: &[Arm], taken: &[(Arm, i64, Turn)]) {
    let Some(junction) = &road.junction else { return };
    let mut next = JUNCTION + 1;
    for &arm in arms {
        let (incoming, _) = road.arm_lanes(arm);
        for lane in 1..=i64::from(incoming) {
            for turn in [Turn::Straight, Turn::Left, Turn::Right, Turn::UTurn] {
                let exit = turn.exit(arm);
                let (_, outgoing) = road.arm_lanes(exit);
                let usual = match turn {
                    Turn::Straight => true,
                    Turn::Left => lane == 1,
                    Turn::Right => lane == i64::from(incoming),
                    Turn::UTurn => false,
                };
                if !arms.contains(&exit) || outgoing == 0 || !(usual || taken.contains(&(arm, lane, turn))) {
                    continue;
                }
                let out_lane = turn.exit_lane(lane, outgoing);
                let entry = road.lane_pose(road.edge(arm), lane);
                let out = road.pose_at(road.edge(exit), -out_lane, road.lateral(-out_lane));
                let geometry = if junction.roundabout {
                    ring_path(road.centre(), junction.half * RING, entry, out, turn)
                } else if turn == Turn::UTurn {
                    let d = Vec2::from_yaw(entry.yaw);
                    let mid = road.centre() + d * (junction.half * 0.5);
                    let first = bezier(0.0, entry.position, d, mid, d.left());
                    let second = bezier(first.length, mid, d.left(), out.position, Vec2::from_yaw(out.yaw));
                    vec![first, second]
                } else {
                    vec![bezier(0.0, entry.position, Vec2::from_yaw(entry.yaw), out.position, Vec2::from_yaw(out.yaw))]
                };
                let id = next;
                next += 1;
                let (from, to) = (lane_id(arm, lane), lane_id(exit, -out_lane));
                let contact = |a: Arm| if a == Arm::Ego { Contact::End } else { Contact::Start };
                net.roads.push(RoadDef {
                    id,
                    name: format!("{}_{lane}_{}", arm.as_str(), turn_name(turn)),
                    junction: Some(JUNCTION),
                    geometry,
                    lane_offset: road.lane_width / 2.0,
                    left: Vec::new(),
                    right: vec![Lane {
                        id: -1,
                        kind: LaneKind::Driving,
                        width: road.lane_width,
                        predecessor: Some(from),
                        successor: Some(to),
                    }],
                    predecessor: Some(Link::Road { id: arm_road(arm), contact: contact(arm) }),
                    successor: Some(Link::Road { id: arm_road(exit), contact: contact(exit) }),
                    signals: Vec::new(),
                    crosswalks: Vec::new(),
                    arm: None,
                    turn: Some((arm, lane, turn)),
                });
                let cid = u32::try_from(net.connections.len()).unwrap_or(u32::MAX);
                net.connections.push(Connection { id: cid, incoming: arm_road(arm), connecting: id, from });
            }
        }
    }
}

pub fn turn_name(turn: Turn) -> &'static str {
    match turn {
        Turn::Straight => "straight",
        Turn::Left => "left",
        Turn::Right => "right",
        Turn::UTurn => "uturn",
    }
}

/// `tad_road::geom::bezier`'s curve (its control points) as a `paramPoly3` piece starting
/// at `s`.
fn bezier(s: f64, a: Vec2, da: Vec2, b: Vec2, db: Vec2) -> Geometry {
    let [_, c1, c2, _] = bezier_controls(a, da, b, db);
    // the power basis: B(p) = a + p1 p + p2 p² + p3 p³
    let p1 = (c1 - a) * 3.0;
    let p2 = (a - c1 * 2.0 + c2) * 3.0;
    let p3 = b - a + (c1 - c2) * 3.0;
    let yaw = da.yaw();
    let (e, n) = (Vec2::from_yaw(yaw), Vec2::from_yaw(yaw).left());
    let u = [0.0, p1.dot(e), p2.dot(e), p3.dot(e)];
    let v = [0.0, p1.dot(n), p2.dot(n), p3.dot(n)];
    // arc length by Simpson's rule over 256 intervals
    let speed = |p: f64| (p1 + p2 * (2.0 * p) + p3 * (3.0 * p * p)).length();
    let n_steps = 256;
    let h = 1.0 / n_steps as f64;
    let length = (0..=n_steps)
        .map(|k| {
            let w = if k == 0 || k == n_steps {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * speed(k as f64 * h)
        })
        .sum::<f64>()
        * h
        / 3.0;
    Geometry { s, start: Pose { position: a, yaw }, length, curve: Curve::Poly3 { u, v } }
}

/// A roundabout's path (`tad_road::road::Ring`): a Bézier onto the ring, its
/// counter-clockwise arc, a Bézier out to the exit.
fn ring_path(centre: Vec2, radius: f64, entry: Pose, exit: Pose, turn: Turn) -> Vec<Geometry> {
    let ring = Ring::of(centre, radius, entry.position, turn);
    let (on, off) = (ring.at(0.0), ring.at(ring.sweep));
    let first = bezier(0.0, entry.position, Vec2::from_yaw(entry.yaw), on, ring.tangent(0.0));
    let arc = Geometry {
        s: first.length,
        start: Pose { position: on, yaw: ring.tangent(0.0).yaw() },
        length: radius * ring.sweep,
        curve: Curve::Arc(1.0 / radius),
    };
    let last =
        bezier(first.length + arc.length, off, ring.tangent(ring.sweep), exit.position, Vec2::from_yaw(exit.yaw));
    vec![first, arc, last]
}

/// At a junction: on every arm a stop line, a light (signalised) or a stop sign, facing
/// its incoming traffic; one controller per arm.
fn signals(net: &mut Network, road: &Road, arms: &[Arm]) {
    let Some(junction) = &road.junction else { return };
    let mut next = 1;
    for &arm in arms {
        let (incoming, _) = road.arm_lanes(arm);
        let Some(def) = net.roads.iter_mut().find(|r| r.arm == Some(arm)) else { continue };
        let width = f64::from(incoming) * road.lane_width;
        // the ego's road ends at its stop line and runs with its incoming traffic
        let (s, sign) = if arm == Arm::Ego { (def.length(), -1.0) } else { (0.0, 1.0) };
        let beside = sign * (width + 0.5);
        let mut add = |kind: i64, dynamic: bool, t: f64, height: f64, width: f64, name: &str| {
            let id = next;
            next += 1;
            def.signals.push(Signal {
                id,
                name: format!("{}_{name}", arm.as_str()),
                s,
                t,
                dynamic,
                along: arm == Arm::Ego,
                kind,
                height,
                width,
                arm,
            });
            id
        };
        if incoming > 0 {
            add(294, false, sign * width / 2.0, 0.0, width, "stop_line");
        }
        if junction.signalised {
            let light = add(1_000_001, true, beside, 3.5, 0.3, "light");
            net.controllers.push(Controller {
                id: u32::try_from(net.controllers.len() + 1).unwrap_or(0),
                arm,
                signals: vec![light],
            });
        } else if junction.stop_signs {
            add(206, false, beside, 2.0, 0.6, "stop_sign");
        }
    }
}

/// Crosswalks: at a junction, `CROSSWALK` m inside every arm's stop line; elsewhere,
/// where walkers cross the road.
fn crosswalks(net: &mut Network, layout: &Layout) {
    let road = &layout.road;
    if !road.crosswalks {
        return;
    }
    let mut next = 1;
    let across = |def: &RoadDef| {
        let right = def.right.iter().filter(|l| l.kind == LaneKind::Driving).map(|l| l.width).sum::<f64>();
        let left = def.left.iter().filter(|l| l.kind == LaneKind::Driving).map(|l| l.width).sum::<f64>();
        (-right, left)
    };
    if road.junction.is_some() {
        for def in net.roads.iter_mut().filter(|r| r.arm.is_some()) {
            let (right, left) = across(def);
            let (s, from) = if def.arm == Some(Arm::Ego) {
                (def.length(), CROSSWALK - CROSSWALK_DEPTH / 2.0)
            } else {
                (0.0, -CROSSWALK - CROSSWALK_DEPTH / 2.0)
            };
            def.crosswalks.push(Crosswalk { id: next, s, from, to: from + CROSSWALK_DEPTH, right, left });
            next += 1;
        }
        return;
    }
    let Some(def) = net.roads.iter_mut().find(|r| r.arm == Some(Arm::Ego)) else { return };
    let (right, left) = across(def);
    let x0 = def.geometry[0].start.position.x;
    let mut places: Vec<f64> = layout
        .agents()
        .filter(|a| matches!(a.facing, tad_road::Facing::Across { .. }) && a.station.arm == Arm::Ego)
        .map(|a| a.station.along - x0)
        .filter(|s| *s >= 0.0 && *s <= def.length())
        .collect();
    places.sort_by(f64::total_cmp);
    places.dedup_by(|a, b| (*a - *b).abs() < CROSSWALK_DEPTH);
    for s in places {
        let half = CROSSWALK_DEPTH / 2.0;
        def.crosswalks.push(Crosswalk { id: next, s, from: -half, to: half, right, left });
        next += 1;
    }
}
