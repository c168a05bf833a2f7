//! SAC training of the learned ego (SafeBench's and ChatScene's agent) in candle, on the
//! CPU, against the runtime's episodes. The actor comes out in exactly the safetensors form
//! `tad_policy::Learned` reads, so `--ego learned:PATH` drives with it.
//!
//! ```text
//! Scene + params(seed) ──tad_runtime::run(explorer)──▶ Episode (one record per act)
//!      explorer: tanh(mu + σ·ε) per step, the observation and squashed action kept
//!      ──▶ rewards from the records (SafeBench's) ──▶ transitions ──▶ replay (ring)
//! after each episode, `updates_per_episode` times once the replay holds `start_training`:
//!      batch (with replacement) ─▶ twin-critic loss ─▶ Adam ─▶ actor loss ─▶ Adam ─▶ polyak
//! checkpoint: every tensor, both optimizers' moments, the replay, the generator, the counters
//! ```
//!
//! # Networks
//!
//! Spinning Up's SAC, as ChatScene's `adv_scenic.yaml` sets it: an actor `4 → hidden →`
//! two heads, `fc_mu` and `fc_std` (a clamped log standard deviation in `[−20, 2]`), its
//! action `tanh(mu + σ·ε)`, log-density `Σ log N(u; mu, σ) − Σ 2(log 2 − u − softplus(−2u))`
//! (the tanh change of variables, written stably); two critics `Q(obs, action)`,
//! `6 → hidden → 1`, each with a target copy moved by polyak averaging. The layers are
//! PyTorch's `nn.Linear` (`weight [out, in]`, `bias [out]`) initialised as PyTorch does
//! (uniform `±1/√fan_in`); the actor's are named `fc1 … fcN`, `fc_mu`, `fc_std`, which is
//! `Learned`'s file. The deterministic actor (evaluation, the saved file) is `tanh(fc_mu(x))`
//! scaled to `accel = 3·a0` m/s², `steer = 0.3·a1`, exactly as `Learned` acts; exploration
//! applies the same scaling to the sampled action. Per step the actor runs as plain `f32`
//! sums (the same as `Learned::mu`), not through candle: a candle matmul on the CPU costs
//! more in overhead than the 66 k multiply-adds of a 256 × 256 actor.
//!
//! # Reward
//!
//! SafeBench's (`carla_env.py::_get_reward`), computed from each step's record, the state
//! the action led to: `r = −1·collision + lspeed_lon + 10·r_fast + r_out + 5·(−steer²) +
//! 0.2·(−|steer|·lspeed_lon²)`, with `lspeed_lon` the speed along the route where the ego
//! is, `r_fast = −1` above the desired speed, `r_out = −1` beyond 4 m from the route, and
//! `steer` the applied normalised control. The desired speed is the scenario's own ego
//! speed (`EgoView::desired_speed`) unless [`Config::desired_speed`] fixes one
//! (SafeBench's 8 m/s): a fixed 8 m/s would punish every highway scenario's stated speed.
//!
//! # Transitions
//!
//! The runtime asks the policy once per step, before the step's record: step `k`'s
//! observation `o_k` and action `a_k` lead to record `k`, which gives `r_k`; the next
//! observation is `o_{k+1}`, the one the next `act` sees. The last step has no next
//! observation: after a collision or going off the road it is terminal (`done`, nothing
//! bootstrapped); after a time, distance or route-complete stop it is a truncation, and the
//! transition is left out rather than stored as a false terminal. Its reward still counts
//! in the episode's return.
//!
//! # Update schedule
//!
//! ChatScene: one learning step (batch 512) per finished episode once 1000 transitions
//! are stored, 600 episodes. [`Config::updates_per_episode`] is that 1 by default; more
//! learns faster from the same episodes (the tests use it). Each step: the critics'
//! squared error against `r + γ(1 − d)(min Q_targ(o', ã') − α log π(ã'|o'))`, one Adam
//! step on both critics; then the actor's `α log π(ã|o) − min Q(o, ã)`, one Adam step on
//! the actor; then the targets. Adam is PyTorch's (β 0.9, 0.999, ε 1e-8), written here so
//! its moments can be checkpointed.
//!
//! # Checkpoints
//!
//! A directory, written whole or not at all (a `.part` sibling renamed over it):
//! `state.json` (format, config, the actor's widths, counters, the generator's state, the
//! replay's write position, the caller's note), `actor.safetensors` (`Learned`'s file:
//! loadable by `learned:DIR/actor.safetensors`), `critics.safetensors` (layer names under
//! `q1.`, `q2.`, `q1_target.`, `q2_target.`), `optimizer.safetensors` (each parameter's
//! `.m` and `.v` under `actor.` or `critic.`; the step counts are in the state) and
//! `replay.safetensors` (`transitions`, `[n, 12]`: obs 4, action 2, reward, next obs 4,
//! done). Everything the next step reads is in it, so N episodes, a stop and a resume to
//! 2N give the same bytes as 2N at once.
//!
//! # Determinism
//!
//! Every random choice draws from one `tad_ir::SplitMix64` seeded by [`Config::seed`]:
//! initialisation, exploration noise (Box–Muller), replay batches, the update's noise. The
//! scenario and parameter seed of the `n`-th episode ([`Trainer::task`]) are a function of
//! the seed and `n` only. Same seed, scenarios and settings ⇒ the same file bytes on the
//! same machine (candle's CPU matmul splits work by output block, so the sums' order does
//! not depend on the thread count, but a different CPU's kernels may round differently).

mod nets;
pub mod reward;

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::path::{Path, PathBuf};

use candle_core::{DType, Device, Tensor};
use serde::{Deserialize, Serialize};
use tad_ir::{Rng, SplitMix64};
use tad_metrics::{Mode, StopReason};
use tad_policy::{Action, EgoPolicy, EgoView, Learned, PolicyError};
use tad_runtime::{Options, Scene};

use nets::{ACT, Adam, Net, OBS, PlainActor, normal_pair, normals, q_values, sample_actions, tensor_error};
pub use reward::{Reward, Rewarder};

/// A stored transition's width: obs, action, reward, next obs, done.
const WIDTH: usize = OBS + ACT + 1 + OBS + 1;
const FORMAT: &str = "tad-train checkpoint 1";

/// The training run's settings; the defaults are ChatScene's (`adv_scenic.yaml`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Hidden widths of the actor and of each critic.
    pub hidden: Vec<usize>,
    pub actor_lr: f64,
    pub critic_lr: f64,
    /// The entropy weight (fixed).
    pub alpha: f64,
    pub gamma: f64,
    /// Target networks keep this much of themselves per update.
    pub polyak: f64,
    pub batch: usize,
    /// The replay's capacity, transitions (oldest overwritten).
    pub buffer: usize,
    /// No update before the replay holds this many transitions.
    pub start_training: usize,
    /// Episodes in all (for callers' loops; the trainer itself counts).
    pub episodes: usize,
    /// Learning steps after each episode (ChatScene: 1).
    pub updates_per_episode: usize,
    /// The reward's desired speed, m/s; `None`: the scenario's ego speed.
    pub desired_speed: Option<f64>,
    /// SafeBench's quirks (off-road never ends an episode) instead of the fixed rules.
    pub compat: bool,
    pub seed: u64,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            hidden: vec![256, 256],
            actor_lr: 1e-4,
            critic_lr: 1e-4,
            alpha: 0.01,
            gamma: 0.99,
            polyak: 0.995,
            batch: 512,
            buffer: 30_000,
            start_training: 1000,
            episodes: 600,
            updates_per_episode: 1,
            desired_speed: None,
            compat: false,
            seed: 0,
        }
    }
}

impl Config {
    /// Why these settings cannot train, if they cannot.
    pub fn check(&self) -> Result<(), TrainError> {
        let bad = |m: String| Err(TrainError::Config(m));
        if self.hidden.is_empty() || self.hidden.contains(&0) {
            return bad(format!(
                "the hidden widths must be at least one layer of at least one unit (got {:?})",
                self.hidden
            ));
        }
        for (name, v) in [("actor learning rate", self.actor_lr), ("critic learning rate", self.critic_lr)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("the {name} must be a positive number (got {v})"));
            }
        }
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            return bad(format!("alpha must be a number ≥ 0 (got {})", self.alpha));
        }
        for (name, v) in [("gamma", self.gamma), ("polyak", self.polyak)] {
            if !(0.0..=1.0).contains(&v) {
                return bad(format!("{name} must be within 0..=1 (got {v})"));
            }
        }
        if self.batch == 0 || self.buffer == 0 {
            return bad("the batch and the replay's capacity must not be zero".into());
        }
        if let Some(v) = self.desired_speed
            && !(v.is_finite() && v >= 0.0)
        {
            return bad(format!("the desired speed must be a number ≥ 0 (got {v})"));
        }
        Ok(())
    }

    fn options(&self) -> Options {
        Options { mode: if self.compat { Mode::Compat } else { Mode::Fixed }, ..Options::default() }
    }
}

/// Why training could not go on.
#[derive(Clone, Debug, PartialEq)]
pub enum TrainError {
    /// Settings that cannot train.
    Config(String),
    /// A file could not be read or written.
    Io { path: String, message: String },
    /// A checkpoint directory that is not one of ours, or is damaged.
    Checkpoint { path: String, message: String },
    /// The actor could not be made into, or read from, `Learned`'s form.
    Policy(PolicyError),
    /// Anything candle reports.
    Tensor(String),
}

impl fmt::Display for TrainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TrainError::Config(m) => f.write_str(m),
            TrainError::Io { path, message } => write!(f, "{path}: {message}"),
            TrainError::Checkpoint { path, message } => write!(f, "{path}: not a usable checkpoint: {message}"),
            TrainError::Policy(e) => write!(f, "{e}"),
            TrainError::Tensor(m) => write!(f, "tensor error: {m}"),
        }
    }
}

impl std::error::Error for TrainError {}

impl From<PolicyError> for TrainError {
    fn from(e: PolicyError) -> TrainError {
        TrainError::Policy(e)
    }
}

/// One learning step's losses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Losses {
    /// Both critics' mean squared errors, summed.
    pub critic: f32,
    pub actor: f32,
    /// The batch's mean `−log π`, nats.
    pub entropy: f32,
}

/// What an episode did.
#[derive(Clone, Debug, PartialEq)]
pub struct EpisodeStats {
    /// The sum of the steps' rewards.
    pub episode_return: f64,
    pub steps: u32,
    pub collision: bool,
    pub stop_reason: StopReason,
    /// Transitions stored in the replay (0 when evaluating).
    pub stored: usize,
    /// The last learning step's losses after it, when one ran.
    pub losses: Option<Losses>,
}

/// The scenario (an index into the caller's list) and the seed of an episode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Task {
    pub scenario: usize,
    pub seed: u64,
}

/// The replay: a ring of transitions.
#[derive(Clone, Debug, Default)]
struct Replay {
    data: Vec<[f32; WIDTH]>,
    next: usize,
}

impl Replay {
    fn push(&mut self, capacity: usize, t: [f32; WIDTH]) {
        if self.data.len() < capacity {
            self.data.push(t);
            self.next = self.data.len() % capacity;
        } else {
            self.data[self.next] = t;
            self.next = (self.next + 1) % capacity;
        }
    }
}

/// The explorer or the evaluator: acts with the actor, keeps what it saw and did.
struct Driver<'a> {
    actor: &'a PlainActor,
    /// `None`: deterministic (`tanh(mu)`).
    noise: Option<&'a mut SplitMix64>,
    obs: Vec<[f64; OBS]>,
    actions: Vec<[f32; ACT]>,
}

impl EgoPolicy for Driver<'_> {
    fn name(&self) -> &str {
        "learned"
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let (mu, log_std) = self.actor.heads(view.obs);
        let a = match self.noise.as_deref_mut() {
            Some(rng) => {
                let eps = normal_pair(rng);
                let u = |k: usize| mu[k] + log_std[k].exp() * eps[k] as f32;
                [u(0).tanh(), u(1).tanh()]
            }
            None => [mu[0].tanh(), mu[1].tanh()],
        };
        self.obs.push(view.obs);
        self.actions.push(a);
        Action::from_unit(a)
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
    let episode_return = episode
        .records
        .iter()
        .zip(&recording.steers)
        .map(|(record, &steer)| rewarder.step(record, steer).total())
        .sum();
    EpisodeStats {
        episode_return,
        steps: episode.steps,
        collision: episode.records.iter().any(|r| r.collision),
        stop_reason: episode.stop_reason,
        stored: 0,
        losses: None,
    }
}

/// SAC's state: the networks, their optimizers, the replay, the generator, the counters.
pub struct Trainer {
    config: Config,
    actor: Net,
    q1: Net,
    q2: Net,
    q1_target: Net,
    q2_target: Net,
    actor_opt: Adam,
    critic_opt: Adam,
    plain: PlainActor,
    replay: Replay,
    rng: SplitMix64,
    episodes: u64,
    updates: u64,
    note: String,
}

/// What `state.json` holds.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
struct State {
    format: String,
    config: Config,
    actor_hidden: Vec<usize>,
    episodes: u64,
    updates: u64,
    actor_steps: u64,
    critic_steps: u64,
    rng: u64,
    replay_len: usize,
    replay_next: usize,
    note: String,
}

const STATE_FILE: &str = "state.json";
const ACTOR_FILE: &str = "actor.safetensors";
const CRITICS_FILE: &str = "critics.safetensors";
const OPTIMIZER_FILE: &str = "optimizer.safetensors";
const REPLAY_FILE: &str = "replay.safetensors";

fn actor_net(hidden: &[usize], rng: &mut SplitMix64) -> Result<Net, TrainError> {
    Net::random(OBS, hidden, &[("fc_mu", ACT), ("fc_std", ACT)], rng)
}

impl Trainer {
    /// A fresh run: networks initialised from the seed.
    pub fn new(config: Config) -> Result<Trainer, TrainError> {
        config.check()?;
        let mut rng = SplitMix64::new(config.seed);
        let actor = actor_net(&config.hidden, &mut rng)?;
        let critic = |rng: &mut SplitMix64| Net::random(OBS + ACT, &config.hidden, &[("fc_q", 1)], rng);
        let q1 = critic(&mut rng)?;
        let q2 = critic(&mut rng)?;
        let (q1_target, q2_target) = (q1.copy()?, q2.copy()?);
        let actor_opt = Adam::new(actor.vars(), config.actor_lr)?;
        let critic_vars = q1.vars().into_iter().map(|(n, v)| (format!("q1.{n}"), v));
        let critic_vars = critic_vars.chain(q2.vars().into_iter().map(|(n, v)| (format!("q2.{n}"), v))).collect();
        let critic_opt = Adam::new(critic_vars, config.critic_lr)?;
        let plain = PlainActor::of(&actor)?;
        Ok(Trainer {
            config,
            actor,
            q1,
            q2,
            q1_target,
            q2_target,
            actor_opt,
            critic_opt,
            plain,
            replay: Replay::default(),
            rng,
            episodes: 0,
            updates: 0,
            note: String::new(),
        })
    }

    /// Start the actor from an existing one (the paper fine-tunes SafeBench's checkpoint):
    /// its widths and weights; a missing `fc_std` head keeps a fresh one. The actor's
    /// optimizer starts over.
    pub fn init_actor(&mut self, learned: &Learned) -> Result<(), TrainError> {
        let actor = actor_net(&learned.hidden(), &mut self.rng)?;
        let mut tensors = learned.tensors()?;
        for name in ["fc_std.weight", "fc_std.bias"] {
            if !tensors.contains_key(name) {
                let fresh = actor.tensors("");
                tensors.insert(name.to_string(), fresh[name].clone());
            }
        }
        actor.set(&tensors, "", "the initial actor")?;
        self.actor_opt = Adam::new(actor.vars(), self.config.actor_lr)?;
        self.plain = PlainActor::of(&actor)?;
        self.actor = actor;
        Ok(())
    }

    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Episodes run so far (with those before a resume).
    pub fn episodes(&self) -> u64 {
        self.episodes
    }

    /// Learning steps taken so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// Transitions in the replay.
    pub fn replay_len(&self) -> usize {
        self.replay.data.len()
    }

    /// The caller's record kept in checkpoints (the command line keeps its scenarios').
    pub fn note(&self) -> &str {
        &self.note
    }

    pub fn set_note(&mut self, note: impl Into<String>) {
        self.note = note.into();
    }

    /// The next episode's scenario among `scenarios` and its seed: a function of the
    /// seed and the episodes run only, so a resumed run goes on as an unbroken one.
    pub fn task(&self, scenarios: usize) -> Task {
        let mut rng = SplitMix64::new(self.config.seed ^ 0xA076_1D64_78BD_642F);
        rng.0 = rng.0.wrapping_add(self.episodes.wrapping_mul(0xD1B5_4A32_D192_ED03));
        let scenario = rng.below(scenarios);
        Task { scenario, seed: rng.next_u64() }
    }

    /// One exploring episode: stochastic actions, its transitions stored.
    pub fn episode(&mut self, scene: &Scene, params: Vec<f64>, seed: u64) -> EpisodeStats {
        let desired = desired_speed(&self.config, scene, &params);
        let mut driver =
            Driver { actor: &self.plain, noise: Some(&mut self.rng), obs: Vec::new(), actions: Vec::new() };
        let episode = tad_runtime::run(scene, Some(seed), params, &mut driver, &self.config.options());
        let Driver { obs, actions, .. } = driver;
        let n = episode.records.len().min(obs.len());
        let terminal = matches!(episode.stop_reason, StopReason::Collision | StopReason::OffRoad);
        let mut rewarder = Rewarder::new(scene, desired);
        let mut episode_return = 0.0;
        let mut stored = 0;
        for k in 0..n {
            let a = actions[k];
            let r = rewarder.step(&episode.records[k], Action::from_unit(a).steer).total();
            episode_return += r;
            let (next, done) = match obs.get(k + 1) {
                Some(next) if k + 1 < n => (*next, 0.0),
                _ if terminal => (obs[k], 1.0),
                _ => continue,
            };
            let mut t = [0f32; WIDTH];
            for i in 0..OBS {
                t[i] = obs[k][i] as f32;
                t[OBS + ACT + 1 + i] = next[i] as f32;
            }
            t[OBS..OBS + ACT].copy_from_slice(&a);
            t[OBS + ACT] = r as f32;
            t[WIDTH - 1] = done;
            self.replay.push(self.config.buffer, t);
            stored += 1;
        }
        self.episodes += 1;
        EpisodeStats {
            episode_return,
            steps: episode.steps,
            collision: episode.records.iter().any(|r| r.collision),
            stop_reason: episode.stop_reason,
            stored,
            losses: None,
        }
    }

    /// One learning step on a batch from the replay; `None` while it holds fewer than
    /// `start_training` transitions.
    pub fn update(&mut self) -> Result<Option<Losses>, TrainError> {
        let len = self.replay.data.len();
        if len == 0 || len < self.config.start_training {
            return Ok(None);
        }
        self.learn().map(Some).map_err(tensor_error)
    }

    fn learn(&mut self) -> candle_core::Result<Losses> {
        let b = self.config.batch;
        let (mut obs, mut act, mut rew, mut next, mut done) = (
            Vec::with_capacity(b * OBS),
            Vec::with_capacity(b * ACT),
            Vec::with_capacity(b),
            Vec::with_capacity(b * OBS),
            Vec::with_capacity(b),
        );
        for _ in 0..b {
            let t = &self.replay.data[self.rng.below(self.replay.data.len())];
            obs.extend_from_slice(&t[..OBS]);
            act.extend_from_slice(&t[OBS..OBS + ACT]);
            rew.push(t[OBS + ACT]);
            next.extend_from_slice(&t[OBS + ACT + 1..WIDTH - 1]);
            done.push(t[WIDTH - 1]);
        }
        let cpu = &Device::Cpu;
        let obs = Tensor::from_vec(obs, (b, OBS), cpu)?;
        let act = Tensor::from_vec(act, (b, ACT), cpu)?;
        let rew = Tensor::from_vec(rew, (b, 1), cpu)?;
        let next = Tensor::from_vec(next, (b, OBS), cpu)?;
        let done = Tensor::from_vec(done, (b, 1), cpu)?;
        let eps_next = Tensor::from_vec(normals(&mut self.rng, b * ACT), (b, ACT), cpu)?;
        let eps_now = Tensor::from_vec(normals(&mut self.rng, b * ACT), (b, ACT), cpu)?;
        let (gamma, alpha) = (self.config.gamma, self.config.alpha);

        // critics: r + γ(1 − d)(min Q_targ(o', ã') − α log π(ã'|o')), held fixed
        let (a2, logp2) = sample_actions(&self.actor, &next, &eps_next)?;
        let (t1, t2) = q_values(&self.q1_target, &self.q2_target, &next, &a2)?;
        let soft = (t1.minimum(&t2)? - logp2.affine(alpha, 0.0)?)?;
        let backup = (rew + (done.affine(-gamma, gamma)? * soft)?)?.detach();
        let (c1, c2) = q_values(&self.q1, &self.q2, &obs, &act)?;
        let critic_loss = ((c1 - &backup)?.sqr()?.mean_all()? + (c2 - &backup)?.sqr()?.mean_all()?)?;
        self.critic_opt.minimise(&critic_loss)?;

        // actor: α log π(ã|o) − min Q(o, ã), on the critics just updated
        let (a, logp) = sample_actions(&self.actor, &obs, &eps_now)?;
        let (p1, p2) = q_values(&self.q1, &self.q2, &obs, &a)?;
        let actor_loss = (logp.affine(alpha, 0.0)? - p1.minimum(&p2)?)?.mean_all()?;
        self.actor_opt.minimise(&actor_loss)?;

        self.q1_target.polyak_from(&self.q1, self.config.polyak)?;
        self.q2_target.polyak_from(&self.q2, self.config.polyak)?;
        self.plain = PlainActor::of(&self.actor).map_err(|e| candle_core::Error::Msg(e.to_string()))?;
        self.updates += 1;
        Ok(Losses {
            critic: critic_loss.to_scalar::<f32>()?,
            actor: actor_loss.to_scalar::<f32>()?,
            entropy: -logp.mean_all()?.to_scalar::<f32>()?,
        })
    }

    /// An exploring episode, then `updates_per_episode` learning steps.
    pub fn step(&mut self, scene: &Scene, params: Vec<f64>, seed: u64) -> Result<EpisodeStats, TrainError> {
        let mut stats = self.episode(scene, params, seed);
        for _ in 0..self.config.updates_per_episode {
            if let Some(losses) = self.update()? {
                stats.losses = Some(losses);
            }
        }
        Ok(stats)
    }

    /// The deterministic actor's episode (nothing stored, no noise drawn).
    pub fn evaluate(&self, scene: &Scene, params: Vec<f64>, seed: u64) -> EpisodeStats {
        let mut driver = Driver { actor: &self.plain, noise: None, obs: Vec::new(), actions: Vec::new() };
        evaluate(scene, params, seed, &mut driver, &self.config)
    }

    /// The deterministic actor in `tad_policy`'s form.
    pub fn actor(&self) -> Result<Learned, TrainError> {
        Ok(Learned::from_tensors(&self.actor.tensors(""), "the trained actor")?)
    }

    /// Write the actor as `Learned`'s safetensors file (`--ego learned:PATH`).
    pub fn save_actor(&self, path: impl AsRef<Path>) -> Result<(), TrainError> {
        Ok(self.actor()?.save(path)?)
    }

    /// Write a checkpoint into `dir` (see the crate's header), whole or not at all.
    pub fn save_checkpoint(&self, dir: impl AsRef<Path>) -> Result<(), TrainError> {
        let dir = dir.as_ref();
        let io = |path: &Path, e: &dyn fmt::Display| TrainError::Io {
            path: path.display().to_string(),
            message: format!("cannot write it: {e}"),
        };
        let mut name = dir.file_name().map(|n| n.to_os_string()).unwrap_or_else(|| "checkpoint".into());
        name.push(".part");
        let partial = dir.with_file_name(name);
        if partial.exists() {
            std::fs::remove_dir_all(&partial).map_err(|e| io(&partial, &e))?;
        }
        std::fs::create_dir_all(&partial).map_err(|e| io(&partial, &e))?;

        let save = |file: &str, tensors: &HashMap<String, Tensor>| {
            let path = partial.join(file);
            candle_core::safetensors::save(tensors, &path).map_err(|e| io(&path, &e))
        };
        self.save_actor(partial.join(ACTOR_FILE))?;
        let mut critics = self.q1.tensors("q1.");
        critics.extend(self.q2.tensors("q2."));
        critics.extend(self.q1_target.tensors("q1_target."));
        critics.extend(self.q2_target.tensors("q2_target."));
        save(CRITICS_FILE, &critics)?;
        let mut moments = HashMap::new();
        self.actor_opt.tensors("actor.", &mut moments);
        self.critic_opt.tensors("critic.", &mut moments);
        save(OPTIMIZER_FILE, &moments)?;
        let rows = self.replay.data.len();
        let flat: Vec<f32> = self.replay.data.iter().flatten().copied().collect();
        let transitions = Tensor::from_vec(flat, (rows, WIDTH), &Device::Cpu).map_err(tensor_error)?;
        save(REPLAY_FILE, &HashMap::from([("transitions".to_string(), transitions)]))?;
        let state = State {
            format: FORMAT.to_string(),
            config: self.config.clone(),
            actor_hidden: self.actor.widths(),
            episodes: self.episodes,
            updates: self.updates,
            actor_steps: self.actor_opt.step,
            critic_steps: self.critic_opt.step,
            rng: self.rng.0,
            replay_len: rows,
            replay_next: self.replay.next,
            note: self.note.clone(),
        };
        let text = serde_json::to_string_pretty(&state).map_err(|e| io(&partial.join(STATE_FILE), &e))?;
        let state_path = partial.join(STATE_FILE);
        std::fs::write(&state_path, text + "\n").map_err(|e| io(&state_path, &e))?;
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|e| io(dir, &e))?;
        }
        std::fs::rename(&partial, dir).map_err(|e| io(dir, &e))
    }

    /// The run a checkpoint directory holds, to go on with.
    pub fn load_checkpoint(dir: impl AsRef<Path>) -> Result<Trainer, TrainError> {
        let dir = dir.as_ref();
        let shown = |p: &Path| p.display().to_string();
        let broken = |path: &Path, message: String| TrainError::Checkpoint { path: shown(path), message };
        let state_path = dir.join(STATE_FILE);
        let text = std::fs::read_to_string(&state_path)
            .map_err(|e| TrainError::Io { path: shown(&state_path), message: format!("cannot read it: {e}") })?;
        let state: State = serde_json::from_str(&text).map_err(|e| broken(&state_path, e.to_string()))?;
        if state.format != FORMAT {
            return Err(broken(&state_path, format!("format `{}`, expected `{FORMAT}`", state.format)));
        }
        state.config.check().map_err(|e| broken(&state_path, e.to_string()))?;
        let mut trainer = Trainer::new(state.config.clone())?;
        let read = |file: &str| -> Result<HashMap<String, Tensor>, TrainError> {
            let path = dir.join(file);
            let bytes = std::fs::read(&path)
                .map_err(|e| TrainError::Io { path: shown(&path), message: format!("cannot read it: {e}") })?;
            candle_core::safetensors::load_buffer(&bytes, &Device::Cpu).map_err(|e| broken(&path, e.to_string()))
        };

        let actor_path = dir.join(ACTOR_FILE);
        let actor_tensors = read(ACTOR_FILE)?;
        trainer.actor =
            actor_net(&state.actor_hidden, &mut SplitMix64::new(0)).map_err(|e| broken(&state_path, e.to_string()))?;
        trainer.actor.set(&actor_tensors, "", &shown(&actor_path))?;
        trainer.actor_opt = Adam::new(trainer.actor.vars(), trainer.config.actor_lr)?;

        let critics_path = shown(&dir.join(CRITICS_FILE));
        let critics = read(CRITICS_FILE)?;
        for (net, prefix) in [
            (&trainer.q1, "q1."),
            (&trainer.q2, "q2."),
            (&trainer.q1_target, "q1_target."),
            (&trainer.q2_target, "q2_target."),
        ] {
            net.set(&critics, prefix, &critics_path)?;
        }

        let optimizer_path = shown(&dir.join(OPTIMIZER_FILE));
        let moments = read(OPTIMIZER_FILE)?;
        trainer.actor_opt.set(&moments, "actor.", &optimizer_path)?;
        trainer.critic_opt.set(&moments, "critic.", &optimizer_path)?;
        trainer.actor_opt.step = state.actor_steps;
        trainer.critic_opt.step = state.critic_steps;

        let replay_path = dir.join(REPLAY_FILE);
        let replay = read(REPLAY_FILE)?;
        let transitions =
            replay.get("transitions").filter(|t| t.dims() == [state.replay_len, WIDTH]).ok_or_else(|| {
                broken(&replay_path, format!("no `transitions` of shape [{}, {WIDTH}]", state.replay_len))
            })?;
        let flat = transitions
            .to_dtype(DType::F32)
            .and_then(|t| t.flatten_all()?.to_vec1::<f32>())
            .map_err(|e| broken(&replay_path, e.to_string()))?;
        // filling, the next write appends; full, it overwrites the oldest
        let valid = match state.replay_len.cmp(&state.config.buffer) {
            std::cmp::Ordering::Less => state.replay_next == state.replay_len,
            std::cmp::Ordering::Equal => state.replay_next < state.replay_len,
            std::cmp::Ordering::Greater => false,
        };
        if !valid {
            return Err(broken(&state_path, "the replay's length or position does not fit its capacity".into()));
        }
        trainer.replay = Replay {
            data: flat.chunks_exact(WIDTH).map(|c| c.try_into().unwrap_or([0.0; WIDTH])).collect(),
            next: state.replay_next,
        };

        trainer.plain = PlainActor::of(&trainer.actor)?;
        trainer.rng = SplitMix64::new(state.rng);
        trainer.episodes = state.episodes;
        trainer.updates = state.updates;
        trainer.note = state.note;
        Ok(trainer)
    }
}

/// The held-out split of the paper: for each key (a behaviour), 3/5 of its items for
/// training (rounded to the nearest, at least one and, with two or more, at most all but
/// one), the rest for testing; which ones is drawn from `seed` and the key alone, so adding
/// items of another key changes nothing here. Both lists in ascending order.
pub fn split(keys: &[String], seed: u64) -> (Vec<usize>, Vec<usize>) {
    let mut groups: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, key) in keys.iter().enumerate() {
        groups.entry(key.as_str()).or_default().push(i);
    }
    let (mut train, mut test) = (Vec::new(), Vec::new());
    for (key, mut items) in groups {
        let mut rng = SplitMix64::new(seed ^ tad_base::fnv1a(key.bytes()));
        rng.shuffle(&mut items);
        let n = items.len();
        let keep = if n >= 2 { ((n as f64 * 0.6).round() as usize).clamp(1, n - 1) } else { n };
        train.extend_from_slice(&items[..keep]);
        test.extend_from_slice(&items[keep..]);
    }
    train.sort_unstable();
    test.sort_unstable();
    (train, test)
}

/// Where a run's checkpoints go by default: `<out>.ckpt`.
pub fn default_checkpoint_dir(out: &Path) -> PathBuf {
    beside(out, ".ckpt")
}

/// `OUT` with `suffix` added to its name (`actor.safetensors.split.json`), in the same
/// directory; `actor` when `out` has no name.
pub fn beside(out: &Path, suffix: &str) -> PathBuf {
    let mut name = out.file_name().map(|n| n.to_os_string()).unwrap_or_else(|| "actor".into());
    name.push(suffix);
    out.with_file_name(name)
}
