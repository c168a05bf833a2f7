//! ChatScene's adversarial search on the runtime, and a scenario's source rewritten with the
//! chosen parameters fixed.
//!
//! ```text
//! Scene (parameter slots with ranges) ──search(ego, Config)──▶ Outcome
//!   round r = 0..samples/round:                                  trials (params, collision, OS)
//!     draw `round` parameter vectors from the current ranges     ranges per round
//!     run each once with the ego (in parallel, rayon)            chosen: the most challenging
//!     re-fit each range to mean ± std of every colliding
//!     sample so far (clipped to the slot's own range)
//! ```
//!
//! The rules are ChatScene's (`scenic_runner.py`, `scenic_utils.py`; the numbers are its
//! `train_scenario_scenic.yaml`): 50 samples in rounds of 10; after each round a slot with
//! more than one colliding value so far gets `[max(mean − std, min), min(mean + std, max)]`
//! (population std); the chosen scenes are the colliding ones by ascending OS, filled up with
//! the lowest-OS others, 2 by default. ChatScene rounds re-fitted ends to two decimals; here
//! they are kept exact. Each episode's OS is its own ([`tad_metrics::score_episode`]), as
//! ChatScene ranks single scenes.
//!
//! Determinism: trial `i` draws from `SplitMix64(mix(seed, i))` and runs with that seed, so
//! the outcome is the same for any number of threads. [`fix`] writes a chosen trial as TAD.

mod fix;

pub use fix::{FixError, fix};

use rayon::prelude::*;
use tad_bytecode::ParamSlot;
use tad_ir::{Rng, SplitMix64};
use tad_metrics::{EpisodeScore, Mode, StopReason};
use tad_policy::EgoPolicy;
use tad_runtime::{Options, Scene};

/// The search's settings; [`Config::default`] is ChatScene's.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Scenes sampled per scenario (`sample_num`).
    pub samples: usize,
    /// Ranges are re-fitted after every this many (`opt_step`).
    pub round: usize,
    /// Scenes kept (`select_num`).
    pub keep: usize,
    pub seed: u64,
    pub mode: Mode,
}

impl Default for Config {
    fn default() -> Config {
        Config { samples: 50, round: 10, keep: 2, seed: 0, mode: Mode::Fixed }
    }
}

/// One sampled scene and how the ego fared.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Trial {
    pub index: usize,
    pub round: usize,
    /// The episode's seed (also the parameters' generator's).
    pub seed: u64,
    /// One value per slot, in the program's slot order.
    pub params: Vec<f64>,
    pub collision: bool,
    pub stop: StopReason,
    /// The episode scored on its own; `None` for an episode with no step.
    pub score: Option<EpisodeScore>,
}

impl Trial {
    /// This scene's overall score (1 is perfect); an unscored episode ranks last.
    pub fn os(&self) -> f64 {
        self.score.as_ref().map_or(f64::INFINITY, |s| s.metrics.os)
    }
}

/// What a search found for one scenario (serialisable, so an interrupted run's finished
/// searches can be kept and taken up again).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Outcome {
    pub trials: Vec<Trial>,
    /// The ranges each round drew from: `ranges[r][slot] = (low, high)`.
    pub ranges: Vec<Vec<(f64, f64)>>,
    /// Indexes into `trials`, most challenging first.
    pub chosen: Vec<usize>,
}

impl Outcome {
    /// The share of each round's trials that collided.
    pub fn collision_rates(&self) -> Vec<f64> {
        (0..self.ranges.len())
            .map(|r| {
                let round: Vec<&Trial> = self.trials.iter().filter(|t| t.round == r).collect();
                round.iter().filter(|t| t.collision).count() as f64 / round.len().max(1) as f64
            })
            .collect()
    }
}

/// The seed of trial `index`: SplitMix64's mixer over the search's seed and the index, so
/// neighbouring seeds give unrelated draws.
pub fn trial_seed(seed: u64, index: usize) -> u64 {
    let mut rng = SplitMix64::new(seed ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
    rng.next_u64()
}

/// Searches one scenario's parameters with the ego `make` gives (one fresh policy per
/// episode); `tick` is called after every episode (a progress bar). A program without
/// slots has one scene to try: it runs once.
pub fn search(
    scene: &Scene,
    make: &(dyn Fn() -> Box<dyn EgoPolicy> + Sync),
    config: &Config,
    tick: &(dyn Fn() + Sync),
) -> Outcome {
    let slots = &scene.program.params;
    let samples = if slots.is_empty() { 1 } else { config.samples.max(1) };
    let round = config.round.max(1);
    let mut ranges: Vec<(f64, f64)> = slots.iter().map(|s| (s.min, s.max)).collect();
    let mut out = Outcome { trials: Vec::with_capacity(samples), ranges: Vec::new(), chosen: Vec::new() };
    let opts = Options { mode: config.mode, ..Options::default() };
    let mut start = 0;
    while start < samples {
        let r = out.ranges.len();
        out.ranges.push(ranges.clone());
        let end = (start + round).min(samples);
        let batch: Vec<Trial> = (start..end)
            .into_par_iter()
            .map(|index| {
                let seed = trial_seed(config.seed, index);
                let mut rng = SplitMix64::new(seed);
                let params: Vec<f64> = ranges.iter().map(|&(low, high)| low + (high - low) * rng.unit()).collect();
                let mut ego = make();
                let episode = tad_runtime::run(scene, Some(seed), params.clone(), ego.as_mut(), &opts);
                let collision =
                    episode.stop_reason == StopReason::Collision || episode.records.iter().any(|x| x.collision);
                let score = tad_metrics::score_episode(&episode.records, config.mode).ok();
                tick();
                Trial { index, round: r, seed, params, collision, stop: episode.stop_reason, score }
            })
            .collect();
        out.trials.extend(batch);
        ranges = refit(slots, &ranges, &out.trials);
        start = end;
    }
    out.chosen = choose(&out.trials, config.keep);
    out
}

/// The ranges after a round: each slot with more than one colliding value so far gets
/// mean ± std of those values, clipped to the slot's own range; the others keep theirs.
pub fn refit(slots: &[ParamSlot], ranges: &[(f64, f64)], trials: &[Trial]) -> Vec<(f64, f64)> {
    let colliding: Vec<&Trial> = trials.iter().filter(|t| t.collision).collect();
    slots
        .iter()
        .zip(ranges)
        .enumerate()
        .map(|(k, (slot, &range))| {
            let values: Vec<f64> = colliding.iter().filter_map(|t| t.params.get(k).copied()).collect();
            if values.len() < 2 {
                return range;
            }
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            let low = (mean - std).max(slot.min);
            let high = (mean + std).min(slot.max);
            if low <= high { (low, high) } else { range }
        })
        .collect()
}

/// The `keep` most challenging trials: colliding ones by ascending OS, then the others by
/// ascending OS; ties by index.
pub fn choose(trials: &[Trial], keep: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..trials.len()).collect();
    order.sort_by(|&a, &b| {
        let (x, y) = (&trials[a], &trials[b]);
        y.collision.cmp(&x.collision).then(x.os().total_cmp(&y.os())).then(x.index.cmp(&y.index))
    });
    order.truncate(keep);
    order
}

#[cfg(test)]
mod tests;
