//! Plots as standalone SVG: grouped bar charts of histograms, bars of scores with their
//! 95 % intervals as error bars and the number of episodes over each ([`grouped`]), and a
//! scatter of embeddings projected to two dimensions (PCA over the pooled points, like the
//! paper's Figure 3, which uses UMAP). Colours are the Okabe–Ito palette (distinguishable
//! with colour blindness); text is escaped; the output is deterministic.
//!
//! Text is not measured: a character is taken as [`CHAR_EM`] font sizes wide, enough for
//! the fonts viewers substitute for Helvetica, and every margin is sized from the longest
//! text it holds (tick labels, slanted group names, legend entries), so nothing is clipped.
//! Axes carry titles; data that would fall outside the frame (an interval past the axis,
//! a non-finite point) is left out or the axis widened, never drawn over the edge.

use std::fmt::Write;

use crate::stats::{Histogram, Stats};

const COLOURS: &[&str] = &["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#D55E00", "#F0E442", "#000000"];
const FONT: &str = "font-family=\"Helvetica, Arial, sans-serif\"";

/// A character's width in font sizes (see the module's header).
const CHAR_EM: f64 = 0.62;

/// A text's estimated width, px.
fn text_width(text: &str, font: f64) -> f64 {
    text.chars().count() as f64 * font * CHAR_EM
}

/// A legend's width, px: the swatch and the longest name.
fn legend_width(names: &[&str]) -> f64 {
    18.0 + names.iter().map(|n| text_width(n, 12.0)).fold(0.0, f64::max) + 12.0
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn legend(out: &mut String, names: &[&str], x: f64, y: f64) {
    for (i, name) in names.iter().enumerate() {
        let yy = y + i as f64 * 18.0;
        let _ = write!(
            out,
            "<rect x=\"{x}\" y=\"{}\" width=\"12\" height=\"12\" fill=\"{}\"/><text x=\"{}\" y=\"{}\" font-size=\"12\" {FONT}>{}</text>",
            yy - 10.0,
            COLOURS[i % COLOURS.len()],
            x + 18.0,
            yy,
            escape(name)
        );
    }
}

/// The plots of corpora's statistics, as (name, SVG): one bar chart per attribute, and
/// the actors per scenario.
pub fn corpora(all: &[Stats]) -> Vec<(String, String)> {
    let mut plots = Vec::new();
    for a in crate::ATTRIBUTES {
        let sets: Vec<(&str, &Histogram)> = all.iter().map(|s| (s.corpus.as_str(), &s.histograms[a.key])).collect();
        plots.push((a.key.to_string(), bars(a.title, &sets, 20)));
    }
    let counts: Vec<(String, Histogram)> = all
        .iter()
        .map(|s| (s.corpus.clone(), s.actor_counts.iter().map(|(n, c)| (format!("{n:>3}"), *c)).collect()))
        .collect();
    let sets: Vec<(&str, &Histogram)> = counts.iter().map(|(n, h)| (n.as_str(), h)).collect();
    plots.push(("actors".to_string(), bars("Actors per scenario", &sets, 30)));
    plots
}

/// One bar of [`grouped`]: its cluster, its series (its colour), its value, its 95 %
/// interval `(low, high)` when there is one, and how many episodes it stands for.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    pub group: String,
    pub series: String,
    pub value: f64,
    pub interval: Option<(f64, f64)>,
    pub n: usize,
}

/// Scores as bars: one cluster per group, one colour per series, like the paper's bar
/// charts of OS by method and agent; each bar with its interval as an error bar and `n`
/// over it. `axes` are the x and y axes' titles. The y axis runs from 0 to 1, widened to
/// hold every finite value and interval.
pub fn grouped(title: &str, axes: (&str, &str), bars: &[Bar]) -> String {
    let mut groups: Vec<&str> = Vec::new();
    let mut series: Vec<&str> = Vec::new();
    for b in bars {
        if !groups.contains(&b.group.as_str()) {
            groups.push(&b.group);
        }
        if !series.contains(&b.series.as_str()) {
            series.push(&b.series);
        }
    }
    let finite = bars.iter().flat_map(|b| [Some(b.value), b.interval.map(|i| i.0), b.interval.map(|i| i.1)]).flatten();
    let finite: Vec<f64> = finite.filter(|v| v.is_finite()).collect();
    let y0 = (finite.iter().copied().fold(0.0f64, f64::min) * 4.0).floor() / 4.0;
    let y1 = (finite.iter().copied().fold(1.0f64, f64::max) * 4.0).ceil() / 4.0;
    let (bar, plot_h, font) = (22.0, 260.0, 11.0);
    let cluster = bar * series.len().max(1) as f64 + 28.0;
    // slanted group names: (width, height) of each at -35°
    let (sin, cos) = (35f64.to_radians().sin(), 35f64.to_radians().cos());
    let slant = |g: &str| (text_width(g, font) * cos, text_width(g, font) * sin + font);
    let first_reach = groups.first().map_or(0.0, |g| slant(g).0) - cluster / 2.0;
    let left = (64.0f64).max(first_reach + 24.0);
    let top = 56.0;
    let below = groups.iter().map(|g| slant(g).1).fold(0.0, f64::max) + 48.0;
    let plot_w = cluster * groups.len().max(1) as f64;
    let legend_w = legend_width(&series).max(text_width("whiskers: 95 % interval", 11.0) + 12.0);
    let width = left + plot_w + 24.0 + legend_w;
    let height = top + plot_h + below;
    let y_of = |v: f64| top + plot_h * (1.0 - (v - y0) / (y1 - y0).max(1e-9));
    let mut out = String::new();
    let _ = write!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" height=\"{height:.0}\" viewBox=\"0 0 {width:.0} {height:.0}\" {FONT}>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{left:.1}\" y=\"24\" font-size=\"15\">{}</text>\n",
        escape(title)
    );
    let ticks = ((y1 - y0) / 0.25).round().max(1.0) as usize;
    for k in 0..=ticks {
        let v = y0 + k as f64 * 0.25;
        let y = y_of(v);
        let _ = writeln!(
            out,
            "<line x1=\"{left:.1}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"{font}\" text-anchor=\"end\">{v:.2}</text>",
            left + plot_w,
            left - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        out,
        "<line x1=\"{left:.1}\" y1=\"{top:.1}\" x2=\"{left:.1}\" y2=\"{:.1}\" stroke=\"black\"/><line x1=\"{left:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\"/>",
        top + plot_h,
        y_of(y0.max(0.0)),
        left + plot_w,
        y_of(y0.max(0.0))
    );
    let (ty, tx) = (top + plot_h / 2.0, left - 44.0);
    let _ = writeln!(
        out,
        "<text class=\"axis-title\" x=\"{tx:.1}\" y=\"{ty:.1}\" font-size=\"12\" text-anchor=\"middle\" transform=\"rotate(-90 {tx:.1} {ty:.1})\">{}</text>",
        escape(axes.1)
    );
    let _ = writeln!(
        out,
        "<text class=\"axis-title\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\">{}</text>",
        left + plot_w / 2.0,
        height - 10.0,
        escape(axes.0)
    );
    for (gi, g) in groups.iter().enumerate() {
        let x0 = left + 14.0 + gi as f64 * cluster;
        for (si, s) in series.iter().enumerate() {
            let Some(b) = bars.iter().find(|b| b.group == *g && b.series == *s) else { continue };
            bar_with_interval(&mut out, b, x0 + si as f64 * bar, bar - 3.0, COLOURS[si % COLOURS.len()], &y_of, y0);
        }
        let cx = x0 + bar * series.len() as f64 / 2.0;
        let gy = top + plot_h + 16.0;
        let _ = write!(
            out,
            "<text class=\"group\" x=\"{cx:.1}\" y=\"{gy:.1}\" font-size=\"{font}\" text-anchor=\"end\" transform=\"rotate(-35 {cx:.1} {gy:.1})\">{}</text>",
            escape(g)
        );
    }
    legend(&mut out, &series, left + plot_w + 24.0, top + 10.0);
    let _ = write!(
        out,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"#444\">numbers: episodes</text><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"#444\">whiskers: 95 % interval</text>",
        left + plot_w + 24.0,
        top + 10.0 + series.len() as f64 * 18.0 + 8.0,
        left + plot_w + 24.0,
        top + 10.0 + series.len() as f64 * 18.0 + 24.0
    );
    out.push_str("</svg>\n");
    out
}

/// One bar of [`grouped`] at `x`, `w` wide: the bar, its error bar (whiskers capped), and
/// its `n` (episodes) above both.
fn bar_with_interval(out: &mut String, b: &Bar, x: f64, w: f64, colour: &str, y_of: &dyn Fn(f64) -> f64, y0: f64) {
    if !b.value.is_finite() {
        return;
    }
    let base = y_of(y0.max(0.0).min(b.value.max(y0)));
    let (ya, yb) = (y_of(b.value).min(base), y_of(b.value).max(base));
    let _ = write!(
        out,
        "<rect class=\"bar\" x=\"{x:.1}\" y=\"{ya:.1}\" width=\"{w:.1}\" height=\"{:.1}\" fill=\"{colour}\"><title>{}: {:.3}</title></rect>",
        yb - ya,
        escape(&format!("{} · {}", b.group, b.series)),
        b.value
    );
    let mut over = y_of(b.value);
    if let Some((lo, hi)) = b.interval.filter(|(lo, hi)| lo.is_finite() && hi.is_finite()) {
        let (lo, hi) = (lo.min(hi), lo.max(hi));
        let cx = x + w / 2.0;
        let (yl, yh) = (y_of(lo), y_of(hi));
        let _ = write!(
            out,
            "<g class=\"error-bar\" data-low=\"{lo:.4}\" data-high=\"{hi:.4}\" stroke=\"black\" stroke-width=\"1.2\"><line x1=\"{cx:.1}\" y1=\"{yl:.1}\" x2=\"{cx:.1}\" y2=\"{yh:.1}\"/><line x1=\"{:.1}\" y1=\"{yl:.1}\" x2=\"{:.1}\" y2=\"{yl:.1}\"/><line x1=\"{:.1}\" y1=\"{yh:.1}\" x2=\"{:.1}\" y2=\"{yh:.1}\"/></g>",
            cx - 4.0,
            cx + 4.0,
            cx - 4.0,
            cx + 4.0
        );
        over = over.min(yh);
    }
    let _ = write!(
        out,
        "<text class=\"n\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"9\" text-anchor=\"middle\" fill=\"#444\">{}</text>",
        x + w / 2.0,
        over - 4.0,
        b.n
    );
}

/// Shares of each value per corpus, bars side by side; values by total share, at most
/// `max_values` of them.
pub fn bars(title: &str, corpora: &[(&str, &Histogram)], max_values: usize) -> String {
    let tables: Vec<std::collections::BTreeMap<&str, f64>> = corpora
        .iter()
        .map(|(_, h)| {
            let total = h.values().sum::<u32>().max(1) as f64;
            h.iter().map(|(v, c)| (v.as_str(), *c as f64 / total)).collect()
        })
        .collect();
    let share = |c: usize, v: &str| tables[c].get(v).copied().unwrap_or(0.0);
    let mut values: Vec<(String, f64)> = Vec::new();
    for (_, h) in corpora {
        for v in h.keys() {
            if !values.iter().any(|(x, _)| x == v) {
                values.push((v.clone(), (0..corpora.len()).map(|c| share(c, v)).sum()));
            }
        }
    }
    values.sort_by(|a, b| b.1.total_cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    values.truncate(max_values.max(1));
    let top = values.iter().flat_map(|(v, _)| (0..corpora.len()).map(|c| share(c, v))).fold(0.0f64, f64::max).max(0.01);
    let top = (top * 10.0).ceil() / 10.0;
    let (left, right, upper, lower) = (60.0, 170.0, 40.0, 120.0);
    let group = (corpora.len() as f64 * 14.0 + 10.0).max(24.0);
    let width = left + right + group * values.len().max(1) as f64;
    let height = 360.0;
    let plot_h = height - upper - lower;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    let _ = writeln!(out, "<text x=\"{left}\" y=\"24\" font-size=\"16\" {FONT}>{}</text>", escape(title));
    for tick in 0..=5 {
        let share = top * tick as f64 / 5.0;
        let y = upper + plot_h * (1.0 - share / top);
        let _ = writeln!(
            out,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y}\" y2=\"{y}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"end\" {FONT}>{:.0}%</text>",
            width - right,
            left - 6.0,
            y + 4.0,
            share * 100.0
        );
    }
    for (i, (v, _)) in values.iter().enumerate() {
        let x0 = left + i as f64 * group + 5.0;
        for c in 0..corpora.len() {
            let p = share(c, v);
            let h = plot_h * p / top;
            let _ = write!(
                out,
                "<rect x=\"{}\" y=\"{}\" width=\"12\" height=\"{h}\" fill=\"{}\"><title>{}: {:.1}%</title></rect>",
                x0 + c as f64 * 14.0,
                upper + plot_h - h,
                COLOURS[c % COLOURS.len()],
                escape(&format!("{} {v}", corpora[c].0)),
                p * 100.0
            );
        }
        let cx = x0 + corpora.len() as f64 * 7.0;
        let _ = writeln!(
            out,
            "<text transform=\"translate({cx},{}) rotate(-45)\" font-size=\"11\" text-anchor=\"end\" {FONT}>{}</text>",
            upper + plot_h + 14.0,
            escape(&v.replace('_', " "))
        );
    }
    let _ = writeln!(
        out,
        "<line x1=\"{left}\" x2=\"{}\" y1=\"{}\" y2=\"{}\" stroke=\"black\"/>",
        width - right,
        upper + plot_h,
        upper + plot_h
    );
    let names: Vec<&str> = corpora.iter().map(|(n, _)| *n).collect();
    legend(&mut out, &names, width - right + 16.0, upper + 10.0);
    out.push_str("</svg>\n");
    out
}

/// The first two principal components of `points` (rows), as coordinates.
pub fn pca(points: &[Vec<f32>]) -> Vec<[f64; 2]> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    let d = points[0].len();
    let mut mean = vec![0f64; d];
    for p in points {
        for (m, x) in mean.iter_mut().zip(p) {
            *m += *x as f64 / n as f64;
        }
    }
    let x = nalgebra::DMatrix::from_fn(n, d, |i, j| points[i][j] as f64 - mean[j]);
    // the principal directions are the top eigenvectors of the n×n Gram matrix mapped back
    let gram = &x * x.transpose();
    let eigen = gram.symmetric_eigen();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let component = |k: usize| -> Vec<f64> {
        let Some(&i) = order.get(k) else { return vec![0.0; n] };
        let v = eigen.eigenvectors.column(i);
        let scale = eigen.eigenvalues[i].max(0.0).sqrt();
        // a deterministic sign: the largest coordinate positive
        let sign = if v.iter().fold(0.0f64, |m, x| if x.abs() > m.abs() { *x } else { m }) < 0.0 { -1.0 } else { 1.0 };
        v.iter().map(|x| x * scale * sign).collect()
    };
    let (c1, c2) = (component(0), component(1));
    (0..n).map(|i| [c1[i], c2[i]]).collect()
}

/// The first two principal components of `points` (as [`pca`]) and the share of the
/// total variance each explains (0 for points without spread).
pub fn pca_explained(points: &[Vec<f32>]) -> (Vec<[f64; 2]>, [f64; 2]) {
    let projected = pca(points);
    let n = points.len().max(1) as f64;
    let d = points.first().map_or(0, |p| p.len());
    let mut total = 0.0;
    for j in 0..d {
        let mean = points.iter().map(|p| p.get(j).copied().unwrap_or(0.0) as f64).sum::<f64>() / n;
        total += points.iter().map(|p| (p.get(j).copied().unwrap_or(0.0) as f64 - mean).powi(2)).sum::<f64>();
    }
    let share = |k: usize| {
        let v: f64 = projected.iter().map(|p| p[k] * p[k]).sum();
        if total > 0.0 { v / total } else { 0.0 }
    };
    let explained = [share(0), share(1)];
    (projected, explained)
}

/// A scatter plot of labelled point sets projected on their first two principal
/// components, each axis titled with the share of the variance it explains
/// ([`pca_explained`]).
pub fn scatter(title: &str, explained: [f64; 2], sets: &[(&str, Vec<[f64; 2]>)]) -> String {
    let axis = |k: usize| format!("PC{} ({:.0} % of the variance)", k + 1, explained[k] * 100.0);
    scatter_axes(title, (&axis(0), &axis(1)), sets)
}

/// A scatter plot of labelled 2-D point sets with the x and y axes' titles: every finite
/// point inside the frame (non-finite ones are left out), ticks on both axes.
pub fn scatter_axes(title: &str, axes: (&str, &str), sets: &[(&str, Vec<[f64; 2]>)]) -> String {
    let finite = |p: &&[f64; 2]| p[0].is_finite() && p[1].is_finite();
    let all: Vec<[f64; 2]> = sets.iter().flat_map(|(_, p)| p.iter().filter(finite).copied()).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for [x, y] in &all {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    if all.is_empty() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let (sx, sy) = ((x1 - x0).max(1e-9), (y1 - y0).max(1e-9));
    let names: Vec<&str> = sets.iter().map(|(n, _)| *n).collect();
    let (size, left, top, inset) = (480.0, 72.0, 44.0, 10.0);
    let below = 56.0;
    let width = left + size + 24.0 + legend_width(&names);
    let height = top + size + below;
    let px = |x: f64| left + inset + (size - 2.0 * inset) * (x - x0) / sx;
    let py = |y: f64| top + inset + (size - 2.0 * inset) * (1.0 - (y - y0) / sy);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" height=\"{height:.0}\" viewBox=\"0 0 {width:.0} {height:.0}\" {FONT}>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    let _ = writeln!(out, "<text x=\"{left}\" y=\"24\" font-size=\"15\">{}</text>", escape(title));
    let _ = writeln!(
        out,
        "<rect class=\"plot-area\" x=\"{left}\" y=\"{top}\" width=\"{size}\" height=\"{size}\" fill=\"none\" stroke=\"#999\"/>"
    );
    let frame = Frame { left, top, width: size, height: size };
    grid(
        &mut out,
        &frame,
        nice_ticks(x0, x1).into_iter().map(|v| (v, px(v))),
        nice_ticks(y0, y1).into_iter().map(|v| (v, py(v))),
    );
    for (c, (name, points)) in sets.iter().enumerate() {
        let _ = write!(
            out,
            "<g class=\"points\" fill=\"{}\" fill-opacity=\"0.6\"><title>{}</title>",
            COLOURS[c % COLOURS.len()],
            escape(name)
        );
        for [x, y] in points.iter().filter(finite) {
            let _ = write!(out, "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\"/>", px(*x), py(*y));
        }
        out.push_str("</g>\n");
    }
    let (ty, tx) = (top + size / 2.0, 16.0);
    let _ = writeln!(
        out,
        "<text class=\"axis-title\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\">{}</text>\n<text class=\"axis-title\" x=\"{tx}\" y=\"{ty:.1}\" font-size=\"12\" text-anchor=\"middle\" transform=\"rotate(-90 {tx} {ty:.1})\">{}</text>",
        left + size / 2.0,
        height - 14.0,
        escape(axes.0),
        escape(axes.1)
    );
    legend(&mut out, &names, left + size + 24.0, top + 10.0);
    out.push_str("</svg>\n");
    out
}

/// Round values from `lo` to `hi`: multiples of 1, 2 or 5 times a power of ten, the finest
/// such step that gives at most six of them (none for a range that is not finite and
/// positive).
fn nice_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let range = hi - lo;
    if !(range.is_finite() && range > 0.0) {
        return Vec::new();
    }
    let p = 10f64.powf((range / 6.0).log10().floor());
    // a hair of slack, so that 0.8 / 0.2 is 4, not 3.9999999
    let span = |step: f64| ((lo / step - 1e-9).ceil() as i64, (hi / step + 1e-9).floor() as i64);
    let step = [1.0, 2.0, 5.0, 10.0, 20.0]
        .into_iter()
        .map(|k| k * p)
        .find(|&s| {
            let (first, last) = span(s);
            last - first < 6
        })
        .unwrap_or(20.0 * p);
    let (first, last) = span(step);
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick's value, short: two significant decimals at most.
fn tick(v: f64) -> String {
    let s = if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    };
    if s.starts_with('-') && s.trim_start_matches(['-', '0', '.']).is_empty() { s[1..].to_string() } else { s }
}

/// A plot's frame, in pixels.
struct Frame {
    left: f64,
    top: f64,
    width: f64,
    height: f64,
}

/// Grid lines across `frame` at each tick, labelled below it (`x-tick`) and left of it
/// (`y-tick`); a tick is its value and its pixel.
fn grid(out: &mut String, frame: &Frame, xs: impl Iterator<Item = (f64, f64)>, ys: impl Iterator<Item = (f64, f64)>) {
    let Frame { left, top, width, height } = *frame;
    for (value, x) in xs {
        let _ = writeln!(
            out,
            "<line x1=\"{x:.1}\" y1=\"{top}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#eee\"/><text class=\"x-tick\" x=\"{x:.1}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"middle\" {FONT}>{}</text>",
            top + height,
            top + height + 14.0,
            tick(value)
        );
    }
    for (value, y) in ys {
        let _ = writeln!(
            out,
            "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#eee\"/><text class=\"y-tick\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"end\" {FONT}>{}</text>",
            left + width,
            left - 5.0,
            y + 3.5,
            tick(value)
        );
    }
}

/// A panel of [`curves`]: its y label and its named series of (x, y) points.
pub type Panel<'a> = (&'a str, Vec<(&'a str, Vec<[f64; 2]>)>);

/// Line charts stacked over one x axis: each panel a y label and named series of (x, y)
/// points, each panel scaled to its own range with round ticks on both axes (training
/// curves: return and collision rate over episodes).
pub fn curves(title: &str, x_label: &str, panels: &[Panel]) -> String {
    let (plot_w, plot_h, margin, legend_w, gap) = (560.0, 200.0, 56.0, 190.0, 44.0);
    let width = plot_w + 2.0 * margin + legend_w;
    let height = margin + panels.len() as f64 * (plot_h + gap) + 20.0;
    let all = panels.iter().flat_map(|(_, series)| series.iter().flat_map(|(_, p)| p.iter()));
    let (x0, x1) = all.fold((f64::MAX, f64::MIN), |(a, b), [x, _]| (a.min(*x), b.max(*x)));
    let (x0, x1) = if x0 > x1 { (0.0, 1.0) } else { (x0, x1) };
    let sx = (x1 - x0).max(1e-9);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    let _ = writeln!(out, "<text x=\"{margin}\" y=\"24\" font-size=\"16\" {FONT}>{}</text>", escape(title));
    for (k, (label, series)) in panels.iter().enumerate() {
        let top = margin + k as f64 * (plot_h + gap);
        let ys = series.iter().flat_map(|(_, p)| p.iter().map(|[_, y]| *y)).filter(|y| y.is_finite());
        let (y0, y1) = ys.fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(y), b.max(y)));
        let (y0, y1) = if y0 > y1 {
            (0.0, 1.0)
        } else if y0 == y1 {
            (y0 - 0.5, y1 + 0.5)
        } else {
            (y0, y1)
        };
        let sy = y1 - y0;
        let _ = writeln!(
            out,
            "<rect x=\"{margin}\" y=\"{top}\" width=\"{plot_w}\" height=\"{plot_h}\" fill=\"none\" stroke=\"#999\"/>"
        );
        let frame = Frame { left: margin, top, width: plot_w, height: plot_h };
        let xs = nice_ticks(x0, x1).into_iter().map(|v| (v, margin + plot_w * (v - x0) / sx));
        let ys = nice_ticks(y0, y1).into_iter().map(|v| (v, top + plot_h * (1.0 - (v - y0) / sy)));
        grid(&mut out, &frame, xs, ys);
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"12\" {FONT}>{}</text>",
            margin,
            top - 6.0,
            escape(label)
        );
        for (c, (name, points)) in series.iter().enumerate() {
            let path: Vec<String> = points
                .iter()
                .filter(|[_, y]| y.is_finite())
                .map(|[x, y]| {
                    let px = margin + plot_w * (x - x0) / sx;
                    let py = top + plot_h * (1.0 - (y - y0) / sy);
                    format!("{px:.1},{py:.1}")
                })
                .collect();
            let _ = writeln!(
                out,
                "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" points=\"{}\"><title>{}</title></polyline>",
                COLOURS[c % COLOURS.len()],
                path.join(" "),
                escape(name)
            );
        }
        let names: Vec<&str> = series.iter().map(|(n, _)| *n).collect();
        legend(&mut out, &names, margin + plot_w + 16.0, top + 12.0);
    }
    let _ = writeln!(
        out,
        "<text class=\"axis-title\" x=\"{}\" y=\"{}\" font-size=\"12\" text-anchor=\"middle\" {FONT}>{}</text>",
        margin + plot_w / 2.0,
        height - 8.0,
        escape(x_label)
    );
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pca_finds_the_spread_direction() {
        // points along (1, 1, 0) with a little noise in z
        let pts: Vec<Vec<f32>> = (0..10).map(|i| vec![i as f32, i as f32, (i % 2) as f32 * 0.1]).collect();
        let p = pca(&pts);
        let spread1 = p.iter().map(|q| q[0].abs()).fold(0.0, f64::max);
        let spread2 = p.iter().map(|q| q[1].abs()).fold(0.0, f64::max);
        assert!(spread1 > 6.0 && spread2 < 0.2, "{spread1} {spread2}");
        // first component ordered like the points
        assert!(p.windows(2).all(|w| w[0][0] < w[1][0]) || p.windows(2).all(|w| w[0][0] > w[1][0]));
    }

    #[test]
    fn svg_is_escaped_and_well_formed() {
        let mut h = Histogram::new();
        h.insert("a<b".into(), 2);
        let svg = bars("x & y", &[("one", &h), ("two", &h)], 10);
        assert!(svg.contains("a&lt;b") && svg.contains("x &amp; y"));
        assert_eq!(svg.matches("<svg").count(), 1);
        assert!(svg.trim_end().ends_with("</svg>"));
        let c = curves("r & c", "episode", &[("return", vec![("a<", vec![[0.0, 1.0], [10.0, 2.0]])]), ("CR", vec![])]);
        assert!(c.contains("a&lt;") && c.contains("r &amp; c") && c.matches("<polyline").count() == 1);
        assert!(c.trim_end().ends_with("</svg>"));
        let s = scatter("t", [0.5, 0.25], &[("a", vec![[0.0, 0.0], [1.0, 2.0]]), ("b", vec![])]);
        assert_eq!(s.matches("<circle").count(), 2);
    }

    /// The numbers of an attribute `name="…"` in order of appearance.
    fn numbers(svg: &str, name: &str) -> Vec<f64> {
        let key = format!(" {name}=\"");
        svg.split(&key).skip(1).filter_map(|rest| rest.split('"').next()?.parse().ok()).collect()
    }

    fn bar(group: &str, series: &str, value: f64, interval: Option<(f64, f64)>, n: usize) -> Bar {
        Bar { group: group.into(), series: series.into(), value, interval, n }
    }

    #[test]
    fn grouped_bars_have_error_bars_counts_and_titled_axes() {
        let long = "a very long region name · generator";
        let bars = [
            bar(long, "idm", 0.8, Some((0.7, 0.9)), 24),
            bar(long, "naive", 0.5, Some((0.41, 0.62)), 24),
            bar("b", "idm", 0.95, Some((0.9, 1.2)), 7),
            bar("b", "naive", 0.3, None, 3),
        ];
        let svg = grouped("OS", ("region · generator", "overall score"), &bars);
        assert_eq!(svg.matches("class=\"bar\"").count(), 4);
        assert_eq!(numbers(&svg, "data-low"), vec![0.7, 0.41, 0.9], "the intervals' values");
        assert_eq!(numbers(&svg, "data-high"), vec![0.9, 0.62, 1.2]);
        assert!(svg.contains(">24</text>") && svg.contains(">7</text>") && svg.contains(">3</text>"), "n per bar");
        assert!(svg.contains(">overall score</text>") && svg.contains(">region · generator</text>"), "axis titles");
        // the y axis grew to hold the interval past 1; the error bar stays inside the plot
        assert!(svg.contains(">1.25</text>"));
        let width = numbers(&svg, "width")[0];
        // the slanted group name of the first cluster starts right of the picture's left edge
        let xs = numbers(&svg, "x");
        assert!(xs.iter().all(|x| *x >= 0.0 && *x <= width), "{xs:?}");
        let first = svg.split("class=\"group\" x=\"").nth(1).and_then(|r| r.split('"').next()?.parse::<f64>().ok());
        let reach = long.chars().count() as f64 * 11.0 * CHAR_EM * 35f64.to_radians().cos();
        assert!(first.is_some_and(|x| x - reach >= 0.0), "{first:?} - {reach} clips the first group's name");
    }

    #[test]
    fn curves_tick_both_axes_with_round_values_inside_each_panel() {
        let ret: Vec<[f64; 2]> = (0..=300).map(|e| [e as f64, -40.0 + 0.37 * e as f64]).collect();
        let rate: Vec<[f64; 2]> = (0..=300).map(|e| [e as f64, 0.8 - 0.002 * e as f64]).collect();
        let svg = curves("t", "episode", &[("return", vec![("sac", ret)]), ("collision rate", vec![("sac", rate)])]);
        let labels = |class: &str| -> Vec<f64> {
            let marker = format!("class=\"{class}\"");
            svg.split(&marker).skip(1).filter_map(|r| r.split('>').nth(1)?.split('<').next()?.parse().ok()).collect()
        };
        let (y, x) = (labels("y-tick"), labels("x-tick"));
        // return -40..71: ticks every 20 from -40; rate 0.2..0.8: every 0.1 or 0.2
        assert!(y.contains(&-40.0) && y.contains(&60.0) && y.contains(&0.2) && y.contains(&0.8), "{y:?}");
        assert!(y.iter().all(|v| (-40.0..=71.0).contains(v)), "a tick outside its panel's range: {y:?}");
        assert_eq!(x.iter().filter(|v| **v == 0.0 || **v == 300.0).count(), 4, "both ends, on both panels: {x:?}");
        assert!(x.len() >= 8 && x.windows(2).all(|w| w[0] < w[1] || w[1] == 0.0), "{x:?}");
        assert!(svg.contains(">episode</text>"));
    }

    #[test]
    fn scatter_keeps_every_point_inside_the_frame_and_titles_its_axes() {
        let points: Vec<[f64; 2]> = (0..50).map(|i| [(i as f64).sin() * 1e3, (i as f64 * 0.7).cos() - 5.0]).collect();
        let s = scatter_axes("t", ("PC1 (41 %)", "PC2 (12 %)"), &[("a", points), ("b", vec![[f64::NAN, 1.0]])]);
        let area = s.split("class=\"plot-area\"").nth(1).expect("the plot area");
        let n = |k: &str| numbers(area, k)[0];
        let (x, y, w, h) = (n("x"), n("y"), n("width"), n("height"));
        let (cx, cy) = (numbers(&s, "cx"), numbers(&s, "cy"));
        assert_eq!(cx.len(), 50, "the non-finite point is left out");
        for (px, py) in cx.iter().zip(&cy) {
            assert!(*px - 4.0 >= x && *px + 4.0 <= x + w && *py - 4.0 >= y && *py + 4.0 <= y + h, "({px}, {py})");
        }
        assert!(s.contains(">PC1 (41 %)</text>") && s.contains(">PC2 (12 %)</text>"));
        assert!(scatter("t", [0.5, 0.25], &[]).contains("PC1"));
        let (p, explained) = pca_explained(&[vec![0.0, 0.0], vec![2.0, 0.1], vec![4.0, -0.1]]);
        assert_eq!(p.len(), 3);
        assert!(explained[0] > 0.99 && explained[0] + explained[1] <= 1.0 + 1e-9, "{explained:?}");
    }
}
