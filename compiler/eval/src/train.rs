//! The one driver of training (PPO, SAC, TD3) on the runtime's scenes, for `tadslc train-ego` and the
//! fine-tuning stage of `tadslc eval`.
//!
//! A trainer starts from scratch, from an actor (its critics fresh, or a shipped model's
//! own), or from a `train-ego` checkpoint (actor, critics, optimisers and replay: as ChatScene goes on from
//! SafeBench's). Episode `n` runs scene `task_at(n)` of the list, with the scene's fixed
//! parameters and seed, or parameters sampled from the task's seed; so a run is a function
//! of its seed and scenes, and resuming a checkpoint gives the unbroken run.

use std::path::Path;

use tad_policy::Learned;
use tad_train::{Config, EpisodeStats, TrainError, Trainer};

/// Where training starts.
pub enum Start<'a> {
    Scratch,
    /// An actor already read, with the critics of a shipped model (its name and their
    /// bytes), else fresh ones.
    Learned {
        actor: Learned,
        critics: Option<(&'static str, &'static [u8])>,
    },
    /// An actor (safetensors, as `learned:PATH` reads), with fresh critics.
    Actor(&'a Path),
    /// A `train-ego` checkpoint directory.
    Checkpoint(&'a Path),
}

impl<'a> Start<'a> {
    /// A checkpoint when `path` is a directory, else an actor file.
    pub fn from_path(path: &'a Path) -> Start<'a> {
        if path.is_dir() { Start::Checkpoint(path) } else { Start::Actor(path) }
    }

    /// The trainer, and the actor it started from (`None` from scratch). A checkpoint keeps
    /// its own settings.
    pub fn trainer(&self, config: Config) -> Result<(Trainer, Option<Learned>), TrainError> {
        match self {
            Start::Scratch => Ok((Trainer::new(config)?, None)),
            Start::Learned { actor, critics } => {
                let mut trainer = Trainer::new(config)?;
                trainer.init_actor(actor)?;
                if let Some((name, bytes)) = critics {
                    trainer.init_critics(bytes, &format!("the critics of `{name}`"))?;
                }
                Ok((trainer, Some(actor.clone())))
            }
            Start::Actor(path) => {
                let actor = Learned::load(path)?;
                let mut trainer = Trainer::new(config)?;
                trainer.init_actor(&actor)?;
                Ok((trainer, Some(actor)))
            }
            Start::Checkpoint(dir) => {
                let trainer = Trainer::load_checkpoint(dir)?;
                let actor = trainer.actor()?;
                Ok((trainer, Some(actor)))
            }
        }
    }
}

pub use tad_train::TrainScene;

/// Train until the trainer has run `until` episodes in all, a round of `envs` episodes at
/// a time (fewer at the end), calling `after` with each round's statistics; stops at the
/// first error, the trainer's or `after`'s.
pub fn train<E: From<TrainError>>(
    trainer: &mut Trainer,
    until: usize,
    scenes: &[TrainScene],
    mut after: impl FnMut(&Trainer, &[EpisodeStats]) -> Result<(), E>,
) -> Result<(), E> {
    if scenes.is_empty() {
        return Err(TrainError::Config("no scene to train on".into()).into());
    }
    while (trainer.episodes() as usize) < until {
        let count = trainer.config().envs.min(until - trainer.episodes() as usize);
        let jobs = trainer.jobs(scenes, count);
        let stats = trainer.round(&jobs)?;
        after(trainer, &stats)?;
    }
    Ok(())
}
