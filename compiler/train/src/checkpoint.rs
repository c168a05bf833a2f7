//! Checkpoints: a directory written whole or not at all (a `.part` sibling renamed over
//! it). `state.json` (format, settings, the actor's widths, counters, the generator's state,
//! the replay's length and write position, the caller's note), `actor.safetensors`
//! (`Learned`'s file: `learned:DIR/actor.safetensors` drives with it), `critics.safetensors`
//! (each critic under its name: `q1.`, `q2.`, `q1_target.`, `q2_target.`, TD3's
//! `actor_target.`, PPO's `v.`), `optimizer.safetensors` (each parameter's `.m` and `.v`
//! under `actor.` or `critic.`), `replay.safetensors` (`transitions`, one row each, and
//! `collisions` when colliding steps are kept apart) and,
//! after a warm start, `demos.safetensors` (`demos`: obs and the teacher's action).
//! Everything the next step reads is in it, so N episodes, a stop and a resume to 2N give
//! the same bytes as 2N at once.

use std::collections::HashMap;
use std::fmt;
use std::path::Path;

use candle_core::{DType, Device, Tensor};
use serde::{Deserialize, Serialize};
use tad_ir::SplitMix64;

use crate::nets::{Adam, PlainActor, tensor_error};
use crate::{Config, Replay, TrainError, Trainer, actor_net};

const FORMAT: &str = "tad-train checkpoint 2";
const STATE_FILE: &str = "state.json";
const ACTOR_FILE: &str = "actor.safetensors";
const CRITICS_FILE: &str = "critics.safetensors";
const OPTIMIZER_FILE: &str = "optimizer.safetensors";
const REPLAY_FILE: &str = "replay.safetensors";
const DEMOS_FILE: &str = "demos.safetensors";

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
    /// The colliding steps' ring (none: no `collisions` tensor).
    #[serde(default)]
    collisions_len: usize,
    #[serde(default)]
    collisions_next: usize,
    /// Rows in `demos.safetensors` (none: no file).
    #[serde(default)]
    demos: usize,
    note: String,
}

impl Trainer {
    /// Write a checkpoint into `dir` (see the module's header), whole or not at all.
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
        let mut critics = HashMap::new();
        for (name, net) in &self.critics.nets {
            critics.extend(net.tensors(&format!("{name}.")));
        }
        save(CRITICS_FILE, &critics)?;
        let mut moments = HashMap::new();
        self.actor_opt.tensors("actor.", &mut moments);
        self.critic_opt.tensors("critic.", &mut moments);
        save(OPTIMIZER_FILE, &moments)?;
        let rows = self.replay.len();
        let ring =
            |r: &Replay| Tensor::from_vec(r.data.clone(), (r.len(), r.width), &Device::Cpu).map_err(tensor_error);
        let mut rings = HashMap::from([("transitions".to_string(), ring(&self.replay)?)]);
        if self.collisions.len() > 0 {
            rings.insert("collisions".to_string(), ring(&self.collisions)?);
        }
        save(REPLAY_FILE, &rings)?;
        let demo_width = self.config.observation.width() + crate::nets::ACT;
        let demos = self.demos.len() / demo_width;
        if demos > 0 {
            let t = Tensor::from_vec(self.demos.clone(), (demos, demo_width), &Device::Cpu).map_err(tensor_error)?;
            save(DEMOS_FILE, &HashMap::from([("demos".to_string(), t)]))?;
        }
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
            collisions_len: self.collisions.len(),
            collisions_next: self.collisions.next,
            demos,
            note: self.note.clone(),
        };
        let state_path = partial.join(STATE_FILE);
        let text = serde_json::to_string_pretty(&state).map_err(|e| io(&state_path, &e))?;
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
        if state.actor_hidden.is_empty() || state.actor_hidden.iter().any(|&w| w == 0 || w > crate::MAX_WIDTH) {
            return Err(broken(&state_path, format!("the actor's widths {:?} cannot be", state.actor_hidden)));
        }
        let mut trainer = Trainer::new(state.config.clone())?;
        let read = |file: &str| -> Result<HashMap<String, Tensor>, TrainError> {
            let path = dir.join(file);
            let bytes = std::fs::read(&path)
                .map_err(|e| TrainError::Io { path: shown(&path), message: format!("cannot read it: {e}") })?;
            candle_core::safetensors::load_buffer(&bytes, &Device::Cpu).map_err(|e| broken(&path, e.to_string()))
        };

        let obs = trainer.config.observation.width();
        let actor_path = dir.join(ACTOR_FILE);
        let actor = actor_net(&trainer.config, obs, &state.actor_hidden, &mut SplitMix64::new(0))
            .map_err(|e| broken(&state_path, e.to_string()))?;
        actor.set(&read(ACTOR_FILE)?, "", &shown(&actor_path))?;
        trainer.actor_opt = Adam::new(actor.vars(), trainer.config.actor_lr)?;
        // TD3's target actor has the actor's widths
        if let Some(slot) = trainer.critics.nets.iter_mut().find(|(n, _)| *n == "actor_target") {
            slot.1 = actor.copy()?;
        }
        trainer.actor = actor;

        let critics_path = shown(&dir.join(CRITICS_FILE));
        let critics = read(CRITICS_FILE)?;
        for (name, net) in &trainer.critics.nets {
            net.set(&critics, &format!("{name}."), &critics_path)?;
        }

        let optimizer_path = shown(&dir.join(OPTIMIZER_FILE));
        let moments = read(OPTIMIZER_FILE)?;
        trainer.actor_opt.set(&moments, "actor.", &optimizer_path)?;
        trainer.critic_opt.set(&moments, "critic.", &optimizer_path)?;
        trainer.actor_opt.step = state.actor_steps;
        trainer.critic_opt.step = state.critic_steps;

        let replay_path = dir.join(REPLAY_FILE);
        let width = trainer.replay.width;
        let replay = read(REPLAY_FILE)?;
        let ring = |name: &str, len: usize, next: usize, capacity: usize| -> Result<Replay, TrainError> {
            if len == 0 && next == 0 {
                return Ok(Replay::new(obs));
            }
            let t = replay.get(name).filter(|t| t.dims() == [len, width]);
            let t = t.ok_or_else(|| broken(&replay_path, format!("no `{name}` of shape [{len}, {width}]")))?;
            let data = t
                .to_dtype(DType::F32)
                .and_then(|t| t.flatten_all()?.to_vec1::<f32>())
                .map_err(|e| broken(&replay_path, e.to_string()))?;
            // filling, the next write appends; full, it overwrites the oldest (PPO's
            // rollout only fills)
            let valid = match len.cmp(&capacity) {
                std::cmp::Ordering::Less => next == len % capacity,
                std::cmp::Ordering::Equal => next < len,
                std::cmp::Ordering::Greater => false,
            };
            if !valid {
                return Err(broken(
                    &state_path,
                    format!("the `{name}` ring's length or position does not fit its capacity"),
                ));
            }
            Ok(Replay { width, data, next })
        };
        let config = &state.config;
        trainer.replay = ring("transitions", state.replay_len, state.replay_next, config.replay_capacity())?;
        trainer.collisions =
            ring("collisions", state.collisions_len, state.collisions_next, config.collision_capacity())?;

        if state.demos > 0 {
            let demos_path = dir.join(DEMOS_FILE);
            let demo_width = obs + crate::nets::ACT;
            let demos = read(DEMOS_FILE)?;
            let t = demos
                .get("demos")
                .filter(|t| t.dims() == [state.demos, demo_width])
                .ok_or_else(|| broken(&demos_path, format!("no `demos` of shape [{}, {demo_width}]", state.demos)))?;
            trainer.demos = t
                .to_dtype(DType::F32)
                .and_then(|t| t.flatten_all()?.to_vec1::<f32>())
                .map_err(|e| broken(&demos_path, e.to_string()))?;
        }

        trainer.plain = PlainActor::of(&trainer.actor)?;
        trainer.rng = SplitMix64::new(state.rng);
        trainer.episodes = state.episodes;
        trainer.updates = state.updates;
        trainer.note = state.note;
        Ok(trainer)
    }
}
