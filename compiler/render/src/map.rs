//! The road as shapes in metres, in paint order, for both pictures to draw.
//!
//! Every arm is a strip along its centre line (the layout's `Road::pose_at`), measured by
//! `s`: on a junction's arm, metres from the junction's centre outwards; without a junction,
//! metres along the ego's road. A strip has its incoming lanes on the right (`lo`) and
//! outgoing ones on the left (`hi`). Painting in layers keeps the geometry simple: sidewalks,
//! then asphalt over them (each arm runs on into the junction up to the crossing road's far
//! curb, and each corner between two arms is rounded by a quarter ellipse about the box's
//! corner), then the roundabout's island, then markings. Only the part of each arm near the
//! view is drawn.
//!
//! Crosswalks lie where the layout puts them: `CROSSWALK` m inside each junction arm's stop
//! line. A roundabout's would lie on its ring, so they are drawn just outside the yield
//! lines instead. A road without a junction has crosswalks where walkers cross it: the
//! layout does not keep their place, so it is read from the walkers whose first heading is
//! across the road or who end on its other side.

use crate::palette::{self, Colour};
use crate::view::Bounds;
use crate::{Kind, Scene};
use tad_road::geom::{Path, Vec2};
use tad_road::road::{CROSSWALK, RING, RUN, SIDEWALK_WIDTH, Station};
use tad_road::{Arm, Road, Shape};

/// A shape in metres.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Area { class: &'static str, points: Vec<Vec2>, colour: Colour },
    Line { class: &'static str, points: Vec<Vec2>, colour: Colour, width: f64, dash: Option<(f64, f64)> },
    Disc { class: &'static str, centre: Vec2, radius: f64, colour: Colour },
}

/// The road drawn, and where each arm's signal stands.
#[derive(Clone, Debug, Default)]
pub struct Map {
    pub items: Vec<Item>,
    pub signals: Vec<(Arm, Vec2)>,
}

/// Arms in counter-clockwise order of their outward directions.
const CCW: [Arm; 4] = [Arm::Opposite, Arm::Left, Arm::Ego, Arm::Right];
/// How far past the view an arm is still drawn, m (beyond its widest part).
const NEAR: f64 = 6.0;
/// Walkers whose crossings are nearer than this share a crosswalk, m.
const SAME_CROSSING: f64 = 6.0;

/// One arm's strip: see the module's header.
struct Strip<'a> {
    road: &'a Road,
    arm: Arm,
    /// Lateral extent: the right curb (negative) and the left one.
    lo: f64,
    hi: f64,
    /// The range of `s` it has, and the part of it near the view.
    near: (f64, f64),
}

impl Strip<'_> {
    fn at(&self, s: f64, lateral: f64) -> Vec2 {
        let road = self.road;
        let along = match (&road.junction, self.arm) {
            (None, _) => s,
            (Some(j), Arm::Ego) => road.approach + j.half - s,
            (Some(j), _) => s - j.half,
        };
        road.pose_at(Station { arm: self.arm, along }, 1, lateral).position
    }

    /// Whether the strip bends (then lines along it are sampled every metre).
    fn curved(&self) -> bool {
        self.arm == Arm::Ego && matches!(self.road.shape, Shape::Curve { .. })
    }

    /// Values of `s` from `a` to `b`, clipped to the part near the view.
    fn span(&self, a: f64, b: f64) -> Option<Vec<f64>> {
        self.samples(a.max(self.near.0), b.min(self.near.1))
    }

    /// Values of `s` from `a` to `b`.
    fn samples(&self, a: f64, b: f64) -> Option<Vec<f64>> {
        if (b - a).is_nan() || b - a < 1e-6 {
            return None;
        }
        let n = if self.curved() { ((b - a).ceil() as usize).clamp(1, 2000) } else { 1 };
        Some((0..=n).map(|k| a + (b - a) * k as f64 / n as f64).collect())
    }

    fn line(&self, a: f64, b: f64, lateral: f64) -> Option<Vec<Vec2>> {
        Some(self.span(a, b)?.into_iter().map(|s| self.at(s, lateral)).collect())
    }

    /// A dashed line from `a` (or, without a start, from `s = 0`), starting where a whole
    /// number of dash periods from there leaves the view, so that dashes stay in place
    /// whatever the view.
    fn dashed(&self, a: f64, b: f64, lateral: f64, period: f64) -> Option<Vec<Vec2>> {
        let anchor = if a.is_finite() { a } else { 0.0 };
        let from = anchor + ((a.max(self.near.0) - anchor) / period).floor() * period;
        Some(self.samples(from, b.min(self.near.1))?.into_iter().map(|s| self.at(s, lateral)).collect())
    }

    fn area(&self, a: f64, b: f64, l0: f64, l1: f64) -> Option<Vec<Vec2>> {
        let span = self.span(a, b)?;
        let mut points: Vec<Vec2> = span.iter().map(|&s| self.at(s, l0)).collect();
        points.extend(span.iter().rev().map(|&s| self.at(s, l1)));
        Some(points)
    }
}

/// The road near `view`: see the module's header.
pub fn draw(scene: &Scene, view: &Bounds) -> Map {
    let painter = Painter::new(scene, view);
    let mut items = Vec::new();
    if painter.road.sidewalks {
        painter.sidewalks(&mut items);
    }
    painter.asphalt(&mut items);
    painter.markings(&mut items);
    if painter.road.crosswalks {
        painter.crosswalks(&mut items);
    }
    let signals = painter.stop_lines(&mut items);
    Map { items, signals }
}

/// What painting the road's layers shares: the road, its sizes, and its arms' strips near
/// the view.
struct Painter<'a> {
    scene: &'a Scene<'a>,
    road: &'a Road,
    /// The lane width, m.
    w: f64,
    junction: bool,
    roundabout: bool,
    /// Half the junction's box, m (0 without a junction).
    half: f64,
    /// Where an arm's own markings start: the box's edge, or the whole road.
    outer: f64,
    centre: Vec2,
    /// The roundabout's ring's outer radius, m.
    ring_outer: f64,
    strips: Vec<Strip<'a>>,
}

impl<'a> Painter<'a> {
    fn new(scene: &'a Scene<'a>, view: &Bounds) -> Painter<'a> {
        let road = scene.road;
        let w = if road.lane_width.is_finite() && road.lane_width > 0.0 { road.lane_width } else { 3.5 };
        let junction = road.junction.as_ref();
        let half = junction.map_or(0.0, |j| j.half.max(0.0));
        let mut painter = Painter {
            scene,
            road,
            w,
            junction: junction.is_some(),
            roundabout: junction.is_some_and(|j| j.roundabout),
            half,
            outer: if junction.is_some() { half } else { f64::NEG_INFINITY },
            centre: road.centre(),
            ring_outer: half.max(half * RING + palette::RING_LANES * w / 2.0),
            strips: Vec::new(),
        };
        painter.strips = painter.strips(view);
        painter
    }

    /// A curb's distance from an arm's centre line on the side towards `toward`.
    fn ext(&self, arm: Arm, toward: Vec2) -> f64 {
        let (incoming, outgoing) = self.road.arm_lanes(arm);
        let left = (-arm.outward()).left();
        if left.dot(toward) > 0.0 { outgoing as f64 * self.w } else { incoming as f64 * self.w }
    }

    /// The strips of the arms that have lanes and come near the view.
    fn strips(&self, view: &Bounds) -> Vec<Strip<'a>> {
        let road = self.road;
        let reach = (road.lanes.max(road.opposite).max(road.cross_lanes) as f64) * self.w + SIDEWALK_WIDTH + NEAR;
        let window = view.grown(reach);
        let arms: Vec<Arm> =
            if self.junction { CCW.into_iter().filter(|a| road.has_arm(*a)).collect() } else { vec![Arm::Ego] };
        arms.iter().filter_map(|&arm| self.strip(arm, &window)).collect()
    }

    /// An arm's strip, if it has lanes and comes into `window`.
    fn strip(&self, arm: Arm, window: &Bounds) -> Option<Strip<'a>> {
        let road = self.road;
        let (incoming, outgoing) = road.arm_lanes(arm);
        if incoming + outgoing == 0 {
            return None;
        }
        // the range of s, from the crossing road's far curb (at a junction) outwards
        let domain = if self.junction {
            let beyond = CCW
                .into_iter()
                .filter(|p| road.has_arm(*p) && p.outward().dot(arm.outward()).abs() < 0.5)
                .map(|p| self.ext(p, -arm.outward()))
                .fold(0.0, f64::max);
            let far = if arm == Arm::Ego { road.approach + self.half + RUN } else { self.half + RUN };
            (-beyond.min(self.half), far)
        } else {
            (-RUN, RUN)
        };
        let mut strip = Strip {
            road,
            arm,
            lo: -(incoming as f64) * self.w,
            hi: outgoing as f64 * self.w,
            near: (domain.0, domain.1),
        };
        let mut near: Option<(f64, f64)> = None;
        let mut s = domain.0;
        while s <= domain.1 {
            if window.contains(strip.at(s, 0.0)) {
                near = Some(near.map_or((s, s), |(a, _)| (a, s)));
            }
            s += 1.0;
        }
        let (a, b) = near?;
        strip.near = ((a - 1.0).max(domain.0), (b + 1.0).min(domain.1));
        Some(strip)
    }

    /// Sidewalks along each arm, then round the roundabout or the junction's corners.
    fn sidewalks(&self, items: &mut Vec<Item>) {
        for st in &self.strips {
            let right = st.area(self.outer, f64::INFINITY, st.lo - SIDEWALK_WIDTH, st.lo);
            area(items, "sidewalk", right, palette::SIDEWALK);
            let left = st.area(self.outer, f64::INFINITY, st.hi, st.hi + SIDEWALK_WIDTH);
            area(items, "sidewalk", left, palette::SIDEWALK);
        }
        if self.junction && self.roundabout {
            items.push(Item::Disc {
                class: "sidewalk",
                centre: self.centre,
                radius: self.ring_outer + SIDEWALK_WIDTH,
                colour: palette::SIDEWALK,
            });
        } else if self.junction {
            self.corner_sidewalks(items);
        }
    }

    /// A band round each corner of the junction, joining two arms' sidewalks; where an arm
    /// is missing, the crossing road's sidewalk runs past it.
    fn corner_sidewalks(&self, items: &mut Vec<Item>) {
        let (centre, half) = (self.centre, self.half);
        for (i, &a) in CCW.iter().enumerate() {
            let b = CCW[(i + 1) % 4];
            let (ua, ub) = (a.outward(), b.outward());
            if self.road.has_arm(a) && self.road.has_arm(b) {
                let (rx, ry) = (half - self.ext(b, ua), half - self.ext(a, ub));
                if rx > 0.0 && ry > 0.0 {
                    let k = centre + (ua + ub) * half;
                    let mut points = quarter(k, ua, ub, rx, ry);
                    let inner = quarter(k, ua, ub, (rx - SIDEWALK_WIDTH).max(0.0), (ry - SIDEWALK_WIDTH).max(0.0));
                    points.extend(inner.into_iter().rev());
                    items.push(Item::Area { class: "sidewalk", points, colour: palette::SIDEWALK });
                }
            }
        }
        for m in CCW.into_iter().filter(|m| !self.road.has_arm(*m)) {
            if let Some((e, along)) = past_missing(self.road, m, &|arm, toward| self.ext(arm, toward)) {
                let (um, up) = (m.outward(), along);
                let points = vec![
                    centre + um * e + up * half,
                    centre + um * (e + SIDEWALK_WIDTH) + up * half,
                    centre + um * (e + SIDEWALK_WIDTH) - up * half,
                    centre + um * e - up * half,
                ];
                items.push(Item::Area { class: "sidewalk", points, colour: palette::SIDEWALK });
            }
        }
    }

    /// Asphalt over the sidewalks: each arm, then the roundabout's ring (with its island) or
    /// the junction's rounded corners.
    fn asphalt(&self, items: &mut Vec<Item>) {
        let (centre, half, w) = (self.centre, self.half, self.w);
        for st in &self.strips {
            area(items, "surface", st.area(f64::NEG_INFINITY, f64::INFINITY, st.lo, st.hi), palette::ASPHALT);
        }
        if self.junction && self.roundabout {
            items.push(Item::Disc { class: "surface", centre, radius: self.ring_outer, colour: palette::ASPHALT });
            let island = (half * RING - palette::RING_LANES * w / 2.0).max(1.0);
            items.push(Item::Disc { class: "island", centre, radius: island, colour: palette::ISLAND });
            let mut ring: Vec<Vec2> = (0..=72)
                .map(|k| centre + Vec2::from_yaw(k as f64 * std::f64::consts::TAU / 72.0) * (island + 0.3))
                .collect();
            ring.dedup();
            line(items, "edge-line", Some(ring), palette::MARKING, palette::LINE, None);
        } else if self.junction {
            for (i, &a) in CCW.iter().enumerate() {
                let b = CCW[(i + 1) % 4];
                let (ua, ub) = (a.outward(), b.outward());
                let (ea, eb) = (self.ext(a, ub), self.ext(b, ua));
                let (rx, ry) = (half - eb, half - ea);
                if self.road.has_arm(a) && self.road.has_arm(b) && rx > 0.0 && ry > 0.0 {
                    // the rounded corner: from the inner corner, round the quarter ellipse
                    let k = centre + (ua + ub) * half;
                    let mut points = vec![centre + ua * eb + ub * ea];
                    points.extend(quarter(k, ua, ub, rx, ry));
                    items.push(Item::Area { class: "surface", points, colour: palette::ASPHALT });
                }
            }
        }
    }

    /// Markings along each arm: lane lines, the centre line, edge lines; at a junction, the
    /// crossing road's edge line runs on past a missing arm.
    fn markings(&self, items: &mut Vec<Item>) {
        let w = self.w;
        for st in &self.strips {
            let (incoming, outgoing) = self.road.arm_lanes(st.arm);
            let from = self.outer;
            let to = f64::INFINITY;
            let period = palette::DASH.0 + palette::DASH.1;
            let dividers = (1..incoming).map(|k| -(k as f64) * w).chain((1..outgoing).map(|k| k as f64 * w));
            for lateral in dividers {
                let points = st.dashed(from, to, lateral, period);
                line(items, "lane-line", points, palette::MARKING, palette::LINE, Some(palette::DASH));
            }
            if incoming > 0 && outgoing > 0 {
                let off = (palette::CENTRE_GAP + palette::LINE) / 2.0;
                for lateral in [-off, off] {
                    line(items, "centre-line", st.line(from, to, lateral), palette::CENTRE_LINE, palette::LINE, None);
                }
            }
            for lateral in [st.lo + palette::EDGE_INSET, st.hi - palette::EDGE_INSET] {
                line(items, "edge-line", st.line(from, to, lateral), palette::MARKING, palette::LINE, None);
            }
        }
        if self.junction && !self.roundabout {
            for m in CCW.into_iter().filter(|m| !self.road.has_arm(*m)) {
                if let Some((e, along)) = past_missing(self.road, m, &|arm, toward| self.ext(arm, toward)) {
                    let at = |t: f64| self.centre + m.outward() * (e - palette::EDGE_INSET) + along * t;
                    let points = Some(vec![at(-self.half), at(self.half)]);
                    line(items, "edge-line", points, palette::MARKING, palette::LINE, None);
                }
            }
        }
    }

    /// Crosswalks: inside each junction arm's stop line (outside a roundabout's yield line),
    /// or where walkers cross a road without a junction; stripes across the whole arm.
    fn crosswalks(&self, items: &mut Vec<Item>) {
        let depth = palette::CROSSWALK_DEPTH;
        let places: Vec<(&Strip, f64)> = if self.junction {
            let s = if self.roundabout { self.half + palette::STOP_LINE + CROSSWALK } else { self.half - CROSSWALK };
            self.strips.iter().map(|st| (st, s)).collect()
        } else {
            self.strips
                .first()
                .map(|st| crossings(self.scene, st).into_iter().map(|s| (st, s)).collect())
                .unwrap_or_default()
        };
        for (st, s) in places {
            let width = st.hi - st.lo;
            let n = (width / palette::STRIPE_PITCH).floor();
            let first =
                st.lo + (width - n * palette::STRIPE_PITCH) / 2.0 + (palette::STRIPE_PITCH - palette::STRIPE) / 2.0;
            for k in 0..n as usize {
                let l0 = first + k as f64 * palette::STRIPE_PITCH;
                // a stripe is a short strip of the arm, never sampled on a bend
                let corners = [
                    (s - depth / 2.0, l0),
                    (s + depth / 2.0, l0),
                    (s + depth / 2.0, l0 + palette::STRIPE),
                    (s - depth / 2.0, l0 + palette::STRIPE),
                ];
                let points: Vec<Vec2> = corners.iter().map(|&(s, l)| st.at(s, l)).collect();
                if st.near.0 <= s && s <= st.near.1 {
                    items.push(Item::Area { class: "crosswalk", points, colour: palette::MARKING });
                }
            }
        }
    }

    /// At a junction, each arm's stop line (a roundabout's yield line) across its incoming
    /// lanes; returns where each arm's signal stands.
    fn stop_lines(&self, items: &mut Vec<Item>) -> Vec<(Arm, Vec2)> {
        let mut signals = Vec::new();
        if !self.junction {
            return signals;
        }
        for st in &self.strips {
            let (incoming, outgoing) = self.road.arm_lanes(st.arm);
            if incoming == 0 {
                continue;
            }
            let s = self.half + palette::STOP_LINE / 2.0;
            let end = if outgoing > 0 { -(palette::CENTRE_GAP / 2.0 + palette::LINE) } else { st.hi };
            let (class, dash) = if self.roundabout { ("yield-line", Some((0.6, 0.4))) } else { ("stop-line", None) };
            if st.near.0 <= s && s <= st.near.1 {
                let points = vec![st.at(s, st.lo), st.at(s, end)];
                items.push(Item::Line { class, points, colour: palette::MARKING, width: palette::STOP_LINE, dash });
            }
            signals.push((st.arm, st.at(self.half + palette::STOP_LINE, st.lo - palette::SIGNAL_OFFSET)));
        }
        signals
    }
}

/// An area, when there is one.
fn area(items: &mut Vec<Item>, class: &'static str, points: Option<Vec<Vec2>>, colour: Colour) {
    if let Some(points) = points {
        items.push(Item::Area { class, points, colour });
    }
}

/// A line, when there is one.
fn line(
    items: &mut Vec<Item>,
    class: &'static str,
    points: Option<Vec<Vec2>>,
    colour: Colour,
    width: f64,
    dash: Option<(f64, f64)>,
) {
    if let Some(points) = points {
        items.push(Item::Line { class, points, colour, width, dash });
    }
}

/// Where an arm is missing: the crossing road's curb on its side (m from the centre), and
/// the direction along that road.
fn past_missing(road: &Road, missing: Arm, ext: &impl Fn(Arm, Vec2) -> f64) -> Option<(f64, Vec2)> {
    let crossing: Vec<Arm> =
        CCW.into_iter().filter(|p| road.has_arm(*p) && p.outward().dot(missing.outward()).abs() < 0.5).collect();
    let e = crossing
        .iter()
        .map(|p| ext(*p, missing.outward()))
        .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))))?;
    Some((e, missing.outward().left()))
}

/// A quarter ellipse about the corner `k` of a junction's box, from the point `ry` back
/// along `ub` (on arm `a`'s curb) to the point `rx` back along `ua` (on arm `b`'s).
fn quarter(k: Vec2, ua: Vec2, ub: Vec2, rx: f64, ry: f64) -> Vec<Vec2> {
    const N: usize = 16;
    (0..=N)
        .map(|i| {
            let t = i as f64 / N as f64 * std::f64::consts::FRAC_PI_2;
            k - ua * (rx * t.sin()) - ub * (ry * t.cos())
        })
        .collect()
}

/// Where walkers cross the ego's road (no junction): values of `s`, one per group of
/// crossings (see the module's header).
fn crossings(scene: &Scene, strip: &Strip) -> Vec<f64> {
    let centre =
        Path::new(strip.span(strip.near.0, strip.near.1).unwrap_or_default().into_iter().map(|s| strip.at(s, 0.0)));
    if centre.points().len() < 2 {
        return Vec::new();
    }
    let mut found: Vec<f64> = Vec::new();
    for actor in 0..scene.actors.len() {
        if scene.kind(actor) != Kind::Walker {
            continue;
        }
        let poses: Vec<[f64; 3]> = (0..scene.frames.len()).filter_map(|f| scene.pose(f, actor)).collect();
        let (Some(first), Some(last)) = (poses.first(), poses.last()) else { continue };
        let local = |p: &[f64; 3]| {
            let (arc, _) = centre.project(Vec2::new(p[0], p[1]));
            let pose = centre.pose(arc);
            (arc, pose.local(Vec2::new(p[0], p[1])).y, pose.yaw)
        };
        let (arc, y0, yaw) = local(first);
        let (_, y1, _) = local(last);
        let across = (first[2] - yaw).cos().abs() < 0.5;
        let reach = strip.hi - strip.lo + 2.0 * SIDEWALK_WIDTH + 3.0;
        if y0.abs() < reach && (across || y0.signum() != y1.signum()) {
            found.push(strip.near.0 + arc);
        }
    }
    found.sort_by(f64::total_cmp);
    let mut groups: Vec<Vec<f64>> = Vec::new();
    for s in found {
        match groups.last_mut() {
            Some(g) if s - g[g.len() - 1] < SAME_CROSSING => g.push(s),
            _ => groups.push(vec![s]),
        }
    }
    groups.iter().map(|g| g.iter().sum::<f64>() / g.len() as f64).collect()
}
