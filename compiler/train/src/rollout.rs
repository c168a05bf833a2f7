//! Episodes for learning and for judging: the explorer acts with the actor and its
//! algorithm's noise and keeps what it saw and did; the records give SafeBench's rewards;
//! the transitions come out as replay rows (see the crate's header for the rules).

use tad_ir::SplitMix64;
use tad_metrics::StopReason;
use tad_policy::{Action, EgoPolicy, EgoView, Observation};
use tad_runtime::Scene;

use crate::nets::{ACT, PlainActor, normal_pair};
use crate::{Algo, Config, EpisodeStats, Job, Rewarder, row_width};

/// The explorer or the evaluator: acts with the actor, keeps what it saw and did.
pub(crate) struct Driver<'a> {
    actor: &'a PlainActor,
    algo: Algo,
    observation: Observation,
    explore_noise: f64,
    /// `None`: deterministic (`tanh(mu)`).
    noise: Option<SplitMix64>,
    pub obs: Vec<Vec<f64>>,
    /// What the replay keeps: the applied action, or PPO's pre-tanh sample.
    pub stored: Vec<[f32; ACT]>,
    /// The applied action in `[−1, 1]²`.
    pub applied: Vec<[f32; ACT]>,
}

impl<'a> Driver<'a> {
    pub fn deterministic(actor: &'a PlainActor, config: &Config) -> Driver<'a> {
        Driver::new(actor, config, None)
    }

    fn new(actor: &'a PlainActor, config: &Config, noise: Option<SplitMix64>) -> Driver<'a> {
        Driver {
            actor,
            algo: config.algo,
            observation: config.observation,
            explore_noise: config.explore_noise,
            noise,
            obs: Vec::new(),
            stored: Vec::new(),
            applied: Vec::new(),
        }
    }
}

impl EgoPolicy for Driver<'_> {
    fn name(&self) -> &str {
        "learned"
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let obs = self.observation.of(view);
        let (mu, log_std) = self.actor.heads(&obs);
        let (applied, stored) = match self.noise.as_mut() {
            None => {
                let a = [mu[0].tanh(), mu[1].tanh()];
                (a, a)
            }
            Some(rng) => {
                let eps = normal_pair(rng);
                match self.algo {
                    Algo::Td3 => {
                        let a = |k: usize| (mu[k].tanh() + (self.explore_noise * eps[k]) as f32).clamp(-1.0, 1.0);
                        let a = [a(0), a(1)];
                        (a, a)
                    }
                    Algo::Sac | Algo::Ppo => {
                        let u = |k: usize| mu[k] + log_std[k].exp() * eps[k] as f32;
                        let u = [u(0), u(1)];
                        let a = [u[0].tanh(), u[1].tanh()];
                        (a, if self.algo == Algo::Ppo { u } else { a })
                    }
                }
            }
        };
        self.obs.push(obs);
        self.stored.push(stored);
        self.applied.push(applied);
        Action::from_unit(applied)
    }
}

/// Records the steer any policy applies, for its reward.
struct Recording<'a> {
    policy: &'a mut dyn EgoPolicy,
    steers: Vec<f64>,
}

impl EgoPolicy for Recording<'_> {
    fn name(&self) -> &str {
        self.policy.name()
    }

    fn reset(&mut self) {
        self.policy.reset();
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let action = self.policy.act(view);
        // as the runtime applies it
        let steer = if action.steer.is_finite() { action.steer.clamp(-1.0, 1.0) } else { 0.0 };
        self.steers.push(steer);
        action
    }
}

/// The desired speed of the reward for an episode of `scene` with `params`.
fn desired_speed(config: &Config, scene: &Scene, params: &[f64]) -> f64 {
    config.desired_speed.unwrap_or_else(|| scene.ego.speed.eval(params).max(0.0))
}

fn stats(episode: &tad_runtime::Episode, episode_return: f64, stored: usize) -> EpisodeStats {
    EpisodeStats {
        episode_return,
        steps: episode.steps,
        collision: episode.records.iter().any(|r| r.collision),
        stop_reason: episode.stop_reason,
        route_complete: episode.records.last().map_or(0.0, |r| r.route_complete / 100.0),
        stored,
        losses: None,
    }
}

/// Any policy's episode scored with the training reward (the settings' desired speed and
/// rules): how to compare egos on held-out scenarios.
pub fn evaluate(
    scene: &Scene,
    params: Vec<f64>,
    seed: u64,
    policy: &mut dyn EgoPolicy,
    config: &Config,
) -> EpisodeStats {
    let desired = desired_speed(config, scene, &params);
    let mut recording = Recording { policy, steers: Vec::new() };
    recording.reset();
    let episode = tad_runtime::run(scene, Some(seed), params, &mut recording, &config.options());
    let mut rewarder = Rewarder::new(scene, desired);
    let total = episode
        .records
        .iter()
        .zip(&recording.steers)
        .map(|(record, &steer)| rewarder.step(record, steer).total())
        .sum();
    stats(&episode, total, 0)
}

/// An exploring episode's replay rows and statistics.
pub(crate) struct Collected {
    pub rows: Vec<f32>,
    /// The rows whose step collided.
    pub collided: Vec<usize>,
    pub stats: EpisodeStats,
}

/// One exploring episode of `job` with `noise`.
pub(crate) fn explore(actor: &PlainActor, config: &Config, job: &Job, noise: SplitMix64) -> Collected {
    let desired = desired_speed(config, job.scene, &job.params);
    let mut driver = Driver::new(actor, config, Some(noise));
    let episode = tad_runtime::run(job.scene, Some(job.seed), job.params.clone(), &mut driver, &config.options());
    let n = episode.records.len().min(driver.obs.len());
    let terminal = matches!(episode.stop_reason, StopReason::Collision | StopReason::OffRoad);
    let obs_width = config.observation.width();
    let width = row_width(obs_width);
    let mut rewarder = Rewarder::new(job.scene, desired);
    let (mut total, mut rows, mut collided) = (0.0, Vec::with_capacity(n * width), Vec::new());
    for k in 0..n {
        let r = rewarder.step(&episode.records[k], Action::from_unit(driver.applied[k]).steer).total();
        total += r;
        let (next, done) = match driver.obs.get(k + 1) {
            Some(next) if k + 1 < n => (next, 0.0),
            _ if terminal => (&driver.obs[k], 1.0),
            // PPO bootstraps a truncation from its own observation's value
            _ if config.algo == Algo::Ppo => (&driver.obs[k], 0.0),
            _ => continue,
        };
        if episode.records[k].collision {
            collided.push(rows.len() / width);
        }
        rows.extend(driver.obs[k].iter().map(|&v| v as f32));
        rows.extend_from_slice(&driver.stored[k]);
        rows.push(r as f32);
        rows.extend(next.iter().map(|&v| v as f32));
        rows.push(done);
        rows.push(if k + 1 == n { 1.0 } else { 0.0 });
    }
    let stored = rows.len() / width;
    Collected { stats: stats(&episode, total, stored), rows, collided }
}
