//! Plane geometry of footprints: oriented rectangles, whether two overlap (separating axis
//! theorem) and how far apart they are (distance between two convex polygons).
//!
//! Headings follow Scenic: radians, counter-clockwise from north (the +y axis), so a
//! footprint of heading `h` faces `(-sin h, cos h)`.

/// A point or vector of the plane.
pub type Point = [f64; 2];

/// How deep two shapes must interpenetrate to overlap: touching (and rounding noise) is not
/// an overlap.
pub const OVERLAP_TOLERANCE: f64 = 1e-9;

/// An object's footprint: a rectangle `length` long (along its heading) and `width` wide,
/// centred on `(x, y)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    pub x: f64,
    pub y: f64,
    /// Radians, counter-clockwise from +y (Scenic's convention).
    pub heading: f64,
    pub length: f64,
    pub width: f64,
}

impl Footprint {
    pub fn new(x: f64, y: f64, heading: f64, length: f64, width: f64) -> Self {
        Footprint { x, y, heading, length, width }
    }

    /// The unit vector the footprint faces.
    pub fn forward(&self) -> Point {
        [-self.heading.sin(), self.heading.cos()]
    }

    /// The unit vector to its left.
    pub fn left(&self) -> Point {
        [-self.heading.cos(), -self.heading.sin()]
    }

    /// Its corners, counter-clockwise: front left, rear left, rear right, front right.
    pub fn corners(&self) -> [Point; 4] {
        let [fx, fy] = self.forward();
        let [lx, ly] = self.left();
        let (hl, hw) = (self.length / 2.0, self.width / 2.0);
        let at = |f: f64, l: f64| [self.x + fx * f + lx * l, self.y + fy * f + ly * l];
        [at(hl, hw), at(-hl, hw), at(-hl, -hw), at(hl, -hw)]
    }

    /// Whether the two footprints overlap (more than touch).
    pub fn overlaps(&self, other: &Footprint) -> bool {
        polygons_overlap(&self.corners(), &other.corners())
    }

    /// The distance between the two footprints: 0 when they touch or overlap.
    pub fn distance(&self, other: &Footprint) -> f64 {
        polygon_distance(&self.corners(), &other.corners())
    }
}

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The interval a polygon covers along `axis`.
fn project(polygon: &[Point], axis: Point) -> (f64, f64) {
    polygon.iter().map(|&p| dot(p, axis)).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| (lo.min(d), hi.max(d)))
}

/// The edge normals of a polygon (not normalised; zero-length edges skipped).
fn normals(polygon: &[Point]) -> impl Iterator<Item = Point> + '_ {
    (0..polygon.len()).filter_map(move |i| {
        let [dx, dy] = sub(polygon[(i + 1) % polygon.len()], polygon[i]);
        let norm = dx.hypot(dy);
        (norm > 0.0).then(|| [-dy / norm, dx / norm])
    })
}

/// Whether two convex polygons (vertices in order, either orientation) overlap by more than
/// [`OVERLAP_TOLERANCE`]: the separating axis theorem over both polygons' edge normals.
pub fn polygons_overlap(a: &[Point], b: &[Point]) -> bool {
    if a.is_empty() || b.is_empty() {
        return false;
    }
    normals(a).chain(normals(b)).all(|axis| {
        let (a_lo, a_hi) = project(a, axis);
        let (b_lo, b_hi) = project(b, axis);
        a_hi.min(b_hi) - a_lo.max(b_lo) > OVERLAP_TOLERANCE
    })
}

/// The distance from point `p` to the segment `a`–`b`.
pub fn point_segment_distance(p: Point, a: Point, b: Point) -> f64 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 { (dot(ap, ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    let closest = [a[0] + ab[0] * t, a[1] + ab[1] * t];
    let [dx, dy] = sub(p, closest);
    dx.hypot(dy)
}

/// The distance between two convex polygons: 0 when they overlap or touch, else the least
/// distance from a vertex of one to an edge of the other (for disjoint convex polygons the
/// closest pair of points always has a vertex in it).
pub fn polygon_distance(a: &[Point], b: &[Point]) -> f64 {
    if polygons_overlap(a, b) {
        return 0.0;
    }
    let one_way = |from: &[Point], to: &[Point]| {
        from.iter()
            .flat_map(|&p| (0..to.len()).map(move |i| point_segment_distance(p, to[i], to[(i + 1) % to.len()])))
            .fold(f64::INFINITY, f64::min)
    };
    one_way(a, b).min(one_way(b, a))
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    fn car(x: f64, y: f64, heading: f64) -> Footprint {
        Footprint::new(x, y, heading, 4.0, 2.0)
    }

    #[test]
    fn corners_follow_scenic_headings() {
        // heading 0 faces +y: the front corners have y = +2 (half the length)
        let c = car(0.0, 0.0, 0.0).corners();
        assert!(close(c[0][0], -1.0) && close(c[0][1], 2.0), "{c:?}");
        assert!(close(c[2][0], 1.0) && close(c[2][1], -2.0), "{c:?}");
        // heading pi/2 faces -x (counter-clockwise from north)
        let f = car(0.0, 0.0, FRAC_PI_2).forward();
        assert!(close(f[0], -1.0) && close(f[1], 0.0), "{f:?}");
        let c = car(0.0, 0.0, FRAC_PI_2).corners();
        assert!(close(c[0][0], -2.0) && close(c[0][1], -1.0), "{c:?}");
    }

    #[test]
    fn axis_aligned_boxes() {
        let a = car(0.0, 0.0, 0.0);
        assert!(a.overlaps(&car(1.0, 1.0, 0.0)));
        assert!(a.overlaps(&a));
        // side by side, 1 m apart (widths 2: centres 3 m apart)
        let b = car(3.0, 0.0, 0.0);
        assert!(!a.overlaps(&b));
        assert!(close(a.distance(&b), 1.0));
        // one behind the other, 0.5 m apart
        let c = car(0.0, -4.5, 0.0);
        assert!(!a.overlaps(&c));
        assert!(close(a.distance(&c), 0.5));
        // diagonally apart: corner to corner
        let d = car(5.0, 7.0, 0.0);
        assert!(close(a.distance(&d), (3.0f64 * 3.0 + 3.0 * 3.0).sqrt()));
    }

    #[test]
    fn touching_is_not_overlapping_and_is_at_distance_zero() {
        let a = car(0.0, 0.0, 0.0);
        let b = car(2.0, 0.0, 0.0);
        assert!(!a.overlaps(&b));
        assert!(close(a.distance(&b), 0.0));
        // a heading of pi is the same rectangle
        assert!(!a.overlaps(&car(2.0, 0.0, PI)));
    }

    #[test]
    fn rotated_boxes() {
        let a = car(0.0, 0.0, 0.0);
        // crosswise through the middle
        assert!(a.overlaps(&car(0.0, 0.0, FRAC_PI_2)));
        // a box turned 45° whose corner pokes into `a`'s side: its centre 2.5 m to the
        // right, its half-diagonal (in x) is (2 + 1) / √2 ≈ 2.12, so it reaches x ≈ 0.38 < 1
        let b = car(2.5, 0.0, FRAC_PI_4);
        assert!(a.overlaps(&b));
        // the same box 4 m away reaches x ≈ 1.88: 0.88 m from `a`'s side
        let c = car(4.0, 0.0, FRAC_PI_4);
        assert!(!a.overlaps(&c));
        assert!(close(a.distance(&c), 4.0 - 3.0 / 2f64.sqrt() - 1.0), "{}", a.distance(&c));
        // two 45° boxes whose bounding boxes overlap but which do not: the separating axis
        // is an edge normal of the rotated boxes, not x or y
        let d = car(0.0, 0.0, FRAC_PI_4);
        let e = car(1.8, 1.8, FRAC_PI_4);
        assert!(!d.overlaps(&e));
        let along = 1.8 * 2f64.sqrt(); // distance of the centres along their common side axis
        assert!(close(d.distance(&e), along - 2.0), "{}", d.distance(&e));
        // ... and the same ones turned the other way overlap
        assert!(d.overlaps(&car(1.8, 1.8, -FRAC_PI_4)));
    }

    #[test]
    fn distance_is_symmetric_and_zero_inside() {
        let a = Footprint::new(10.0, -3.0, 0.3, 4.5, 1.8);
        let b = Footprint::new(14.0, 1.0, 2.0, 7.5, 2.5);
        assert!(close(a.distance(&b), b.distance(&a)));
        let small = Footprint::new(10.0, -3.0, 1.0, 0.5, 0.5);
        assert!(a.overlaps(&small) && small.overlaps(&a));
        assert_eq!(a.distance(&small), 0.0);
    }

    #[test]
    fn point_to_segment() {
        assert!(close(point_segment_distance([0.0, 1.0], [-1.0, 0.0], [1.0, 0.0]), 1.0));
        assert!(close(point_segment_distance([3.0, 4.0], [0.0, 0.0], [0.0, 0.0]), 5.0));
        assert!(close(point_segment_distance([2.0, 1.0], [-1.0, 0.0], [1.0, 0.0]), 2f64.sqrt()));
    }
}
