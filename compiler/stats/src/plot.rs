//! Plots as standalone SVG: grouped bar charts of histograms, and a scatter of embeddings
//! projected to two dimensions (PCA over the pooled points, like the paper's Figure 3,
//! which uses UMAP). Colours are the Okabe–Ito palette (distinguishable with colour
//! blindness); text is escaped; the output is deterministic.

use std::fmt::Write;

use crate::stats::{Histogram, Stats};

const COLOURS: &[&str] = &["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#D55E00", "#F0E442", "#000000"];
const FONT: &str = "font-family=\"Helvetica, Arial, sans-serif\"";

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

/// Values in `[0, 1]` as bars: one cluster per group (the first item), one colour per
/// series (the second), like the paper's bar charts of OS by method and agent.
pub fn grouped(title: &str, bars: &[(String, String, f64)]) -> String {
    let mut groups: Vec<&str> = Vec::new();
    let mut series: Vec<&str> = Vec::new();
    for (g, s, _) in bars {
        if !groups.contains(&g.as_str()) {
            groups.push(g);
        }
        if !series.contains(&s.as_str()) {
            series.push(s);
        }
    }
    let (left, top, height, bar) = (50.0, 40.0, 240.0, 18.0);
    let cluster = bar * series.len().max(1) as f64 + 24.0;
    let width = left + cluster * groups.len().max(1) as f64 + 160.0;
    let mut out = String::new();
    let _ = write!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{}\" viewBox=\"0 0 {width} {}\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/><text x=\"{left}\" y=\"22\" font-size=\"15\" {FONT}>{}</text>",
        top + height + 110.0,
        top + height + 110.0,
        escape(title)
    );
    for k in 0..=4 {
        let v = k as f64 / 4.0;
        let y = top + height * (1.0 - v);
        let _ = write!(
            out,
            "<line x1=\"{left}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"end\" {FONT}>{v:.2}</text>",
            width - 160.0,
            left - 6.0,
            y + 4.0
        );
    }
    for (gi, g) in groups.iter().enumerate() {
        let x0 = left + 12.0 + gi as f64 * cluster;
        for (si, s) in series.iter().enumerate() {
            let Some(v) = bars.iter().find(|(a, b, _)| a == g && b == s).map(|b| b.2.clamp(0.0, 1.0)) else { continue };
            let _ = write!(
                out,
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"><title>{}: {v:.3}</title></rect>",
                x0 + si as f64 * bar,
                top + height * (1.0 - v),
                bar - 2.0,
                height * v,
                COLOURS[si % COLOURS.len()],
                escape(&format!("{g} · {s}"))
            );
        }
        let cx = x0 + bar * series.len() as f64 / 2.0;
        let _ = write!(
            out,
            "<text x=\"{cx}\" y=\"{}\" font-size=\"11\" text-anchor=\"end\" transform=\"rotate(-35 {cx} {})\" {FONT}>{}</text>",
            top + height + 16.0,
            top + height + 16.0,
            escape(g)
        );
    }
    legend(&mut out, &series, width - 140.0, top + 10.0);
    out.push_str("</svg>\n");
    out
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

/// A scatter plot of labelled 2-D point sets.
pub fn scatter(title: &str, sets: &[(&str, Vec<[f64; 2]>)]) -> String {
    let all: Vec<[f64; 2]> = sets.iter().flat_map(|(_, p)| p.iter().copied()).collect();
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
    let (size, margin, legend_w) = (480.0, 40.0, 170.0);
    let width = size + 2.0 * margin + legend_w;
    let height = size + 2.0 * margin;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    let _ = writeln!(out, "<text x=\"{margin}\" y=\"24\" font-size=\"16\" {FONT}>{}</text>", escape(title));
    let _ = writeln!(
        out,
        "<rect x=\"{margin}\" y=\"{margin}\" width=\"{size}\" height=\"{size}\" fill=\"none\" stroke=\"#999\"/>"
    );
    for (c, (name, points)) in sets.iter().enumerate() {
        let _ = write!(
            out,
            "<g fill=\"{}\" fill-opacity=\"0.6\"><title>{}</title>",
            COLOURS[c % COLOURS.len()],
            escape(name)
        );
        for [x, y] in points {
            let px = margin + 8.0 + (size - 16.0) * (x - x0) / sx;
            let py = margin + 8.0 + (size - 16.0) * (1.0 - (y - y0) / sy);
            let _ = write!(out, "<circle cx=\"{px:.1}\" cy=\"{py:.1}\" r=\"4\"/>");
        }
        out.push_str("</g>\n");
    }
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\" {FONT}>first principal component</text>",
        margin + size / 2.0,
        height - 12.0
    );
    let names: Vec<&str> = sets.iter().map(|(n, _)| *n).collect();
    legend(&mut out, &names, margin + size + 16.0, margin + 10.0);
    out.push_str("</svg>\n");
    out
}

/// A panel of [`curves`]: its y label and its named series of (x, y) points.
pub type Panel<'a> = (&'a str, Vec<(&'a str, Vec<[f64; 2]>)>);

/// Line charts stacked over one x axis: each panel a y label and named series of (x, y)
/// points, each panel scaled to its own range (training curves: return and collision rate
/// over episodes).
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
        for (value, y) in [(y1, top + 4.0), (y0, top + plot_h)] {
            let _ = writeln!(
                out,
                "<text x=\"{}\" y=\"{y}\" font-size=\"10\" text-anchor=\"end\" {FONT}>{value:.3}</text>",
                margin - 4.0
            );
        }
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
        "<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\" {FONT}>{} ({x0:.0} to {x1:.0})</text>",
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
        let s = scatter("t", &[("a", vec![[0.0, 0.0], [1.0, 2.0]]), ("b", vec![])]);
        assert_eq!(s.matches("<circle").count(), 2);
    }
}
