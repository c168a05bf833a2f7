//! The warm start: DAgger (Ross, Gordon, Bagnell 2011) from a teacher into the actor.
//! Round 0 lets the teacher drive; later rounds let the actor drive (deterministic), so the
//! data holds the states the actor's own mistakes lead to. The teacher labels every state
//! seen with its action in `[−1, 1]²` (`tad_policy::Action::to_unit`). After each round
//! the actor's `tanh(fc_mu)` is fitted to all labels so far by mean squared error (Adam,
//! shuffled minibatches). Episodes run in parallel; each round's tasks are a function of
//! the seed and the round, so the result does not depend on the thread count.

use candle_core::{Device, Tensor};
use rayon::prelude::*;
use tad_ir::{Rng, SplitMix64};
use tad_metrics::StopReason;
use tad_policy::{Action, EgoPolicy, EgoView, Observation};

use crate::nets::{ACT, Adam, PlainActor, deterministic, tensor_error};
use crate::{PolicyMaker, TrainError, TrainScene, Trainer};

/// The warm start's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Imitation {
    pub rounds: usize,
    /// Episodes per round.
    pub episodes: usize,
    /// Passes over the data after each round; 0 keeps the actor and only collects the
    /// teacher's labelled states as demonstrations ([`crate::Config::bc_weight`]).
    pub epochs: usize,
    pub lr: f64,
    pub batch: usize,
    /// The standard deviation the stochastic head starts with (SAC, PPO): `fc_std` is set
    /// to that constant.
    pub std: f64,
}

impl Default for Imitation {
    fn default() -> Imitation {
        Imitation { rounds: 4, episodes: 64, epochs: 8, lr: 1e-3, batch: 256, std: crate::INITIAL_STD }
    }
}

/// What a round did.
#[derive(Clone, Debug, PartialEq)]
pub struct ImitationRound {
    pub round: usize,
    /// Who drove: the teacher (round 0) or the actor.
    pub driver: &'static str,
    /// Labelled states so far.
    pub samples: usize,
    /// The driver's episodes that collided, and their mean route completion (0..=1).
    pub collisions: usize,
    pub route_complete: f64,
    /// The fit's mean squared error over the last pass.
    pub loss: f32,
}

/// Drives with the actor or the teacher; the teacher labels every state.
struct Dagger<'a> {
    teacher: Box<dyn EgoPolicy>,
    actor: Option<&'a PlainActor>,
    observation: Observation,
    obs: Vec<f32>,
    labels: Vec<f32>,
}

impl EgoPolicy for Dagger<'_> {
    fn name(&self) -> &str {
        "dagger"
    }

    fn reset(&mut self) {
        self.teacher.reset();
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let obs = self.observation.of(view);
        let label = self.teacher.act(view).to_unit();
        self.obs.extend(obs.iter().map(|&v| v as f32));
        self.labels.extend_from_slice(&label);
        match self.actor {
            Some(actor) => {
                let (mu, _) = actor.heads(&obs);
                Action::from_unit([mu[0].tanh(), mu[1].tanh()])
            }
            None => Action::from_unit(label),
        }
    }
}

impl Trainer {
    /// Clone `teacher` into the actor on `scenes` (see the module's header); `after` with
    /// each round. The actor's optimizer starts over afterwards, TD3's target is the clone.
    pub fn imitate(
        &mut self,
        scenes: &[TrainScene],
        teacher: PolicyMaker,
        settings: &Imitation,
        mut after: impl FnMut(&ImitationRound),
    ) -> Result<(), TrainError> {
        if scenes.is_empty() {
            return Err(TrainError::Config("no scene to imitate on".into()));
        }
        if settings.batch == 0 || !(settings.lr.is_finite() && settings.lr > 0.0) {
            return Err(TrainError::Config("imitation needs a batch ≥ 1 and a positive learning rate".into()));
        }
        let width = self.config.observation.width();
        let (mut obs, mut labels) = (Vec::new(), Vec::new());
        let mut opt =
            Adam::new(self.actor.vars().into_iter().filter(|(n, _)| !n.starts_with("fc_std")).collect(), settings.lr)?;
        let stream = SplitMix64::new(self.config.seed ^ 0x5851_F42D_4C95_7F2D).0;
        for round in 0..settings.rounds {
            let jobs: Vec<_> = (0..settings.episodes as u64)
                .map(|k| {
                    let mut rng = SplitMix64::new(
                        stream.wrapping_add((round as u64 * 1_000_003 + k).wrapping_mul(0xD1B5_4A32_D192_ED03)),
                    );
                    let scene = &scenes[rng.below(scenes.len())];
                    scene.job(rng.next_u64())
                })
                .collect();
            let actor = (round > 0).then_some(&self.plain);
            let (config, observation) = (&self.config, self.config.observation);
            let runs: Vec<(Dagger, bool, f64)> = jobs
                .par_iter()
                .map(|job| {
                    let mut dagger =
                        Dagger { teacher: teacher(), actor, observation, obs: Vec::new(), labels: Vec::new() };
                    let episode =
                        tad_runtime::run(job.scene, Some(job.seed), job.params.clone(), &mut dagger, &config.options());
                    let collided = episode.stop_reason == StopReason::Collision;
                    let complete = episode.records.last().map_or(0.0, |r| r.route_complete / 100.0);
                    (dagger, collided, complete)
                })
                .collect();
            let collisions = runs.iter().filter(|r| r.1).count();
            let route_complete = runs.iter().map(|r| r.2).sum::<f64>() / runs.len().max(1) as f64;
            for (dagger, _, _) in runs {
                obs.extend(dagger.obs);
                labels.extend(dagger.labels);
            }
            let loss = self.fit(&obs, &labels, width, settings, &mut opt).map_err(tensor_error)?;
            after(&ImitationRound {
                round,
                driver: if round == 0 { "teacher" } else { "actor" },
                samples: labels.len() / ACT,
                collisions,
                route_complete,
                loss,
            });
        }
        self.demos = obs
            .chunks_exact(width)
            .zip(labels.chunks_exact(ACT))
            .flat_map(|(o, a)| o.iter().chain(a).copied())
            .collect();
        // no pass over the data: only the demonstrations were wanted
        if settings.epochs == 0 {
            return Ok(());
        }
        self.settle(settings.std)
    }

    /// `epochs` passes of minibatches of MSE(tanh(mu(o)), label); the last pass's mean.
    fn fit(
        &mut self,
        obs: &[f32],
        labels: &[f32],
        width: usize,
        settings: &Imitation,
        opt: &mut Adam,
    ) -> candle_core::Result<f32> {
        let n = labels.len() / ACT;
        let cpu = &Device::Cpu;
        let mut order: Vec<usize> = (0..n).collect();
        let mut last = 0.0;
        for _ in 0..settings.epochs {
            self.rng.shuffle(&mut order);
            let (mut total, mut batches) = (0.0, 0);
            for chunk in order.chunks(settings.batch) {
                let o: Vec<f32> = chunk.iter().flat_map(|&i| obs[i * width..(i + 1) * width].iter().copied()).collect();
                let y: Vec<f32> = chunk.iter().flat_map(|&i| labels[i * ACT..(i + 1) * ACT].iter().copied()).collect();
                let o = Tensor::from_vec(o, (chunk.len(), width), cpu)?;
                let y = Tensor::from_vec(y, (chunk.len(), ACT), cpu)?;
                let loss = (deterministic(&self.actor, &o)? - y)?.sqr()?.mean_all()?;
                opt.minimise(&loss)?;
                total += loss.to_scalar::<f32>()?;
                batches += 1;
            }
            last = total / batches.max(1) as f32;
        }
        self.plain = PlainActor::of(&self.actor).map_err(|e| candle_core::Error::Msg(e.to_string()))?;
        Ok(last)
    }

    /// After cloning: a constant `std` from the stochastic head, a fresh actor optimizer,
    /// TD3's target the clone.
    fn settle(&mut self, std: f64) -> Result<(), TrainError> {
        self.actor.constant_std(std)?;
        let actor = self.actor.copy()?;
        self.set_actor(actor)
    }
}
