//! The animated GIF: a title band (the scene's title, and the time), the map fitted to the
//! same place as the SVG's, and a legend band (each kind of actor present in its colours,
//! events, lights, and a scale bar in metres); one frame every `every` steps and one of the
//! last step. It is [`palette::GIF_WIDTH`] pixels wide (at least
//! [`palette::GIF_MIN_WIDTH`]), as high as the view's aspect asks unless told a height.
//!
//! The road (and the route) is rasterised once with `tiny-skia`, the bands too; each frame
//! copies that and adds the lights' current colours, the events that have happened (hollow
//! rings), the ego's trail so far, every actor present as a filled rotated rectangle (dark
//! at its front) in its kind's colour, the ego last with a white halo, at least
//! [`palette::GIF_EGO_MIN_PX`] long and named, the time and a progress bar. Text is set in
//! `font`'s bitmap. Drawing without anti-aliasing keeps every pixel in the palette's
//! colours, so frames index the GIF's one global colour table exactly. Each frame after the
//! first holds only the rectangle that changed, unchanged pixels in it transparent, and is
//! encoded as soon as it is drawn: a 300-step episode at every second step is a few hundred
//! kilobytes. The last frame is held a little longer.

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
    let layout = layout(scene, options);
    let (w, h) = (layout.width, layout.height);
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
    let count = steps(scene, options).len().max(1);
    let mut nearest: HashMap<[u8; 3], u8> = HashMap::new();
    let mut failed = false;
    each_frame(scene, options, |k, pixmap| {
        if failed {
            return;
        }
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
        failed = encoder.write_frame(&frame).is_err();
        previous = Some(indices);
    });
    drop(encoder);
    if failed { Vec::new() } else { out }
}

/// Where the GIF's parts go: its size, px, the title band's and the legend band's height,
/// and the map's view between them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    pub width: u32,
    pub height: u32,
    pub band: u32,
    pub view: View,
}

/// The GIF's layout: `options.width` (at least [`palette::GIF_MIN_WIDTH`]) wide, and
/// `options.height` high, or (0) as high as the view's aspect asks.
pub fn layout(scene: &Scene, options: GifOptions) -> Layout {
    let width = options.width.clamp(palette::GIF_MIN_WIDTH, MAX_SIDE);
    let band = palette::GIF_BAND_PX;
    let focus = view::focus(scene);
    let aspect = (focus.width() / focus.height().max(1e-6)).clamp(1.0 / 1.25, palette::MAX_ASPECT);
    let map = if options.height == 0 {
        (width as f64 / aspect).round() as u32
    } else {
        options.height.saturating_sub(2 * band)
    };
    let map = map.clamp(16, MAX_SIDE - 2 * band);
    let view = View::fit(focus, 0.0, band as f64, width as f64, map as f64);
    Layout { width, height: map + 2 * band, band, view }
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
    let mut picture = None;
    each_frame(scene, last, |_, pixmap| picture = Some(pixmap));
    picture.and_then(|pixmap| pixmap.encode_png().ok()).unwrap_or_default()
}

/// The view the GIF's map shows.
#[cfg(test)]
pub fn view_of(scene: &Scene, options: GifOptions) -> View {
    layout(scene, options).view
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

/// Every frame of the animation as pixels (for tests; `gif` encodes each as it is drawn).
#[cfg(test)]
pub fn frames(scene: &Scene, options: GifOptions) -> Vec<Pixmap> {
    let mut out = Vec::new();
    each_frame(scene, options, |_, pixmap| out.push(pixmap));
    out
}

/// The picture without what changes: the bands, the road, the route.
fn ground(scene: &Scene, layout: &Layout) -> Option<(Pixmap, map::Map)> {
    let mut ground = Pixmap::new(layout.width, layout.height)?;
    let mut r = Raster { pixmap: &mut ground, view: layout.view };
    r.pixmap.fill(colour(palette::BACKGROUND));
    let map = map::draw(scene, &layout.view.bounds);
    for item in &map.items {
        r.item(item);
    }
    let route: Vec<Vec2> =
        scene.route.iter().map(|p| Vec2::new(p[0], p[1])).filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    r.line(&route, palette::ROUTE, palette::ROUTE_WIDTH, Some(palette::ROUTE_DASH));
    let (w, band) = (layout.width, layout.band);
    r.rect(0, 0, w, band, palette::PAPER);
    r.rect(0, layout.height - band, w, band, palette::PAPER);
    r.rect(0, band - 1, w, 1, palette::FRAME);
    r.rect(0, layout.height - band, w, 1, palette::FRAME);
    r.text(palette::GIF_PAD_PX, (band - crate::font::HEIGHT) / 2, &scene.title, palette::INK);
    legend(&mut r, scene, &map, layout);
    Some((ground, map))
}

/// Calls `each` with every frame drawn (its number and pixels); a scene without frames
/// gives one of the road. Bodies are drawn at least [`palette::GIF_MIN_BODY_PX`] a side, so
/// walkers seen from afar stay visible.
fn each_frame(scene: &Scene, options: GifOptions, mut each: impl FnMut(usize, Pixmap)) {
    let layout = layout(scene, options);
    let view = layout.view;
    let Some((ground, map)) = ground(scene, &layout) else { return };
    let steps = steps(scene, options);
    let total = scene.frames.len().saturating_sub(1).max(1);
    for (k, &step) in steps.iter().chain(steps.is_empty().then_some(&0)).enumerate() {
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
        let trail: Vec<Vec2> = (0..=step).filter_map(|f| scene.pose(f, 0)).map(|[x, y, _]| Vec2::new(x, y)).collect();
        if !scene.actors.is_empty() && trail.len() > 1 {
            r.line(&trail, palette::kind(crate::Kind::Ego).fill, palette::kind(crate::Kind::Ego).trail, None);
        }
        // the ego last, on top
        for a in (1..scene.actors.len()).chain((!scene.actors.is_empty()).then_some(0)) {
            let Some(pose) = scene.pose(step, a) else { continue };
            r.actor(scene, a, pose);
        }
        for e in scene.events.iter().filter(|e| e.step <= step) {
            let p = Vec2::new(e.position[0], e.position[1]);
            r.ring(p, palette::EVENT_RADIUS, palette::EVENT_STROKE * 1.8, palette::EVENT_EDGE);
            r.ring(p, palette::EVENT_RADIUS, palette::EVENT_STROKE, palette::EVENT);
        }
        if let Some(pose) = scene.pose(step, 0).filter(|_| !scene.actors.is_empty()) {
            r.tag(Vec2::new(pose[0], pose[1]), &scene.actors[0].label);
        }
        let dt = scene.step();
        let label = if dt > 0.0 { format!("t = {:.1} s", step as f64 * dt) } else { format!("step {step}") };
        let tw = crate::font::width(&label);
        r.text(
            layout.width.saturating_sub(tw + palette::GIF_PAD_PX),
            (layout.band - crate::font::HEIGHT) / 2,
            &label,
            palette::INK,
        );
        r.progress(layout.height - layout.band, step as f64 / total as f64);
        each(k, pixmap);
    }
}

/// The legend band: each kind present (a body in its colours and its name), events and
/// lights when there are some, and a scale bar at the right end.
fn legend(r: &mut Raster, scene: &Scene, map: &map::Map, layout: &Layout) {
    let y = layout.height - layout.band;
    let mid = y + layout.band / 2;
    let text_y = y + (layout.band - crate::font::HEIGHT) / 2 + 1;
    let mut x = palette::GIF_PAD_PX;
    for k in crate::Kind::ALL {
        if (0..scene.actors.len()).any(|a| scene.kind(a) == k) {
            let st = palette::kind(k);
            r.rect(x, mid - 4, 18, 9, st.fill);
            r.rect(x + 14, mid - 4, 4, 9, st.dark);
            x += 22;
            r.text(x, text_y, st.name, palette::INK);
            x += crate::font::width(st.name) + 14;
        }
    }
    if !scene.events.is_empty() {
        r.rect(x, mid - 6, 12, 12, palette::EVENT_EDGE);
        r.rect(x + 2, mid - 4, 8, 8, palette::EVENT);
        r.rect(x + 4, mid - 2, 4, 4, palette::PAPER);
        x += 16;
        r.text(x, text_y, "event", palette::INK);
        x += crate::font::width("event") + 14;
    }
    if !map.signals.is_empty() && scene.frames.iter().any(|f| !f.lights.is_empty()) {
        for l in crate::LIGHTS.iter().filter(|l| scene.frames.iter().any(|f| f.lights.iter().any(|(_, x)| x == *l))) {
            r.rect(x, mid - 4, 9, 9, palette::light(*l));
            x += 12;
        }
        x += 2;
        r.text(x, text_y, "lights", palette::INK);
    }
    let metres = crate::svg::nice_length(palette::SCALE_BAR_PX / layout.view.scale.max(1e-9));
    let len = (metres * layout.view.scale).round().max(1.0) as u32;
    let words = format!("{metres} m");
    let right = layout.width.saturating_sub(palette::GIF_PAD_PX + crate::font::width(&words));
    r.text(right, text_y, &words, palette::INK);
    let x0 = right.saturating_sub(len + 6);
    r.rect(x0, mid + 2, len, 2, palette::INK);
    r.rect(x0, mid - 4, 2, 8, palette::INK);
    r.rect(x0 + len.saturating_sub(2), mid - 4, 2, 8, palette::INK);
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

    /// Text in the font's bitmap, its top-left corner at `(x, y)`.
    fn text(&mut self, x: u32, y: u32, text: &str, c: Colour) {
        for (px, py) in crate::font::pixels(text) {
            self.rect(x + px, y + py, 1, 1, c);
        }
    }

    /// An actor's body at a pose, at least [`palette::GIF_MIN_BODY_PX`] a side; the ego at
    /// least [`palette::GIF_EGO_MIN_PX`] long, with a halo.
    fn actor(&mut self, scene: &Scene, a: usize, pose: [f64; 3]) {
        let least = palette::GIF_MIN_BODY_PX / self.view.scale;
        let (length, width) = scene.size(a);
        let (mut length, width) = (length.max(least), width.max(least));
        if a == 0 {
            length = length.max(palette::GIF_EGO_MIN_PX / self.view.scale);
            let halo = palette::GIF_HALO_PX as f64 / self.view.scale;
            let around = view::body(pose, length + 2.0 * halo, width + 2.0 * halo);
            self.area(&around.corners(), palette::PAPER);
        }
        let style = palette::kind(scene.kind(a));
        let body = view::body(pose, length, width);
        self.area(&body.corners(), style.fill);
        self.area(&crate::svg::front(&body), style.dark);
    }

    /// A ring of `radius` m, `width` m wide.
    fn ring(&mut self, centre: Vec2, radius: f64, width: f64, c: Colour) {
        let (x, y) = self.view.px(centre);
        let r = (radius * self.view.scale).max(2.0);
        let Some(path) = PathBuilder::from_circle(x as f32, y as f32, r as f32) else { return };
        let stroke = Stroke { width: (width * self.view.scale).max(1.0) as f32, ..Stroke::default() };
        self.pixmap.stroke_path(&path, &paint(c), &stroke, Transform::identity(), None);
    }

    /// A name on paper above a point, kept inside the map.
    fn tag(&mut self, at: Vec2, text: &str) {
        let (x, y) = self.view.px(at);
        let (w, h) = (crate::font::width(text) + 4, crate::font::HEIGHT + 2);
        let top = self.view.top as u32;
        let bottom = (self.view.top + self.view.height()) as u32;
        let right = self.pixmap.width().saturating_sub(w);
        let tx = ((x - w as f64 / 2.0).round().max(0.0) as u32).min(right);
        let ring = (palette::EVENT_RADIUS + palette::EVENT_STROKE) * self.view.scale;
        let lift = palette::GIF_EGO_MIN_PX.max(ring) + 2.0 + h as f64;
        let ty = ((y - lift).round().max(top as f64) as u32).min(bottom.saturating_sub(h));
        self.rect(tx, ty, w, h, palette::PAPER);
        self.text(tx + 2, ty + 1, text, palette::INK);
    }

    /// A bar along the map's bottom edge (ending at row `bottom`), `done` of it filled.
    fn progress(&mut self, bottom: u32, done: f64) {
        let w = self.pixmap.width();
        let bar = palette::GIF_BAR_PX.min(bottom);
        self.rect(0, bottom - bar, w, bar, palette::PAPER);
        let filled = (done.clamp(0.0, 1.0) * w as f64).round() as u32;
        self.rect(0, bottom - bar, filled, bar, palette::ROUTE);
    }
}
