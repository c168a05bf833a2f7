//! Where the layout lies on a CARLA town (`--map TownNN`, `spec/backends/openscenario.md` §4).
//!
//! The layout is placed, never re-decided: its arms become town roads, its lanes town lanes
//! counted from the centre line, and its stations distances from the same junction edge.
//!
//! 1. **The site.** With a junction, every incoming road of every town junction is tried as
//!    the ego's; the junction's other incoming roads take the layout's other arms by their
//!    bearing (left, right, ahead). Without one, every ordinary road in either direction.
//!    Each candidate costs its mismatches: lanes each way, missing arms and turns, lights,
//!    metres of road the layout needs and the town lacks. The cheapest wins; ties go to the
//!    lowest ids, so the same town gives the same site.
//! 2. **Places.** A station becomes the same distance from the junction's edge on the arm's
//!    road (the ego's start without a junction), a lane the town lane with the same rank
//!    from the centre, an offset beyond a lane the same distance beyond the town's lane.
//! 3. **Points** of the junction's inside (conflict points, paths) are carried by the
//!    rotation and translation that takes the layout's junction centre and ego heading to
//!    the town's.
//!
//! What does not fit is said: the cost's parts become W0712 warnings.

use std::f64::consts::PI;

use tad_layout::Layout;
use tad_road::geom::{Pose, Vec2, wrap};
use tad_road::road::{CURVE_RADIUS, Station};
use tad_road::{Arm, Road, Shape, Turn};

use crate::town::{Connection, Town};

/// Metres of road kept past the farthest actor.
const MARGIN: f64 = 5.0;
/// How far a way runs past the junction (or, without one, ahead), m.
pub const WAY_BEYOND: f64 = 30.0;
/// Bearings within this of an arm's are that arm, rad.
const BEARING: f64 = PI / 4.0;

/// One arm of the layout on the town.
#[derive(Clone, Debug, PartialEq)]
pub struct ArmSite {
    pub arm: Arm,
    pub road: u32,
    /// +1: the arm's incoming traffic drives with the road's reference line; -1: against.
    pub dir: f64,
    /// `s` of the arm's origin: the junction's edge, or (the ego's road without a junction)
    /// the ego's start.
    pub s0: f64,
    /// The town's driving lanes each way at the origin, innermost first: incoming, outgoing.
    pub incoming: Vec<i32>,
    pub outgoing: Vec<i32>,
}

impl ArmSite {
    /// `s` on the arm's road `out` metres out from its origin (within the road).
    fn s_at(&self, road: &crate::town::Road, out: f64) -> f64 {
        (self.s0 - self.dir * out).clamp(0.0, road.length)
    }

    /// The heading of the arm's incoming traffic on its road at `s`.
    fn traffic_yaw(&self, road: &crate::town::Road, s: f64) -> f64 {
        along_dir(road.pose(s).yaw, self.dir)
    }
}

/// A reference line's heading turned to the way traffic going `dir` drives.
fn along_dir(yaw: f64, dir: f64) -> f64 {
    if dir > 0.0 { yaw } else { yaw + PI }
}

/// The layout's place on a town.
#[derive(Clone, Debug)]
pub struct Site<'t> {
    pub town: &'t Town,
    pub arms: Vec<ArmSite>,
    pub junction: Option<u32>,
    /// What does not fit (each a W0712).
    pub misfits: Vec<Misfit>,
    /// The layout's junction centre and the town's, and the rotation from one to the other.
    centre: (Vec2, Vec2, f64),
    /// The ego's way on the town, every metre ([`Site::way`]).
    pub ego_way: Vec<Vec2>,
}

/// One way the site differs from the scenario: what, in words, and whether it is about the
/// road's lanes (else the road as a whole).
#[derive(Clone, Debug, PartialEq)]
pub struct Misfit {
    pub what: String,
    pub lanes: bool,
}

/// What the layout needs of the town.
struct Needs {
    arms: Vec<Arm>,
    lanes: Vec<(Arm, u32, u32)>,
    /// Metres of road outwards from each arm's origin (before it, for the ego without a
    /// junction: behind and ahead).
    reach: Vec<(Arm, f64, f64)>,
    turns: Vec<(Arm, i64, Turn)>,
    signalised: bool,
}

fn needs(layout: &Layout) -> Needs {
    let road = &layout.road;
    let mut arms = vec![Arm::Ego];
    if let Some(j) = &road.junction {
        arms.extend(j.arms.iter().copied().filter(|a| *a != Arm::Ego));
    }
    arms.sort();
    arms.dedup();
    let lanes = arms
        .iter()
        .map(|&a| {
            let (i, o) = road.arm_lanes(a);
            (a, i, o)
        })
        .collect();
    let reach = arms
        .iter()
        .map(|&arm| {
            let outward = layout.agents().filter(|a| a.station.arm == arm).map(|a| outward(road, arm, a.station.along));
            let (lo, hi) = outward.fold((0.0_f64, 0.0_f64), |(lo, hi), b| (lo.min(b), hi.max(b)));
            (arm, lo - MARGIN, hi + MARGIN)
        })
        .collect();
    let mut turns: Vec<(Arm, i64, Turn)> = Vec::new();
    let vehicles =
        layout.agents().filter(|a| a.lane > 0 && a.body == tad_road::Body::Vehicle && road.junction.is_some());
    for turn in vehicles.map(|a| (a.station.arm, a.lane, a.turn)) {
        if !turns.contains(&turn) {
            turns.push(turn);
        }
    }
    Needs { arms, lanes, reach, turns, signalised: road.junction.as_ref().is_some_and(|j| j.signalised) }
}

/// A station's distance out from its arm's origin: from the junction's edge outwards, or
/// (the ego's road without a junction, whose `approach` is 0) backwards from the ego's start.
fn outward(road: &Road, arm: Arm, along: f64) -> f64 {
    road.before_stop_line(Station { arm, along })
}

/// A candidate and its cost.
struct Candidate {
    arms: Vec<ArmSite>,
    junction: Option<u32>,
    misfits: Vec<(f64, Misfit)>,
}

impl Candidate {
    fn cost(&self) -> f64 {
        self.misfits.iter().map(|m| m.0).sum()
    }
}

/// Where the layout goes on `town`: the cheapest site (module header).
pub fn site<'t>(layout: &Layout, town: &'t Town) -> Option<Site<'t>> {
    let needs = needs(layout);
    let candidates: Vec<Candidate> = if layout.road.junction.is_some() {
        town.junctions.keys().flat_map(|&j| junction_candidates(town, j, &needs)).collect()
    } else {
        road_candidates(town, &needs)
    };
    let best = candidates.into_iter().min_by(|a, b| a.cost().total_cmp(&b.cost()))?;
    let centre = centre(layout, town, &best);
    let misfits = best.misfits.into_iter().map(|m| m.1).collect();
    let mut site = Site { town, arms: best.arms, junction: best.junction, misfits, centre, ego_way: Vec::new() };
    let ego = &layout.ego;
    let out = outward(&layout.road, Arm::Ego, ego.station.along);
    site.ego_way = site.way(Arm::Ego, ego.lane, ego.turn, out);
    Some(site)
}

/// An ordinary road's driving lanes at `s` each way for traffic going `dir`.
fn lanes_at(road: &crate::town::Road, s: f64, dir: f64) -> (Vec<i32>, Vec<i32>) {
    let (with, against) = (road.driving(s, -1), road.driving(s, 1));
    if dir > 0.0 { (with, against) } else { (against, with) }
}

fn lane_misfits(misfits: &mut Vec<(f64, Misfit)>, arm: Arm, want: (u32, u32), have: (usize, usize)) {
    let (want, have) = ((want.0 as usize, want.1 as usize), have);
    if want == have {
        return;
    }
    // fewer lanes than the scenario's crowd its actors; more only leave some empty
    let fewer = want.0.saturating_sub(have.0) + want.1.saturating_sub(have.1);
    let cost = 10.0 * (want.0.abs_diff(have.0) + want.1.abs_diff(have.1)) as f64 + 100.0 * fewer as f64;
    let words = format!(
        "the {} road has {} + {} lanes (its way + the other) where the scenario has {} + {}",
        arm_words(arm),
        have.0,
        have.1,
        want.0,
        want.1
    );
    misfits.push((cost, Misfit { what: words, lanes: true }));
}

fn arm_words(arm: Arm) -> &'static str {
    match arm {
        Arm::Ego => "ego's",
        Arm::Left => "left",
        Arm::Right => "right",
        Arm::Opposite => "opposite",
    }
}

fn length_misfit(misfits: &mut Vec<(f64, Misfit)>, arm: Arm, want: f64, have: f64) {
    let short = want - have;
    if short > MARGIN {
        let words =
            format!("the {} road is {:.0} m shorter than the scenario's actors need", arm_words(arm), short - MARGIN);
        misfits.push((short / 10.0, Misfit { what: words, lanes: false }));
    }
}

fn road_candidates(town: &Town, needs: &Needs) -> Vec<Candidate> {
    let Some(&(_, lo, hi)) = needs.reach.iter().find(|r| r.0 == Arm::Ego) else { return Vec::new() };
    // outward from the start is backwards
    let (behind, ahead) = (hi, -lo);
    let want = needs.lanes.first().map_or((1, 0), |l| (l.1, l.2));
    let mut out = Vec::new();
    for road in town.roads.values().filter(|r| r.junction.is_none()) {
        for dir in [1.0, -1.0] {
            let (incoming, outgoing) = lanes_at(road, road.length / 2.0, dir);
            if incoming.is_empty() {
                continue;
            }
            let mut misfits = Vec::new();
            lane_misfits(&mut misfits, Arm::Ego, want, (incoming.len(), outgoing.len()));
            length_misfit(&mut misfits, Arm::Ego, behind + ahead, road.length);
            // the start: as far in as it needs behind it, within the road
            let back = behind.min(road.length);
            let s0 = if dir > 0.0 { back } else { road.length - back };
            let arm = ArmSite { arm: Arm::Ego, road: road.id, dir, s0, incoming, outgoing };
            out.push(Candidate { arms: vec![arm], junction: None, misfits });
        }
    }
    out
}

/// The roads coming into junction `j`: `(road, dir, s of the junction's edge)`.
fn incoming_roads(town: &Town, j: u32) -> Vec<(u32, f64, f64)> {
    let mut out: Vec<(u32, f64, f64)> = Vec::new();
    for road in town.roads.values().filter(|r| r.junction.is_none()) {
        let at_junction = |l: Option<crate::town::Link>| l.is_some_and(|l| l.junction && l.id == j);
        if at_junction(road.successor) {
            out.push((road.id, 1.0, road.length));
        }
        if at_junction(road.predecessor) {
            out.push((road.id, -1.0, 0.0));
        }
    }
    out
}

/// The road a connecting road leads out to.
fn exit_of(town: &Town, c: &Connection) -> Option<u32> {
    let road = town.road(c.connecting)?;
    let link = if c.at_end { road.predecessor } else { road.successor }?;
    (!link.junction).then_some(link.id)
}

/// The connection a vehicle in town lane `lane` of `from` takes to `to`, with its lane on the
/// connecting road.
pub fn connection(town: &Town, j: u32, from: u32, lane: i32, to: u32) -> Option<(&Connection, i32)> {
    let junction = town.junctions.get(&j)?;
    junction
        .connections
        .iter()
        .filter(|c| c.incoming == from && exit_of(town, c) == Some(to))
        .find_map(|c| c.lanes.iter().find(|(f, _)| *f == lane).map(|(_, t)| (c, *t)))
}

fn junction_candidates(town: &Town, j: u32, needs: &Needs) -> Vec<Candidate> {
    let roads = incoming_roads(town, j);
    let into = |(id, dir, s): (u32, f64, f64)| -> Option<Pose> {
        let p = town.road(id)?.pose(s);
        Some(Pose { yaw: along_dir(p.yaw, dir), ..p })
    };
    let signalised = town.junctions.get(&j).is_some_and(|jn| {
        jn.connections.iter().any(|c| town.road(c.connecting).is_some_and(|r| !r.signals.is_empty()))
    });
    let mut out = Vec::new();
    for &ego in &roads {
        let Some(ego_pose) = into(ego) else { continue };
        let mut arms = Vec::new();
        let mut misfits = Vec::new();
        for &arm in &needs.arms {
            // an arm's incoming traffic heads the way the ego's would turn to go out of it
            let want = wrap(ego_pose.yaw + (-arm.outward()).yaw());
            let found = roads
                .iter()
                .filter_map(|&r| into(r).map(|p| (r, wrap(p.yaw - want).abs())))
                .filter(|(_, off)| *off < BEARING)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let Some(((road, dir, s0), _)) = found else {
                let what = format!("the junction has no {} road", arm_words(arm));
                misfits.push((1000.0, Misfit { what, lanes: false }));
                continue;
            };
            let Some(r) = town.road(road) else { continue };
            let (incoming, outgoing) = lanes_at(r, s0, dir);
            if let Some(&(_, i, o)) = needs.lanes.iter().find(|l| l.0 == arm) {
                lane_misfits(&mut misfits, arm, (i, o), (incoming.len(), outgoing.len()));
            }
            if let Some(&(_, _, reach)) = needs.reach.iter().find(|l| l.0 == arm) {
                length_misfit(&mut misfits, arm, reach, r.length);
            }
            arms.push(ArmSite { arm, road, dir, s0, incoming, outgoing });
        }
        if needs.signalised != signalised {
            let words = if signalised { "has traffic lights" } else { "has no traffic lights" };
            misfits.push((5.0, Misfit { what: format!("the town's junction {words}"), lanes: false }));
        }
        for &(arm, lane, turn) in &needs.turns {
            if route_of(town, &arms, j, arm, lane, turn).is_none() {
                let turn = crate::network::turn_name(turn);
                let what = format!("the junction has no {turn} turn from lane {lane} of the {} road", arm_words(arm));
                misfits.push((20.0, Misfit { what, lanes: true }));
            }
        }
        out.push(Candidate { arms, junction: Some(j), misfits });
    }
    out
}

/// A vehicle's connecting road and its lane on it, for TAD lane `lane` of `arm` taking `turn`.
fn route_of(town: &Town, arms: &[ArmSite], j: u32, arm: Arm, lane: i64, turn: Turn) -> Option<(u32, i32)> {
    let from = arms.iter().find(|a| a.arm == arm)?;
    let to = arms.iter().find(|a| a.arm == turn.exit(arm))?;
    let id = *from.incoming.get(usize::try_from(lane - 1).ok()?)?;
    connection(town, j, from.road, id, to.road).map(|(c, l)| (c.connecting, l))
}

/// The layout's junction centre, the town's (the mean of its arms' edges) and the rotation
/// between them.
fn centre(layout: &Layout, town: &Town, c: &Candidate) -> (Vec2, Vec2, f64) {
    let origin = Vec2::new(0.0, 0.0);
    let ego = c.arms.iter().find(|a| a.arm == Arm::Ego);
    let Some(yaw) = ego.and_then(|a| town.road(a.road).map(|r| a.traffic_yaw(r, a.s0))) else {
        return (origin, origin, 0.0);
    };
    let edges: Vec<Vec2> = c.arms.iter().filter_map(|a| town.road(a.road).map(|r| r.pose(a.s0).position)).collect();
    let mean = edges.iter().fold(origin, |acc, p| acc + *p) * (1.0 / edges.len().max(1) as f64);
    (layout.road.centre(), mean, yaw)
}

/// A place on the town: road, `s`, `t` and the heading relative to the reference line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    pub road: u32,
    pub s: f64,
    pub t: f64,
    pub heading: f64,
}

impl Site<'_> {
    pub fn arm(&self, arm: Arm) -> Option<&ArmSite> {
        self.arms.iter().find(|a| a.arm == arm)
    }

    /// The town lane of TAD lane `lane` on an arm (incoming `> 0`, outgoing `< 0`).
    pub fn lane(&self, arm: Arm, lane: i64) -> Option<i32> {
        let a = self.arm(arm)?;
        let (list, k) = if lane > 0 { (&a.incoming, lane) } else { (&a.outgoing, -lane) };
        list.get(usize::try_from(k - 1).ok()?).copied()
    }

    /// Where a layout point `lateral` metres left of an arm's centre line, `out` metres out
    /// from its origin, lies on the town, facing `yaw` relative to the arm's incoming traffic.
    pub fn place(&self, road: &Road, arm: Arm, out: f64, lateral: f64, yaw: f64) -> Option<Place> {
        let a = self.arm(arm)?;
        let town_road = self.town.road(a.road)?;
        let s = a.s_at(town_road, out);
        // the nearest layout lane, and how far from its centre
        let w = road.lane_width;
        let (incoming, outgoing) = road.arm_lanes(arm);
        let lanes = (1..=i64::from(incoming)).chain((1..=i64::from(outgoing)).map(|k| -k));
        let (k, id) = lanes
            .filter_map(|k| self.lane(arm, k).map(|id| (k, id)))
            .min_by(|a, b| (lateral - road.lateral(a.0)).abs().total_cmp(&(lateral - road.lateral(b.0)).abs()))?;
        let offset = lateral - road.lateral(k);
        let (inner, outer) = town_road.lane_span(s, id)?;
        let (centre, half) = ((inner + outer) / 2.0, (outer - inner).abs() / 2.0);
        // beyond the lane: as far beyond the town's lane
        let town_offset =
            if offset.abs() > w / 2.0 { offset.signum() * (half + offset.abs() - w / 2.0) } else { offset };
        let t = centre + a.dir * town_offset;
        let heading = wrap(along_dir(yaw, a.dir));
        Some(Place { road: a.road, s, t, heading })
    }

    /// Where a layout point is in the town's world (module header, 3).
    pub fn world(&self, road: &Road, p: Vec2) -> Vec2 {
        if let Some((arm, out, lateral)) = on_arm(road, &self.arms, p)
            && let Some(place) = self.place(road, arm, out, lateral, 0.0)
            && let Some(r) = self.town.road(place.road)
        {
            return r.point(place.s, place.t);
        }
        self.rotate(p)
    }

    /// A layout direction in the town's world.
    pub fn direction(&self, d: Vec2) -> Vec2 {
        let (_, _, yaw) = self.centre;
        let (c, s) = (yaw.cos(), yaw.sin());
        Vec2::new(c * d.x - s * d.y, s * d.x + c * d.y)
    }

    fn rotate(&self, p: Vec2) -> Vec2 {
        let (from, to, _) = self.centre;
        to + self.direction(p - from)
    }

    /// The traffic lights facing an arm's incoming traffic: on each of its connecting roads,
    /// the one nearest where its traffic enters.
    pub fn signals(&self, arm: Arm) -> Vec<u32> {
        let (Some(j), Some(a)) = (self.junction.and_then(|j| self.town.junctions.get(&j)), self.arm(arm)) else {
            return Vec::new();
        };
        let mut ids: Vec<u32> = j
            .connections
            .iter()
            .filter(|c| c.incoming == a.road)
            .filter_map(|c| {
                let road = self.town.road(c.connecting)?;
                let entry = if c.at_end { road.length } else { 0.0 };
                road.signals.iter().min_by(|x, y| (x.1 - entry).abs().total_cmp(&(y.1 - entry).abs())).map(|x| x.0)
            })
            .collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }

    /// A vehicle's way on the town, a point every metre: its lane from `out` metres out to the
    /// junction's edge, its connecting road, then [`WAY_BEYOND`] metres of its exit lane;
    /// without a junction, its lane on for [`WAY_BEYOND`] metres. Empty for a lane the town lacks.
    pub fn way(&self, arm: Arm, lane: i64, turn: Turn, out: f64) -> Vec<Vec2> {
        let mut points = Vec::new();
        let Some((a, id)) = self.arm(arm).zip(self.lane(arm, lane)) else { return points };
        let end = if self.junction.is_some() { 0.0 } else { out - WAY_BEYOND };
        self.lane_points(a, id, out, end, &mut points);
        let Some((connecting, via, exit)) = self.route(arm, lane, turn) else { return points };
        if let Some(r) = self.town.road(connecting) {
            let n = r.length.ceil().max(1.0) as usize;
            for k in 0..=n {
                let f = k as f64 / n as f64;
                let s = if via > 0 { r.length * (1.0 - f) } else { r.length * f };
                points.extend(r.lane_centre(s, via).map(|t| r.point(s, t)));
            }
        }
        if let Some(id) = self.exit_lane(exit, lane, turn) {
            self.lane_points(exit, id, 0.0, WAY_BEYOND, &mut points);
        }
        points
    }

    /// The town lane a vehicle from TAD lane `lane` leaves the junction in, on the exit arm:
    /// counted from the side its turn keeps to (`Turn::exit_lane`) among the town's lanes.
    pub fn exit_lane(&self, exit: &ArmSite, lane: i64, turn: Turn) -> Option<i32> {
        let outgoing = u32::try_from(exit.outgoing.len()).ok()?;
        let k = turn.exit_lane(lane, outgoing).clamp(1, i64::from(outgoing.max(1)));
        exit.outgoing.get(usize::try_from(k - 1).ok()?).copied()
    }

    /// A layout heading at a point of an arm, on the town: the unit vector at the same angle
    /// to the arm's incoming traffic there.
    pub fn direction_on(&self, road: &Road, arm: Arm, p: Vec2, yaw: f64) -> Vec2 {
        let (out, _, traffic) = frame(road, arm, p);
        let Some((a, r)) = self.arm(arm).and_then(|a| self.town.road(a.road).map(|r| (a, r))) else {
            return self.direction(Vec2::from_yaw(yaw));
        };
        Vec2::from_yaw(a.traffic_yaw(r, a.s_at(r, out)) + yaw - traffic)
    }

    /// Points every metre of a lane of an arm from `from` to `to` metres out.
    fn lane_points(&self, a: &ArmSite, id: i32, from: f64, to: f64, points: &mut Vec<Vec2>) {
        let Some(r) = self.town.road(a.road) else { return };
        let n = (from - to).abs().ceil().max(1.0) as usize;
        for k in 0..=n {
            let s = a.s_at(r, from + (to - from) * k as f64 / n as f64);
            points.extend(r.lane_centre(s, id).map(|t| r.point(s, t)));
        }
    }

    /// A conflict point of the layout on the town: carried over ([`Site::world`]), then moved
    /// onto the ego's way, where the ego's time to it is measured.
    pub fn conflict(&self, road: &Road, p: Vec2) -> Vec2 {
        let q = self.world(road, p);
        self.ego_way.iter().copied().min_by(|a, b| a.distance(q).total_cmp(&b.distance(q))).unwrap_or(q)
    }

    /// The connecting road a vehicle in TAD lane `lane` of `arm` takes for `turn`, its lane
    /// there, and the exit arm's site.
    pub fn route(&self, arm: Arm, lane: i64, turn: Turn) -> Option<(u32, i32, &ArmSite)> {
        let j = self.junction?;
        let (road, l) = route_of(self.town, &self.arms, j, arm, lane, turn)?;
        Some((road, l, self.arm(turn.exit(arm))?))
    }
}

/// A layout point in an arm's frame: its distance out from the arm's origin, its offset left
/// of the centre line (as the arm's incoming traffic sees it) and that traffic's heading there.
pub fn frame(road: &Road, arm: Arm, p: Vec2) -> (f64, f64, f64) {
    let (along, lateral, yaw) = match arm {
        Arm::Ego => {
            let (along, lateral) = ego_road_inverse(road, p);
            (along, lateral, road.ego_road(along, 0.0).yaw)
        }
        arm => {
            let u = arm.outward();
            let q = p - road.centre();
            let half = road.junction.as_ref().map_or(0.0, |j| j.half);
            (q.dot(u) - half, q.dot((-u).left()), (-u).yaw())
        }
    };
    (outward(road, arm, along), lateral, yaw)
}

/// The arm a layout point lies on (outside the junction), its distance out from the arm's
/// origin and its lateral offset.
fn on_arm(road: &Road, arms: &[ArmSite], p: Vec2) -> Option<(Arm, f64, f64)> {
    let mut best: Option<(Arm, f64, f64)> = None;
    for a in arms {
        if a.arm != Arm::Ego && road.junction.is_none() {
            continue;
        }
        let (out, lateral, _) = frame(road, a.arm, p);
        if (out >= 0.0 || road.junction.is_none()) && best.is_none_or(|b| out > b.1) {
            best = Some((a.arm, out, lateral));
        }
    }
    best
}

/// `(along, lateral)` of a point of the ego's road: the inverse of `Road::ego_road`.
fn ego_road_inverse(road: &Road, p: Vec2) -> (f64, f64) {
    match road.shape {
        Shape::Curve { left } if p.x > 0.0 => {
            let sign = if left { 1.0 } else { -1.0 };
            let q = Vec2::new(p.x, sign * p.y);
            let r = CURVE_RADIUS;
            let phi = q.x.atan2(r - q.y);
            (phi * r, sign * (r - (q - Vec2::new(0.0, r)).length()))
        }
        _ => (p.x, p.y),
    }
}
