//! The three algorithms and their settings: one [`Config`], with SafeBench's defaults per
//! algorithm ([`Config::safebench`]) and ChatScene's SAC ([`Config::default`], the search
//! surrogate and the fine-tuning of `eval --finetune`).

use serde::{Deserialize, Serialize};
use tad_metrics::Mode;
use tad_policy::Observation;
use tad_runtime::Options;

use crate::TrainError;

/// A reinforcement-learning algorithm.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Algo {
    /// Proximal policy optimisation (clipped), on-policy.
    Ppo,
    /// Soft actor-critic, off-policy, stochastic actor.
    #[default]
    Sac,
    /// Twin delayed DDPG, off-policy, deterministic actor.
    Td3,
}

impl Algo {
    pub const ALL: [Algo; 3] = [Algo::Ppo, Algo::Sac, Algo::Td3];

    pub fn name(self) -> &'static str {
        match self {
            Algo::Ppo => "ppo",
            Algo::Sac => "sac",
            Algo::Td3 => "td3",
        }
    }

    pub fn parse(name: &str) -> Option<Algo> {
        Algo::ALL.into_iter().find(|a| a.name() == name)
    }
}

/// A training run's settings. Fields one algorithm does not use are ignored by it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Config {
    pub algo: Algo,
    /// What the actor sees.
    pub observation: Observation,
    /// Hidden widths of the actor and of each critic (PPO: of the value network).
    pub hidden: Vec<usize>,
    pub actor_lr: f64,
    pub critic_lr: f64,
    /// SAC's entropy weight (fixed).
    pub alpha: f64,
    pub gamma: f64,
    /// Target networks keep this much of themselves per update (1 − SafeBench's `tau`).
    pub polyak: f64,
    /// Transitions per learning step (PPO: per minibatch).
    pub batch: usize,
    /// The replay's capacity, transitions (oldest overwritten).
    pub buffer: usize,
    /// No update before the replay holds this many transitions.
    pub start_training: usize,
    /// Episodes in all (for callers' loops; the trainer itself counts).
    pub episodes: usize,
    /// Off-policy learning steps per finished episode (ChatScene: 1).
    pub updates_per_episode: usize,
    /// ChatScene's replay split (`RouteReplayBuffer`): the transitions of colliding steps
    /// go to a ring of their own (`buffer / 100` rows) and make up this share of every
    /// off-policy batch, drawn without replacement (ChatScene: 1/5); fewer held, all of
    /// them. 0: one ring, as SafeBench. A setting read without it is 0.
    #[serde(default)]
    pub collision_share: f64,
    /// Episodes rolled out at once with the same actor, in parallel over the cores; a
    /// setting of the run, never the thread count, so results do not depend on the machine.
    pub envs: usize,
    /// Learning steps at the start that train the critics only (a warm-started actor
    /// keeps its driving while fresh critics learn what it is worth).
    pub critic_warmup: usize,
    /// The weight of the demonstrations' term in the actor's loss (0: pure RL, as
    /// SafeBench). With it, the actor's RL term is scaled as TD3+BC scales it (Fujimoto &
    /// Gu 2021: `α / mean |Q|`, α 2.5; PPO's advantages are normalised already) and
    /// `bc_weight · MSE(tanh(mu(o)), a)` is added on a batch of the warm start's labelled
    /// states, so learning improves on the cloned driver instead of forgetting it.
    pub bc_weight: f64,
    /// TD3: the actor and the targets move every this many critic steps.
    pub policy_delay: usize,
    /// TD3: the target policy's smoothing noise, its clip, and the exploration noise
    /// (standard deviations in the `[−1, 1]` action).
    pub target_noise: f64,
    pub noise_clip: f64,
    pub explore_noise: f64,
    /// PPO: the ratio's clip, passes over each rollout, GAE's λ, and the transitions
    /// collected before each update.
    pub clip: f64,
    pub epochs: usize,
    pub lambda: f64,
    pub rollout: usize,
    /// The reward's desired speed, m/s; `None`: the scenario's ego speed.
    pub desired_speed: Option<f64>,
    /// SafeBench's quirks (off-road never ends an episode) instead of the fixed rules.
    pub compat: bool,
    pub seed: u64,
}

impl Default for Config {
    /// ChatScene's SAC (`adv_scenic.yaml`): the search surrogate and the fine-tuning.
    fn default() -> Config {
        Config {
            algo: Algo::Sac,
            observation: Observation::SafeBench,
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
            collision_share: 0.0,
            envs: 1,
            critic_warmup: 0,
            bc_weight: 0.0,
            policy_delay: 2,
            target_noise: 0.2,
            noise_clip: 0.5,
            explore_noise: 0.1,
            clip: 0.2,
            epochs: 20,
            lambda: 0.95,
            rollout: 2048,
            desired_speed: None,
            compat: false,
            seed: 0,
        }
    }
}

impl Config {
    /// The transitions stored before the first learning step: PPO's rollout, else
    /// `start_training`.
    pub fn transitions_to_learn(&self) -> usize {
        if self.algo == Algo::Ppo { self.rollout } else { self.start_training }
    }

    /// SafeBench's settings for `algo` (`agent/config/*.yaml`; see the crate's header).
    pub fn safebench(algo: Algo) -> Config {
        let base = Config { algo, episodes: 2000, ..Config::default() };
        match algo {
            Algo::Sac => Config {
                actor_lr: 5e-4,
                critic_lr: 5e-4,
                polyak: 0.995,
                batch: 32,
                buffer: 10_000,
                updates_per_episode: 3,
                ..base
            },
            Algo::Td3 => Config {
                actor_lr: 3e-4,
                critic_lr: 3e-4,
                polyak: 0.995,
                batch: 32,
                buffer: 10_000,
                updates_per_episode: 3,
                ..base
            },
            Algo::Ppo => Config { actor_lr: 1e-4, critic_lr: 1e-4, batch: 64, epochs: 20, clip: 0.2, ..base },
        }
    }

    /// Fine-tuning a pretrained model on searched scenes: the paper's learning rate 1e-4
    /// (TrafficAlign; ChatScene's `train_agent_scenic.yaml`), SAC with ChatScene's other
    /// settings, PPO and TD3 with SafeBench's. The critics (a shipped model's own, else
    /// fresh ones) learn alone for their first 200 steps (PPO: 2 updates), and the model's
    /// own actions on the training scenes stay in the actor's loss at weight 1: without
    /// both, SAC and TD3 learned to stop (collisions down 32-53 %, route completion from
    /// 0.55 to 0.04-0.16). Colliding steps are not kept apart ([`Config::collision_share`]
    /// 0, where ChatScene's fine-tuning draws a fifth of each batch from them): with a
    /// fifth, TD3's route completion on its training scenes fell from 0.54 to 0.12 within
    /// 150 episodes while its collisions rose (critics that overrate collisions teach the
    /// actor to stand still); without, it kept 0.51 and collided less.
    pub fn finetune(algo: Algo) -> Config {
        let base = match algo {
            Algo::Sac => Config::default(),
            _ => Config {
                actor_lr: 1e-4,
                critic_lr: 1e-4,
                episodes: Config::default().episodes,
                ..Config::safebench(algo)
            },
        };
        Config { critic_warmup: if algo == Algo::Ppo { 2 } else { 200 }, bc_weight: 1.0, collision_share: 0.0, ..base }
    }

    /// Why these settings cannot train, if they cannot.
    pub fn check(&self) -> Result<(), TrainError> {
        let bad = |m: String| Err(TrainError::Config(m));
        if self.hidden.is_empty() || self.hidden.contains(&0) {
            return bad(format!(
                "the hidden widths must be at least one layer of at least one unit (got {:?})",
                self.hidden
            ));
        }
        // a 4096-wide layer is 16 M weights: beyond, the allocation is the user's typo
        if let Some(w) = self.hidden.iter().find(|&&w| w > MAX_WIDTH) {
            return bad(format!("a hidden layer of {w} units is too wide (at most {MAX_WIDTH})"));
        }
        for (name, v) in [("actor learning rate", self.actor_lr), ("critic learning rate", self.critic_lr)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("the {name} must be a positive number (got {v})"));
            }
        }
        if !(self.bc_weight.is_finite() && self.bc_weight >= 0.0) {
            return bad(format!("the demonstrations' weight must be a number ≥ 0 (got {})", self.bc_weight));
        }
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            return bad(format!("alpha must be a number ≥ 0 (got {})", self.alpha));
        }
        for (name, v) in [
            ("gamma", self.gamma),
            ("polyak", self.polyak),
            ("lambda", self.lambda),
            ("the collisions' share", self.collision_share),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return bad(format!("{name} must be within 0..=1 (got {v})"));
            }
        }
        for (name, v) in [
            ("the target noise", self.target_noise),
            ("the noise clip", self.noise_clip),
            ("the exploration noise", self.explore_noise),
            ("the clip", self.clip),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(format!("{name} must be a number ≥ 0 (got {v})"));
            }
        }
        let counts = [
            ("the batch", self.batch),
            ("the replay's capacity", self.buffer),
            ("envs", self.envs),
            ("the policy delay", self.policy_delay),
            ("the epochs", self.epochs),
            ("the rollout", self.rollout),
        ];
        if let Some((name, _)) = counts.iter().find(|(_, v)| *v == 0) {
            return bad(format!("{name} must not be zero"));
        }
        if self.buffer > MAX_BUFFER || self.rollout > MAX_BUFFER || self.batch > MAX_BUFFER {
            return bad(format!("the replay, the rollout and the batch hold at most {MAX_BUFFER} transitions"));
        }
        if let Some(v) = self.desired_speed
            && !(v.is_finite() && v >= 0.0)
        {
            return bad(format!("the desired speed must be a number ≥ 0 (got {v})"));
        }
        Ok(())
    }

    /// How many transitions the replay holds before overwriting the oldest: `buffer`, and
    /// for PPO's rollout, emptied by each update instead, no bound.
    pub(crate) fn replay_capacity(&self) -> usize {
        if self.algo == Algo::Ppo { usize::MAX } else { self.buffer }
    }

    /// The colliding steps' ring's capacity (ChatScene: 1/100 of the replay's).
    pub(crate) fn collision_capacity(&self) -> usize {
        (self.buffer / 100).max(1)
    }

    /// Whether colliding steps have a ring of their own: an off-policy run with a share.
    pub(crate) fn splits_collisions(&self) -> bool {
        self.algo != Algo::Ppo && self.collision_share > 0.0
    }

    pub(crate) fn options(&self) -> Options {
        Options { mode: if self.compat { Mode::Compat } else { Mode::Fixed }, ..Options::default() }
    }
}

/// ChatScene's share of colliding steps in a fine-tuning batch (`batch_size // 5`).
pub const CHATSCENE_COLLISION_SHARE: f64 = 0.2;

/// The widest hidden layer a run may ask for.
pub const MAX_WIDTH: usize = 4096;
/// The most transitions a replay, rollout or batch may hold.
pub const MAX_BUFFER: usize = 10_000_000;
