//! `tadslc train-ego` and the fine-tuning stage of `tadslc eval`: SAC training of a learned
//! ego through `tad-eval`'s one driver (`tad_eval::train`), with checkpoints, resume,
//! progress with returns, and the paper's held-out split.
//!
//! Episode `n` runs scenario `task(n)` of the training list with parameters sampled from
//! the task's seed, so the whole run is a function of the seed and the inputs. The split
//! keys each scenario by its behaviour (`tad_eval::corpus::behaviour`).

use std::path::PathBuf;

use tad_eval::train::{Start, TrainScene};
use tad_train::{Config, TrainError, Trainer};

use crate::output::{CliError, Closed};
use crate::scenes::Loaded;
use crate::{Status, errln, outln, plural};

/// Train a learned ego with SAC on scenarios
#[derive(clap::Args, Debug, Clone)]
pub struct TrainEgoArgs {
    /// Scenario files or directories (e.g. the scenes `tadslc search` kept), or `.tadc` files
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The trained actor (safetensors; `--ego learned:PATH` drives with it)
    #[arg(short, long, value_name = "FILE")]
    pub out: PathBuf,
    /// Training episodes in all (ChatScene: 600)
    #[arg(long, value_name = "N", default_value_t = Config::default().episodes)]
    pub episodes: usize,
    /// Learning steps after each episode (ChatScene: 1)
    #[arg(long, value_name = "N", default_value_t = Config::default().updates_per_episode)]
    pub updates_per_episode: usize,
    /// Hidden widths of the actor and the critics
    #[arg(long, value_delimiter = ',', default_value = "256,256")]
    pub hidden: Vec<usize>,
    /// Learning rate of the actor and the critics
    #[arg(long, default_value_t = Config::default().actor_lr)]
    pub lr: f64,
    /// Transitions per learning step
    #[arg(long, value_name = "N", default_value_t = Config::default().batch)]
    pub batch: usize,
    /// No learning before the replay holds this many transitions
    #[arg(long, value_name = "N", default_value_t = Config::default().start_training)]
    pub start_training: usize,
    /// Start the actor from a trained one (a safetensors actor, as `learned:PATH` reads)
    #[arg(long, value_name = "FILE")]
    pub init: Option<PathBuf>,
    /// Train on 3/5 of each behaviour's scenarios and list the held-out 2/5 in OUT.split.json
    #[arg(long)]
    pub split: bool,
    /// The checkpoint directory (default: OUT.ckpt)
    #[arg(long, value_name = "DIR")]
    pub checkpoint: Option<PathBuf>,
    /// Write a checkpoint every N episodes (and at the end)
    #[arg(long, value_name = "N", default_value_t = 50)]
    pub every: usize,
    /// Continue from the checkpoint
    #[arg(long)]
    pub resume: bool,
    #[arg(long, default_value_t = Config::default().seed)]
    pub seed: u64,
}

impl TrainEgoArgs {
    fn config(&self) -> Config {
        Config {
            hidden: self.hidden.clone(),
            actor_lr: self.lr,
            critic_lr: self.lr,
            batch: self.batch,
            start_training: self.start_training,
            episodes: self.episodes,
            updates_per_episode: self.updates_per_episode,
            seed: self.seed,
            ..Config::default()
        }
    }
}

/// A scenario's behaviour for the split (`none` for a `.tadc` file, which has no source).
fn behaviour_key(loaded: &Loaded) -> String {
    loaded.key.clone().unwrap_or_else(|| "none".into())
}

pub fn run(args: &TrainEgoArgs, color: bool) -> Result<Status, CliError> {
    let config = args.config();
    config.check().map_err(CliError::usage)?;
    // raised by inputs that do not load
    let (scenes, status) = crate::scenes::load(&args.paths, color)?;
    let scenes: &[Loaded] = &scenes;
    if scenes.is_empty() {
        return Err(CliError::usage("no scenario to train on"));
    }
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", parent.display())))?;
    }
    let (train, test) = split(args, scenes)?;
    let checkpoint = args.checkpoint.clone().unwrap_or_else(|| tad_train::default_checkpoint_dir(&args.out));
    let mut trainer = trainer(args, config, &checkpoint)?;
    let total = args.episodes;
    let start = trainer.episodes() as usize;
    let progress = crate::output::progress(total.saturating_sub(start), "episodes");
    let window = 25;
    let (mut returns, mut collisions) = (Vec::new(), Vec::new());
    let started = std::time::Instant::now();
    let train_scenes: Vec<TrainScene> =
        train.iter().map(|&i| TrainScene { scene: &scenes[i].scene, fixed: None }).collect();
    let trained = tad_eval::train::train(&mut trainer, total, &train_scenes, |trainer, stats| -> Result<(), Stop> {
        returns.push(stats.episode_return);
        collisions.push(stats.collision);
        progress.inc(1);
        let n = trainer.episodes() as usize;
        if n.is_multiple_of(window) || n == total {
            let k = returns.len().min(window);
            let mean = returns[returns.len() - k..].iter().sum::<f64>() / k as f64;
            let hits = collisions[collisions.len() - k..].iter().filter(|c| **c).count();
            errln!(
                "episode {n}/{total}: return {mean:.1} (mean of the last {k}), collisions {hits}/{k}, replay {}, updates {}",
                trainer.replay_len(),
                trainer.updates()
            )
            .map_err(Stop::Closed)?;
        }
        if args.every > 0 && n.is_multiple_of(args.every) && n < total {
            trainer.save_checkpoint(&checkpoint).map_err(Stop::Checkpoint)?;
        }
        Ok(())
    });
    progress.finish_and_clear();
    match trained {
        Ok(()) => {}
        Err(Stop::Closed(closed)) => return Err(closed.into()),
        Err(Stop::Checkpoint(e)) => return Err(CliError::usage(e)),
        Err(Stop::Train(e)) => {
            let _ = trainer.save_checkpoint(&checkpoint);
            return Err(CliError::failed(format!("training stopped at episode {}: {e}", trainer.episodes())));
        }
    }
    trainer.save_checkpoint(&checkpoint).and_then(|_| trainer.save_actor(&args.out)).map_err(CliError::usage)?;
    // the deterministic actor on the held-out scenarios (or the training ones)
    let judged = if test.is_empty() { &train } else { &test };
    let mut hits = 0;
    let mut total_return = 0.0;
    for &i in judged {
        let scene = &scenes[i].scene;
        let params = tad_runtime::sample::sample(&scene.program.params, Some(args.seed));
        let stats = trainer.evaluate(scene, params, args.seed);
        hits += usize::from(stats.collision);
        total_return += stats.episode_return;
    }
    outln!(
        "trained {} in {:.1} s; {} ({}): mean return {:.1}, collisions {hits}/{}",
        plural(trainer.episodes() as usize - start, "episode"),
        started.elapsed().as_secs_f64(),
        if test.is_empty() { "on the training scenarios" } else { "on the held-out scenarios" },
        plural(judged.len(), "scenario"),
        total_return / judged.len().max(1) as f64,
        judged.len()
    )?;
    errln!(
        "actor in {} (use --ego learned:{}); checkpoint in {}",
        args.out.display(),
        args.out.display(),
        checkpoint.display()
    )?;
    Ok(status)
}

/// The scenarios trained on and held out: all and none, or with `--split` 3/5 of each
/// behaviour's and the rest (listed in `OUT.split.json`).
fn split(args: &TrainEgoArgs, scenes: &[Loaded]) -> Result<(Vec<usize>, Vec<usize>), CliError> {
    if !args.split {
        return Ok(((0..scenes.len()).collect(), Vec::new()));
    }
    let keys: Vec<String> = scenes.iter().map(behaviour_key).collect();
    let (train, test) = tad_train::split(&keys, args.seed);
    let names = |list: &[usize]| list.iter().map(|&i| scenes[i].name.clone()).collect::<Vec<_>>();
    let value = serde_json::json!({ "seed": args.seed, "train": names(&train), "test": names(&test) });
    let path = tad_train::beside(&args.out, ".split.json");
    std::fs::write(&path, serde_json::to_string_pretty(&value).unwrap_or_default() + "\n")
        .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    errln!("split: {} for training, {} held out ({})", train.len(), test.len(), path.display())?;
    Ok((train, test))
}

/// The trainer: the checkpoint's with `--resume` (of the same seed and widths), else a new
/// one from scratch or from `--init`'s actor.
fn trainer(args: &TrainEgoArgs, config: Config, checkpoint: &std::path::Path) -> Result<Trainer, CliError> {
    if !(args.resume && checkpoint.join("state.json").exists()) {
        let start = args.init.as_deref().map_or(Start::Scratch, Start::Actor);
        return start.trainer(config).map(|(t, _)| t).map_err(CliError::usage);
    }
    let t = Trainer::load_checkpoint(checkpoint).map_err(CliError::usage)?;
    if t.config().seed != config.seed || t.config().hidden != config.hidden {
        return Err(CliError::usage(format!(
            "{} was trained with another seed or other widths: resume with the same --seed and --hidden",
            checkpoint.display()
        )));
    }
    errln!("resumed from {} after {}", checkpoint.display(), plural(t.episodes() as usize, "episode"))?;
    Ok(t)
}

/// Why a training loop stopped early.
enum Stop {
    Closed(Closed),
    Checkpoint(TrainError),
    Train(TrainError),
}

impl From<TrainError> for Stop {
    fn from(e: TrainError) -> Stop {
        Stop::Train(e)
    }
}
