//! The SVG figure: the title with a scale bar above, the map (road, route, trajectories
//! with a tick each second, every actor at its first pose outlined and at its last filled,
//! signals, events as hollow rings), the labels over it, and the legend below it.
//!
//! The map is fitted to where things happen (`view`); what leaves it is clipped at its
//! frame. Labels are placed last, above everything, by `label`: events first, then each
//! actor (the ego first; actors of one group standing together, like `parked[0]` to
//! `parked[4]`, share one label `parked[0–4]`), then time marks (`4 s`) along the
//! trajectories, which are dropped where there is no free room. No two labels overlap and
//! each lies inside the map; each `<text>` carries its box as `data-box="x y w h"`.
//!
//! Coordinates are written in pixels (the `View` flips `y`), one decimal each, so text is
//! never mirrored and the same scene gives the same bytes. Elements carry classes (`road`
//! items by role, `actor-start`, `actor-end`, `trajectory`, `ticks`, `route`, `signal`,
//! `event`, `label`, `event-label`, `time-label`, `leader`) and each actor's group the id
//! `actor-N`, for tests and for readers who restyle the figure.

use crate::label::{self, Placed, Rect, Request};
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

/// The map's view: where things happen, at most [`palette::MAX_ASPECT`] times as wide as
/// high (or high as wide), its longer side [`palette::MAP_PX`] pixels.
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
    let (mx, my, mw, mh) = (view.left, view.top, view.width(), view.height());
    let legend = Legend::new(legend_entries(scene), mw);
    let width = palette::PAD_PX * 2.0 + mw;
    let height = my + mh + legend.height + palette::PAD_PX;

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
    scale_bar(&mut s, mx + mw);
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
    s.push("</g>");
    s.push(&format!(
        "<rect class=\"frame\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1\"/>",
        n(mx),
        n(my),
        n(mw),
        n(mh),
        palette::FRAME.hex()
    ));
    labels(&mut s, &map.signals);
    legend.draw(&mut s, mx, my + mh + palette::PAD_PX);
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
/// first pose outlined and its last filled; the ego last, on top. Labels come later.
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

/// A hollow ring round each event (what collided stays visible inside it): dark under
/// bright. Its words are a label.
fn events(s: &mut Svg) {
    let scene = s.scene;
    s.push("<g class=\"events\">");
    for e in &scene.events {
        let p = Vec2::new(e.position[0], e.position[1]);
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let (x, y) = s.view.px(p);
        for (class, colour, width) in [
            ("event-edge", palette::EVENT_EDGE, palette::EVENT_STROKE * 1.8),
            ("event", palette::EVENT, palette::EVENT_STROKE),
        ] {
            let line = format!(
                "<circle class=\"{class}\" cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"/>",
                n(x),
                n(y),
                s.m(palette::EVENT_RADIUS),
                colour.hex(),
                s.m(width)
            );
            s.push(&line);
        }
    }
    s.push("</g>");
}

/// What an event's label says: what happened and when.
fn event_text(scene: &Scene, e: &crate::Event) -> String {
    let dt = scene.step();
    if dt > 0.0 {
        format!("{}, t = {:.1} s", e.label, e.step as f64 * dt)
    } else {
        format!("{}, step {}", e.label, e.step)
    }
}

/// `name[3]` → (`name`, 3); other labels have no index.
fn indexed(label: &str) -> Option<(&str, usize)> {
    let (base, rest) = label.rsplit_once('[')?;
    Some((base, rest.strip_suffix(']')?.parse().ok()?))
}

/// One actor label: what it says, in which kind's colour, and the box (px) it names.
struct Named {
    text: String,
    kind: Kind,
    anchor: Rect,
    /// The first actor it names.
    first: usize,
}

/// An actor, where its label would stand (px) and its body's box there.
type Single = (usize, (f64, f64), Rect);

/// The actors' labels: each at its last pose inside the view; actors of one group whose
/// labels would stand within [`palette::GROUP_M`] of each other share one.
fn actor_labels(s: &Svg) -> Vec<Named> {
    let scene = s.scene;
    let mut singles: Vec<Single> = Vec::new();
    let mut order: Vec<usize> = (0..scene.actors.len()).collect();
    order.sort_by_key(|&a| a != 0);
    for a in order {
        let Some(pose) = (0..scene.frames.len())
            .rev()
            .filter_map(|f| scene.pose(f, a))
            .find(|p| s.view.bounds.contains(Vec2::new(p[0], p[1])))
        else {
            continue;
        };
        let (length, width) = scene.size(a);
        let corners = view::body(pose, length, width).corners().map(|c| s.view.px(c));
        let Some(body) = Rect::bounding(corners) else { continue };
        singles.push((a, s.view.px(Vec2::new(pose[0], pose[1])), body));
    }
    let mut groups: Vec<Vec<Single>> = Vec::new();
    for single in singles {
        let (a, at, _) = single;
        let key = indexed(&scene.actors[a].label).map(|(b, _)| b);
        let joins = groups.iter_mut().find(|g| {
            let (b, _, _) = g[0];
            b != 0
                && a != 0
                && key.is_some()
                && indexed(&scene.actors[b].label).map(|(k, _)| k) == key
                && scene.kind(a) == scene.kind(b)
                && g.iter().any(|m| (m.1.0 - at.0).hypot(m.1.1 - at.1) < palette::GROUP_M * s.view.scale)
        });
        match joins {
            Some(g) => g.push(single),
            None => groups.push(vec![single]),
        }
    }
    groups
        .into_iter()
        .filter_map(|g| {
            let corners = g.iter().flat_map(|m| [(m.2.x, m.2.y), (m.2.x + m.2.w, m.2.y + m.2.h)]);
            let anchor = Rect::bounding(corners)?;
            let text = group_text(scene, &g.iter().map(|m| m.0).collect::<Vec<_>>());
            Some(Named { text, kind: scene.kind(g[0].0), anchor, first: g[0].0 })
        })
        .collect()
}

/// A group's label: `name[0–4]` for a run of indices, `name[0, 2]` otherwise.
fn group_text(scene: &Scene, members: &[usize]) -> String {
    let first = &scene.actors[members[0]].label;
    let mut indices: Vec<usize> =
        members.iter().filter_map(|&m| indexed(&scene.actors[m].label)).map(|x| x.1).collect();
    let Some((base, _)) = indexed(first).filter(|_| members.len() > 1) else { return first.clone() };
    indices.sort_unstable();
    let (lo, hi) = (indices[0], indices[indices.len() - 1]);
    if hi - lo + 1 == indices.len() {
        format!("{base}[{lo}–{hi}]")
    } else {
        let list: Vec<String> = indices.iter().map(usize::to_string).collect();
        format!("{base}[{}]", list.join(", "))
    }
}

/// Time marks along the trajectories of `actors` that moved, the ego's first: whole
/// seconds, every 1, 2, 5, 10… s, whichever puts them about [`palette::TIME_GAP_PX`] apart.
fn time_marks(s: &Svg, actors: &[usize]) -> Vec<(Request, Kind)> {
    let scene = s.scene;
    let dt = scene.step();
    let mut out = Vec::new();
    if dt <= 0.0 {
        return out;
    }
    let mut order: Vec<usize> = actors.to_vec();
    order.sort_by_key(|&a| (a != 0, a));
    for a in order {
        let mut ticks: Vec<(i64, (f64, f64), f64)> = Vec::new();
        let mut previous_second = 0i64;
        for f in 0..scene.frames.len() {
            let Some([x, y, yaw]) = scene.pose(f, a) else { continue };
            let second = (f as f64 * dt + 1e-9).floor() as i64;
            if f == 0 || second > previous_second {
                ticks.push((second, s.view.px(Vec2::new(x, y)), yaw));
            }
            previous_second = second;
        }
        let mut steps: Vec<f64> = ticks.windows(2).map(|w| (w[1].1.0 - w[0].1.0).hypot(w[1].1.1 - w[0].1.1)).collect();
        steps.sort_by(f64::total_cmp);
        let Some(&median) = steps.get(steps.len() / 2).filter(|m| **m > 0.5) else { continue };
        let every =
            [1, 2, 5, 10, 20, 30, 60].into_iter().find(|k| median * *k as f64 >= palette::TIME_GAP_PX).unwrap_or(60);
        let mut last = ticks[0].1;
        let half = palette::TICK_LONG / 2.0 * s.view.scale;
        for &(second, p, yaw) in &ticks[1..] {
            if second % every == 0 && (p.0 - last.0).hypot(p.1 - last.1) >= palette::TIME_GAP_PX * 0.6 {
                last = p;
                let text = format!("{second} s");
                let (anchor, along) = (Rect::around(p, half), Some((yaw.cos(), -yaw.sin())));
                out.push((Request { text, font: palette::TIME_FONT_PX, anchor, optional: true, along }, scene.kind(a)));
            }
        }
    }
    out
}

/// Every label, placed by `label` over the map: events, actors, time marks.
fn labels(s: &mut Svg, signals: &[(tad_road::Arm, Vec2)]) {
    let scene = s.scene;
    let view = s.view;
    let frame = Rect { x: view.left, y: view.top, w: view.width(), h: view.height() };
    let mut obstacles: Vec<Rect> = Vec::new();
    for a in 0..scene.actors.len() {
        let (length, width) = scene.size(a);
        let present: Vec<[f64; 3]> = (0..scene.frames.len()).filter_map(|f| scene.pose(f, a)).collect();
        for pose in present.first().into_iter().chain(present.last()) {
            let corners = view::body(*pose, length, width).corners();
            obstacles.extend(Rect::bounding(corners.iter().map(|c| view.px(*c))));
        }
    }
    let ring = (palette::EVENT_RADIUS + palette::EVENT_STROKE) * view.scale;
    for e in &scene.events {
        obstacles.push(Rect::around(view.px(Vec2::new(e.position[0], e.position[1])), ring));
    }
    for (_, p) in signals {
        obstacles.push(Rect::around(view.px(*p), palette::SIGNAL_RADIUS * 1.6 * view.scale));
    }
    let mut requests: Vec<(Request, &str, crate::palette::Colour)> = Vec::new();
    for e in &scene.events {
        let anchor = Rect::around(view.px(Vec2::new(e.position[0], e.position[1])), ring);
        let r =
            Request { text: event_text(scene, e), font: palette::LABEL_FONT_PX, anchor, optional: false, along: None };
        requests.push((r, "event-label", palette::INK));
    }
    let named = actor_labels(s);
    // one trajectory of a group that shares a label is marked, not every one
    let marked: Vec<usize> = named.iter().map(|n| n.first).collect();
    for named in named {
        let colour = palette::kind(named.kind).dark;
        let r = Request {
            text: named.text,
            font: palette::LABEL_FONT_PX,
            anchor: named.anchor,
            optional: false,
            along: None,
        };
        requests.push((r, "label", colour));
    }
    for (r, kind) in time_marks(s, &marked) {
        requests.push((r, "time-label", palette::kind(kind).dark));
    }
    let only: Vec<Request> = requests.iter().map(|r| r.0.clone()).collect();
    let placed = label::place(&only, &obstacles, frame);
    s.push("<g class=\"labels\">");
    for ((r, class, colour), at) in requests.iter().zip(placed) {
        let Some(Placed { rect, leader }) = at else { continue };
        if leader {
            let centre = |b: &Rect| (b.x + b.w / 2.0, b.y + b.h / 2.0);
            let (x0, y0) = r.anchor.nearest(centre(&rect));
            let (x1, y1) = rect.nearest(centre(&r.anchor));
            let line = format!(
                "<line class=\"leader\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\" stroke-width=\"1\"/>",
                n(x0),
                n(y0),
                n(x1),
                n(y1),
                palette::INK.hex()
            );
            s.push(&line);
        }
        let weight = if *class == "event-label" { " font-weight=\"bold\"" } else { "" };
        let line = format!(
            "<text class=\"{class}\" data-box=\"{} {} {} {}\" x=\"{}\" y=\"{}\" font-size=\"{}\"{weight} fill=\"{}\" stroke=\"{}\" stroke-width=\"3\" paint-order=\"stroke\" stroke-linejoin=\"round\">{}</text>",
            n(rect.x),
            n(rect.y),
            n(rect.w),
            n(rect.h),
            n(rect.x + 2.0),
            n(rect.y + r.font * 1.0),
            n(r.font),
            colour.hex(),
            palette::PAPER.hex(),
            text(&r.text)
        );
        s.push(&line);
    }
    s.push("</g>");
}

/// A scale bar at the title band's right end, ending at `right`: 1, 2 or 5 times a power
/// of ten metres, at most [`palette::SCALE_BAR_PX`] long.
fn scale_bar(s: &mut Svg, right: f64) {
    let metres = nice_length(palette::SCALE_BAR_PX / s.view.scale.max(1e-9));
    let len = metres * s.view.scale;
    let words = format!("{metres} m");
    let (tw, _) = label::size(&words, palette::FONT_PX);
    let y = palette::TITLE_PX - 14.0;
    let x = right - tw - 4.0 - len;
    let lines = [
        format!(
            "<g class=\"scale\"><path d=\"M{} {} V{} H{} V{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>",
            n(x),
            n(y - 5.0),
            n(y),
            n(x + len),
            n(y - 5.0),
            palette::INK.hex()
        ),
        format!(
            "<text x=\"{}\" y=\"{}\" fill=\"{}\">{}</text></g>",
            n(x + len + 6.0),
            n(y + 1.0),
            palette::INK.hex(),
            words
        ),
    ];
    for l in lines {
        s.push(&l);
    }
}

/// The longest of 1, 2 or 5 times a power of ten that is at most `most` (at least 1).
pub fn nice_length(most: f64) -> f64 {
    if !(most.is_finite() && most >= 1.0) {
        return 1.0;
    }
    let p = 10f64.powf(most.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|k| k * p).find(|v| *v <= most).unwrap_or(p)
}

/// What the legend shows, one cell each.
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

/// The legend below the map: its entries down as few rows as let their columns (each as
/// wide as its widest entry) fit the map's width.
struct Legend {
    entries: Vec<Entry>,
    rows: usize,
    /// Each column's left edge from the legend's, px.
    lefts: Vec<f64>,
    height: f64,
}

impl Legend {
    fn new(entries: Vec<Entry>, width: f64) -> Legend {
        let widths: Vec<f64> = entries
            .iter()
            .map(|e| {
                let (words, symbol) = e.words();
                label::size(&words, palette::FONT_PX).0 + if symbol { palette::LEGEND_SYMBOL_PX + 8.0 } else { 0.0 }
            })
            .collect();
        let n = entries.len().max(1);
        let layout = |rows: usize| -> Vec<f64> {
            let mut lefts = vec![0.0];
            for column in widths.chunks(rows) {
                let right =
                    lefts[lefts.len() - 1] + column.iter().copied().fold(0.0, f64::max) + palette::LEGEND_GAP_PX;
                lefts.push(right);
            }
            lefts
        };
        let rows =
            (1..=n).find(|&r| layout(r).last().is_some_and(|w| w - palette::LEGEND_GAP_PX <= width)).unwrap_or(n);
        let mut lefts = layout(rows);
        lefts.pop();
        let height = if entries.is_empty() { 0.0 } else { rows as f64 * palette::LEGEND_ROW_PX };
        Legend { entries, rows, lefts, height }
    }

    fn draw(&self, s: &mut Svg, x: f64, y: f64) {
        s.push("<g class=\"legend\">");
        for (i, e) in self.entries.iter().enumerate() {
            let (col, row) = (i / self.rows, i % self.rows);
            let sx = x + self.lefts.get(col).copied().unwrap_or(0.0);
            let cy = y + (row as f64 + 0.5) * palette::LEGEND_ROW_PX;
            let symbol = e.symbol(sx, cy);
            let (words, has_symbol) = e.words();
            let tx = if has_symbol { sx + palette::LEGEND_SYMBOL_PX + 8.0 } else { sx };
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
}

impl Entry {
    /// The entry's words, and whether it has a symbol.
    fn words(&self) -> (String, bool) {
        match self {
            Entry::Kind(k) => (palette::kind(*k).name.to_string(), true),
            Entry::Start => ("first pose".to_string(), true),
            Entry::End => ("last pose (dark: front)".to_string(), true),
            Entry::Trajectory => ("trajectory: a tick each second, marked in s".to_string(), true),
            Entry::Route => ("ego's route".to_string(), true),
            Entry::Event => ("event".to_string(), true),
            Entry::Light(l) => (format!("light {}", tad_ir::ClosedSet::as_str(*l)), true),
            Entry::Note(t) => (t.clone(), false),
        }
    }

    /// The entry's symbol, its left edge at `sx`, centred on `cy`.
    fn symbol(&self, sx: f64, cy: f64) -> String {
        let vehicle = palette::kind(Kind::Vehicle);
        let w = palette::LEGEND_SYMBOL_PX;
        // a body in a kind's colours, its front (right) dark: as actors are drawn
        let body = |st: palette::KindStyle| {
            format!(
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"10\" fill=\"{}\" stroke=\"{}\"/><rect x=\"{}\" y=\"{}\" width=\"5\" height=\"10\" fill=\"{}\"/>",
                n(sx),
                n(cy - 5.0),
                n(w),
                st.fill.hex(),
                st.dark.hex(),
                n(sx + w - 5.0),
                n(cy - 5.0),
                st.dark.hex()
            )
        };
        match self {
            Entry::Kind(k) => body(palette::kind(*k)),
            Entry::Start => format!(
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"10\" fill=\"none\" stroke=\"{}\" stroke-dasharray=\"3 2\"/>",
                n(sx),
                n(cy - 5.0),
                n(w),
                vehicle.dark.hex()
            ),
            Entry::End => body(vehicle),
            Entry::Trajectory => format!(
                "<path d=\"M{} {} H{} M{} {} V{} M{} {} V{}\" stroke=\"{}\" stroke-width=\"2\" fill=\"none\"/>",
                n(sx),
                n(cy),
                n(sx + w),
                n(sx + 9.0),
                n(cy - 4.0),
                n(cy + 4.0),
                n(sx + 19.0),
                n(cy - 4.0),
                n(cy + 4.0),
                vehicle.fill.hex()
            ),
            Entry::Route => format!(
                "<path d=\"M{} {} H{}\" stroke=\"{}\" stroke-width=\"2\" stroke-dasharray=\"4 3\"/>",
                n(sx),
                n(cy),
                n(sx + w),
                palette::ROUTE.hex()
            ),
            Entry::Event => format!(
                "<circle cx=\"{x}\" cy=\"{y}\" r=\"6\" fill=\"none\" stroke=\"{}\" stroke-width=\"4\"/><circle cx=\"{x}\" cy=\"{y}\" r=\"6\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>",
                palette::EVENT_EDGE.hex(),
                palette::EVENT.hex(),
                x = n(sx + w / 2.0),
                y = n(cy)
            ),
            Entry::Light(l) => format!(
                "<circle cx=\"{}\" cy=\"{}\" r=\"5\" fill=\"{}\" stroke=\"{}\"/>",
                n(sx + w / 2.0),
                n(cy),
                palette::light(*l).hex(),
                palette::INK.hex()
            ),
            Entry::Note(_) => String::new(),
        }
    }
}
