//! Label placement, in pixels: each label is put beside its anchor where it overlaps no
//! label placed before it, lies wholly inside the frame, and covers as little of the
//! obstacles (bodies, signals, event rings) as it can.
//!
//! Labels are placed greedily in the order given, so the important ones (events, then
//! actors, ego first) get the best places and the optional ones (time marks) take what is
//! left or are dropped. A label names a box (a body, a group of bodies, an event's ring, a
//! time tick) and tries eight positions round it (beside, above, below, and the four
//! diagonals) at growing distances; the first ring with a
//! position free of obstacles wins, else the position covering the least of them. A label
//! put further than [`LEADER`] px from its box gets a leader line back to it. Text is not
//! measured: its width is [`palette::CHAR_EM`] font sizes a character, wide enough for
//! the fonts a viewer substitutes for Helvetica. Everything is deterministic.

use crate::palette;

/// An axis-aligned rectangle, px (`y` down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub x: f64,
    pub y: f64,
    pub w: f64,
    pub h: f64,
}

impl Rect {
    /// The square of half-side `r` about a point.
    pub fn around((x, y): (f64, f64), r: f64) -> Rect {
        Rect { x: x - r, y: y - r, w: 2.0 * r, h: 2.0 * r }
    }

    /// The smallest rectangle holding the points; `None` without finite ones.
    pub fn bounding(points: impl IntoIterator<Item = (f64, f64)>) -> Option<Rect> {
        let mut b: Option<(f64, f64, f64, f64)> = None;
        for (x, y) in points.into_iter().filter(|(x, y)| x.is_finite() && y.is_finite()) {
            b = Some(b.map_or((x, y, x, y), |(a, c, d, e)| (a.min(x), c.min(y), d.max(x), e.max(y))));
        }
        b.map(|(x0, y0, x1, y1)| Rect { x: x0, y: y0, w: x1 - x0, h: y1 - y0 })
    }

    /// The area two rectangles share.
    pub fn overlap(&self, o: &Rect) -> f64 {
        let w = (self.x + self.w).min(o.x + o.w) - self.x.max(o.x);
        let h = (self.y + self.h).min(o.y + o.h) - self.y.max(o.y);
        if w > 0.0 && h > 0.0 { w * h } else { 0.0 }
    }

    pub fn inside(&self, o: &Rect) -> bool {
        self.x >= o.x && self.y >= o.y && self.x + self.w <= o.x + o.w && self.y + self.h <= o.y + o.h
    }

    pub fn grown(&self, by: f64) -> Rect {
        Rect { x: self.x - by, y: self.y - by, w: self.w + 2.0 * by, h: self.h + 2.0 * by }
    }

    /// The point of the rectangle nearest `p`.
    pub fn nearest(&self, (px, py): (f64, f64)) -> (f64, f64) {
        (px.clamp(self.x, self.x + self.w), py.clamp(self.y, self.y + self.h))
    }
}

/// A label to place: its text and size, the box it names, whether it may be dropped, and
/// the direction (px) of a line through the box that it should sit beside rather than on
/// (a time mark's trajectory).
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub text: String,
    pub font: f64,
    pub anchor: Rect,
    pub optional: bool,
    pub along: Option<(f64, f64)>,
}

/// Where a label went: its box, and whether it needs a leader line to its anchor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    pub rect: Rect,
    pub leader: bool,
}

/// Farther than this from its anchor, px, a label gets a leader line.
pub const LEADER: f64 = 14.0;
/// The gap kept between two labels, px.
const GAP: f64 = 6.0;
/// Distances from the named box, px: the first only for optional labels.
const RINGS: [f64; 12] = [2.0, 6.0, 11.0, 17.0, 24.0, 32.0, 42.0, 54.0, 68.0, 84.0, 102.0, 125.0];
/// Directions in order of preference: right-up, right-down, left-up, left-down, right,
/// left, up, down, then the sixteenth points between them. Each is scaled so that its
/// larger coordinate is 1: `(1, -1)` puts the label's corner at the box's, `(1, -0.5)`
/// beside the box and half-way up.
const DIRECTIONS: [(f64, f64); 16] = [
    (1.0, -1.0),
    (1.0, 1.0),
    (-1.0, -1.0),
    (-1.0, 1.0),
    (1.0, 0.0),
    (-1.0, 0.0),
    (0.0, -1.0),
    (0.0, 1.0),
    (1.0, -0.5),
    (1.0, 0.5),
    (-1.0, -0.5),
    (-1.0, 0.5),
    (0.5, -1.0),
    (-0.5, -1.0),
    (0.5, 1.0),
    (-0.5, 1.0),
];

/// A text's box, px: its estimated width and one line's height, with a little padding.
pub fn size(text: &str, font: f64) -> (f64, f64) {
    (text.chars().count() as f64 * font * palette::CHAR_EM + 4.0, font * 1.3)
}

/// The labels placed, one entry per request (`None`: dropped, or no anchor inside the
/// frame); see the module's header.
pub fn place(requests: &[Request], obstacles: &[Rect], frame: Rect) -> Vec<Option<Placed>> {
    let mut placed: Vec<Rect> = Vec::new();
    let mut out = Vec::with_capacity(requests.len());
    for r in requests {
        let b = r.anchor;
        let finite = [b.x, b.y, b.w, b.h, r.font].iter().all(|v| v.is_finite());
        let centre = (b.x + b.w / 2.0, b.y + b.h / 2.0);
        if !finite || !Rect::around(centre, 0.0).inside(&frame) {
            out.push(None);
            continue;
        }
        let (w, h) = size(&r.text, r.font.max(1.0));
        let rings = if r.optional { &RINGS[..1] } else { &RINGS[..] };
        let mut directions = DIRECTIONS;
        if let Some((ux, uy)) = r.along.filter(|(x, y)| x.is_finite() && y.is_finite() && x.hypot(*y) > 0.0) {
            // beside the line first: the least aligned with it
            let aligned = |(dx, dy): (f64, f64)| ((dx * ux + dy * uy) / (dx.hypot(dy) * ux.hypot(uy))).abs();
            directions.sort_by(|a, b| aligned(*a).total_cmp(&aligned(*b)));
        }
        let mut best: Option<(f64, Rect, f64)> = None;
        for &d in rings {
            for (k, &(dx, dy)) in directions.iter().enumerate() {
                // the label's centre, `d` px clear of the box along the direction
                let cx = centre.0 + dx * ((b.w + w) / 2.0 + d);
                let cy = centre.1 + dy * ((b.h + h) / 2.0 + d);
                let (x, y) = (cx - w / 2.0, cy - h / 2.0);
                let rect = Rect { x, y, w, h };
                if !rect.inside(&frame) || placed.iter().any(|p| p.grown(GAP).overlap(&rect) > 0.0) {
                    continue;
                }
                let covered: f64 = obstacles.iter().map(|o| o.overlap(&rect)).sum();
                if r.optional && covered > 0.0 {
                    continue;
                }
                let cost = covered + k as f64 * 1e-3;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, rect, d));
                }
            }
            if best.is_some_and(|(c, _, _)| c < 1.0) {
                break;
            }
        }
        match best {
            Some((_, rect, d)) => {
                placed.push(rect);
                out.push(Some(Placed { rect, leader: d > LEADER }));
            }
            None => out.push(None),
        }
    }
    out
}
