//! Plane geometry: points, poses, polyline paths, and oriented boxes (footprints) with
//! overlap and distance by the separating axis theorem.
//!
//! The frame is right-handed with `y` to the left of `x`; a heading (yaw) is the angle
//! from `+x`, counter-clockwise, in radians.

use std::ops::{Add, Mul, Neg, Sub};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec2 {
    pub x: f64,
    pub y: f64,
}

impl Vec2 {
    pub const fn new(x: f64, y: f64) -> Vec2 {
        Vec2 { x, y }
    }

    /// The unit vector of heading `yaw`.
    pub fn from_yaw(yaw: f64) -> Vec2 {
        Vec2::new(yaw.cos(), yaw.sin())
    }

    pub fn dot(self, o: Vec2) -> f64 {
        self.x * o.x + self.y * o.y
    }

    pub fn cross(self, o: Vec2) -> f64 {
        self.x * o.y - self.y * o.x
    }

    pub fn length(self) -> f64 {
        self.x.hypot(self.y)
    }

    /// Rotated a quarter turn to the left.
    pub fn left(self) -> Vec2 {
        Vec2::new(-self.y, self.x)
    }

    /// Rotated a quarter turn to the right.
    pub fn right(self) -> Vec2 {
        Vec2::new(self.y, -self.x)
    }

    pub fn yaw(self) -> f64 {
        self.y.atan2(self.x)
    }

    pub fn distance(self, o: Vec2) -> f64 {
        (self - o).length()
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}

impl Sub for Vec2 {
    type Output = Vec2;
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}

impl Mul<f64> for Vec2 {
    type Output = Vec2;
    fn mul(self, k: f64) -> Vec2 {
        Vec2::new(self.x * k, self.y * k)
    }
}

impl Neg for Vec2 {
    type Output = Vec2;
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}

/// A position and a heading.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    pub position: Vec2,
    pub yaw: f64,
}

impl Pose {
    /// `p` in this pose's frame: `x` ahead, `y` to the left.
    pub fn local(&self, p: Vec2) -> Vec2 {
        let d = p - self.position;
        let f = Vec2::from_yaw(self.yaw);
        Vec2::new(d.dot(f), d.dot(f.left()))
    }
}

/// An angle in `(-π, π]`.
pub fn wrap(angle: f64) -> f64 {
    let a = angle.rem_euclid(std::f64::consts::TAU);
    if a > std::f64::consts::PI { a - std::f64::consts::TAU } else { a }
}

/// A path as a polyline with its cumulative arc lengths. Positions beyond either end
/// continue straight along the end segments.
///
/// Projections onto a path are the runtime's hottest code (every vehicle projects the
/// others onto its path each step), so they visit the segments from the hint outwards and
/// rule out runs of [`CHUNK`] segments ([`Chunk`]: a bounding box, and a strip along the
/// run's chord, which follows a diagonal or gently curved road closely) and single
/// segments by their squared distance before taking a square root, each with a margin far
/// above rounding: the result is the one a forward scan with exact distances gives (the
/// nearest segment, ties to the first). A segment is found from the mean spacing, then
/// walked to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Path {
    points: Vec<Vec2>,
    arcs: Vec<f64>,
    /// Each segment's heading, rad, as [`Path::pose`] gives it (computed once: poses are
    /// asked for many times a step).
    yaws: Vec<f64>,
    /// Each run of [`CHUNK`] segments, bounded.
    chunks: Vec<Chunk>,
    /// Segments per metre, on average.
    density: f64,
}

/// A stretch of a [`Path`] around an arc (its hint): its first and last segments, the
/// segment of the hint, and that segment's unit direction.
#[derive(Clone, Copy, Debug)]
pub struct Window {
    first: usize,
    last: usize,
    start: usize,
    pub heading: Vec2,
}

/// Segments per [`Chunk`].
const CHUNK: usize = 8;

/// What bounds a run of segments: its box `[min x, min y, max x, max y]`; the line from its
/// first point (`origin`) along its chord (`along`, unit), how far its points stray from
/// that line (`slack`, infinite for a closed run), and the rectangle along it that holds
/// them (its `centre`, `half` its length); its first segment's heading and how far any of
/// its segments' headings turns from it (`turn`, rad, at most π).
#[derive(Clone, Debug, Default, PartialEq)]
struct Chunk {
    bounds: [f64; 4],
    origin: Vec2,
    along: Vec2,
    slack: f64,
    centre: Vec2,
    half: f64,
    yaw: f64,
    turn: f64,
}

impl Chunk {
    /// The chunk of `points` (a run's points, at least two) whose segments head `yaws`.
    fn new(points: &[Vec2], yaws: &[f64]) -> Chunk {
        let bounds =
            points.iter().fold([f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY], |b, q| {
                [b[0].min(q.x), b[1].min(q.y), b[2].max(q.x), b[3].max(q.y)]
            });
        let origin = points[0];
        let chord = points[points.len() - 1] - origin;
        let (along, slack) = if chord.length() > 1e-9 {
            let along = chord * (1.0 / chord.length());
            (along, points.iter().map(|&q| along.cross(q - origin).abs()).fold(0.0, f64::max))
        } else {
            (Vec2::new(1.0, 0.0), f64::INFINITY)
        };
        let [lo, hi] = points.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], &q| {
            let t = along.dot(q - origin);
            [lo.min(t), hi.max(t)]
        });
        let (centre, half) = (origin + along * ((lo + hi) / 2.0), (hi - lo) / 2.0);
        let yaw = yaws[0];
        let turn = yaws.iter().map(|&y| angle_between(y, yaw)).fold(0.0, f64::max);
        Chunk { bounds, origin, along, slack, centre, half, yaw, turn }
    }

    /// The farthest its rectangle reaches from the line through `origin` along `along`
    /// (unit): its farthest corner's distance.
    fn reach_from(&self, origin: Vec2, along: Vec2) -> f64 {
        along.cross(self.centre - origin).abs()
            + self.half * along.cross(self.along).abs()
            + self.slack * along.dot(self.along).abs()
    }
}

/// The angle between headings `a` and `b` on the circle, in `[0, π]`, for headings in
/// `(-π, π]` (as `wrap(a - b).abs()`, without its remainder).
fn angle_between(a: f64, b: f64) -> f64 {
    let d = (a - b).abs();
    d.min(std::f64::consts::TAU - d)
}

/// At most how far, rad, any segment of `chunks` heads from `yaw`; at most π.
fn turn_from(chunks: &[Chunk], yaw: f64) -> f64 {
    let turn = chunks.iter().map(|c| angle_between(c.yaw, yaw) + c.turn).fold(0.0, f64::max);
    turn.min(std::f64::consts::PI)
}

/// A run of whole chunks of a path ([`Path::stretch`]); `None` near an end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stretch(Option<(usize, usize)>);

/// A straight line a stretch of a path keeps near ([`Path::strip`]): every point of its
/// segments is within `slack` of the line through `origin` along `along` (unit), and every
/// segment heads within `turn` rad of `along`. Nothing is known of a stretch whose slack is
/// infinite.
#[derive(Clone, Copy, Debug)]
pub struct Strip {
    pub origin: Vec2,
    pub along: Vec2,
    pub slack: f64,
    pub turn: f64,
}

impl Strip {
    /// A strip of nothing known.
    pub const UNKNOWN: Strip = Strip {
        origin: Vec2::new(0.0, 0.0),
        along: Vec2::new(1.0, 0.0),
        slack: f64::INFINITY,
        turn: std::f64::consts::PI,
    };

    /// At least how far `p` is from every point of the stretch (up to rounding).
    pub fn distance_from(&self, p: Vec2) -> f64 {
        self.along.cross(p - self.origin).abs() - self.slack
    }
}

/// A projection under way: the best segment so far (index, parameter on it, distance), the
/// distance beyond which nothing matters (the best's, at first the caller's reach), and the
/// squared distance beyond which a point is surely farther than that (a margin far above
/// rounding; below 1e-100 m nothing is ruled out). A box of segments is surely farther when
/// its distance exceeds `limit` + 1 µm (it holds the exact points, not the rounded ones).
struct Scan {
    best: (usize, f64, f64),
    limit: f64,
    bound: f64,
}

impl Scan {
    fn new(reach: f64) -> Scan {
        Scan { best: (usize::MAX, 0.0, f64::INFINITY), limit: reach, bound: Scan::bound(reach) }
    }

    fn bound(limit: f64) -> f64 {
        if limit >= 1e-100 { limit * limit * (1.0 + 1e-9) } else { f64::INFINITY }
    }

    /// Whether every point of `chunk` is surely farther from `p` than the limit: beyond its
    /// box, or farther from its chord's line than its points stray.
    fn rules_out(&self, chunk: &Chunk, p: Vec2) -> bool {
        let [x0, y0, x1, y1] = chunk.bounds;
        let dx = (x0 - p.x).max(p.x - x1).max(0.0);
        let dy = (y0 - p.y).max(p.y - y1).max(0.0);
        let m = self.limit + 1e-6;
        dx * dx + dy * dy > m * m || chunk.along.cross(p - chunk.origin).abs() - chunk.slack > m
    }
}

impl Path {
    /// A path through `points`; repeated points are dropped. At least two distinct points
    /// make a path; fewer give a degenerate one that stays at its point, facing `+x`.
    pub fn new(points: impl IntoIterator<Item = Vec2>) -> Path {
        let points = points.into_iter();
        let mut path = Path::default();
        path.points.reserve(points.size_hint().0);
        path.arcs.reserve(points.size_hint().0);
        for p in points {
            match path.points.last() {
                Some(last) if last.distance(p) < 1e-6 => {}
                Some(last) => {
                    let arc = path.arcs.last().copied().unwrap_or(0.0) + last.distance(p);
                    path.points.push(p);
                    path.arcs.push(arc);
                }
                None => {
                    path.points.push(p);
                    path.arcs.push(0.0);
                }
            }
        }
        let segments = path.points.len().saturating_sub(1);
        path.yaws = (0..segments).map(|i| path.direction(i).yaw()).collect();
        path.chunks = (0..segments.div_ceil(CHUNK))
            .map(|c| {
                let end = ((c + 1) * CHUNK).min(segments);
                Chunk::new(&path.points[c * CHUNK..=end], &path.yaws[c * CHUNK..end])
            })
            .collect();
        // (paths compare equal by value: no NaN for a path of fewer than two points)
        path.density = if segments > 0 { segments as f64 / path.length() } else { 0.0 };
        path
    }

    pub fn length(&self) -> f64 {
        self.arcs.last().copied().unwrap_or(0.0)
    }

    pub fn points(&self) -> &[Vec2] {
        &self.points
    }

    /// The segment holding arc `s`, clamped to the ends.
    fn segment(&self, s: f64) -> usize {
        if self.points.len() < 2 {
            return 0;
        }
        self.arcs_upto(s).clamp(1, self.points.len() - 1) - 1
    }

    /// How many arcs are at most `s` (`partition_point`): guessed from the mean segment
    /// length (paths are mostly sampled evenly), then walked a few steps; bisection when the
    /// guess is far off.
    fn arcs_upto(&self, s: f64) -> usize {
        let arcs = &self.arcs;
        let n = arcs.len();
        let guess = s * self.density;
        if !guess.is_finite() {
            return arcs.partition_point(|&a| a <= s);
        }
        let mut k = (guess.max(0.0) as usize).min(n);
        for _ in 0..4 {
            if k < n && arcs[k] <= s {
                k += 1;
            } else if k > 0 && arcs[k - 1] > s {
                k -= 1;
            } else {
                return k;
            }
        }
        arcs.partition_point(|&a| a <= s)
    }

    /// The pose at arc length `s` (extrapolated straight beyond the ends).
    pub fn pose(&self, s: f64) -> Pose {
        match self.points.len() {
            0 => Pose::default(),
            1 => Pose { position: self.points[0], yaw: 0.0 },
            _ => {
                let i = self.segment(s);
                let along = self.direction(i);
                Pose { position: self.points[i] + along * (s - self.arcs[i]), yaw: self.yaws[i] }
            }
        }
    }

    /// Segment `i`'s unit direction.
    fn direction(&self, i: usize) -> Vec2 {
        (self.points[i + 1] - self.points[i]) * (1.0 / (self.arcs[i + 1] - self.arcs[i]))
    }

    /// The path moved `left` metres to the left of its direction (negative: to the right),
    /// point by point, each along the segment that starts at it.
    pub fn offset(&self, left: f64) -> Path {
        let n = self.points.len();
        if n < 2 {
            return self.clone();
        }
        Path::new((0..n).map(|k| {
            let i = k.min(n - 2);
            let along = self.points[i + 1] - self.points[i];
            self.points[k] + along.left() * (left / along.length())
        }))
    }

    /// The arc length of the point of the path nearest `p`, and the distance to it.
    pub fn project(&self, p: Vec2) -> (f64, f64) {
        self.project_from(p, self.length() / 2.0)
    }

    /// [`Path::project`], searched from arc `hint` outwards: the same result, found sooner
    /// from a hint near it.
    pub fn project_from(&self, p: Vec2, hint: f64) -> (f64, f64) {
        let n = self.points.len();
        if n < 2 {
            return (0.0, self.points.first().map_or(f64::INFINITY, |q| q.distance(p)));
        }
        let start = if hint.is_nan() { 0 } else { self.segment(hint) };
        match self.scan(p, 0, n - 2, start, f64::INFINITY, false) {
            Some((i, t, d)) => (self.arc(i, t), d),
            None => (0.0, f64::INFINITY),
        }
    }

    /// The arc of the point nearest `p` among the segments within `window` metres of arc
    /// `hint`, with the signed distance to it (positive: `p` is left of the path); beyond
    /// either end the path goes on straight. What follows a path step by step uses this:
    /// its cost does not grow with the path's length.
    pub fn locate(&self, p: Vec2, hint: f64, window: f64) -> (f64, f64) {
        self.nearest(p, hint, window, f64::INFINITY).unwrap_or((hint, f64::INFINITY))
    }

    /// [`Path::locate`]'s result when its distance is at most `reach`; otherwise `None`, or
    /// a result farther than `reach` (the caller compares).
    pub fn nearest(&self, p: Vec2, hint: f64, window: f64, reach: f64) -> Option<(f64, f64)> {
        self.nearest_in(&self.window(hint, window), p, reach)
    }

    /// [`Path::nearest`] in a window taken before.
    pub fn nearest_in(&self, window: &Window, p: Vec2, reach: f64) -> Option<(f64, f64)> {
        if self.points.len() < 2 {
            return Some((0.0, self.points.first().map_or(f64::INFINITY, |q| q.distance(p))));
        }
        let Window { first, last, start, .. } = *window;
        let (i, t, d) = self.scan(p, first, last, start, reach, true)?;
        let (a, b) = (self.points[i], self.points[i + 1]);
        Some((self.arc(i, t), if (b - a).cross(p - a) < 0.0 { -d } else { d }))
    }

    /// The stretch of the path within `window` metres of arc `hint`, where
    /// [`Path::nearest_in`] looks.
    pub fn window(&self, hint: f64, window: f64) -> Window {
        if self.points.len() < 2 {
            return Window { first: 0, last: 0, start: 0, heading: Vec2::new(1.0, 0.0) };
        }
        let (first, last, start) = (self.segment(hint - window), self.segment(hint + window), self.segment(hint));
        Window { first, last, start, heading: self.direction(start) }
    }

    /// At most how far, rad, the heading [`Path::pose`] gives at any arc of `window` (or
    /// one segment beyond either side) turns from the window's [`Window::heading`]; at
    /// most π.
    pub fn turn_within(&self, window: &Window) -> f64 {
        if self.points.len() < 2 {
            return 0.0;
        }
        let (first, last) = (window.first.saturating_sub(1), (window.last + 1).min(self.points.len() - 2));
        turn_from(&self.chunks[first / CHUNK..=last / CHUNK], self.yaws[window.start])
    }

    /// The stretch from arc `from` to arc `to`, as [`Path::strip`] bounds it: the whole
    /// chunks holding its segments and one more either side (where [`Path::pose`] may
    /// turn a point on their ends), or nothing where it reaches an end segment (the path
    /// goes on straight beyond it). Equal stretches give equal strips, so a caller
    /// moving along a path can keep its strip while the stretch stays.
    pub fn stretch(&self, from: f64, to: f64) -> Stretch {
        if self.points.len() < 3 {
            return Stretch(None);
        }
        let last = self.points.len() - 2;
        let (first, end) = (self.segment(from), self.segment(to) + 1);
        if first == 0 || end >= last {
            return Stretch(None);
        }
        Stretch(Some((first / CHUNK, end / CHUNK)))
    }

    /// The [`Strip`] of a `stretch`: it holds every point [`Path::nearest`] may find with
    /// its window within the stretch, and the heading [`Path::pose`] gives there. Built
    /// from whole chunks, so it is a bound, not the tightest.
    pub fn strip(&self, stretch: Stretch) -> Strip {
        let Stretch(Some((a, b))) = stretch else { return Strip::UNKNOWN };
        let chunks = &self.chunks[a..=b];
        let origin = self.points[a * CHUNK];
        let chord = self.points[((b + 1) * CHUNK).min(self.points.len() - 1)] - origin;
        if chord.length() < 1e-9 || chunks.iter().any(|c| c.slack.is_infinite()) {
            return Strip::UNKNOWN;
        }
        let along = chord * (1.0 / chord.length());
        let slack = chunks.iter().map(|c| c.reach_from(origin, along)).fold(0.0, f64::max);
        Strip { origin, along, slack, turn: turn_from(chunks, along.yaw()) }
    }

    fn arc(&self, i: usize, t: f64) -> f64 {
        self.arcs[i] + t * (self.arcs[i + 1] - self.arcs[i])
    }

    /// The segment of `first..=last` nearest `p` within `reach` (index, parameter on it,
    /// distance), visited from `start` outwards; with `extend`, the path goes on straight
    /// beyond its end segments.
    fn scan(
        &self,
        p: Vec2,
        first: usize,
        last: usize,
        start: usize,
        reach: f64,
        extend: bool,
    ) -> Option<(usize, f64, f64)> {
        let n = self.points.len();
        let mut scan = Scan::new(reach);
        let home = start / CHUNK;
        for c in (home..=last / CHUNK).chain((first / CHUNK..home).rev()) {
            let from = (c * CHUNK).max(first);
            let to = (c * CHUNK + CHUNK - 1).min(last);
            // extended end segments reach beyond their box
            let boxed = !extend || (from > 0 && to < n - 2);
            if boxed && scan.rules_out(&self.chunks[c], p) {
                continue;
            }
            if c == home {
                (start..=to).chain((from..start).rev()).for_each(|i| self.visit(i, p, extend, &mut scan));
            } else {
                (from..=to).for_each(|i| self.visit(i, p, extend, &mut scan));
            }
        }
        (scan.best.0 != usize::MAX).then_some(scan.best)
    }

    /// Segment `i` against the best so far.
    fn visit(&self, i: usize, p: Vec2, extend: bool, scan: &mut Scan) {
        let (a, b) = (self.points[i], self.points[i + 1]);
        let ab = b - a;
        let mut t = (p - a).dot(ab) / ab.dot(ab);
        if !(extend && (i == 0 && t < 0.0 || i == self.points.len() - 2 && t > 1.0)) {
            t = t.clamp(0.0, 1.0);
        }
        let q = a + ab * t;
        let e = q - p;
        if e.dot(e) > scan.bound {
            return;
        }
        let d = q.distance(p);
        let (best_i, _, best_d) = scan.best;
        if d < best_d || (d == best_d && d.is_finite() && i < best_i) {
            scan.best = (i, t, d);
            scan.limit = scan.limit.min(d);
            scan.bound = Scan::bound(scan.limit);
        }
    }

    /// The first arc length of this path at which it comes within `reach` of `other`,
    /// with the arc length on `other`; sampled every `step` metres.
    pub fn first_within(&self, other: &Path, reach: f64, step: f64) -> Option<(f64, f64)> {
        let mut s = 0.0;
        let end = self.length();
        while s <= end {
            let (o, d) = other.project(self.pose(s).position);
            if d <= reach {
                return Some((s, o));
            }
            s += step;
        }
        None
    }
}

/// The cubic Bézier's four points from `a` heading `da` to `b` heading `db` (unit
/// directions): its control arms are 0.39 of the chord.
pub fn bezier_controls(a: Vec2, da: Vec2, b: Vec2, db: Vec2) -> [Vec2; 4] {
    // a quarter circle of radius r has chord r·√2 and control arms of 0.552·r
    let arm = a.distance(b) * 0.39;
    [a, a + da * arm, b - db * arm, b]
}

/// A cubic Bézier curve from `a` (leaving along `da`) to `b` (arriving along `db`),
/// sampled four times a metre (at least 8 segments), on [`bezier_controls`].
pub fn bezier(a: Vec2, da: Vec2, b: Vec2, db: Vec2) -> Vec<Vec2> {
    let chord = a.distance(b);
    let [_, c1, c2, _] = bezier_controls(a, da, b, db);
    // four points a metre: within 5 mm of the curve on the tightest turns of a junction
    let n = ((chord * 4.0).ceil() as usize).clamp(8, 1600);
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let u = 1.0 - t;
            a * (u * u * u) + c1 * (3.0 * u * u * t) + c2 * (3.0 * u * t * t) + b * (t * t * t)
        })
        .collect()
}

/// A rectangle of `length` along its heading and `width` across, centred on its pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub pose: Pose,
    pub length: f64,
    pub width: f64,
}

impl Footprint {
    pub fn corners(&self) -> [Vec2; 4] {
        let f = Vec2::from_yaw(self.pose.yaw) * (self.length / 2.0);
        let l = Vec2::from_yaw(self.pose.yaw).left() * (self.width / 2.0);
        let c = self.pose.position;
        [c + f + l, c + f - l, c - f - l, c - f + l]
    }

    /// Whether the two rectangles share interior points (touching edges do not count).
    pub fn overlaps(&self, other: &Footprint) -> bool {
        let (a, b) = (self.corners(), other.corners());
        let axes = [
            Vec2::from_yaw(self.pose.yaw),
            Vec2::from_yaw(self.pose.yaw).left(),
            Vec2::from_yaw(other.pose.yaw),
            Vec2::from_yaw(other.pose.yaw).left(),
        ];
        axes.iter().all(|axis| {
            let (a0, a1) = extent(&a, *axis);
            let (b0, b1) = extent(&b, *axis);
            a0 < b1 - 1e-9 && b0 < a1 - 1e-9
        })
    }

    /// The distance between the rectangles: 0 when they overlap or touch.
    pub fn distance(&self, other: &Footprint) -> f64 {
        if self.overlaps(other) {
            return 0.0;
        }
        let (a, b) = (self.corners(), other.corners());
        let mut best = f64::INFINITY;
        for i in 0..4 {
            for j in 0..4 {
                best = best.min(point_segment(a[i], b[j], b[(j + 1) % 4]));
                best = best.min(point_segment(b[j], a[i], a[(i + 1) % 4]));
            }
        }
        best
    }
}

fn extent(corners: &[Vec2; 4], axis: Vec2) -> (f64, f64) {
    corners.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
        let p = c.dot(axis);
        (lo.min(p), hi.max(p))
    })
}

fn point_segment(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    let t = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t).distance(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// [`Path::locate`] (with `extend`) or [`Path::project`] over `first..=last` as a plain
    /// forward scan with exact distances: (arc, distance, side).
    fn scan(t: &Path, p: Vec2, first: usize, last: usize, extend: bool) -> (f64, f64, f64) {
        let n = t.points.len();
        let mut best = (f64::NAN, f64::INFINITY, 0.0);
        for i in first..=last {
            let (a, b) = (t.points[i], t.points[i + 1]);
            let ab = b - a;
            let mut u = (p - a).dot(ab) / ab.dot(ab);
            if !(extend && (i == 0 && u < 0.0 || i == n - 2 && u > 1.0)) {
                u = u.clamp(0.0, 1.0);
            }
            let d = (a + ab * u).distance(p);
            if d < best.1 {
                best = (t.arcs[i] + u * (t.arcs[i + 1] - t.arcs[i]), d, ab.cross(p - a));
            }
        }
        best
    }

    #[test]
    fn projections_give_what_a_forward_scan_gives() {
        // a lane sampled every metre, a hairpin that comes back beside itself, a vee with a
        // point equally near both arms; points on the paths and far off them
        let lane = Path::new((0..=400).map(|k| Vec2::new(k as f64 - 200.0, -5.25)));
        let hairpin = Path::new(
            (0..=60)
                .map(|k| Vec2::new(k as f64, 0.0))
                .chain((1..=30).map(|k| Vec2::from_yaw(-FRAC_PI_2 + k as f64 * 0.1047) * 3.0 + Vec2::new(60.0, 3.0)))
                .chain((0..=60).rev().map(|k| Vec2::new(k as f64, 6.0))),
        );
        let vee = Path::new([Vec2::new(-10.0, 10.0), Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)]);
        let diagonal = Path::new((0..=300).map(|k| Vec2::from_yaw(0.5) * k as f64 + Vec2::new(-100.0, -7.0)));
        let bits = |(s, d): (f64, f64)| (s.to_bits(), d.to_bits());
        let mut checked = 0;
        for path in [&lane, &hairpin, &vee, &diagonal] {
            let n = path.points.len();
            for k in 0..2000 {
                let x = (k as f64 * 0.37).sin() * 90.0 + 30.0;
                let y = (k as f64 * 0.91).cos() * 12.0 + 3.0;
                let p = if k % 7 == 0 { Vec2::new(0.0, 5.0) } else { Vec2::new(x, y) };
                let (s0, d0, _) = scan(path, p, 0, n - 2, false);
                assert_eq!(bits(path.project(p)), bits((s0, d0)), "project {p:?}");
                for (hint, window) in
                    [(k as f64 * 0.2 - 100.0, 8.0), (50.0, 30.0), (path.length() / 2.0, path.length())]
                {
                    assert_eq!(bits(path.project_from(p, hint)), bits((s0, d0)), "project {p:?} from {hint}");
                    let (first, last) = (path.segment(hint - window), path.segment(hint + window));
                    let (s1, d1, side) = scan(path, p, first, last, true);
                    let d1 = if side < 0.0 { -d1 } else { d1 };
                    assert_eq!(bits(path.locate(p, hint, window)), bits((s1, d1)), "{p:?} hint {hint} window {window}");
                    for reach in [0.5, 3.0, d1.abs(), 20.0] {
                        match path.nearest(p, hint, window, reach) {
                            Some(found) if d1.abs() <= reach => assert_eq!(bits(found), bits((s1, d1))),
                            Some((_, d)) => assert!(d.abs() > reach, "{p:?} {d} within {reach}, but {d1}"),
                            None => assert!(d1.abs() > reach, "{p:?} {d1} within {reach}, not found"),
                        }
                    }
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 24_000);
    }

    #[test]
    fn strips_and_windows_bound_their_stretch() {
        // a lane across the axes, a circle's arc, the hairpin of the test above
        let diagonal = Path::new((0..=300).map(|k| Vec2::from_yaw(0.5) * k as f64 + Vec2::new(3.0, -7.0)));
        let arc = Path::new((0..=300).map(|k| Vec2::from_yaw(k as f64 / 40.0) * 40.0));
        let hairpin = Path::new(
            (0..=60)
                .map(|k| Vec2::new(k as f64, 0.0))
                .chain((1..=30).map(|k| Vec2::from_yaw(-FRAC_PI_2 + k as f64 * 0.1047) * 3.0 + Vec2::new(60.0, 3.0)))
                .chain((0..=60).rev().map(|k| Vec2::new(k as f64, 6.0))),
        );
        let mut known = 0;
        for path in [&diagonal, &arc, &hairpin] {
            for k in 0..60 {
                let (from, to) = (k as f64 * 2.5 - 10.0, k as f64 * 2.5 + 60.0);
                let strip = path.strip(path.stretch(from, to));
                let window = path.window((from + to) / 2.0, 30.0);
                let turn = path.turn_within(&window);
                let (first, last) = (path.segment(from), path.segment(to) + 1);
                if strip.slack.is_finite() {
                    known += 1;
                    for i in first..=last {
                        for u in [0.0, 0.3, 1.0] {
                            let q = path.points[i] + (path.points[i + 1] - path.points[i]) * u;
                            assert!(strip.distance_from(q) <= 1e-9, "{q:?} off the strip {strip:?}");
                        }
                        let off = wrap(path.yaws[i] - strip.along.yaw()).abs();
                        assert!(off <= strip.turn + 1e-12, "segment {i} turns {off} > {}", strip.turn);
                    }
                }
                let yaw = path.pose((from + to) / 2.0).yaw;
                let (first, last) = (window.first.saturating_sub(1), (window.last + 1).min(path.points.len() - 2));
                for i in first..=last {
                    let off = wrap(path.yaws[i] - yaw).abs();
                    assert!(off <= turn + 1e-12, "segment {i} turns {off} > {turn}");
                }
            }
        }
        // the straight lanes are known wherever the stretch stays off their ends, and thin
        assert!(known > 100, "{known}");
        let strip = diagonal.strip(diagonal.stretch(50.0, 120.0));
        assert!(strip.slack < 1e-9 && strip.turn < 1e-9, "{strip:?}");
    }

    #[test]
    fn paths_of_the_same_points_are_equal() {
        for points in [vec![], vec![Vec2::new(1.0, 2.0)], vec![Vec2::new(0.0, 0.0), Vec2::new(3.0, 4.0)]] {
            assert_eq!(Path::new(points.clone()), Path::new(points));
        }
        assert_eq!(Path::new([]), Path::default());
    }

    #[test]
    fn the_arcs_before_a_point_are_counted_as_a_bisection_counts_them() {
        let even = Path::new((0..=400).map(|k| Vec2::new(k as f64 - 200.0, 1.0)));
        let uneven = Path::new((0..=100).map(|k| Vec2::new((k * k) as f64 / 50.0, 0.0)));
        let two = Path::new([Vec2::new(0.0, 0.0), Vec2::new(5.0, 0.0)]);
        for t in [&even, &uneven, &two] {
            let extra = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, t.length(), 1.0];
            for s in (-50..=4500).map(|k| k as f64 * 0.1003 - 2.0).chain(extra) {
                assert_eq!(t.arcs_upto(s), t.arcs.partition_point(|&a| a <= s), "{s}");
            }
        }
    }

    #[test]
    fn locate_is_signed_local_and_extrapolates() {
        let t = Path::new([Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0), Vec2::new(10.0, 10.0)]);
        let (s, d) = t.locate(Vec2::new(5.0, 1.0), 5.0, 3.0);
        assert!((s - 5.0).abs() < 1e-9 && (d - 1.0).abs() < 1e-9);
        let (s, d) = t.locate(Vec2::new(11.0, 5.0), 15.0, 3.0);
        assert!((s - 15.0).abs() < 1e-9 && (d + 1.0).abs() < 1e-9, "right of the path: {d}");
        let (s, d) = t.locate(Vec2::new(-4.0, 0.0), 0.0, 2.0);
        assert!((s + 4.0).abs() < 1e-9 && d.abs() < 1e-9, "beyond the start it goes on straight");
        // only near the hint: the far leg is not searched
        let (s, _) = t.locate(Vec2::new(10.5, 9.0), 2.0, 2.0);
        assert!((s - 10.0).abs() < 1e-9, "the end of the first leg, not 19 m on the second: {s}");
    }

    fn boxed(x: f64, y: f64, yaw: f64, length: f64, width: f64) -> Footprint {
        Footprint { pose: Pose { position: Vec2::new(x, y), yaw }, length, width }
    }

    #[test]
    fn boxes_overlap_by_their_rotated_sides() {
        let car = boxed(0.0, 0.0, 0.0, 4.0, 2.0);
        assert!(car.overlaps(&boxed(3.9, 0.0, 0.0, 4.0, 2.0)));
        assert!(!car.overlaps(&boxed(4.1, 0.0, 0.0, 4.0, 2.0)));
        assert!((car.distance(&boxed(5.0, 0.0, 0.0, 4.0, 2.0)) - 1.0).abs() < 1e-9);
        // a box turned 45° whose corner reaches into the car
        let turned = boxed(2.0 + 1.0, 0.0, std::f64::consts::FRAC_PI_4, 2.0, 2.0);
        assert!(turned.overlaps(&car), "corner at x = {}", 3.0 - 2f64.sqrt());
        // across, beside it
        let across = boxed(0.0, 2.6, FRAC_PI_2, 1.0, 0.6);
        assert!(!car.overlaps(&across));
        assert!((car.distance(&across) - 1.1).abs() < 1e-9);
    }

    #[test]
    fn paths_give_poses_and_projections() {
        let path = Path::new([Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0), Vec2::new(10.0, 10.0)]);
        assert_eq!(path.length(), 20.0);
        let p = path.pose(15.0);
        assert!((p.position.y - 5.0).abs() < 1e-9 && (p.yaw - FRAC_PI_2).abs() < 1e-9);
        let before = path.pose(-5.0);
        assert!((before.position.x + 5.0).abs() < 1e-9);
        let (s, d) = path.project(Vec2::new(4.0, 2.0));
        assert!((s - 4.0).abs() < 1e-9 && (d - 2.0).abs() < 1e-9);
        let other = Path::new([Vec2::new(5.0, -5.0), Vec2::new(5.0, 5.0)]);
        let (s, _) = path.first_within(&other, 1.0, 0.5).unwrap();
        assert!((s - 4.0).abs() < 1e-9);
        assert!(Path::new([Vec2::new(1.0, 1.0)]).pose(3.0).position == Vec2::new(1.0, 1.0));
        // moved left of its direction: up on the first leg, left (−x) on the second
        let left = path.offset(2.0);
        assert_eq!(left.points()[0], Vec2::new(0.0, 2.0));
        assert_eq!(left.points()[2], Vec2::new(8.0, 10.0));
    }

    #[test]
    fn wrap_keeps_angles_in_one_turn() {
        assert!((wrap(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-9);
        assert!((wrap(-FRAC_PI_2 - std::f64::consts::TAU) + FRAC_PI_2).abs() < 1e-9);
    }
}
