//! `tadslc train-ego` and the fine-tuning stage of `tadslc eval`: PPO, SAC or TD3 training of a learned
//! ego through `tad-eval`'s one driver (`tad_eval::train`), with checkpoints, resume,
//! progress with returns, and the paper's held-out split.
//!
//! Episode `n` runs scenario `task(n)` of the training list with parameters sampled from
//! the task's seed, so the whole run is a function of the seed and the inputs. The split
//! keys each scenario by its behaviour (`tad_eval::corpus::behaviour`).

use std::path::{Path, PathBuf};

use tad_eval::pretrain::Judged;
use tad_eval::train::{Start, TrainScene};
use tad_policy::{EgoSpec, Observation};
use tad_train::{Algo, Config, Imitation, TrainError, Trainer};

use crate::output::{CliError, Closed};
use crate::scenes::Loaded;
use crate::{Status, errln, outln, plural};

/// Train a learned ego with PPO, SAC or TD3 on scenarios
#[derive(clap::Args, Debug, Clone)]
pub struct TrainEgoArgs {
    /// Scenario files or directories (e.g. the scenes `tadslc search` kept), or `.tadc` files
    #[arg(required_unless_present = "pretrained")]
    pub paths: Vec<PathBuf>,
    /// Reproduce a shipped model (`ppo`, `sac`, `td3`): its corpus, warm start and settings
    /// (`tad_eval::pretrain`); every other training flag is ignored
    #[arg(long, value_name = "ALGO", value_parser = ["ppo", "sac", "td3"], conflicts_with = "paths")]
    pub pretrained: Option<String>,
    /// The trained actor (safetensors; `--ego learned:PATH` drives with it)
    #[arg(short, long, value_name = "FILE")]
    pub out: PathBuf,
    /// The algorithm; its settings are SafeBench's, or with `--chatscene` ChatScene's SAC
    #[arg(long, value_parser = ["ppo", "sac", "td3"], default_value = "sac")]
    pub algo: String,
    /// ChatScene's SAC settings (`adv_scenic.yaml`) instead of SafeBench's
    #[arg(long)]
    pub chatscene: bool,
    /// Keep colliding steps apart, as ChatScene's fine-tuning does: a ring of their own,
    /// drawn for a fifth of every off-policy batch
    #[arg(long)]
    pub collisions_apart: bool,
    /// What the actor sees: SafeBench's 4 values, the 13-value `state`, or the `kinematics`
    /// (the `state` and the six actors nearest the ego)
    #[arg(long, value_parser = observation_names(), default_value = "safebench")]
    pub observation: String,
    /// Training episodes in all (SafeBench: 2000; ChatScene: 600) (at most 10,000,000)
    #[arg(long, value_name = "N", value_parser = crate::count::<10_000_000>)]
    pub episodes: Option<usize>,
    /// Off-policy learning steps after each episode (SafeBench: 3; ChatScene: 1)
    #[arg(long, value_name = "N")]
    pub updates_per_episode: Option<usize>,
    /// Hidden widths of the actor and the critics (at most 4,096 each)
    #[arg(long, value_delimiter = ',', value_parser = crate::count::<4096>)]
    pub hidden: Option<Vec<usize>>,
    /// Learning rate of the actor and the critics
    #[arg(long)]
    pub lr: Option<f64>,
    /// Transitions per learning step (PPO: per minibatch)
    #[arg(long, value_name = "N")]
    pub batch: Option<usize>,
    /// No learning before the replay holds this many transitions
    #[arg(long, value_name = "N")]
    pub start_training: Option<usize>,
    /// Episodes rolled out at once over the cores (results do not depend on the thread count)
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub envs: usize,
    /// Train under SafeBench's episode rules (off road does not end an episode), so that
    /// leaving the road is never an escape from the steps' penalties
    #[arg(long)]
    pub compat: bool,
    /// Learning steps at the start that train the critics only
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub critic_warmup: usize,
    /// The weight of the warm start's demonstrations in the actor's loss (TD3+BC's form; 0: pure RL)
    #[arg(long, value_name = "W", default_value_t = 0.0)]
    pub bc_weight: f64,
    /// Warm-start the actor by imitating this driver (DAgger), e.g. `idm`
    #[arg(long, value_name = "EGO")]
    pub imitate: Option<String>,
    /// DAgger rounds and episodes per round for `--imitate`
    #[arg(long, value_name = "N", default_value_t = Imitation::default().rounds)]
    pub imitate_rounds: usize,
    #[arg(long, value_name = "N", default_value_t = Imitation::default().episodes)]
    pub imitate_episodes: usize,
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
    /// Draw the training curves as SVG: the return and the collision rate over episodes
    /// (means of the last 25), and with `--pretrained` the validation's collision rate
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    #[arg(long, default_value_t = Config::default().seed)]
    pub seed: u64,
}

impl TrainEgoArgs {
    fn config(&self) -> Result<Config, CliError> {
        if let Some(algo) = self.pretrained.as_deref().and_then(Algo::parse) {
            return Ok(tad_eval::pretrain::config(algo));
        }
        let algo = Algo::parse(&self.algo).unwrap_or_default();
        let base = match (self.chatscene, algo) {
            (true, Algo::Sac) => Config::default(),
            (true, _) => return Err(CliError::usage("--chatscene is ChatScene's SAC: use it with --algo sac")),
            (false, algo) => Config::safebench(algo),
        };
        Ok(Config {
            observation: Observation::parse(&self.observation).unwrap_or_default(),
            hidden: self.hidden.clone().unwrap_or(base.hidden.clone()),
            actor_lr: self.lr.unwrap_or(base.actor_lr),
            critic_lr: self.lr.unwrap_or(base.critic_lr),
            batch: self.batch.unwrap_or(base.batch),
            start_training: self.start_training.unwrap_or(base.start_training),
            episodes: self.episodes.unwrap_or(base.episodes),
            updates_per_episode: self.updates_per_episode.unwrap_or(base.updates_per_episode),
            envs: self.envs,
            critic_warmup: self.critic_warmup,
            bc_weight: self.bc_weight,
            collision_share: if self.collisions_apart { tad_train::CHATSCENE_COLLISION_SHARE } else { 0.0 },
            compat: self.compat || base.compat,
            seed: self.seed,
            ..base
        })
    }
}

/// Without a warm start, a run whose episodes cannot store the transitions learning starts
/// at, even at the longest training scenario's step limit, would make nothing: refused
/// before it runs.
fn refuse_what_cannot_learn(
    trainer: &Trainer,
    scenes: &[Loaded],
    train: &[usize],
    total: usize,
    warm: bool,
) -> Result<(), CliError> {
    let longest = train.iter().map(|&i| scenes[i].scene.limits.max_steps as usize).max().unwrap_or(0);
    let to_run = total.saturating_sub(trainer.episodes() as usize);
    match trainer.cannot_learn_within(to_run, longest).filter(|_| !warm) {
        Some(why) => Err(CliError::usage(format!("no learning step could be taken: {why} (--episodes)"))),
        None => Ok(()),
    }
}

/// A run that took no learning step: an error without a warm start (its actor is the one it
/// started with, so it is not written as if trained; the checkpoint is), else a warning.
fn no_learning_step(trainer: &Trainer, warm: bool, checkpoint: &Path) -> Result<(), CliError> {
    let (stored, needed) = (trainer.replay_len(), trainer.config().transitions_to_learn());
    if !warm {
        return Err(CliError::failed(format!(
            "no learning step was taken: the episodes ended early and stored {stored} transitions; learning starts \
             at {needed}. The checkpoint is in `{}`: continue with --resume and more --episodes",
            checkpoint.display()
        )));
    }
    errln!(
        "warning: no learning step was taken after the warm start: {stored} transitions are stored and learning \
         starts at {needed} (more --episodes)"
    )?;
    Ok(())
}

/// The observations' names, from `tad_policy::Observation::ALL`.
fn observation_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(tad_policy::Observation::ALL.map(|(name, _)| name))
}

/// A scenario's behaviour for the split (`none` for a `.tadc` file, which has no source).
fn behaviour_key(loaded: &Loaded) -> String {
    loaded.key.clone().unwrap_or_else(|| "none".into())
}

pub fn run(args: &TrainEgoArgs, color: bool) -> Result<Status, CliError> {
    let config = args.config()?;
    config.check().map_err(CliError::usage)?;
    let teacher = match args.pretrained {
        Some(_) => Some(tad_eval::pretrain::TEACHER),
        None => args.imitate.as_deref(),
    };
    let teacher = teacher.map(EgoSpec::parse).transpose().map_err(CliError::usage)?;
    // raised by inputs that do not load
    let (scenes, status) = match args.pretrained {
        Some(_) => (pretraining_corpus()?, Status::Ok),
        None => crate::scenes::load(&args.paths, color)?,
    };
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
    let config_episodes = config.episodes;
    let mut trainer = trainer(args, config, &checkpoint)?;
    let total = config_episodes;
    let train_scenes: Vec<TrainScene> =
        train.iter().map(|&i| TrainScene { scene: &scenes[i].scene, fixed: None }).collect();
    let warm = teacher.is_some();
    refuse_what_cannot_learn(&trainer, scenes, &train, total, warm)?;
    if let Some(teacher) = teacher.filter(|_| trainer.episodes() == 0) {
        imitate(&mut trainer, &train_scenes, &teacher, args)?;
    }
    // the recipe's selection: the clone and every VALIDATE_EVERY episodes, the best kept
    let mut selection = match args.pretrained {
        Some(_) => Some(Selection::new()?),
        None => None,
    };
    if let Some(selection) = &mut selection {
        selection.judge(&trainer, false).map_err(|e| match e {
            Stop::Closed(c) => c.into(),
            Stop::Checkpoint(e) | Stop::Train(e) => CliError::failed(e),
        })?;
    }
    let start = trainer.episodes() as usize;
    let progress = crate::output::progress(total.saturating_sub(start), "episodes");
    let window = RECENT;
    let (mut returns, mut collisions) = (Vec::new(), Vec::new());
    let started = std::time::Instant::now();
    let trained = tad_eval::train::train(&mut trainer, total, &train_scenes, |trainer, round| -> Result<(), Stop> {
        let n = trainer.episodes() as usize;
        let before = n - round.len();
        returns.extend(round.iter().map(|s| s.episode_return));
        collisions.extend(round.iter().map(|s| s.collision));
        progress.inc(round.len() as u64);
        // a multiple of N crossed by this round
        let crossed = |every: usize| every > 0 && n / every > before / every;
        if crossed(window) || n == total {
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
        if crossed(args.every) && n < total {
            trainer.save_checkpoint(&checkpoint).map_err(Stop::Checkpoint)?;
        }
        if let Some(selection) = &mut selection
            && (crossed(tad_eval::pretrain::VALIDATE_EVERY) || n == total)
        {
            selection.judge(trainer, true)?;
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
    trainer.save_checkpoint(&checkpoint).map_err(CliError::usage)?;
    if trainer.updates() == 0 && trainer.episodes() > 0 {
        no_learning_step(&trainer, warm, &checkpoint)?;
    }
    if let Some(path) = &args.plot {
        let validation = selection.as_ref().map(|s| s.history.clone()).unwrap_or_default();
        let svg = curves(&config_name(args), start, &returns, &collisions, &validation, window);
        std::fs::write(path, svg).map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    }
    match selection.and_then(|s| s.best) {
        Some((episode, judged, actor, critics)) => {
            actor.save(&args.out).map_err(CliError::usage)?;
            critics.save(critics_path(&args.out)).map_err(CliError::usage)?;
            errln!(
                "kept the actor of episode {episode} and its critics (`{}`): validation collision rate {:.3}, route {:.3}",
                critics_path(&args.out).display(),
                judged.collision_rate,
                judged.route_complete
            )?;
        }
        None => trainer.save_actor(&args.out).map_err(CliError::usage)?,
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
        "actor in `{}` (use `--ego learned:{}`); checkpoint in `{}`",
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
    errln!("split: {} for training, {} held out (`{}`)", train.len(), test.len(), path.display())?;
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
    let had = t.config();
    if (had.seed, &had.hidden, had.algo, had.observation)
        != (config.seed, &config.hidden, config.algo, config.observation)
    {
        return Err(CliError::usage(format!(
            "{} was trained with another seed, widths, algorithm or observation: resume with the same --seed, --hidden, --algo and --observation",
            checkpoint.display()
        )));
    }
    errln!("resumed from `{}` after {}", checkpoint.display(), plural(t.episodes() as usize, "episode"))?;
    Ok(t)
}

/// The shipped models' corpus (`tad_eval::pretrain::corpus`) from the embedded examples.
fn pretraining_corpus() -> Result<Vec<Loaded>, CliError> {
    let examples = crate::corpus::counted(tad_eval::examples::corpus("examples", "examples/"))?;
    let (units, notes) = tad_eval::pretrain::corpus(&examples);
    for note in notes {
        errln!("note: {note}")?;
    }
    errln!("the shipped models' corpus: {} (fitted and baseline over every region)", plural(units.len(), "scene"))?;
    Ok(units
        .into_iter()
        .map(|u| Loaded { name: format!("{}/{}", u.generator, u.name), scene: u.scene, source: None, key: Some(u.key) })
        .collect())
}

/// The DAgger warm start from `teacher`, its rounds reported.
fn imitate(
    trainer: &mut Trainer,
    scenes: &[TrainScene],
    teacher: &EgoSpec,
    args: &TrainEgoArgs,
) -> Result<(), CliError> {
    let settings = match args.pretrained {
        Some(_) => tad_eval::pretrain::imitation(),
        None => Imitation { rounds: args.imitate_rounds, episodes: args.imitate_episodes, ..Imitation::default() },
    };
    let make = || teacher.make();
    let mut closed = None;
    trainer
        .imitate(scenes, &make, &settings, |r| {
            let line = errln!(
                "imitation round {}/{} ({} drove): {} collided, route {:.0} %, {} labelled states, loss {:.4}",
                r.round + 1,
                settings.rounds,
                r.driver,
                plural(r.collisions, "episode"),
                100.0 * r.route_complete,
                r.samples,
                r.loss
            );
            if let Err(e) = line {
                closed.get_or_insert(e);
            }
        })
        .map_err(CliError::usage)?;
    match closed {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

/// How many of the latest episodes the progress lines and the curves average over (the
/// `--plot` help says it too).
const RECENT: usize = 25;

/// The run's name on its plot.
fn config_name(args: &TrainEgoArgs) -> String {
    match &args.pretrained {
        Some(algo) => format!("{algo}: the shipped model's training"),
        None => format!("{} training", args.algo),
    }
}

/// The training curves: the means of the last `window` episodes' returns and collisions
/// after each episode from `start`, and the validation's collision rates.
fn curves(
    title: &str,
    start: usize,
    returns: &[f64],
    collisions: &[bool],
    validation: &[[f64; 2]],
    window: usize,
) -> String {
    let mean_of = |values: &[f64]| -> Vec<[f64; 2]> {
        (0..values.len())
            .map(|i| {
                let from = (i + 1).saturating_sub(window);
                let part = &values[from..=i];
                [(start + i + 1) as f64, part.iter().sum::<f64>() / part.len() as f64]
            })
            .collect()
    };
    let hits: Vec<f64> = collisions.iter().map(|&c| f64::from(u8::from(c))).collect();
    let (recent, mean) =
        (format!("training (last {window} episodes)"), format!("return (mean of the last {window} episodes)"));
    let mut rates = vec![(recent.as_str(), mean_of(&hits))];
    if !validation.is_empty() {
        rates.push(("validation", validation.to_vec()));
    }
    tad_stats::plot::curves(
        title,
        "episode",
        &[(mean.as_str(), vec![("training", mean_of(returns))]), ("collision rate", rates)],
    )
}

/// The recipe's choice among a run's actors: each judged on the validation scenes
/// (`tad_eval::pretrain`), the best kept with its episode.
struct Selection {
    units: Vec<tad_eval::Unit>,
    /// The best so far: its episode, how it did, the actor and the critics beside it.
    best: Option<(u64, Judged, tad_policy::Learned, tad_train::Critics)>,
    /// Each judged episode and its collision rate.
    history: Vec<[f64; 2]>,
}

impl Selection {
    fn new() -> Result<Selection, CliError> {
        use tad_eval::pretrain::{VALIDATION_PER_REGION, VALIDATION_SEED, scenes};
        let examples = crate::corpus::counted(tad_eval::examples::corpus("examples", "examples/"))?;
        let (units, _) = scenes(&examples, VALIDATION_PER_REGION, VALIDATION_SEED);
        // the teacher on the same scenes, for scale
        let idm = tad_eval::pretrain::judge(&units, tad_eval::pretrain::VALIDATION_SEEDS, &|| {
            Box::new(tad_policy::Idm::default())
        });
        errln!(
            "validation: {} scenes; idm's collision rate {:.3}, route {:.3}",
            units.len(),
            idm.collision_rate,
            idm.route_complete
        )?;
        Ok(Selection { units, best: None, history: Vec::new() })
    }

    /// Judge the trainer's actor; keep it if `eligible` and the best so far.
    fn judge(&mut self, trainer: &Trainer, eligible: bool) -> Result<(), Stop> {
        let actor = trainer.actor().map_err(Stop::Train)?;
        let judged =
            tad_eval::pretrain::judge(&self.units, tad_eval::pretrain::VALIDATION_SEEDS, &|| Box::new(actor.clone()));
        let episode = trainer.episodes();
        errln!(
            "validation at episode {episode}: collision rate {:.3}, route {:.3} ({} scenes)",
            judged.collision_rate,
            judged.route_complete,
            self.units.len()
        )
        .map_err(Stop::Closed)?;
        self.history.push([episode as f64, judged.collision_rate]);
        if eligible && self.best.as_ref().is_none_or(|(_, b, _, _)| judged.better_than(b)) {
            self.best = Some((episode, judged, actor, trainer.critics().map_err(Stop::Train)?));
        }
        Ok(())
    }
}

/// Where `--pretrained` writes the kept actor's critics: `X.critics.safetensors` beside
/// `X.safetensors` (what `tad_policy::pretrained` ships beside each actor).
fn critics_path(out: &std::path::Path) -> std::path::PathBuf {
    out.with_extension("critics.safetensors")
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
