//! Two corpora compared: every distance with a bootstrap interval.
//!
//! Each of `resamples` rounds draws both corpora again with replacement (one seeded
//! generator, so a seed gives the same intervals everywhere) and recomputes every
//! distance. The value is the distance between the corpora as given; the interval is the
//! basic (reverse-percentile) bootstrap interval, `[2v − q97.5, 2v − q2.5]` of the
//! resampled values `q`, clipped to the measure's range (JSD in [0, 1], the Wasserstein
//! and Fréchet distances at least 0; squared MMD's unbiased estimate may be negative).
//! Not the plain percentiles: a resample repeats scenarios, which makes two samples look
//! more different than they are, so plug-in distances of resamples sit above the value,
//! often all of them; reflecting the percentiles about the value corrects that bias.

use std::collections::BTreeMap;

use serde::Serialize;
use tad_ir::{Rng, SplitMix64};

use crate::distance::{self, Kernel};
use crate::features::{ATTRIBUTES, Features};
use crate::stats::histogram;

#[derive(Clone, Copy, Debug)]
pub struct Options {
    pub resamples: usize,
    pub seed: u64,
}

impl Default for Options {
    fn default() -> Self {
        Options { resamples: 200, seed: 0 }
    }
}

/// A distance and its bootstrap interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Interval {
    pub value: f64,
    pub low: f64,
    pub high: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    pub a: String,
    pub b: String,
    pub scenarios: [usize; 2],
    /// Jensen–Shannon divergence (base 2) per attribute, and `mean` over the attributes.
    pub jsd: BTreeMap<String, Interval>,
    pub actor_count_wasserstein: Interval,
    /// Squared MMD (unbiased) of the embeddings; `None` without embeddings.
    pub mmd: Option<Interval>,
    pub frechet: Option<Interval>,
    pub embedding: Option<String>,
    pub resamples: usize,
    pub seed: u64,
}

/// The embeddings of both corpora (one per scenario, in order) and the model's name.
pub struct Embeddings<'a> {
    pub model: String,
    pub a: &'a [Vec<f32>],
    pub b: &'a [Vec<f32>],
}

pub fn compare(
    (name_a, a): (&str, &[Features]),
    (name_b, b): (&str, &[Features]),
    embeddings: Option<Embeddings>,
    options: Options,
) -> Comparison {
    let all_a: Vec<usize> = (0..a.len()).collect();
    let all_b: Vec<usize> = (0..b.len()).collect();
    let pooled: Option<Vec<Vec<f32>>> = embeddings.as_ref().map(|e| e.a.iter().chain(e.b).cloned().collect());
    let kernel = pooled.as_ref().filter(|p| !p.is_empty()).map(|p| Kernel::new(p));
    let measure = |ia: &[usize], ib: &[usize]| -> Vec<f64> {
        let mut out = Vec::with_capacity(ATTRIBUTES.len() + 4);
        let mut sum = 0.0;
        for attr in ATTRIBUTES {
            let d = distance::jsd(
                &histogram(ia.iter().map(|&i| &a[i]), attr.key),
                &histogram(ib.iter().map(|&i| &b[i]), attr.key),
            );
            sum += d;
            out.push(d);
        }
        out.push(sum / ATTRIBUTES.len() as f64);
        let counts = |s: &[Features], idx: &[usize]| idx.iter().map(|&i| s[i].actors as f64).collect::<Vec<_>>();
        out.push(distance::wasserstein1(&counts(a, ia), &counts(b, ib)));
        if let (Some(k), Some(e)) = (&kernel, &embeddings) {
            let shifted: Vec<usize> = ib.iter().map(|i| i + a.len()).collect();
            out.push(k.mmd2(ia, &shifted));
            let ra: Vec<&[f32]> = ia.iter().map(|&i| e.a[i].as_slice()).collect();
            let rb: Vec<&[f32]> = ib.iter().map(|&i| e.b[i].as_slice()).collect();
            out.push(distance::frechet(&ra, &rb));
        }
        out
    };
    let point = measure(&all_a, &all_b);
    let mut rng = SplitMix64::new(options.seed);
    let mut draws: Vec<Vec<f64>> = vec![Vec::with_capacity(options.resamples); point.len()];
    for _ in 0..options.resamples {
        let ia: Vec<usize> = (0..a.len()).map(|_| rng.below(a.len())).collect();
        let ib: Vec<usize> = (0..b.len()).map(|_| rng.below(b.len())).collect();
        for (slot, v) in draws.iter_mut().zip(measure(&ia, &ib)) {
            slot.push(v);
        }
    }
    let n = ATTRIBUTES.len();
    let interval = |i: usize| {
        let range = match i {
            _ if i <= n => (0.0, 1.0),
            _ if i == n + 2 => (f64::NEG_INFINITY, f64::INFINITY),
            _ => (0.0, f64::INFINITY),
        };
        basic_interval(point[i], &draws[i], range)
    };
    let mut jsd: BTreeMap<String, Interval> =
        ATTRIBUTES.iter().enumerate().map(|(i, attr)| (attr.key.to_string(), interval(i))).collect();
    jsd.insert("mean".into(), interval(n));
    Comparison {
        a: name_a.to_string(),
        b: name_b.to_string(),
        scenarios: [a.len(), b.len()],
        jsd,
        actor_count_wasserstein: interval(n + 1),
        mmd: kernel.as_ref().map(|_| interval(n + 2)),
        frechet: kernel.as_ref().map(|_| interval(n + 3)),
        embedding: embeddings.map(|e| e.model),
        resamples: options.resamples,
        seed: options.seed,
    }
}

/// The basic bootstrap 95 % interval of `value` from its resampled values, clipped to
/// `range` and holding the value; the value alone without resamples.
pub fn basic_interval(value: f64, resampled: &[f64], (floor, ceiling): (f64, f64)) -> Interval {
    let mut v: Vec<f64> = resampled.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() || !value.is_finite() {
        return Interval { value, low: value, high: value };
    }
    v.sort_by(f64::total_cmp);
    let quantile = |q: f64| {
        let at = q * (v.len() - 1) as f64;
        let (i, t) = (at.floor() as usize, at.fract());
        v[i] + t * (v[(i + 1).min(v.len() - 1)] - v[i])
    };
    let low = (2.0 * value - quantile(0.975)).clamp(floor, ceiling).min(value);
    let high = (2.0 * value - quantile(0.025)).clamp(floor, ceiling).max(value);
    Interval { value, low, high }
}

impl Comparison {
    /// A Markdown table: each distance with its interval.
    pub fn markdown(&self) -> String {
        let mut out = format!(
            "{} ({} scenarios) vs {} ({} scenarios); 95% intervals: basic bootstrap over {} resamples, seed {}, clipped to each distance's range\n\n| distance | value | 95% interval |\n|---|---:|---|\n",
            self.a, self.scenarios[0], self.b, self.scenarios[1], self.resamples, self.seed
        );
        let row = |out: &mut String, name: &str, i: &Interval| {
            out.push_str(&format!("| {name} | {:.4} | [{:.4}, {:.4}] |\n", i.value, i.low, i.high));
        };
        row(&mut out, "JSD, mean over attributes", &self.jsd["mean"]);
        row(&mut out, "actor count, Wasserstein-1", &self.actor_count_wasserstein);
        if let (Some(m), Some(f), Some(model)) = (&self.mmd, &self.frechet, &self.embedding) {
            row(&mut out, &format!("MMD² ({model})"), m);
            row(&mut out, &format!("Fréchet ({model})"), f);
        }
        for attr in ATTRIBUTES {
            row(&mut out, &format!("JSD {}", attr.key), &self.jsd[attr.key]);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_reflect_the_percentiles_and_stay_in_range() {
        // resamples spread 0.45..0.75 about a value of 0.5: reflected about it
        let draws: Vec<f64> = (0..=100).map(|k| 0.45 + 0.3 * k as f64 / 100.0).collect();
        let i = basic_interval(0.5, &draws, (0.0, 1.0));
        assert!((i.low - (1.0 - 0.7425)).abs() < 1e-9 && (i.high - (1.0 - 0.4575)).abs() < 1e-9, "{i:?}");
        // all of them above the value: the interval still holds it
        let above: Vec<f64> = draws.iter().map(|d| d + 0.2).collect();
        let i = basic_interval(0.5, &above, (0.0, 1.0));
        assert!(i.low <= i.value && i.value == i.high, "{i:?}");
        // a JSD near its ceiling does not pass it, nor a distance its floor
        let wide: Vec<f64> = (0..=100).map(|k| 0.5 + k as f64 / 100.0).collect();
        assert_eq!(basic_interval(0.98, &wide, (0.0, 1.0)).high, 1.0);
        assert_eq!(basic_interval(0.02, &wide, (0.0, f64::INFINITY)).low, 0.0);
        assert_eq!(basic_interval(0.3, &[], (0.0, 1.0)), Interval { value: 0.3, low: 0.3, high: 0.3 });
    }
}
