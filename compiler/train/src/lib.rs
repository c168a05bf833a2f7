//! PPO, SAC and TD3 for the learned ego, in candle on the CPU, against the runtime's
//! episodes: SafeBench's observation, action and reward, SafeBench's settings per algorithm
//! and ChatScene's SAC. Every actor comes out in the safetensors form `tad_policy::Learned`
//! reads, so `--ego learned:PATH` drives with it.
//!
//! ```text
//! jobs (scene, params, seed) ──rayon: one explorer per episode, its own noise──▶ episodes
//!      ──▶ SafeBench's rewards from the records ──▶ transitions, in the jobs' order
//!   SAC, TD3: replay (ring) ─▶ `updates_per_episode` learning steps per episode
//!   PPO: rollout ─▶ once it holds `rollout` transitions: GAE, `epochs` passes of minibatches
//! checkpoint: every tensor, both optimizers' moments, the replay, the generator, the counters
//! ```
//!
//! # Algorithms
//!
//! All three share the actor's body (`obs → hidden → fc_mu`, ReLU, PyTorch's `nn.Linear`
//! and its initialisation, layers named `fc1 … fcN`, `fc_mu`) and its deterministic action
//! `tanh(fc_mu(x))`, applied by `tad_policy::Action::from_unit` (3 m/s² forward and 0.3
//! of the steer as SafeBench; the full brake of 8 m/s²):
//!
//! - **SAC** (Spinning Up's, as ChatScene runs it): a second head `fc_std`, a clamped log
//!   standard deviation in `[−20, 2]`; exploration `tanh(mu + σ·ε)`; twin critics
//!   `Q(obs, action)` with polyak-averaged targets; a fixed entropy weight `alpha`.
//! - **TD3** (Fujimoto et al. 2018): no `fc_std`; exploration `clip(tanh(mu) + N(0, s))`;
//!   twin critics against a target actor whose action is smoothed by clipped noise; the
//!   actor (`−Q1`) and every target move each `policy_delay` critic steps.
//! - **PPO** (clipped, Schulman et al. 2017): the `fc_std` head gives a Gaussian over the
//!   pre-tanh action `u`; the rollout keeps `u`, and the ratio is that Gaussian's (the tanh
//!   correction depends on `u` alone and cancels); a value network `obs → hidden → v`;
//!   advantages by GAE(γ, λ), normalised per update; `epochs` passes in shuffled minibatches.
//!
//! [`Config::safebench`] holds SafeBench's settings per algorithm
//! (`agent/config/{sac,td3,ppo}.yaml`): SAC lr 5e-4, τ .005, batch 32, buffer 10 k,
//! 3 updates per episode; TD3 lr 3e-4, τ .005, policy delay 2, target noise .2 clipped at
//! .5, exploration .1; PPO lr 1e-4, clip .2, 20 passes, minibatch 64; γ .99 for all. What
//! SafeBench leaves unsaid is Spinning Up's or SB3's default (PPO's λ .95 and rollout
//! 2048). [`Config::default`] is ChatScene's SAC (`adv_scenic.yaml`: lr 1e-4, α .01,
//! polyak .995, batch 512, buffer 30 k, learning from 1000 transitions, 600 episodes).
//!
//! # Reward
//!
//! SafeBench's (`carla_env.py::_get_reward`), computed from each step's record, the state
//! the action led to: `r = −1·collision + lspeed_lon + 10·r_fast + r_out + 5·(−steer²) +
//! 0.2·(−|steer|·lspeed_lon²)` ([`Rewarder`]). The desired speed is the scenario's own ego
//! speed unless [`Config::desired_speed`] fixes one (SafeBench's 8 m/s).
//!
//! # Transitions
//!
//! Step `k`'s observation `o_k` and action `a_k` lead to record `k`, which gives `r_k`; the
//! next observation is `o_{k+1}`. After a collision or going off the road the last step is
//! terminal (`done`). After a time, distance or route-complete stop it is a truncation: the
//! off-policy replay leaves it out rather than store a false terminal; PPO keeps it and
//! bootstraps from the value of its own observation. Each row also marks the episode's end,
//! where GAE's sum stops.
//!
//! # Parallel rollouts, determinism
//!
//! [`Trainer::round`] runs [`Config::envs`] episodes with the same actor on rayon, each
//! drawing its exploration noise from a generator seeded by the run's seed and the
//! episode's number, and stores them in the jobs' order; so the result does not depend on
//! the thread count. Every other random choice (initialisation, batches, the update's
//! noise) draws from one `tad_ir::SplitMix64` seeded by [`Config::seed`]. The `n`-th
//! episode's scenario and seed ([`Trainer::task_at`]) are a function of the seed and `n`.
//! Same seed, scenes and settings ⇒ the same file bytes, whatever the thread count and the
//! vector width: every layer is one op of candle's graph whose products are this crate's
//! own (`gemm`: each output one chain of fused multiply-adds in a fixed order, vectorised
//! across outputs only), so AVX-512, AVX2 and the scalar fallback sum alike.
//!
//! # Warm start
//!
//! [`Trainer::imitate`] clones a teacher (the idm driver) into the actor by DAgger: the
//! teacher drives the first round, the actor the later ones, and the teacher labels every
//! state seen; the actor's `tanh(fc_mu)` is fitted to the labels by mean squared error.
//! [`Config::critic_warmup`] then lets fresh critics learn the cloned driver's values
//! before the actor moves, and [`Config::bc_weight`] keeps the labelled states as
//! demonstrations in the actor's loss (TD3+BC's form), so the algorithm improves on the
//! clone instead of forgetting it.

mod checkpoint;
mod config;
mod gemm;
mod imitate;
mod nets;
pub mod reward;
mod rollout;
mod update;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use tad_ir::{Rng, SplitMix64};
use tad_metrics::StopReason;
use tad_policy::{EgoPolicy, Learned, PolicyError};
use tad_runtime::Scene;

pub use config::{Algo, CHATSCENE_COLLISION_SHARE, Config, MAX_BUFFER, MAX_WIDTH};
pub use gemm::kernel_name;
pub use imitate::{Imitation, ImitationRound};
pub use reward::{Reward, Rewarder};
pub use rollout::evaluate;

use nets::{ACT, Adam, Net, PlainActor, tensor_error};

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
    /// The critics' (PPO: the value network's) mean squared errors, summed.
    pub critic: f32,
    /// The actor's loss (0 when only the critics moved).
    pub actor: f32,
    /// SAC: the batch's mean `−log π`, nats; PPO: the Gaussian's; TD3: 0.
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
    /// The route completed at the end, 0..=1.
    pub route_complete: f64,
    /// Transitions stored (0 when evaluating).
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

/// A scene to train on: fixed parameters and seed (a searched scene), or none (sampled
/// from each episode's task seed).
#[derive(Clone, Copy)]
pub struct TrainScene<'a> {
    pub scene: &'a Scene,
    pub fixed: Option<(&'a [f64], u64)>,
}

/// One episode to run: a scene, its parameters and its seed.
#[derive(Clone)]
pub struct Job<'a> {
    pub scene: &'a Scene,
    pub params: Vec<f64>,
    pub seed: u64,
}

impl<'a> TrainScene<'a> {
    /// The episode this scene gives for a task's seed.
    pub fn job(&self, seed: u64) -> Job<'a> {
        match self.fixed {
            Some((params, seed)) => Job { scene: self.scene, params: params.to_vec(), seed },
            None => Job {
                scene: self.scene,
                params: tad_runtime::sample::sample(&self.scene.program.params, Some(seed)),
                seed,
            },
        }
    }
}

/// The replay (SAC, TD3: a ring of `buffer` rows) or the rollout (PPO: emptied by each
/// update). A row: obs, action (PPO: pre-tanh), reward, next obs, done, episode end.
#[derive(Clone, Debug, Default)]
struct Replay {
    width: usize,
    data: Vec<f32>,
    next: usize,
}

impl Replay {
    fn new(obs: usize) -> Replay {
        Replay { width: row_width(obs), data: Vec::new(), next: 0 }
    }

    fn len(&self) -> usize {
        self.data.len() / self.width
    }

    fn row(&self, i: usize) -> &[f32] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    /// Append, or overwrite the oldest once `capacity` rows are held.
    fn push(&mut self, capacity: usize, row: &[f32]) {
        if self.len() < capacity {
            self.data.extend_from_slice(row);
            self.next = self.len() % capacity;
        } else {
            let w = self.width;
            self.data[self.next * w..(self.next + 1) * w].copy_from_slice(row);
            self.next = (self.next + 1) % capacity;
        }
    }

    fn clear(&mut self) {
        self.data.clear();
        self.next = 0;
    }
}

/// A row's width for observations of `obs` values.
fn row_width(obs: usize) -> usize {
    obs + ACT + 1 + obs + 2
}

/// The critics of each algorithm, by name (their order is the checkpoint's).
struct CriticNets {
    nets: Vec<(&'static str, Net)>,
}

impl CriticNets {
    fn new(config: &Config, obs: usize, actor: &Net, rng: &mut SplitMix64) -> Result<CriticNets, TrainError> {
        let mut nets = Vec::new();
        match config.algo {
            Algo::Sac | Algo::Td3 => {
                let q = |rng: &mut SplitMix64| Net::random(obs + ACT, &config.hidden, &[("fc_q", 1)], rng);
                let (q1, q2) = (q(rng)?, q(rng)?);
                let (t1, t2) = (q1.copy()?, q2.copy()?);
                nets.extend([("q1", q1), ("q2", q2), ("q1_target", t1), ("q2_target", t2)]);
                if config.algo == Algo::Td3 {
                    nets.push(("actor_target", actor.copy()?));
                }
            }
            Algo::Ppo => nets.push(("v", Net::random(obs, &config.hidden, &[("fc_v", 1)], rng)?)),
        }
        Ok(CriticNets { nets })
    }

    fn get(&self, name: &str) -> &Net {
        // every name asked for is one `new` made for the algorithm
        &self.nets.iter().find(|(n, _)| *n == name).expect("a critic of the algorithm").1
    }

    /// The networks the critic optimizer moves: every one but the targets.
    fn learners(&self) -> impl Iterator<Item = &(&'static str, Net)> {
        self.nets.iter().filter(|(n, _)| !n.ends_with(TARGET))
    }

    /// The target that follows the network `name`, if it has one.
    fn target_of(&self, name: &str) -> Option<&Net> {
        self.nets.iter().find(|(n, _)| n.strip_suffix(TARGET) == Some(name)).map(|(_, net)| net)
    }

    /// The learners' variables, named `{net}.{parameter}`.
    fn trained(&self) -> Vec<(String, candle_core::Var)> {
        self.learners()
            .flat_map(|(n, net)| net.vars().into_iter().map(move |(v, var)| (format!("{n}.{v}"), var)))
            .collect()
    }
}

/// How a target network's name ends (`q1_target` follows `q1`).
const TARGET: &str = "_target";

/// The standard deviation of the pre-tanh action a stochastic head starts with where none
/// is learnt yet (PPO's fresh actor; an actor without `fc_std`): SB3's `log_std_init` 0 is
/// σ 1, which through tanh makes every action near ±1, and a noisy steer makes slow
/// driving the best under SafeBench's steer penalty.
pub const INITIAL_STD: f64 = 0.2;

/// A run's state: the networks, their optimizers, the replay, the generator, the counters.
pub struct Trainer {
    config: Config,
    actor: Net,
    plain: PlainActor,
    actor_opt: Adam,
    critics: CriticNets,
    critic_opt: Adam,
    replay: Replay,
    /// Colliding steps, apart ([`Config::collision_share`]; empty without it).
    collisions: Replay,
    /// The warm start's labelled states: rows of obs and the teacher's action.
    demos: Vec<f32>,
    rng: SplitMix64,
    episodes: u64,
    updates: u64,
    note: String,
}

fn actor_net(config: &Config, obs: usize, hidden: &[usize], rng: &mut SplitMix64) -> Result<Net, TrainError> {
    match config.algo {
        Algo::Td3 => Net::random(obs, hidden, &[("fc_mu", ACT)], rng),
        Algo::Sac | Algo::Ppo => Net::random(obs, hidden, &[("fc_mu", ACT), ("fc_std", ACT)], rng),
    }
}

impl Trainer {
    /// A fresh run: networks initialised from the seed.
    pub fn new(config: Config) -> Result<Trainer, TrainError> {
        config.check()?;
        let obs = config.observation.width();
        let mut rng = SplitMix64::new(config.seed);
        let actor = actor_net(&config, obs, &config.hidden, &mut rng)?;
        if config.algo == Algo::Ppo {
            actor.constant_std(INITIAL_STD)?;
        }
        let critics = CriticNets::new(&config, obs, &actor, &mut rng)?;
        let actor_opt = Adam::new(actor.vars(), config.actor_lr)?;
        let critic_opt = Adam::new(critics.trained(), config.critic_lr)?;
        let plain = PlainActor::of(&actor)?;
        Ok(Trainer {
            actor,
            plain,
            actor_opt,
            critics,
            critic_opt,
            replay: Replay::new(obs),
            collisions: Replay::new(obs),
            demos: Vec::new(),
            rng,
            episodes: 0,
            updates: 0,
            note: String::new(),
            config,
        })
    }

    /// Start the actor from an existing one (the paper fine-tunes SafeBench's checkpoint):
    /// its widths and weights; a missing `fc_std` head gives [`INITIAL_STD`], and TD3 drops
    /// it. The actor's optimizer starts over; TD3's target actor is the new actor.
    pub fn init_actor(&mut self, learned: &Learned) -> Result<(), TrainError> {
        let obs = self.config.observation.width();
        if learned.inputs() != obs {
            return Err(TrainError::Config(format!(
                "the actor reads {} values, but the run's observation `{}` has {obs}",
                learned.inputs(),
                self.config.observation.name()
            )));
        }
        let actor = actor_net(&self.config, obs, &learned.hidden(), &mut self.rng)?;
        actor.constant_std(INITIAL_STD)?;
        let mut tensors = learned.tensors()?;
        let fresh = actor.tensors("");
        for name in ["fc_std.weight", "fc_std.bias"] {
            if let Some(t) = fresh.get(name) {
                tensors.entry(name.to_string()).or_insert_with(|| t.clone());
            }
        }
        actor.set(&tensors, "", "the initial actor")?;
        self.set_actor(actor)
    }

    /// `actor` as the run's, its optimizer fresh and TD3's target a copy.
    fn set_actor(&mut self, actor: Net) -> Result<(), TrainError> {
        self.actor_opt = Adam::new(actor.vars(), self.config.actor_lr)?;
        self.plain = PlainActor::of(&actor)?;
        if let Some(slot) = self.critics.nets.iter_mut().find(|(n, _)| *n == "actor_target") {
            slot.1 = actor.copy()?;
        }
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

    /// Transitions in the replay (PPO: in the rollout not yet learned from).
    pub fn replay_len(&self) -> usize {
        self.replay.len()
    }

    /// Colliding steps held apart ([`Config::collision_share`]).
    pub fn collisions_len(&self) -> usize {
        self.collisions.len()
    }

    /// Why `episodes` more episodes of at most `steps` steps each cannot reach a first
    /// learning step, if they cannot: they store one transition a step, and learning starts
    /// at [`Config::transitions_to_learn`]. `None` once it has learned, or when they may.
    pub fn cannot_learn_within(&self, episodes: usize, steps: usize) -> Option<String> {
        let needed = self.config.transitions_to_learn();
        let stored = self.replay_len();
        let most = stored.saturating_add(episodes.saturating_mul(steps));
        (self.updates == 0 && most < needed).then(|| {
            let enough = (needed - stored).div_ceil(steps.max(1));
            format!(
                "{} of at most {steps} steps store at most {most} transitions ({stored} stored now), \
                 and learning starts at {needed}: at least {enough} episodes are needed",
                tad_base::plural(episodes, "episode")
            )
        })
    }

    /// Labelled states kept from the warm start (the demonstrations of [`Config::bc_weight`]).
    pub fn demos(&self) -> usize {
        self.demos.len() / (self.config.observation.width() + ACT)
    }

    /// The caller's record kept in checkpoints (the command line keeps its scenarios').
    pub fn note(&self) -> &str {
        &self.note
    }

    pub fn set_note(&mut self, note: impl Into<String>) {
        self.note = note.into();
    }

    /// The next episode's scenario among `scenarios` and its seed.
    pub fn task(&self, scenarios: usize) -> Task {
        self.task_at(self.episodes, scenarios)
    }

    /// Episode `n`'s scenario among `scenarios` and its seed: a function of the seed and
    /// `n` only, so a resumed run goes on as an unbroken one.
    pub fn task_at(&self, n: u64, scenarios: usize) -> Task {
        let mut rng = SplitMix64::new(self.config.seed ^ 0xA076_1D64_78BD_642F);
        rng.0 = rng.0.wrapping_add(n.wrapping_mul(0xD1B5_4A32_D192_ED03));
        let scenario = rng.below(scenarios);
        Task { scenario, seed: rng.next_u64() }
    }

    /// The next `count` episodes' jobs on `scenes`.
    pub fn jobs<'a>(&self, scenes: &[TrainScene<'a>], count: usize) -> Vec<Job<'a>> {
        (0..count as u64)
            .map(|k| {
                let task = self.task_at(self.episodes + k, scenes.len());
                scenes[task.scenario].job(task.seed)
            })
            .collect()
    }

    /// Episode `n`'s exploration noise seed.
    fn noise_seed(&self, n: u64) -> u64 {
        SplitMix64::new(self.config.seed ^ 0x9E37_79B9_7F4A_7C15 ^ n.wrapping_mul(0xBF58_476D_1CE4_E5B9)).next_u64()
    }

    /// Exploring episodes of `jobs` with the current actor, in parallel; their
    /// transitions stored in order; then the algorithm's learning steps.
    pub fn round(&mut self, jobs: &[Job]) -> Result<Vec<EpisodeStats>, TrainError> {
        let first = self.episodes;
        let seeds: Vec<u64> = (0..jobs.len() as u64).map(|k| self.noise_seed(first + k)).collect();
        let (plain, config) = (&self.plain, &self.config);
        let collected: Vec<rollout::Collected> = jobs
            .par_iter()
            .zip(&seeds)
            .map(|(job, &seed)| rollout::explore(plain, config, job, SplitMix64::new(seed)))
            .collect();
        let mut all = Vec::with_capacity(collected.len());
        let capacity = self.config.replay_capacity();
        let apart = self.config.splits_collisions();
        for c in collected {
            for (k, row) in c.rows.chunks_exact(self.replay.width).enumerate() {
                if apart && c.collided.contains(&k) {
                    self.collisions.push(self.config.collision_capacity(), row);
                } else {
                    self.replay.push(capacity, row);
                }
            }
            self.episodes += 1;
            all.push(c.stats);
        }
        let losses = self.learn(jobs.len())?;
        if let Some(last) = all.last_mut() {
            last.losses = losses;
        }
        Ok(all)
    }

    /// An exploring episode, then the learning steps it brings.
    pub fn step(&mut self, scene: &Scene, params: Vec<f64>, seed: u64) -> Result<EpisodeStats, TrainError> {
        let mut stats = self.round(&[Job { scene, params, seed }])?;
        Ok(stats.remove(0))
    }

    /// The learning steps after `episodes` finished episodes; the last one's losses.
    fn learn(&mut self, episodes: usize) -> Result<Option<Losses>, TrainError> {
        match self.config.algo {
            Algo::Sac | Algo::Td3 => {
                let mut last = None;
                for _ in 0..self.config.updates_per_episode * episodes {
                    if let Some(losses) = self.update()? {
                        last = Some(losses);
                    }
                }
                Ok(last)
            }
            Algo::Ppo if self.replay.len() >= self.config.rollout => {
                let losses = self.ppo_update().map_err(tensor_error)?;
                self.replay.clear();
                Ok(Some(losses))
            }
            Algo::Ppo => Ok(None),
        }
    }

    /// One off-policy learning step on a batch from the replay; `None` while it holds
    /// fewer than `start_training` transitions, and always for PPO (see [`Trainer::round`]).
    pub fn update(&mut self) -> Result<Option<Losses>, TrainError> {
        let len = self.replay.len();
        if len == 0 || len < self.config.start_training {
            return Ok(None);
        }
        let losses = match self.config.algo {
            Algo::Sac => self.sac_update(),
            Algo::Td3 => self.td3_update(),
            Algo::Ppo => return Ok(None),
        };
        losses.map(Some).map_err(tensor_error)
    }

    /// One learning step now: SAC's or TD3's on a replay batch (as [`Trainer::update`]), or
    /// PPO's on the rollout held so far, whatever its length (then emptied). For
    /// benchmarks and callers with their own schedule.
    pub fn learn_now(&mut self) -> Result<Option<Losses>, TrainError> {
        match self.config.algo {
            Algo::Ppo if self.replay.len() > 0 => {
                let losses = self.ppo_update().map_err(tensor_error)?;
                self.replay.clear();
                Ok(Some(losses))
            }
            Algo::Ppo => Ok(None),
            Algo::Sac | Algo::Td3 => self.update(),
        }
    }

    /// The deterministic actor's episode (nothing stored, no noise drawn).
    pub fn evaluate(&self, scene: &Scene, params: Vec<f64>, seed: u64) -> EpisodeStats {
        let mut driver = rollout::Driver::deterministic(&self.plain, &self.config);
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

    /// A copy of the trained critics (SAC's and TD3's `q1`, `q2`; PPO's `v`), each tensor
    /// under `{critic}.{parameter}`: what fine-tuning starts from beside the actor, as
    /// ChatScene goes on from SafeBench's checkpoint, critics and all.
    pub fn critics(&self) -> Result<Critics, TrainError> {
        let mut tensors = std::collections::HashMap::new();
        for (name, net) in self.critics.learners() {
            for (key, t) in net.tensors(&format!("{name}.")) {
                tensors.insert(key, t.copy().map_err(tensor_error)?);
            }
        }
        Ok(Critics(tensors))
    }

    /// Start the critics from `bytes` (a [`Critics::save`] file, named `source` in errors):
    /// each trained critic set, its target a copy of it, the optimizer's moments fresh. The
    /// widths must be the run's.
    pub fn init_critics(&mut self, bytes: &[u8], source: &str) -> Result<(), TrainError> {
        let broken = |message: String| TrainError::Checkpoint { path: source.to_string(), message };
        let tensors = candle_core::safetensors::load_buffer(bytes, &candle_core::Device::Cpu)
            .map_err(|e| broken(format!("not a safetensors file: {e}")))?;
        for (name, net) in self.critics.learners() {
            let prefix = format!("{name}.");
            net.set(&tensors, &prefix, source)?;
            if let Some(target) = self.critics.target_of(name) {
                target.set(&tensors, &prefix, source)?;
            }
        }
        self.critic_opt = Adam::new(self.critics.trained(), self.config.critic_lr)?;
        Ok(())
    }
}

/// Critics taken out of a run ([`Trainer::critics`]).
pub struct Critics(std::collections::HashMap<String, candle_core::Tensor>);

impl Critics {
    /// Write them as one safetensors file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), TrainError> {
        let path = path.as_ref();
        candle_core::safetensors::save(&self.0, path)
            .map_err(|e| TrainError::Io { path: path.display().to_string(), message: format!("cannot write it: {e}") })
    }
}

/// The thread settings of a process that trains. Call it at the start of the process,
/// before other threads run: it sets environment variables that candle and rayon read.
/// - Tensor operations on the calling thread only, unless `CANDLE_NUM_THREADS` says
///   otherwise. candle's CPU pool keeps its workers spinning between operations; on these
///   networks (256 × 256, batches of 64 to 512) that made learning steps 5× slower than one
///   thread (measured by `bench --rl`), and it competes with the parallel rollouts.
/// - `RAYON_NUM_THREADS`, unless set, to the threads rayon's pool starts anyway (the
///   available parallelism). candle asks for it at every one of its matrix products and,
///   without it, counts the physical cores by reading `/proc/cpuinfo` each time (15-35 %
///   of a learning step, when the layers were candle's matmul; they are this crate's
///   `gemm` now, whose numbers do not depend on the thread count).
pub fn set_up_threads() {
    // SAFETY (both): called at the start of the process, before any other thread reads the
    // environment
    if std::env::var_os("CANDLE_NUM_THREADS").is_none() {
        unsafe { std::env::set_var("CANDLE_NUM_THREADS", "1") };
    }
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        let threads = std::thread::available_parallelism().map_or(1, usize::from);
        unsafe { std::env::set_var("RAYON_NUM_THREADS", threads.to_string()) };
    }
}

/// Any policy, boxed for a thread of its own.
pub type PolicyMaker<'a> = &'a (dyn Fn() -> Box<dyn EgoPolicy> + Sync);

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
