//! The window onto the road: what the picture shows and how metres become pixels.
//!
//! The road runs [`tad_road::road::RUN`] metres each way, far more than a scenario uses,
//! so the window is fitted to where things happen: the ego's whole drive, the events, and
//! every other actor while it is within [`NEAR_EGO`] m of the ego (so a parked van beside
//! the ego's lane counts, an oncoming car's approach from 150 m away does not; what leaves
//! the window is clipped at its edge), and the junction when it is near; plus
//! [`palette::MARGIN`] and at least [`palette::MIN_VIEW`] metres each way. A scene without
//! an ego is fitted to every actor that moved, else to every actor; an empty one to the
//! origin. Pixels have `y` down, so the road's `y` (to the left of `x`) is flipped.

use crate::{Scene, palette};
use tad_road::geom::{Footprint, Pose, Vec2};

/// Actors that moved less than this are "static" for the window, m.
const MOVED: f64 = 0.5;
/// Another actor is in the window while it is this near the ego, m.
pub const NEAR_EGO: f64 = 20.0;
/// A junction whose box is nearer than this to what moved is shown whole, m.
const JUNCTION_NEAR: f64 = 40.0;

/// A rectangle in the road's frame, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: Vec2,
    pub max: Vec2,
}

impl Bounds {
    fn around(points: impl IntoIterator<Item = Vec2>) -> Option<Bounds> {
        points.into_iter().filter(|p| p.x.is_finite() && p.y.is_finite()).fold(None, |b, p| {
            Some(match b {
                None => Bounds { min: p, max: p },
                Some(b) => Bounds {
                    min: Vec2::new(b.min.x.min(p.x), b.min.y.min(p.y)),
                    max: Vec2::new(b.max.x.max(p.x), b.max.y.max(p.y)),
                },
            })
        })
    }

    pub fn width(&self) -> f64 {
        self.max.x - self.min.x
    }

    pub fn height(&self) -> f64 {
        self.max.y - self.min.y
    }

    pub fn centre(&self) -> Vec2 {
        (self.min + self.max) * 0.5
    }

    pub fn grown(&self, by: f64) -> Bounds {
        Bounds { min: self.min - Vec2::new(by, by), max: self.max + Vec2::new(by, by) }
    }

    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// The distance from a point to the rectangle (0 inside).
    fn distance(&self, p: Vec2) -> f64 {
        let dx = (self.min.x - p.x).max(p.x - self.max.x).max(0.0);
        let dy = (self.min.y - p.y).max(p.y - self.max.y).max(0.0);
        dx.hypot(dy)
    }

    /// Grown about its centre to at least `w` × `h`.
    pub fn at_least(&self, w: f64, h: f64) -> Bounds {
        let c = self.centre();
        let (hw, hh) = (self.width().max(w) / 2.0, self.height().max(h) / 2.0);
        Bounds { min: c - Vec2::new(hw, hh), max: c + Vec2::new(hw, hh) }
    }
}

/// The rectangle the pictures show: see the module's header.
pub fn focus(scene: &Scene) -> Bounds {
    let n = scene.actors.len();
    let ego: Vec<Option<[f64; 3]>> = (0..scene.frames.len()).map(|f| scene.pose(f, 0)).collect();
    let mut near = if n > 0 { corners_of(scene, 0, |_| true) } else { Vec::new() };
    let mut moving = Vec::new();
    let mut everyone = Vec::new();
    for actor in 1..n {
        let close = |f: usize| {
            let (Some(e), Some(p)) = (ego[f], scene.pose(f, actor)) else { return false };
            (e[0] - p[0]).hypot(e[1] - p[1]) < NEAR_EGO
        };
        near.extend(corners_of(scene, actor, close));
        let positions: Vec<Vec2> =
            (0..scene.frames.len()).filter_map(|f| scene.pose(f, actor)).map(|[x, y, _]| Vec2::new(x, y)).collect();
        let corners = corners_of(scene, actor, |_| true);
        if positions.first().is_some_and(|a| positions.iter().any(|p| p.distance(*a) > MOVED)) {
            moving.extend(corners.iter().copied());
        }
        everyone.extend(corners);
    }
    let events: Vec<Vec2> = scene.events.iter().map(|e| Vec2::new(e.position[0], e.position[1])).collect();
    let core = if n > 0 && ego.iter().any(Option::is_some) {
        Bounds::around(near.into_iter().chain(events))
    } else {
        Bounds::around(moving.into_iter().chain(events.iter().copied())).or_else(|| Bounds::around(everyone))
    };
    let core = core.unwrap_or(Bounds { min: Vec2::default(), max: Vec2::default() });
    let mut bounds = core;
    if let Some(j) = &scene.road.junction {
        let c = scene.road.centre();
        if core.distance(c) < JUNCTION_NEAR + j.half {
            let h = j.half;
            let corners = [Vec2::new(-h, -h), Vec2::new(h, h)].map(|d| c + d);
            bounds = Bounds::around([bounds.min, bounds.max].into_iter().chain(corners)).unwrap_or(bounds);
        }
    }
    bounds.grown(palette::MARGIN).at_least(palette::MIN_VIEW, palette::MIN_VIEW)
}

/// Every corner of an actor's body at each frame it is present and `when` holds.
fn corners_of(scene: &Scene, actor: usize, when: impl Fn(usize) -> bool) -> Vec<Vec2> {
    let (length, width) = scene.size(actor);
    (0..scene.frames.len())
        .filter(|&f| when(f))
        .filter_map(|f| scene.pose(f, actor))
        .flat_map(|p| body(p, length, width).corners())
        .collect()
}

/// An actor's rectangle at a pose.
pub fn body([x, y, yaw]: [f64; 3], length: f64, width: f64) -> Footprint {
    Footprint { pose: Pose { position: Vec2::new(x, y), yaw }, length, width }
}

/// Metres to pixels: `bounds` drawn `scale` pixels a metre with its top-left corner at
/// `(left, top)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub bounds: Bounds,
    pub scale: f64,
    pub left: f64,
    pub top: f64,
}

impl View {
    /// `bounds` fitted into a box of `w` × `h` pixels at `(left, top)`, grown about its
    /// centre to the box's aspect.
    pub fn fit(bounds: Bounds, left: f64, top: f64, w: f64, h: f64) -> View {
        let scale = (w / bounds.width().max(1e-6)).min(h / bounds.height().max(1e-6));
        let bounds = bounds.at_least(w / scale, h / scale);
        View { bounds, scale, left, top }
    }

    pub fn px(&self, p: Vec2) -> (f64, f64) {
        (self.left + (p.x - self.bounds.min.x) * self.scale, self.top + (self.bounds.max.y - p.y) * self.scale)
    }

    pub fn width(&self) -> f64 {
        self.bounds.width() * self.scale
    }

    pub fn height(&self) -> f64 {
        self.bounds.height() * self.scale
    }
}
