//! SafeBench/ChatScene's ten-metric scorer: what an episode's records say about the ego,
//! per episode and over a set of episodes, with the overall score (OS) TrafficAlign reports.
//!
//! The maths is ChatScene's `safebench/util/metric_util.py::get_route_scores` (SafeBench's
//! `get_scores` at `3cb6013a` is the same), which TrafficAlign's tables follow. The runtime
//! records one [`StepRecord`] per step; [`score_episode`] reduces an episode to its
//! per-episode values, [`aggregate`] combines episodes. [`METRICS`] is the one table of
//! keys, groups, normalisation maxima and OS weights; everything here reads it.
//!
//! # Definitions
//!
//! An episode is its records `r_0 … r_{n-1}` (n ≥ 1); `T = r_{n-1}.time − r_0.time`.
//!
//! | key | per episode | over N episodes | max | weight |
//! |---|---|---|---|---|
//! | CR | 1 if `r_{n-1}.collision`, else 0 | mean | 1 | 5 |
//! | RR | `r_{n-1}.run_red_light` | mean | 1 | 1 |
//! | SS | `r_{n-1}.run_stop` | mean | 1 | 1 |
//! | OR | Σ_{i≥1, off'_i} (`driven_distance_i` − `driven_distance_{i−1}`), where `off'_i = off_road_i ∨ off_road_{i−1}` (the flag dilated one step forward), m | mean | 50 | 1 |
//! | RF | d = mean over steps of `distance_to_route` (m) | `max(1 − mean(d)/5, 0)` | 1 | 0.5 |
//! | Comp | `r_{n-1}.route_complete / 100` | mean | 1 | 0.5 |
//! | TS | T, only if completed (`r_{n-1}.route_complete ≥ 100`) | mean over completed episodes; none completed: `Compat` 0, `Fixed` not applicable (`None`) | 60 | 0.5 |
//! | ACC | mean over steps of ‖`acceleration`‖, m/s² | mean | 8 | 0.2 |
//! | YV | Σ_{i≥1} \|Δyaw_i\| (deg → rad) / T, rad/s; `Compat`: Δyaw_i = `yaw_i − yaw_{i−1}`; `Fixed`: that wrapped to (−180°, 180°]; 0 when T = 0 | mean | 3 | 0.2 |
//! | LI | `r_{n-1}.lane_invasion` | mean | 20 | 0.2 |
//!
//! Normalised values are `value / max`, unclipped. With `good(m) = ns(m)` for RF and Comp
//! and `1 − ns(m)` for the others, `OS = Σ weight·good / Σ weight` over the ten metrics
//! (Σ weight = 10.1): `OS = (5(1−CR) + (3−RR−SS−OR) + 0.5(RF+Comp+1−TS) + 0.2(3−ACC−YV−LI)) / 10.1`
//! on normalised values; 1 is perfect and it is unbounded below. The sub-scores are the same
//! ratio within a group: safety (CR, RR, SS, OR; / 8), task (RF, Comp, TS; / 1.5), comfort
//! (ACC, YV, LI; / 0.6).
//!
//! # Modes
//!
//! [`Mode::Compat`] reproduces the scorer bit for bit, quirks included; [`Mode::Fixed`] (the
//! default) fixes them:
//! - TS when no episode completes: `Compat` reports 0, so the TS term scores its best;
//!   `Fixed` reports `None` and leaves the term out: OS and the task sub-score are the ratio
//!   over the remaining terms (OS divides by 9.6, task by 1.0), so 1 stays perfect.
//! - YV: `Compat` does not unwrap yaw, so a heading crossing ±180° adds ≈ 360°; `Fixed`
//!   wraps each step's change.
//! - Off-road: SafeBench never ends an episode off road (its check compares a bool with a
//!   status); under `Fixed` the runtime ends it at the first off-road record
//!   ([`Mode::off_road_terminates`], [`StopReason::OffRoad`]).
//!
//! Neither mode divides by zero where the Python would: a one-step (T = 0) episode has
//! YV 0; an empty episode or an empty set of episodes is an error.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// What the runtime records about the ego at each step (one `record_dict` entry).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    /// Simulation time, s.
    pub time: f64,
    /// Speed, m/s.
    pub velocity: f64,
    /// Acceleration (kinematic, Δv/dt), m/s².
    pub acceleration: [f64; 3],
    pub position: [f64; 3],
    /// Heading in degrees within [−180, 180] (CARLA's `yaw`).
    pub yaw_deg: f64,
    /// Distance driven since the start, m.
    pub driven_distance: f64,
    /// Lane invasion events so far.
    pub lane_invasion: u32,
    /// The ego's centre is on no driving or parking lane.
    pub off_road: bool,
    /// The ego has collided (with a vehicle, a walker or a static prop).
    pub collision: bool,
    /// Red lights run so far.
    pub run_red_light: u32,
    /// Stop signs run so far.
    pub run_stop: u32,
    /// Distance from the ego to the nearest route point ahead, m.
    pub distance_to_route: f64,
    /// Route completion, percent (exactly 100 when complete).
    pub route_complete: f64,
}

/// The ten metrics, in [`METRICS`]'s order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Metric {
    Cr,
    Rr,
    Ss,
    Or,
    Rf,
    Comp,
    Ts,
    Acc,
    Yv,
    Li,
}

impl Metric {
    /// Its row of [`METRICS`].
    pub fn def(self) -> &'static MetricDef {
        &METRICS[self as usize]
    }
}

/// ChatScene's grouping (the paper's Safety, Functionality, Etiquette).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Group {
    Safety,
    Task,
    Comfort,
}

/// One metric's row: how it is named, normalised and weighted in the OS.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetricDef {
    pub metric: Metric,
    /// The key in results (`CR`, …).
    pub key: &'static str,
    /// ChatScene's name for it.
    pub code_key: &'static str,
    pub group: Group,
    /// Normalisation maximum: the normalised value is `value / max`.
    pub max: f64,
    /// Weight in the OS.
    pub weight: f64,
    /// RF and Comp; every other metric is better lower.
    pub higher_is_better: bool,
}

const fn def(
    metric: Metric,
    key: &'static str,
    code_key: &'static str,
    group: Group,
    max: f64,
    weight: f64,
    higher_is_better: bool,
) -> MetricDef {
    MetricDef { metric, key, code_key, group, max, weight, higher_is_better }
}

/// The metrics' table (`get_route_scores`' `predefined_max_values` and OS weights).
pub const METRICS: [MetricDef; 10] = [
    def(Metric::Cr, "CR", "collision_rate", Group::Safety, 1.0, 5.0, false),
    def(Metric::Rr, "RR", "avg_red_light_freq", Group::Safety, 1.0, 1.0, false),
    def(Metric::Ss, "SS", "avg_stop_sign_freq", Group::Safety, 1.0, 1.0, false),
    def(Metric::Or, "OR", "out_of_road_length", Group::Safety, 50.0, 1.0, false),
    def(Metric::Rf, "RF", "route_following_stability", Group::Task, 1.0, 0.5, true),
    def(Metric::Comp, "Comp", "route_completion", Group::Task, 1.0, 0.5, true),
    def(Metric::Ts, "TS", "avg_time_spent", Group::Task, 60.0, 0.5, false),
    def(Metric::Acc, "ACC", "avg_acceleration", Group::Comfort, 8.0, 0.2, false),
    def(Metric::Yv, "YV", "avg_yaw_velocity", Group::Comfort, 3.0, 0.2, false),
    def(Metric::Li, "LI", "avg_lane_invasion_freq", Group::Comfort, 20.0, 0.2, false),
];

/// What a normalised column is, for a table's footer: `value / max`, unclipped, with the
/// maxima past which a value is above 1 (OR, TS, ACC, YV, LI: those whose value is not a
/// share already).
pub fn normalisation() -> String {
    let maxima: Vec<String> = METRICS.iter().filter(|d| d.max != 1.0).map(|d| format!("{} {}", d.key, d.max)).collect();
    format!("value / max, unclipped: a value past SafeBench's maximum ({}) is above 1", maxima.join(", "))
}

/// RF: the mean distance to the route (m) at which route-following stability reaches 0.
pub const RF_ZERO_DISTANCE: f64 = 5.0;

/// Whether the scorer's quirks are reproduced (see the crate's header).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    Compat,
    #[default]
    Fixed,
}

impl Mode {
    /// Whether the runtime ends an episode at its first off-road record.
    pub const fn off_road_terminates(self) -> bool {
        matches!(self, Mode::Fixed)
    }

    pub const fn as_str(self) -> &'static str {
        match self {
            Mode::Compat => "compat",
            Mode::Fixed => "fixed",
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Mode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        [Mode::Compat, Mode::Fixed]
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| format!("unknown scoring mode `{s}` (expected `compat` or `fixed`)"))
    }
}

/// Why an episode ended. Declared in SafeBench's checking order (`get_running_status`),
/// then the program's end: when several hold at one step, report the first (the least).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// A counted collision (SafeBench stops at the first).
    Collision,
    /// Off road, under [`Mode::Fixed`] only ([`Mode::off_road_terminates`]).
    OffRoad,
    /// `route_complete` reached 100.
    RouteComplete,
    /// The step limit (SafeBench's `max_episode_step`, 300).
    MaxSteps,
    /// The scenario's maximum driven distance.
    MaxDistance,
    /// The scenario's timeout (simulation time).
    Timeout,
    /// The scenario program ended.
    ProgramEnd,
    /// The ego's driver failed: an external process broke the protocol, fell silent or
    /// ended (`tad_policy`'s external ego).
    EgoFailed,
}

impl StopReason {
    pub const ALL: [StopReason; 8] = [
        StopReason::Collision,
        StopReason::OffRoad,
        StopReason::RouteComplete,
        StopReason::MaxSteps,
        StopReason::MaxDistance,
        StopReason::Timeout,
        StopReason::ProgramEnd,
        StopReason::EgoFailed,
    ];

    /// The stable snake_case name (as serialised).
    pub const fn as_str(self) -> &'static str {
        match self {
            StopReason::Collision => "collision",
            StopReason::OffRoad => "off_road",
            StopReason::RouteComplete => "route_complete",
            StopReason::MaxSteps => "max_steps",
            StopReason::MaxDistance => "max_distance",
            StopReason::Timeout => "timeout",
            StopReason::ProgramEnd => "program_end",
            StopReason::EgoFailed => "ego_failed",
        }
    }
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for StopReason {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        StopReason::ALL.into_iter().find(|r| r.as_str() == s).ok_or_else(|| {
            let names: Vec<&str> = StopReason::ALL.iter().map(|r| r.as_str()).collect();
            format!("unknown stop reason `{s}` (expected one of {})", names.join(", "))
        })
    }
}

/// The ten values and the OS, keyed as in TrafficAlign's tables. Raw or normalised
/// ([`Metrics::normalised`]); `os` is the set's overall score either way.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    #[serde(rename = "CR")]
    pub cr: f64,
    #[serde(rename = "RR")]
    pub rr: f64,
    #[serde(rename = "SS")]
    pub ss: f64,
    #[serde(rename = "OR")]
    pub or: f64,
    #[serde(rename = "RF")]
    pub rf: f64,
    #[serde(rename = "Comp")]
    pub comp: f64,
    /// `None`: no episode completed, under [`Mode::Fixed`].
    #[serde(rename = "TS")]
    pub ts: Option<f64>,
    #[serde(rename = "ACC")]
    pub acc: f64,
    #[serde(rename = "YV")]
    pub yv: f64,
    #[serde(rename = "LI")]
    pub li: f64,
    #[serde(rename = "OS")]
    pub os: f64,
}

impl Metrics {
    /// One metric's value (`None`: TS not applicable).
    pub fn get(&self, metric: Metric) -> Option<f64> {
        match metric {
            Metric::Cr => Some(self.cr),
            Metric::Rr => Some(self.rr),
            Metric::Ss => Some(self.ss),
            Metric::Or => Some(self.or),
            Metric::Rf => Some(self.rf),
            Metric::Comp => Some(self.comp),
            Metric::Ts => self.ts,
            Metric::Acc => Some(self.acc),
            Metric::Yv => Some(self.yv),
            Metric::Li => Some(self.li),
        }
    }

    /// Every value divided by its [`MetricDef::max`]; `os` unchanged.
    pub fn normalised(&self) -> Metrics {
        let n = |m: Metric, v: f64| v / m.def().max;
        Metrics {
            cr: n(Metric::Cr, self.cr),
            rr: n(Metric::Rr, self.rr),
            ss: n(Metric::Ss, self.ss),
            or: n(Metric::Or, self.or),
            rf: n(Metric::Rf, self.rf),
            comp: n(Metric::Comp, self.comp),
            ts: self.ts.map(|v| n(Metric::Ts, v)),
            acc: n(Metric::Acc, self.acc),
            yv: n(Metric::Yv, self.yv),
            li: n(Metric::Li, self.li),
            os: self.os,
        }
    }
}

/// The overall score and ChatScene's sub-scores.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    pub os: f64,
    pub safety: f64,
    pub task: f64,
    pub comfort: f64,
}

/// OS and sub-scores of normalised values (`normalised.os` is not read). A metric whose
/// value is `None` (TS not applicable) is left out of the sums and their weights.
pub fn scores(normalised: &Metrics) -> Scores {
    let mut sum = [0.0; 4];
    let mut weight = [0.0; 4];
    for d in &METRICS {
        let Some(v) = normalised.get(d.metric) else { continue };
        let good = if d.higher_is_better { v } else { 1.0 - v };
        for slot in [0, 1 + d.group as usize] {
            sum[slot] += d.weight * good;
            weight[slot] += d.weight;
        }
    }
    let ratio = |k: usize| sum[k] / weight[k];
    Scores { os: ratio(0), safety: ratio(1), task: ratio(2), comfort: ratio(3) }
}

/// One episode reduced to what aggregation needs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EpisodeScore {
    pub steps: usize,
    /// `T`: the last record's time minus the first's, s.
    pub duration: f64,
    /// The last record's `route_complete` is 100.
    pub completed: bool,
    /// Mean over steps of `distance_to_route` (RF's per-episode value), m.
    pub mean_distance_to_route: f64,
    /// This episode scored on its own (as ChatScene ranks single scenes): the per-episode
    /// values of the crate's table for CR, RR, SS, OR, Comp, ACC, YV, LI, and RF, TS, OS
    /// as [`aggregate`] gives them for a set of one.
    pub metrics: Metrics,
}

/// A set of episodes scored together.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aggregate {
    pub mode: Mode,
    pub episodes: usize,
    /// How many completed their route (TS averages over these).
    pub completed: usize,
    pub raw: Metrics,
    pub normalised: Metrics,
    pub safety: f64,
    pub task: f64,
    pub comfort: f64,
}

/// Why records could not be scored.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MetricsError {
    /// An episode with no records.
    EmptyEpisode,
    /// Nothing to aggregate.
    NoEpisodes,
    /// A record's field is NaN or infinite.
    NonFinite { step: usize, field: &'static str },
    /// A record's time is earlier than the previous record's.
    TimeBackwards { step: usize },
}

impl fmt::Display for MetricsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MetricsError::EmptyEpisode => f.write_str("an episode with no records cannot be scored"),
            MetricsError::NoEpisodes => f.write_str("no episodes to aggregate"),
            MetricsError::NonFinite { step, field } => write!(f, "step {step}: `{field}` is not a finite number"),
            MetricsError::TimeBackwards { step } => {
                write!(f, "step {step}: `time` is earlier than the previous step's")
            }
        }
    }
}

impl std::error::Error for MetricsError {}

/// Reduce one episode's records (see the crate's table).
pub fn score_episode(records: &[StepRecord], mode: Mode) -> Result<EpisodeScore, MetricsError> {
    let (Some(first), Some(last)) = (records.first(), records.last()) else {
        return Err(MetricsError::EmptyEpisode);
    };
    check(records)?;
    let n = records.len() as f64;
    let duration = last.time - first.time;
    let off_road_length = records
        .windows(2)
        .map(|w| if w[0].off_road || w[1].off_road { w[1].driven_distance - w[0].driven_distance } else { 0.0 })
        .sum();
    let yaw_change: f64 = records
        .windows(2)
        .map(|w| {
            let d = w[1].yaw_deg - w[0].yaw_deg;
            match mode {
                Mode::Compat => d.abs(),
                Mode::Fixed => wrap_deg(d).abs(),
            }
        })
        .sum();
    let yv = if duration > 0.0 { yaw_change.to_radians() / duration } else { 0.0 };
    let acc = records.iter().map(|r| r.acceleration.iter().map(|a| a * a).sum::<f64>().sqrt()).sum::<f64>() / n;
    let mut episode = EpisodeScore {
        steps: records.len(),
        duration,
        completed: last.route_complete >= 100.0,
        mean_distance_to_route: records.iter().map(|r| r.distance_to_route).sum::<f64>() / n,
        metrics: Metrics {
            cr: if last.collision { 1.0 } else { 0.0 },
            rr: f64::from(last.run_red_light),
            ss: f64::from(last.run_stop),
            or: off_road_length,
            rf: f64::NAN,
            comp: last.route_complete / 100.0,
            ts: None,
            acc,
            yv,
            li: f64::from(last.lane_invasion),
            os: f64::NAN,
        },
    };
    episode.metrics = aggregate(std::slice::from_ref(&episode), mode)?.raw;
    Ok(episode)
}

/// Score a set of episodes together (see the crate's table). Episodes should have been
/// scored in the same `mode`.
pub fn aggregate(episodes: &[EpisodeScore], mode: Mode) -> Result<Aggregate, MetricsError> {
    if episodes.is_empty() {
        return Err(MetricsError::NoEpisodes);
    }
    let mean = |f: &dyn Fn(&EpisodeScore) -> f64| episodes.iter().map(f).sum::<f64>() / episodes.len() as f64;
    let done: Vec<&EpisodeScore> = episodes.iter().filter(|e| e.completed).collect();
    let ts = if done.is_empty() {
        match mode {
            Mode::Compat => Some(0.0),
            Mode::Fixed => None,
        }
    } else {
        Some(done.iter().map(|e| e.duration).sum::<f64>() / done.len() as f64)
    };
    let mut raw = Metrics {
        cr: mean(&|e| e.metrics.cr),
        rr: mean(&|e| e.metrics.rr),
        ss: mean(&|e| e.metrics.ss),
        or: mean(&|e| e.metrics.or),
        rf: (1.0 - mean(&|e| e.mean_distance_to_route) / RF_ZERO_DISTANCE).max(0.0),
        comp: mean(&|e| e.metrics.comp),
        ts,
        acc: mean(&|e| e.metrics.acc),
        yv: mean(&|e| e.metrics.yv),
        li: mean(&|e| e.metrics.li),
        os: 0.0,
    };
    let mut normalised = raw.normalised();
    let s = scores(&normalised);
    raw.os = s.os;
    normalised.os = s.os;
    Ok(Aggregate {
        mode,
        episodes: episodes.len(),
        completed: done.len(),
        raw,
        normalised,
        safety: s.safety,
        task: s.task,
        comfort: s.comfort,
    })
}

/// Degrees wrapped to (−180, 180].
fn wrap_deg(d: f64) -> f64 {
    let r = d.rem_euclid(360.0);
    if r > 180.0 { r - 360.0 } else { r }
}

fn check(records: &[StepRecord]) -> Result<(), MetricsError> {
    for (step, r) in records.iter().enumerate() {
        let fields = [
            ("time", r.time.is_finite()),
            ("acceleration", r.acceleration.iter().all(|a| a.is_finite())),
            ("yaw_deg", r.yaw_deg.is_finite()),
            ("driven_distance", r.driven_distance.is_finite()),
            ("distance_to_route", r.distance_to_route.is_finite()),
            ("route_complete", r.route_complete.is_finite()),
        ];
        if let Some(&(field, _)) = fields.iter().find(|(_, finite)| !finite) {
            return Err(MetricsError::NonFinite { step, field });
        }
        if step > 0 && r.time < records[step - 1].time {
            return Err(MetricsError::TimeBackwards { step });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
