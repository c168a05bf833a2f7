//! `tadslc train-ego`: SAC training of a learned ego (`tad-train`) on scenario files, with
//! checkpoints, resume, progress with returns, and the paper's held-out split.
//!
//! Episode `n` runs scenario `task(n)` of the training list with parameters sampled from
//! the task's seed, so the whole run is a function of the seed and the inputs. The split
//! keys each scenario by its behaviour (`behaviour_key`).

use std::path::{Path, PathBuf};

use tad_train::{Config, Trainer};

use crate::output::Closed;
use crate::run::Loaded;
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
    #[arg(long, value_name = "N", default_value_t = 600)]
    pub episodes: usize,
    /// Learning steps after each episode (ChatScene: 1)
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub updates_per_episode: usize,
    /// Hidden widths of the actor and the critics
    #[arg(long, value_delimiter = ',', default_value = "256,256")]
    pub hidden: Vec<usize>,
    /// Learning rate of the actor and the critics
    #[arg(long, default_value_t = 1e-4)]
    pub lr: f64,
    /// Transitions per learning step
    #[arg(long, value_name = "N", default_value_t = 512)]
    pub batch: usize,
    /// No learning before the replay holds this many transitions
    #[arg(long, value_name = "N", default_value_t = 1000)]
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
    #[arg(long, default_value_t = 0)]
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

/// A scenario's behaviour for the split: its first actor group's behaviour (the adversary
/// of ChatScene's scenarios), else its ego's, else `none`.
pub fn behaviour_key(loaded: &Loaded) -> String {
    loaded.source.as_ref().map_or_else(|| "none".into(), |input| behaviour_of(&input.text))
}

/// [`behaviour_key`] of a scenario's text.
pub fn behaviour_of(text: &str) -> String {
    let module = tad_syntax::analyze(text).0;
    let Some(scenario) = module.scenario else { return "none".into() };
    let name = |attr: Option<&tad_syntax::model::Attr>| attr.and_then(|a| a.symbol()).map(|s| s.name.clone());
    scenario
        .actors
        .first()
        .and_then(|g| name(g.attr("behavior")))
        .or_else(|| name(scenario.attr("ego", "behavior")))
        .unwrap_or_else(|| "none".into())
}

/// `OUT.split.json` beside `out`.
fn sibling(out: &Path, suffix: &str) -> PathBuf {
    let mut name = out.file_name().map(|n| n.to_os_string()).unwrap_or_else(|| "ego".into());
    name.push(suffix);
    out.with_file_name(name)
}

pub fn train_ego(args: &TrainEgoArgs, color: bool) -> Status {
    crate::output::run(|status| train_in(args, color, status))
}

fn train_in(args: &TrainEgoArgs, color: bool, status: &mut Status) -> Result<(), Closed> {
    let config = args.config();
    if let Err(e) = config.check() {
        *status = Status::Usage;
        return errln!("error: {e}");
    }
    let scenes = crate::run::load(&args.paths, color, status)?;
    if scenes.is_empty() {
        *status = (*status).max(Status::Usage);
        return errln!("error: no scenario to train on");
    }
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty())
        && let Err(e) = std::fs::create_dir_all(parent)
    {
        *status = Status::Usage;
        return errln!("error: cannot create `{}`: {e}", parent.display());
    }
    let (train, test): (Vec<usize>, Vec<usize>) = if args.split {
        let keys: Vec<String> = scenes.iter().map(behaviour_key).collect();
        tad_train::split(&keys, args.seed)
    } else {
        ((0..scenes.len()).collect(), Vec::new())
    };
    if args.split {
        let names = |list: &[usize]| list.iter().map(|&i| scenes[i].name.clone()).collect::<Vec<_>>();
        let value = serde_json::json!({ "seed": args.seed, "train": names(&train), "test": names(&test) });
        let path = sibling(&args.out, ".split.json");
        if let Err(e) = std::fs::write(&path, serde_json::to_string_pretty(&value).unwrap_or_default() + "\n") {
            *status = Status::Usage;
            return errln!("error: cannot write `{}`: {e}", path.display());
        }
        errln!("split: {} for training, {} held out ({})", train.len(), test.len(), path.display())?;
    }
    let checkpoint = args.checkpoint.clone().unwrap_or_else(|| tad_train::default_checkpoint_dir(&args.out));
    let mut trainer = if args.resume && checkpoint.join("state.json").exists() {
        match Trainer::load_checkpoint(&checkpoint) {
            Ok(t) if t.config().seed == config.seed && t.config().hidden == config.hidden => {
                errln!("resumed from {} after {}", checkpoint.display(), plural(t.episodes() as usize, "episode"))?;
                t
            }
            Ok(_) => {
                *status = Status::Usage;
                return errln!(
                    "error: {} was trained with another seed or other widths: resume with the same --seed and --hidden",
                    checkpoint.display()
                );
            }
            Err(e) => {
                *status = Status::Usage;
                return errln!("error: {e}");
            }
        }
    } else {
        let made = Trainer::new(config.clone()).and_then(|mut t| {
            if let Some(init) = &args.init {
                let learned = tad_policy::Learned::load(init)?;
                t.init_actor(&learned)?;
            }
            Ok(t)
        });
        match made {
            Ok(t) => t,
            Err(e) => {
                *status = Status::Usage;
                return errln!("error: {e}");
            }
        }
    };
    let total = args.episodes;
    let start = trainer.episodes() as usize;
    let progress = crate::run::Progress::new(total.saturating_sub(start), "episodes");
    let window = 25;
    let (mut returns, mut collisions) = (Vec::new(), Vec::new());
    let started = std::time::Instant::now();
    while (trainer.episodes() as usize) < total {
        let task = trainer.task(train.len());
        let loaded = &scenes[train[task.scenario]];
        let params = tad_runtime::sample::sample(&loaded.scene.program.params, Some(task.seed));
        let stats = match trainer.step(&loaded.scene, params, task.seed) {
            Ok(stats) => stats,
            Err(e) => {
                *status = Status::Failed;
                let _ = trainer.save_checkpoint(&checkpoint);
                return errln!("error: training stopped at episode {}: {e}", trainer.episodes());
            }
        };
        returns.push(stats.episode_return);
        collisions.push(stats.collision);
        progress.tick();
        let n = trainer.episodes() as usize;
        if n.is_multiple_of(window) || n == total {
            let k = returns.len().min(window);
            let mean = returns[returns.len() - k..].iter().sum::<f64>() / k as f64;
            let hits = collisions[collisions.len() - k..].iter().filter(|c| **c).count();
            errln!(
                "episode {n}/{total}: return {mean:.1} (mean of the last {k}), collisions {hits}/{k}, replay {}, updates {}",
                trainer.replay_len(),
                trainer.updates()
            )?;
        }
        if args.every > 0
            && n.is_multiple_of(args.every)
            && n < total
            && let Err(e) = trainer.save_checkpoint(&checkpoint)
        {
            *status = Status::Usage;
            return errln!("error: {e}");
        }
    }
    progress.finish();
    if let Err(e) = trainer.save_checkpoint(&checkpoint).and_then(|_| trainer.save_actor(&args.out)) {
        *status = Status::Usage;
        return errln!("error: {e}");
    }
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
    )
}
