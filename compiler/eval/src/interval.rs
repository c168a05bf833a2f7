//! Paired bootstrap intervals for the fine-tuning table: the held-out scenes (each with
//! its seed) resampled with replacement, the same draw for the model before and after, so
//! the change's interval keeps their pairing. CR is the aggregate's collision rate, OS
//! the aggregate's overall score (`tad_metrics::aggregate`, exactly as the table computes
//! them); an interval is the 2.5 and 97.5 percentiles of [`RESAMPLES`] draws.

use std::collections::BTreeMap;

use serde::Serialize;
use tad_ir::{Rng, SplitMix64};
use tad_metrics::{EpisodeScore, Mode};

use crate::results::Row;

/// Bootstrap draws per interval.
pub const RESAMPLES: usize = 2000;

/// A value and its 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Interval {
    pub value: f64,
    pub low: f64,
    pub high: f64,
}

impl Interval {
    /// `value` with the 2.5 and 97.5 percentiles of its bootstrap `draws` (the finite ones).
    pub fn of(value: f64, mut draws: Vec<f64>) -> Interval {
        draws.retain(|v| v.is_finite());
        draws.sort_by(f64::total_cmp);
        let at = |q: f64| draws.get(((draws.len() as f64 - 1.0) * q).round() as usize).copied().unwrap_or(value);
        Interval { value, low: at(0.025), high: at(0.975) }
    }
}

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = f.precision().unwrap_or(3);
        write!(f, "{:.p$} [{:.p$}, {:.p$}]", self.value, self.low, self.high)
    }
}

/// A model before and after fine-tuning on the same held-out scenes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Change {
    pub before: String,
    pub after: String,
    pub scenes: usize,
    pub cr_before: Interval,
    pub cr_after: Interval,
    pub os_before: Interval,
    pub os_after: Interval,
    /// CR after minus before, percentage points.
    pub cr_points: Interval,
    /// CR after over before, minus 1, percent (not finite when CR before is 0).
    pub cr_relative: Interval,
}

/// CR and OS of some episodes.
pub(crate) fn cr_os(scores: &[&EpisodeScore]) -> (f64, f64) {
    let owned: Vec<EpisodeScore> = scores.iter().map(|s| (*s).clone()).collect();
    match tad_metrics::aggregate(&owned, Mode::Fixed) {
        Ok(agg) => (agg.raw.cr, agg.normalised.os),
        Err(_) => (f64::NAN, f64::NAN),
    }
}

/// The change from ego `before` to ego `after` over the scenes both drove; `None` when
/// they share none.
pub fn change(rows: &[Row], before: &str, after: &str, seed: u64) -> Option<Change> {
    let mut pairs: BTreeMap<(&str, u64, usize), [Option<&EpisodeScore>; 2]> = BTreeMap::new();
    for row in rows {
        let side = if row.ego == before {
            0
        } else if row.ego == after {
            1
        } else {
            continue;
        };
        pairs.entry((row.scenario.as_str(), row.seed, row.trial)).or_default()[side] = Some(&row.score);
    }
    let pairs: Vec<[&EpisodeScore; 2]> = pairs.into_values().filter_map(|[a, b]| Some([a?, b?])).collect();
    if pairs.is_empty() {
        return None;
    }
    let measure = |pick: &[usize]| {
        let side = |k: usize| cr_os(&pick.iter().map(|&i| pairs[i][k]).collect::<Vec<_>>());
        let ((cr0, os0), (cr1, os1)) = (side(0), side(1));
        [cr0, cr1, os0, os1, 100.0 * (cr1 - cr0), 100.0 * (cr1 / cr0 - 1.0)]
    };
    let all: Vec<usize> = (0..pairs.len()).collect();
    let value = measure(&all);
    let mut rng = SplitMix64::new(seed ^ 0xB007_5742_u64);
    let mut draws: [Vec<f64>; 6] = Default::default();
    for _ in 0..RESAMPLES {
        let pick: Vec<usize> = (0..pairs.len()).map(|_| rng.below(pairs.len())).collect();
        for (k, v) in measure(&pick).into_iter().enumerate() {
            draws[k].push(v);
        }
    }
    let [d0, d1, d2, d3, d4, d5] = draws;
    Some(Change {
        before: before.to_string(),
        after: after.to_string(),
        scenes: pairs.len(),
        cr_before: Interval::of(value[0], d0),
        cr_after: Interval::of(value[1], d1),
        os_before: Interval::of(value[2], d2),
        os_after: Interval::of(value[3], d3),
        cr_points: Interval::of(value[4], d4),
        cr_relative: Interval::of(value[5], d5),
    })
}
