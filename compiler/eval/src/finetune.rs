//! The "after fine-tuning" stage of `eval --finetune`: each learned ego of the evaluation
//! (the shipped `ppo`, `sac`, `td3`, or `learned:PATH`) fine-tuned from its own weights with
//! its own algorithm (`learned:PATH` with SAC) through [`crate::train`], on 3/5 of each
//! behaviour's kept scenes (ChatScene's split) at the paper's learning rate
//! (`tad_train::Config::finetune`); a shipped model from its checkpoint, the critics it was
//! kept with included; then every ego, before and after, on the held-out 2/5, with paired
//! bootstrap intervals of each model's change ([`crate::interval`]).
//!
//! TrafficAlign evaluates every 50 epochs and reports the best. Here the actor is scored
//! every [`SELECT_EVERY`] episodes (and at the start and the end) on the scenes it trains
//! on, never the held-out ones, and the best by OS among those that keep [`KEEP_ROUTE`] of
//! the start's route completion is kept: so fine-tuning may keep its start.
//!
//! With `--finetune-from` (a checkpoint or an actor file) or without any learned ego, one
//! ego called `learned` is tuned instead, from that start or from scratch.

use std::path::Path;

use tad_policy::{EgoSpec, Learned, Observation};
use tad_train::{Algo, Config, Imitation, TrainError};

use crate::harness::{Kept, Plan};
use crate::interval::Change;
use crate::results::{Results, Setup};
use crate::train::{Start, TrainScene};

/// The one `learned` ego's name (its row before fine-tuning: `learned (before)`).
pub const LEARNED: &str = "learned";
pub const BEFORE: &str = "learned (before)";

/// The name of `ego`'s row after fine-tuning on `generator`'s scenes.
pub fn tuned_name(ego: &str, generator: &str) -> String {
    format!("{ego} (fine-tuned on {generator})")
}

/// The name of that row when the run took no learning step: the ego as it started.
pub fn untuned_name(ego: &str, generator: &str) -> String {
    format!("{ego} (no learning step on {generator})")
}

/// Why fine-tuning did not finish.
#[derive(Debug)]
pub enum FinetuneError {
    /// The start (`--finetune-from`) could not be loaded.
    Start(TrainError),
    /// Training stopped.
    Training(TrainError),
    /// The trained actor could not be taken out.
    Actor(TrainError),
}

/// One ego to fine-tune on one generator's scenes: its row names, where it starts and the
/// run's settings.
pub struct Tuning<'a> {
    pub before: String,
    pub after: String,
    pub generator: String,
    pub start: Start<'a>,
    pub config: Config,
}

/// What to fine-tune: every learned ego of the plan from its weights, or one `learned`
/// ego from `from` (or from scratch when the plan has no learned ego), each on every
/// generator's scenes. `settings` turns an algorithm into the run's settings.
pub fn tunings<'a>(plan: &Plan, from: Option<&'a Path>, settings: impl Fn(Algo) -> Config) -> Vec<Tuning<'a>> {
    let learned: Vec<(&String, &Learned)> = plan
        .setup
        .egos
        .iter()
        .zip(&plan.egos)
        .filter_map(|(name, ego)| match ego {
            EgoSpec::Learned(actor) => Some((name, actor)),
            _ => None,
        })
        .collect();
    let mut out = Vec::new();
    for generator in &plan.setup.generators {
        if from.is_some() || learned.is_empty() {
            out.push(Tuning {
                before: BEFORE.into(),
                after: tuned_name(LEARNED, generator),
                generator: generator.clone(),
                start: from.map_or(Start::Scratch, Start::from_path),
                config: settings(Algo::Sac),
            });
            continue;
        }
        for (name, actor) in &learned {
            // a shipped model goes on from its checkpoint: its algorithm, its critics
            let shipped = tad_policy::pretrained::find(name);
            let algo = shipped.and_then(|m| Algo::parse(m.name)).unwrap_or(Algo::Sac);
            let observation = Observation::of_inputs(actor.inputs()).unwrap_or_default();
            out.push(Tuning {
                before: (*name).clone(),
                after: tuned_name(name, generator),
                generator: generator.clone(),
                start: Start::Learned { actor: (*actor).clone(), critics: shipped.map(|m| (m.name, m.critics)) },
                config: Config { observation, ..settings(algo) },
            });
        }
    }
    out
}

/// A trained ego, and the one it started from (none from scratch), with their row names.
pub struct Tuned {
    pub before_name: String,
    pub after_name: String,
    /// Learning steps this fine-tuning took (0: it was too short to learn anything, and
    /// `after_name` says so).
    pub updates: u64,
    /// Episodes into fine-tuning when the kept actor was taken (0: the start).
    pub kept_at: usize,
    /// Its score on the scenes it trained on, and the start's (none from scratch).
    pub kept_score: Score,
    pub start_score: Option<Score>,
    pub after: Learned,
    pub before: Option<Learned>,
}

/// Kept scenes split per behaviour: indexes to train on and to hold out.
pub fn split(kept: &[Kept], seed: u64) -> (Vec<usize>, Vec<usize>) {
    let keys: Vec<String> = kept.iter().map(|k| k.unit.key.clone()).collect();
    tad_train::split(&keys, seed)
}

/// Episodes of the model before fine-tuning whose states and actions anchor it.
const ANCHOR_EPISODES: usize = 64;

/// Episodes between two scorings of the actor (TrafficAlign's "every 50 epochs").
pub const SELECT_EVERY: usize = 50;

/// The share of its start's route completion an actor must keep on the training scenes to
/// be kept: below it, fewer collisions come from standing still (the adversaries wait for
/// the ego), not from driving better. The shipped models' bar against idm is the same 0.9.
pub const KEEP_ROUTE: f64 = 0.9;

/// An actor as judged on the training scenes: OS, and the mean route completion (0..=1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Score {
    pub os: f64,
    pub route: f64,
}

/// The best actor offered so far: the highest OS among those that keep [`KEEP_ROUTE`] of
/// the start's route completion (the start always does), the earlier on a tie.
struct Best<'k> {
    kept: &'k [Kept<'k>],
    train: &'k [usize],
    best: Option<(Learned, usize, Score)>,
    start: Option<Score>,
}

impl Best<'_> {
    fn offer(&mut self, actor: Learned, at: usize) {
        // the held-out table's runner, on the training scenes (its rows' labels go unread)
        let rows = crate::harness::held_out(self.kept, self.train, &[(String::new(), EgoSpec::Learned(actor.clone()))]);
        let scores: Vec<&tad_metrics::EpisodeScore> = rows.iter().map(|r| &r.score).collect();
        let (_, os) = crate::interval::cr_os(&scores);
        let route = scores.iter().map(|s| s.metrics.comp).sum::<f64>() / scores.len().max(1) as f64;
        let score = Score { os, route };
        if at == 0 {
            self.start = Some(score);
        }
        let drives = self.start.is_none_or(|start| route >= KEEP_ROUTE * start.route);
        if drives && self.best.as_ref().is_none_or(|(_, _, best)| os > best.os) {
            self.best = Some((actor, at, score));
        }
    }
}

/// The kept scenes of `train` that `generator` made.
pub fn of_generator(kept: &[Kept], train: &[usize], generator: &str) -> Vec<usize> {
    train.iter().copied().filter(|&i| kept[i].unit.generator == generator).collect()
}

/// `tuning`'s ego trained for `config.episodes` more episodes on the kept scenes `train`,
/// each with its kept parameters and seed; `on_episode` after each. The actor kept is the
/// best scored on those scenes (see the module's header).
pub fn tune<'k>(
    kept: &'k [Kept<'k>],
    train: &'k [usize],
    tuning: Tuning,
    mut on_episode: impl FnMut(),
) -> Result<Tuned, FinetuneError> {
    let Tuning { before: before_name, after: after_name, generator, start, config } = tuning;
    let episodes = config.episodes;
    let (mut trainer, before) = start.trainer(config).map_err(FinetuneError::Start)?;
    let first = trainer.episodes() as usize;
    let learned = trainer.updates();
    let scenes: Vec<TrainScene> = train
        .iter()
        .map(|&i| TrainScene { scene: &kept[i].unit.scene, fixed: Some((&kept[i].params, kept[i].seed)) })
        .collect();
    // the model's own actions on the training scenes: what the demonstrations' term keeps
    if let Some(model) = before.as_ref().filter(|_| trainer.config().bc_weight > 0.0 && trainer.demos() == 0) {
        let anchor = Imitation { rounds: 1, episodes: ANCHOR_EPISODES, epochs: 0, ..Imitation::default() };
        let drive = || -> Box<dyn tad_policy::EgoPolicy> { Box::new(model.clone()) };
        trainer.imitate(&scenes, &drive, &anchor, |_| {}).map_err(FinetuneError::Training)?;
    }
    let mut best = Best { kept, train, best: None, start: None };
    if let Some(start) = &before {
        best.offer(start.clone(), 0);
    }
    crate::train::train(&mut trainer, first + episodes, &scenes, |trainer, stats| -> Result<(), TrainError> {
        stats.iter().for_each(|_| on_episode());
        let done = trainer.episodes() as usize - first;
        if done / SELECT_EVERY > (done - stats.len()) / SELECT_EVERY || done == episodes {
            best.offer(trainer.actor()?, done);
        }
        Ok(())
    })
    .map_err(FinetuneError::Training)?;
    let start_score = best.start;
    let (after, kept_at, kept_score) = match best.best {
        Some(best) => best,
        None => (trainer.actor().map_err(FinetuneError::Actor)?, 0, Score { os: f64::NAN, route: f64::NAN }),
    };
    // an actor that learned nothing here is not labelled fine-tuned
    let updates = trainer.updates() - learned;
    let ego = if before_name == BEFORE { LEARNED } else { before_name.as_str() };
    let after_name = if updates == 0 { untuned_name(ego, &generator) } else { after_name };
    Ok(Tuned { before_name, after_name, updates, kept_at, kept_score, start_score, after, before })
}

/// The held-out table, and each tuned ego's change (with a start to change from).
pub struct HeldOut {
    pub results: Results,
    pub changes: Vec<Change>,
}

/// The tuned egos, the ones they started from and the plan's egos on the held-out scenes:
/// each plan ego followed by its tuned self; a `learned` ego's pair first.
pub fn held_out(plan: &Plan, kept: &[Kept], test: &[usize], tuned: Vec<Tuned>, seed: u64) -> HeldOut {
    let mut drivers: Vec<(String, EgoSpec)> = Vec::new();
    let mut pairs = Vec::new();
    let planned = |name: &str| plan.setup.egos.iter().any(|e| e == name);
    let (mut own, standalone): (Vec<Tuned>, Vec<Tuned>) = tuned.into_iter().partition(|t| planned(&t.before_name));
    for t in standalone {
        if let Some(actor) = t.before {
            if !drivers.iter().any(|(n, _)| *n == t.before_name) {
                drivers.push((t.before_name.clone(), EgoSpec::Learned(actor)));
            }
            pairs.push((t.before_name.clone(), t.after_name.clone()));
        }
        drivers.push((t.after_name, EgoSpec::Learned(t.after)));
    }
    for (name, ego) in plan.setup.egos.iter().zip(&plan.egos) {
        drivers.push((name.clone(), ego.clone()));
        for t in own.extract_if(.., |t| &t.before_name == name) {
            pairs.push((t.before_name, t.after_name.clone()));
            drivers.push((t.after_name, EgoSpec::Learned(t.after)));
        }
    }
    let rows = crate::harness::held_out(kept, test, &drivers);
    let changes = pairs.iter().filter_map(|(b, a)| crate::interval::change(&rows, b, a, seed)).collect();
    let setup = Setup {
        regions: vec!["held-out".into()],
        generators: vec!["searched".into()],
        egos: drivers.iter().map(|(n, _)| n.clone()).collect(),
        ..plan.setup.clone()
    };
    let scenarios = [("held-out/searched".to_string(), test.len())].into_iter().collect();
    HeldOut { results: Results::new(setup, tad_base::Shard::ALL, scenarios, rows), changes }
}
