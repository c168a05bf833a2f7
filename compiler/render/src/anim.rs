//! The animated GIF: the SVG's view fitted to the picture, one frame every `every` steps
//! and one of the last step.
//!
//! The road (and the route) is rasterised once with `tiny-skia`; each frame copies it and
//! adds the lights' current colours, the events that have happened, every actor present as
//! a filled rotated rectangle (dark at its front) in its kind's colour, the time (`t = 4.2
//! s`, in the built-in bitmap font of `font`) and a progress bar. Drawing without
//! anti-aliasing keeps every pixel in the palette's colours, so frames index the GIF's one
//! global colour table exactly. Each frame after the first holds only the rectangle that
//! changed, unchanged pixels in it transparent: a 300-step episode at every second step is
//! a few hundred kilobytes. The last frame is held a little longer.

use crate::map::{self, Item};
use crate::palette::{self, Colour};
use crate::view::{self, View};
use crate::{GifOptions, Scene};
use std::collections::HashMap;
use tad_road::geom::Vec2;
use tiny_skia::{FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform};

/// The largest picture drawn, px a side.
const MAX_SIDE: u32 = 4096;
/// How long the last frame stays, s.
const HOLD: f64 = 1.5;

/// The animation of a scene: see the module's header.
pub fn gif(scene: &Scene, options: GifOptions) -> Vec<u8> {
    let (w, h) = size(options);
    let frames = frames(scene, options);
    let table = palette::all();
    let index: HashMap<Colour, u8> = table.iter().enumerate().map(|(i, c)| (*c, i as u8)).collect();
    let transparent = table.len() as u8;
    let mut flat: Vec<u8> = table.iter().flat_map(|c| [c.0, c.1, c.2]).collect();
    flat.extend([0xff, 0x00, 0xff]);
    let delay = (100.0 / options.fps.clamp(1, 50) as f64).round() as u16;
    let hold = delay.max((HOLD * 100.0) as u16);

    let mut out = Vec::new();
    let Ok(mut encoder) = ::gif::Encoder::new(&mut out, w as u16, h as u16, &flat) else { return Vec::new() };
    if encoder.set_repeat(::gif::Repeat::Infinite).is_err() {
        return Vec::new();
    }
    let mut previous: Option<Vec<u8>> = None;
    let count = frames.len();
    let mut nearest: HashMap<[u8; 3], u8> = HashMap::new();
    for (k, pixmap) in frames.into_iter().enumerate() {
        let indices: Vec<u8> = pixmap
            .pixels()
            .iter()
            .map(|p| {
                let c = [p.red(), p.green(), p.blue()];
                index
                    .get(&Colour(c[0], c[1], c[2]))
                    .copied()
                    .unwrap_or_else(|| *nearest.entry(c).or_insert_with(|| closest(&table, c)))
            })
            .collect();
        let mut frame = match &previous {
            None => {
                ::gif::Frame { width: w as u16, height: h as u16, buffer: indices.clone().into(), ..Default::default() }
            }
            Some(before) => changed(before, &indices, w, h, transparent),
        };
        frame.delay = if k + 1 == count { hold } else { delay };
        frame.dispose = ::gif::DisposalMethod::Keep;
        if encoder.write_frame(&frame).is_err() {
            return Vec::new();
        }
        previous = Some(indices);
    }
    drop(encoder);
    out
}

/// The picture's size, clamped to what a GIF holds.
fn size(options: GifOptions) -> (u32, u32) {
    (options.width.clamp(16, MAX_SIDE), options.height.clamp(16, MAX_SIDE))
}

/// The palette entry nearest a colour.
fn closest(table: &[Colour], c: [u8; 3]) -> u8 {
    let d = |t: &Colour| {
        let (r, g, b) = (t.0 as i32 - c[0] as i32, t.1 as i32 - c[1] as i32, t.2 as i32 - c[2] as i32);
        r * r + g * g + b * b
    };
    table.iter().enumerate().min_by_key(|(_, t)| d(t)).map_or(0, |(i, _)| i as u8)
}

/// The part of `now` that differs from `before`, unchanged pixels in it transparent.
fn changed(before: &[u8], now: &[u8], w: u32, h: u32, transparent: u8) -> ::gif::Frame<'static> {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if before[i] != now[i] {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    if x0 > x1 {
        // nothing changed: one transparent pixel keeps the frame's time
        return ::gif::Frame {
            width: 1,
            height: 1,
            buffer: vec![transparent].into(),
            transparent: Some(transparent),
            ..Default::default()
        };
    }
    let mut buffer = Vec::with_capacity(((x1 - x0 + 1) * (y1 - y0 + 1)) as usize);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = (y * w + x) as usize;
            buffer.push(if before[i] == now[i] { transparent } else { now[i] });
        }
    }
    ::gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0 + 1) as u16,
        height: (y1 - y0 + 1) as u16,
        buffer: buffer.into(),
        transparent: Some(transparent),
        ..Default::default()
    }
}

/// The last frame of the animation as a PNG: where everything ended, the events that
/// happened, the time.
pub fn png(scene: &Scene, options: GifOptions) -> Vec<u8> {
    let last = GifOptions { every: usize::MAX, ..options };
    frames(scene, last).pop().and_then(|pixmap| pixmap.encode_png().ok()).unwrap_or_default()
}

/// The view the GIF shows.
pub fn view_of(scene: &Scene, options: GifOptions) -> View {
    let (w, h) = size(options);
    View::fit(view::focus(scene), 0.0, 0.0, w as f64, h as f64)
}

/// The steps drawn: every `every`th from the first, and the last.
pub fn steps(scene: &Scene, options: GifOptions) -> Vec<usize> {
    let n = scene.frames.len();
    let mut steps: Vec<usize> = (0..n).step_by(options.every.max(1)).collect();
    if n > 0 && steps.last() != Some(&(n - 1)) {
        steps.push(n - 1);
    }
    steps
}

/// Every frame of the animation as pixels; a scene without frames gives one of the road.
/// Bodies are drawn at least [`palette::GIF_MIN_BODY_PX`] a side, so walkers seen from
/// afar stay visible.
pub fn frames(scene: &Scene, options: GifOptions) -> Vec<Pixmap> {
    let (w, h) = size(options);
    let view = view_of(scene, options);
    let Some(mut ground) = Pixmap::new(w, h) else { return Vec::new() };
    let mut r = Raster { pixmap: &mut ground, view };
    r.pixmap.fill(colour(palette::BACKGROUND));
    let map = map::draw(scene, &view.bounds);
    for item in &map.items {
        r.item(item);
    }
    let route: Vec<Vec2> =
        scene.route.iter().map(|p| Vec2::new(p[0], p[1])).filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    r.line(&route, palette::ROUTE, palette::ROUTE_WIDTH, Some(palette::ROUTE_DASH));

    let steps = steps(scene, options);
    let total = scene.frames.len().saturating_sub(1).max(1);
    let mut out = Vec::new();
    for &step in steps.iter().chain(steps.is_empty().then_some(&0)) {
        let mut pixmap = ground.clone();
        let mut r = Raster { pixmap: &mut pixmap, view };
        if let Some(frame) = scene.frames.get(step) {
            for &(arm, p) in &map.signals {
                if let Some((_, light)) = frame.lights.iter().find(|(a, _)| *a == arm) {
                    r.disc(p, palette::SIGNAL_RADIUS * 1.3, palette::INK);
                    r.disc(p, palette::SIGNAL_RADIUS, palette::light(*light));
                }
            }
        }
        for e in scene.events.iter().filter(|e| e.step <= step) {
            let p = Vec2::new(e.position[0], e.position[1]);
            let s = palette::EVENT_RADIUS;
            let diamond = |s: f64| {
                vec![p + Vec2::new(s, 0.0), p + Vec2::new(0.0, s), p - Vec2::new(s, 0.0), p - Vec2::new(0.0, s)]
            };
            r.area(&diamond(s * 1.25), palette::EVENT_EDGE);
            r.area(&diamond(s), palette::EVENT);
        }
        // the ego last, on top
        for a in (1..scene.actors.len()).chain((!scene.actors.is_empty()).then_some(0)) {
            let Some(pose) = scene.pose(step, a) else { continue };
            let least = palette::GIF_MIN_BODY_PX / view.scale;
            let (length, width) = scene.size(a);
            let (length, width) = (length.max(least), width.max(least));
            let style = palette::kind(scene.kind(a));
            let body = view::body(pose, length, width);
            r.area(&body.corners(), style.fill);
            r.area(&crate::svg::front(&body), style.dark);
        }
        let dt = scene.step();
        let label = if dt > 0.0 { format!("t = {:.1} s", step as f64 * dt) } else { format!("{step}") };
        r.label(&label);
        r.progress(step as f64 / total as f64);
        out.push(pixmap);
    }
    out
}

fn colour(c: Colour) -> tiny_skia::Color {
    tiny_skia::Color::from_rgba8(c.0, c.1, c.2, 255)
}

fn paint(c: Colour) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(colour(c));
    paint.anti_alias = false;
    paint
}

struct Raster<'p> {
    pixmap: &'p mut Pixmap,
    view: View,
}

impl Raster<'_> {
    fn path(&self, points: &[Vec2], close: bool) -> Option<tiny_skia::Path> {
        let mut pb = PathBuilder::new();
        for (i, p) in points.iter().enumerate() {
            let (x, y) = self.view.px(*p);
            if !(x.is_finite() && y.is_finite()) {
                return None;
            }
            // far outside the picture the rasteriser gains nothing from precision
            let (x, y) = (x.clamp(-1e5, 1e5) as f32, y.clamp(-1e5, 1e5) as f32);
            if i == 0 { pb.move_to(x, y) } else { pb.line_to(x, y) }
        }
        if close {
            pb.close();
        }
        pb.finish()
    }

    fn area(&mut self, points: &[Vec2], c: Colour) {
        if let Some(path) = self.path(points, true) {
            self.pixmap.fill_path(&path, &paint(c), FillRule::Winding, Transform::identity(), None);
        }
    }

    fn line(&mut self, points: &[Vec2], c: Colour, width: f64, dash: Option<(f64, f64)>) {
        let Some(path) = self.path(points, false) else { return };
        let s = self.view.scale as f32;
        let mut stroke = Stroke {
            width: (width as f32 * s).max(palette::GIF_MIN_PX),
            line_cap: LineCap::Butt,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        if let Some((a, b)) = dash {
            stroke.dash = StrokeDash::new(vec![(a as f32 * s).max(1.0), (b as f32 * s).max(1.0)], 0.0);
        }
        self.pixmap.stroke_path(&path, &paint(c), &stroke, Transform::identity(), None);
    }

    fn disc(&mut self, centre: Vec2, radius: f64, c: Colour) {
        let (x, y) = self.view.px(centre);
        let r = (radius * self.view.scale).max(palette::GIF_MIN_PX as f64);
        if let Some(path) = PathBuilder::from_circle(x as f32, y as f32, r as f32) {
            self.pixmap.fill_path(&path, &paint(c), FillRule::Winding, Transform::identity(), None);
        }
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Area { points, colour, .. } => self.area(points, *colour),
            Item::Line { points, colour, width, dash, .. } => self.line(points, *colour, *width, *dash),
            Item::Disc { centre, radius, colour, .. } => self.disc(*centre, *radius, *colour),
        }
    }

    fn rect(&mut self, x: u32, y: u32, w: u32, h: u32, c: Colour) {
        if let Some(rect) = Rect::from_xywh(x as f32, y as f32, w as f32, h as f32) {
            self.pixmap.fill_rect(rect, &paint(c), Transform::identity(), None);
        }
    }

    /// Text in the top left corner, on paper.
    fn label(&mut self, text: &str) {
        let k = palette::GIF_FONT_SCALE;
        let pad = 3;
        self.rect(0, 0, crate::font::width(text) * k + 2 * pad, crate::font::HEIGHT * k + 2 * pad, palette::PAPER);
        for (x, y) in crate::font::pixels(text) {
            self.rect(pad + x * k, pad + y * k, k, k, palette::INK);
        }
    }

    /// A bar along the bottom edge, `done` of it filled.
    fn progress(&mut self, done: f64) {
        let (w, h) = (self.pixmap.width(), self.pixmap.height());
        let bar = palette::GIF_BAR_PX.min(h);
        self.rect(0, h - bar, w, bar, palette::PAPER);
        let filled = (done.clamp(0.0, 1.0) * w as f64).round() as u32;
        self.rect(0, h - bar, filled, bar, palette::ROUTE);
    }
}
