//! Top-down pictures of a simulated scenario: an SVG figure ([`svg()`]), an animated GIF
//! ([`gif()`]) of the same view, and a PNG of the GIF's last frame ([`png()`]).
//!
//! The input is plain data ([`Scene`]): the layout's abstract road, what each actor is, and
//! one [`Frame`] of poses and light states per simulation step. Nothing here knows the
//! runtime; whoever simulates fills a `Scene`. Both pictures are built from one list of
//! shapes in metres (`map`: the road; `view`: the window onto it, fitted to where things
//! happen), then written as SVG elements or rasterised; the SVG's labels are placed apart
//! and inside the map by `label`, the GIF's text set in `font`'s bitmap; colours and sizes
//! come from [`palette`] only.
//!
//! Rendering is total: missing poses, non-finite numbers, empty scenes and odd options give
//! a picture (perhaps an empty road), never a panic. The SVG's numbers have fixed precision,
//! so the same scene gives the same bytes; so does the GIF.

mod anim;
mod font;
mod label;
mod map;
pub mod palette;
mod svg;
mod view;

#[cfg(test)]
mod tests;

pub use anim::{gif, png};
pub use svg::svg;
pub use tad_road::{Arm, Road};

/// The kinds of picture, by the file extension that names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
    Gif,
}

impl Format {
    /// The format a path's extension names (any case); `None` for another one.
    pub fn of(path: &std::path::Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "svg" => Some(Format::Svg),
            "png" => Some(Format::Png),
            "gif" => Some(Format::Gif),
            _ => None,
        }
    }

    /// `scene` drawn in this format.
    pub fn draw(self, scene: &Scene) -> Vec<u8> {
        match self {
            Format::Svg => svg(scene).into_bytes(),
            Format::Png => png(scene, GifOptions::default()),
            Format::Gif => gif(scene, GifOptions::default()),
        }
    }
}

/// A simulated scenario to draw.
#[derive(Clone, Debug)]
pub struct Scene<'a> {
    pub road: &'a Road,
    /// Shown above the picture, e.g. `red_light_running · seed 3 · ego idm`.
    pub title: String,
    /// What each actor is; index 0 is the ego.
    pub actors: Vec<ActorInfo>,
    /// One per simulation step, [`Scene::dt`] apart.
    pub frames: Vec<Frame>,
    /// The step, s.
    pub dt: f64,
    /// The ego's route, a polyline in the road's frame, m.
    pub route: Vec<[f64; 2]>,
    pub events: Vec<Event>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ActorInfo {
    pub label: String,
    pub kind: Kind,
    /// Along its heading, m.
    pub length: f64,
    /// Across it, m.
    pub width: f64,
}

/// What an actor is drawn as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    Ego,
    Vehicle,
    Walker,
    Animal,
    Object,
}

impl Kind {
    pub const ALL: [Kind; 5] = [Kind::Ego, Kind::Vehicle, Kind::Walker, Kind::Animal, Kind::Object];
}

/// The world at one step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Per actor (by index): `[x, y, yaw]` (m, m, rad counter-clockwise from `+x`); `None`
    /// while it is not in the world. Missing entries count as `None`.
    pub poses: Vec<Option<[f64; 3]>>,
    /// What the light on each arm shows, at its stop line.
    pub lights: Vec<(Arm, Light)>,
}

/// What a traffic light shows (`tad_ir::Signal`, the workspace's one light state).
pub use tad_ir::Signal as Light;

/// The lights in the order the legend lists them.
pub const LIGHTS: [Light; 4] = [Light::Green, Light::Yellow, Light::Red, Light::Off];

/// Something that happened: a collision, a red light run, a lane invasion…
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// The frame it happened at.
    pub step: usize,
    /// Where, m.
    pub position: [f64; 2],
    pub label: String,
}

/// How to animate: the picture's width in pixels (at least [`palette::GIF_MIN_WIDTH`]) and
/// height (0: as the view's aspect asks), every how many frames one is drawn, and how many
/// are shown per second.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GifOptions {
    pub width: u32,
    pub height: u32,
    pub every: usize,
    pub fps: u32,
}

impl Default for GifOptions {
    fn default() -> GifOptions {
        GifOptions { width: palette::GIF_WIDTH, height: 0, every: 2, fps: 10 }
    }
}

impl Scene<'_> {
    /// The actor's pose at a frame, if it is present there with finite numbers.
    fn pose(&self, frame: usize, actor: usize) -> Option<[f64; 3]> {
        let p = (*self.frames.get(frame)?.poses.get(actor)?)?;
        p.iter().all(|v| v.is_finite()).then_some(p)
    }

    /// The actor's size, made finite and at least [`palette::MIN_BODY`].
    fn size(&self, actor: usize) -> (f64, f64) {
        let a = &self.actors[actor];
        let fix = |v: f64| if v.is_finite() { v.max(palette::MIN_BODY) } else { palette::MIN_BODY };
        (fix(a.length), fix(a.width))
    }

    /// How an actor is drawn: index 0 is the ego, whatever its kind says.
    fn kind(&self, actor: usize) -> Kind {
        if actor == 0 { Kind::Ego } else { self.actors[actor].kind }
    }

    /// The step, or 0 when it is not a positive finite number.
    fn step(&self) -> f64 {
        if self.dt.is_finite() && self.dt > 0.0 { self.dt } else { 0.0 }
    }
}
