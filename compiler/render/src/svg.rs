//! The SVG figure: the title above, the map (road, route, trajectories with a tick each
//! second, every actor at its first pose outlined and at its last filled, signals, events,
//! a scale bar) and a legend panel to its right.
//!
//! Coordinates are written in pixels (the `View` flips `y`), one decimal each, so text is
//! never mirrored and the same scene gives the same bytes. Elements carry classes (`road`
//! items by role, `actor-start`, `actor-end`, `trajectory`, `route`, `signal`, `event`) and
//! each actor's group the id `actor-N`, for tests and for readers who restyle the figure.

use crate::map::{self, Item};
use crate::palette;
use crate::view::{self, Bounds, View};
use crate::{Kind, Light, Scene};
use std::fmt::Write;
use tad_road::geom::Vec2;

/// A number as SVG gets it: one decimal, never `-0.0`, 0 for what is not finite.
fn n(v: f64) -> String {
    let s = if v.is_finite() { format!("{v:.1}") } else { "0.0".to_string() };
    if s == "-0.0" { "0.0".to_string() } else { s }
}

/// Text for XML: escaped, without the characters XML 1.0 cannot hold.
fn text(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => {}
            c => out.push(c),
        }
    }
    out
}

struct Svg<'a> {
    out: String,
    view: View,
    scene: &'a Scene<'a>,
}

impl Svg<'_> {
    fn pts(&self, points: &[Vec2]) -> String {
        let mut s = String::new();
        for (i, p) in points.iter().enumerate() {
            let (x, y) = self.view.px(*p);
            let _ = write!(s, "{}{},{}", if i > 0 { " " } else { "" }, n(x), n(y));
        }
        s
    }

    fn m(&self, metres: f64) -> String {
        n(metres * self.view.scale)
    }

    fn dash(&self, dash: Option<(f64, f64)>) -> String {
        dash.map_or(String::new(), |(a, b)| format!(" stroke-dasharray=\"{} {}\"", self.m(a), self.m(b)))
    }

    fn item(&mut self, item: &Item) {
        let line = match item {
            Item::Area { class, points, colour } => {
                format!("<polygon class=\"{class}\" points=\"{}\" fill=\"{}\"/>", self.pts(points), colour.hex())
            }
            Item::Line { class, points, colour, width, dash } => format!(
                "<polyline class=\"{class}\" points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"{}/>",
                self.pts(points),
                colour.hex(),
                self.m(*width),
                self.dash(*dash)
            ),
            Item::Disc { class, centre, radius, colour } => {
                let (x, y) = self.view.px(*centre);
                format!(
                    "<circle class=\"{class}\" cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\"/>",
                    n(x),
                    n(y),
                    self.m(*radius),
                    colour.hex()
                )
            }
        };
        self.out.push_str(&line);
        self.out.push('\n');
    }

    fn push(&mut self, s: &str) {
        self.out.push_str(s);
        self.out.push('\n');
    }
}

/// The map's view: what moved, at most [`palette::MAX_ASPECT`] times as wide as high (or
/// high as wide), its longer side [`palette::MAP_PX`] pixels.
pub fn view_of(scene: &Scene) -> View {
    let bounds = view::focus(scene);
    let (w, h) = (bounds.width(), bounds.height());
    let bounds = bounds.at_least(h / palette::MAX_ASPECT, w / palette::MAX_ASPECT);
    let scale = palette::MAP_PX / bounds.width().max(bounds.height());
    View::fit(bounds, palette::PAD_PX, palette::TITLE_PX, bounds.width() * scale, bounds.height() * scale)
}

/// The SVG figure of a scene: see the module's header.
pub fn svg(scene: &Scene) -> String {
    let view = view_of(scene);
    let legend = legend_entries(scene);
    let legend_h = palette::PAD_PX * 2.0 + legend.len() as f64 * palette::FONT_PX * 1.8;
    let width = palette::PAD_PX * 3.0 + view.width() + palette::LEGEND_PX;
    let height = palette::TITLE_PX + view.height().max(legend_h) + palette::PAD_PX;

    let mut s = Svg { out: String::new(), view, scene };
    s.push("<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    s.push(&format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"{f}\">",
        w = n(width),
        h = n(height),
        f = n(palette::FONT_PX)
    ));
    s.push(&format!("<title>{}</title>", text(&scene.title)));
    s.push(&format!("<rect width=\"{}\" height=\"{}\" fill=\"{}\"/>", n(width), n(height), palette::PAPER.hex()));
    s.push(&format!(
        "<text class=\"title\" x=\"{}\" y=\"{}\" font-size=\"{}\" font-weight=\"bold\" fill=\"{}\">{}</text>",
        n(palette::PAD_PX),
        n(palette::TITLE_PX - 12.0),
        n(palette::TITLE_FONT_PX),
        palette::INK.hex(),
        text(&scene.title)
    ));
    let (mx, my, mw, mh) = (view.left, view.top, view.width(), view.height());
    s.push(&format!(
        "<defs><clipPath id=\"map-clip\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath></defs>",
        n(mx),
        n(my),
        n(mw),
        n(mh)
    ));
    s.push("<g class=\"map\" clip-path=\"url(#map-clip)\">");
    s.push(&format!(
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>",
        n(mx),
        n(my),
        n(mw),
        n(mh),
        palette::BACKGROUND.hex()
    ));
    let map = map::draw(scene, &view.bounds);
    s.push("<g class=\"road\">");
    for item in &map.items {
        s.item(item);
    }
    s.push("</g>");
    route(&mut s);
    actors(&mut s);
    signals(&mut s, &map.signals);
    events(&mut s);
    scale_bar(&mut s);
    s.push("</g>");
    s.push(&format!(
        "<rect class=\"frame\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1\"/>",
        n(mx),
        n(my),
        n(mw),
        n(mh),
        palette::FRAME.hex()
    ));
    draw_legend(&mut s, &legend, mx + mw + palette::PAD_PX, my, legend_h);
    s.push("</svg>");
    s.out
}

/// The route, cut to the view (grown a little so it leaves the picture cleanly).
fn route(s: &mut Svg) {
    let window = s.view.bounds.grown(5.0);
    let points: Vec<Vec2> =
        s.scene.route.iter().map(|p| Vec2::new(p[0], p[1])).filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    for run in runs(&points, &window) {
        let line = format!(
            "<polyline class=\"route\" points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"{}/>",
            s.pts(&run),
            palette::ROUTE.hex(),
            s.m(palette::ROUTE_WIDTH),
            s.dash(Some(palette::ROUTE_DASH))
        );
        s.push(&line);
    }
}

/// The stretches of a polyline inside a rectangle, each with one point beyond either end.
fn runs(points: &[Vec2], window: &Bounds) -> Vec<Vec<Vec2>> {
    let mut runs = Vec::new();
    let mut current: Vec<Vec2> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let inside = window.contains(*p);
        let next_inside = points.get(i + 1).is_some_and(|q| window.contains(*q));
        if inside || next_inside || current.last().is_some_and(|q| window.contains(*q)) {
            current.push(*p);
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if current.len() >= 2 {
        runs.push(current);
    }
    runs.retain(|r| r.len() >= 2);
    runs
}

/// Each actor's trajectory (a polyline per stretch it is present), its second ticks, its
/// first pose outlined and its last filled, and its label; the ego last, on top.
fn actors(s: &mut Svg) {
    let scene = s.scene;
    let dt = scene.step();
    let mut order: Vec<usize> = (1..scene.actors.len()).collect();
    if !scene.actors.is_empty() {
        order.push(0);
    }
    s.push("<g class=\"actors\">");
    for &a in &order {
        let style = palette::kind(scene.kind(a));
        let (length, width) = scene.size(a);
        let present: Vec<(usize, [f64; 3])> =
            (0..scene.frames.len()).filter_map(|f| scene.pose(f, a).map(|p| (f, p))).collect();
        let (Some(&(_, first)), Some(&(_, last))) = (present.first(), present.last()) else { continue };
        s.push(&format!("<g id=\"actor-{a}\" class=\"actor {}\">", style.name));
        // trajectory: one polyline per stretch of consecutive frames
        let mut stretch: Vec<Vec2> = Vec::new();
        let mut previous: Option<usize> = None;
        let flush = |s: &mut Svg, stretch: &mut Vec<Vec2>| {
            if stretch.len() >= 2 {
                let line = format!(
                    "<polyline class=\"trajectory\" points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\" stroke-linecap=\"round\" stroke-opacity=\"0.85\"/>",
                    s.pts(stretch),
                    style.fill.hex(),
                    s.m(style.trail)
                );
                s.push(&line);
            }
            stretch.clear();
        };
        for &(f, [x, y, _]) in &present {
            if previous.is_some_and(|p| p + 1 != f) {
                flush(s, &mut stretch);
            }
            let p = Vec2::new(x, y);
            if stretch.last().is_none_or(|q| q.distance(p) > 0.05) {
                stretch.push(p);
            }
            previous = Some(f);
        }
        flush(s, &mut stretch);
        // a tick across the heading at each whole second (longer every fifth)
        if dt > 0.0 && present.len() > 1 {
            let mut ticks = String::new();
            let mut previous_second = 0i64;
            for &(f, [x, y, yaw]) in &present {
                let second = (f as f64 * dt + 1e-9).floor() as i64;
                if f > 0 && second > previous_second {
                    let half = if second % 5 == 0 { palette::TICK_LONG } else { palette::TICK } / 2.0;
                    let across = Vec2::from_yaw(yaw).left() * half;
                    let p = Vec2::new(x, y);
                    let _ = write!(ticks, "M{} ", s.pts(&[p - across]));
                    let _ = write!(ticks, "L{} ", s.pts(&[p + across]));
                }
                previous_second = second;
            }
            if !ticks.is_empty() {
                let line = format!(
                    "<path class=\"ticks\" d=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>",
                    ticks.trim_end().replace(',', " "),
                    style.dark.hex(),
                    s.m(palette::LINE * 1.5)
                );
                s.push(&line);
            }
        }
        // the first pose outlined (when the actor moved), the last filled
        let start = view::body(first, length, width);
        let end = view::body(last, length, width);
        let moved = start.pose.position.distance(end.pose.position) > 0.3 || (first[2] - last[2]).abs() > 0.1;
        let outline = if a == 0 { palette::OUTLINE * 1.5 } else { palette::OUTLINE };
        if moved {
            let line = format!(
                "<polygon class=\"actor-start\" points=\"{}\" fill=\"{}\" fill-opacity=\"0.35\" stroke=\"{}\" stroke-width=\"{}\" stroke-dasharray=\"{} {}\"/>",
                s.pts(&start.corners()),
                palette::PAPER.hex(),
                style.dark.hex(),
                s.m(outline),
                s.m(0.5),
                s.m(0.3)
            );
            s.push(&line);
            let c = start.corners();
            let line = format!(
                "<polyline class=\"actor-start-front\" points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"/>",
                s.pts(&[c[0], c[1]]),
                style.dark.hex(),
                s.m(outline * 2.0)
            );
            s.push(&line);
        }
        let line = format!(
            "<polygon class=\"actor-end\" id=\"actor-{a}-end\" points=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>",
            s.pts(&end.corners()),
            style.fill.hex(),
            if a == 0 { palette::PAPER.hex() } else { style.dark.hex() },
            s.m(outline)
        );
        s.push(&line);
        let line = format!(
            "<polygon class=\"actor-front\" points=\"{}\" fill=\"{}\"/>",
            s.pts(&front(&end)),
            style.dark.hex()
        );
        s.push(&line);
        // the label beside the last pose
        let (px, py) = s.view.px(end.pose.position);
        let off = (length.max(width) / 2.0) * s.view.scale + 3.0;
        let line = format!(
            "<text class=\"label\" x=\"{}\" y=\"{}\" font-size=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"3\" paint-order=\"stroke\" stroke-linejoin=\"round\">{}</text>",
            n(px + off),
            n(py - off),
            n(palette::LABEL_FONT_PX),
            style.dark.hex(),
            palette::PAPER.hex(),
            text(&scene.actors[a].label)
        );
        s.push(&line);
        s.push("</g>");
    }
    s.push("</g>");
}

/// The front share of a body, painted dark to show which way it faces.
pub fn front(body: &tad_road::geom::Footprint) -> [Vec2; 4] {
    let c = body.corners();
    let back = palette::FRONT.min(1.0);
    // corners 0 and 1 are the front ones; 3 and 2 the back ones on the same sides
    [c[0], c[1], c[1] + (c[2] - c[1]) * back, c[0] + (c[3] - c[0]) * back]
}

/// Each arm's light: a dot in its state at the first frame, ringed by its state at the last
/// when that differs.
fn signals(s: &mut Svg, places: &[(tad_road::Arm, Vec2)]) {
    let scene = s.scene;
    let state =
        |frame: Option<&crate::Frame>, arm| frame.and_then(|f| f.lights.iter().find(|(a, _)| *a == arm)).map(|l| l.1);
    let (first, last) = (scene.frames.first(), scene.frames.last());
    s.push("<g class=\"signals\">");
    for &(arm, p) in places {
        let (Some(a), b) = (state(first, arm), state(last, arm)) else { continue };
        let (x, y) = s.view.px(p);
        let r = palette::SIGNAL_RADIUS;
        if let Some(b) = b.filter(|b| *b != a) {
            let line = format!(
                "<circle class=\"signal-end\" cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>",
                n(x),
                n(y),
                s.m(r * 1.6),
                palette::light(b).hex(),
                palette::INK.hex(),
                s.m(0.1)
            );
            s.push(&line);
        }
        let line = format!(
            "<circle class=\"signal\" data-arm=\"{}\" cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>",
            arm.as_str(),
            n(x),
            n(y),
            s.m(r),
            palette::light(a).hex(),
            palette::INK.hex(),
            s.m(0.15)
        );
        s.push(&line);
    }
    s.push("</g>");
}

/// A diamond for each event, labelled with what happened and when.
fn events(s: &mut Svg) {
    let scene = s.scene;
    let dt = scene.step();
    s.push("<g class=\"events\">");
    for e in &scene.events {
        let p = Vec2::new(e.position[0], e.position[1]);
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let r = palette::EVENT_RADIUS;
        let diamond = [p + Vec2::new(r, 0.0), p + Vec2::new(0.0, r), p - Vec2::new(r, 0.0), p - Vec2::new(0.0, r)];
        let line = format!(
            "<polygon class=\"event\" points=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>",
            s.pts(&diamond),
            palette::EVENT.hex(),
            palette::EVENT_EDGE.hex(),
            s.m(0.2)
        );
        s.push(&line);
        let when = if dt > 0.0 { format!(" @ {:.1} s", e.step as f64 * dt) } else { format!(" @ step {}", e.step) };
        let (x, y) = s.view.px(p);
        let off = r * s.view.scale + 3.0;
        let line = format!(
            "<text class=\"event-label\" x=\"{}\" y=\"{}\" font-size=\"{}\" font-weight=\"bold\" fill=\"{}\" stroke=\"{}\" stroke-width=\"3\" paint-order=\"stroke\" stroke-linejoin=\"round\">{}{}</text>",
            n(x + off),
            n(y + off + palette::LABEL_FONT_PX),
            n(palette::LABEL_FONT_PX),
            palette::INK.hex(),
            palette::PAPER.hex(),
            text(&e.label),
            when
        );
        s.push(&line);
    }
    s.push("</g>");
}

/// A bar of [`palette::SCALE_BAR`] metres in the map's lower left corner.
fn scale_bar(s: &mut Svg) {
    let len = palette::SCALE_BAR * s.view.scale;
    let x = s.view.left + palette::PAD_PX;
    let y = s.view.top + s.view.height() - palette::PAD_PX;
    let lines = [
        format!(
            "<g class=\"scale\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" fill-opacity=\"0.8\"/>",
            n(x - 6.0),
            n(y - 24.0),
            n(len + 12.0),
            n(32.0),
            palette::PAPER.hex()
        ),
        format!(
            "<path d=\"M{} {} V{} H{} V{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>",
            n(x),
            n(y - 5.0),
            n(y),
            n(x + len),
            n(y - 5.0),
            palette::INK.hex()
        ),
        format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"{}\">{} m</text></g>",
            n(x + len / 2.0),
            n(y - 9.0),
            palette::INK.hex(),
            palette::SCALE_BAR
        ),
    ];
    for l in lines {
        s.push(&l);
    }
}

/// What the legend shows, one row each.
enum Entry {
    Kind(Kind),
    Start,
    End,
    Trajectory,
    Route,
    Event,
    Light(Light),
    /// Words alone.
    Note(String),
}

fn legend_entries(scene: &Scene) -> Vec<Entry> {
    let mut entries = Vec::new();
    for k in Kind::ALL {
        if (0..scene.actors.len()).any(|a| scene.kind(a) == k) {
            entries.push(Entry::Kind(k));
        }
    }
    entries.extend([Entry::Start, Entry::End, Entry::Trajectory]);
    if !scene.route.is_empty() {
        entries.push(Entry::Route);
    }
    if !scene.events.is_empty() {
        entries.push(Entry::Event);
    }
    for l in crate::LIGHTS {
        if scene.frames.iter().any(|f| f.lights.iter().any(|(_, x)| *x == l)) {
            entries.push(Entry::Light(l));
        }
    }
    let (first, last) = (scene.frames.first(), scene.frames.last());
    if first.zip(last).is_some_and(|(a, b)| a.lights != b.lights) {
        entries.push(Entry::Note("light: dot at the start, ring at the end".to_string()));
    }
    let dt = scene.step();
    if dt > 0.0 && !scene.frames.is_empty() {
        let end = (scene.frames.len() - 1) as f64 * dt;
        entries.push(Entry::Note(format!("{} steps of {} s, {:.1} s", scene.frames.len(), dt, end)));
    }
    entries
}

fn draw_legend(s: &mut Svg, entries: &[Entry], x: f64, y: f64, h: f64) {
    s.push(&format!(
        "<g class=\"legend\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" stroke=\"{}\"/>",
        n(x),
        n(y),
        n(palette::LEGEND_PX),
        n(h),
        palette::PAPER.hex(),
        palette::FRAME.hex()
    ));
    let row = palette::FONT_PX * 1.8;
    let (sx, tx) = (x + palette::PAD_PX, x + palette::PAD_PX + 34.0);
    for (i, e) in entries.iter().enumerate() {
        let cy = y + palette::PAD_PX + row * (i as f64 + 0.5);
        let vehicle = palette::kind(Kind::Vehicle);
        let (symbol, words) = match e {
            Entry::Kind(k) => {
                let st = palette::kind(*k);
                (
                    format!(
                        "<rect x=\"{}\" y=\"{}\" width=\"24\" height=\"10\" fill=\"{}\" stroke=\"{}\"/>",
                        n(sx),
                        n(cy - 5.0),
                        st.fill.hex(),
                        st.dark.hex()
                    ),
                    st.name.to_string(),
                )
            }
            Entry::Start => (
                format!(
                    "<rect x=\"{}\" y=\"{}\" width=\"24\" height=\"10\" fill=\"none\" stroke=\"{}\" stroke-dasharray=\"3 2\"/>",
                    n(sx),
                    n(cy - 5.0),
                    vehicle.dark.hex()
                ),
                "first pose".to_string(),
            ),
            Entry::End => (
                format!(
                    "<rect x=\"{}\" y=\"{}\" width=\"24\" height=\"10\" fill=\"{}\" stroke=\"{}\"/><rect x=\"{}\" y=\"{}\" width=\"5\" height=\"10\" fill=\"{}\"/>",
                    n(sx),
                    n(cy - 5.0),
                    vehicle.fill.hex(),
                    vehicle.dark.hex(),
                    n(sx + 19.0),
                    n(cy - 5.0),
                    vehicle.dark.hex()
                ),
                "last pose (dark: front)".to_string(),
            ),
            Entry::Trajectory => (
                format!(
                    "<path d=\"M{} {} H{} M{} {} V{} M{} {} V{}\" stroke=\"{}\" stroke-width=\"2\" fill=\"none\"/>",
                    n(sx),
                    n(cy),
                    n(sx + 24.0),
                    n(sx + 8.0),
                    n(cy - 4.0),
                    n(cy + 4.0),
                    n(sx + 18.0),
                    n(cy - 4.0),
                    n(cy + 4.0),
                    vehicle.fill.hex()
                ),
                "trajectory, tick = 1 s".to_string(),
            ),
            Entry::Route => (
                format!(
                    "<path d=\"M{} {} H{}\" stroke=\"{}\" stroke-width=\"2\" stroke-dasharray=\"4 3\"/>",
                    n(sx),
                    n(cy),
                    n(sx + 24.0),
                    palette::ROUTE.hex()
                ),
                "ego's route".to_string(),
            ),
            Entry::Event => (
                format!(
                    "<path d=\"M{} {} l7 -7 l7 7 l-7 7 z\" fill=\"{}\" stroke=\"{}\"/>",
                    n(sx + 5.0),
                    n(cy),
                    palette::EVENT.hex(),
                    palette::EVENT_EDGE.hex()
                ),
                "event".to_string(),
            ),
            Entry::Light(l) => (
                format!(
                    "<circle cx=\"{}\" cy=\"{}\" r=\"5\" fill=\"{}\" stroke=\"{}\"/>",
                    n(sx + 12.0),
                    n(cy),
                    palette::light(*l).hex(),
                    palette::INK.hex()
                ),
                format!("light {}", tad_ir::ClosedSet::as_str(*l)),
            ),
            Entry::Note(t) => (String::new(), t.clone()),
        };
        let tx = if symbol.is_empty() { sx } else { tx };
        s.push(&symbol);
        s.push(&format!(
            "<text x=\"{}\" y=\"{}\" dominant-baseline=\"central\" fill=\"{}\">{}</text>",
            n(tx),
            n(cy),
            palette::INK.hex(),
            text(&words)
        ));
    }
    s.push("</g>");
}
