//! `bench --rl`: the learning side of `tad-train` per algorithm, against Stable-Baselines3
//! (PyTorch on the CPU) as the peer, measured in the same run with the same networks
//! (two hidden layers of 256), batch sizes and threads.
//!
//! - **Environment steps per second**: rounds of exploring episodes of ordinary scenes
//!   (`tad_eval::pretrain::scenes`, the `kinematics` observation), no learning, rolled out on
//!   `threads` cores; reported also per core.
//! - **Gradient updates per second**: SAC and TD3, learning steps on a batch of 256 from a
//!   filled replay; PPO, minibatches of 64 over a rollout of 2,048 for 2 passes. SB3's side
//!   (`python/benches/sb3_updates.py`) times `model.train` the same way on a stand-in
//!   environment of the same widths, after `torch.set_num_threads(threads)`.
//!
//! The ratio is TADSL's updates per second over SB3's.

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use tad_train::{Algo, Config, TrainScene, Trainer};

use crate::{BenchError, Report};

/// SB3's side, run as a script.
const SB3_SCRIPT: &str = include_str!("../../../python/benches/sb3_updates.py");

pub struct RlArgs {
    /// The Python with stable-baselines3 and torch (default `python3`); `None` skips the peer.
    pub python: Option<PathBuf>,
    /// Learning steps timed per measurement (SAC, TD3).
    pub updates: usize,
    /// Exploring episodes timed per measurement.
    pub episodes: usize,
    pub threads: Vec<usize>,
}

const HIDDEN: usize = 256;
/// The shipped models' observation, on both sides.
const OBSERVATION: tad_policy::Observation = tad_policy::Observation::Kinematics;
const OFF_POLICY_BATCH: usize = 256;
const PPO_BATCH: usize = 64;
const PPO_ROLLOUT: usize = 2048;
const PPO_EPOCHS: usize = 2;

fn config(algo: Algo) -> Config {
    Config {
        algo,
        observation: OBSERVATION,
        hidden: vec![HIDDEN, HIDDEN],
        batch: if algo == Algo::Ppo { PPO_BATCH } else { OFF_POLICY_BATCH },
        start_training: 1,
        updates_per_episode: 0,
        rollout: tad_train::MAX_BUFFER,
        epochs: PPO_EPOCHS,
        ..Config::safebench(algo)
    }
}

/// (environment steps per second, updates per second) of `algo` on `threads` cores.
fn ours(algo: Algo, threads: usize, scenes: &[TrainScene], args: &RlArgs) -> Result<(f64, f64), BenchError> {
    let failed = |e: tad_train::TrainError| BenchError(format!("{}: {e}", algo.name()));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| BenchError(e.to_string()))?;
    pool.install(|| {
        let mut trainer = Trainer::new(Config { envs: 2 * threads, ..config(algo) }).map_err(failed)?;
        let jobs = trainer.jobs(scenes, args.episodes);
        let started = Instant::now();
        let stats = trainer.round(&jobs).map_err(failed)?;
        let steps: u32 = stats.iter().map(|s| s.steps).sum();
        let env = f64::from(steps) / started.elapsed().as_secs_f64();
        let updates = match algo {
            Algo::Ppo => {
                // a rollout of at least PPO_ROLLOUT transitions
                while trainer.replay_len() < PPO_ROLLOUT {
                    let jobs = trainer.jobs(scenes, 4);
                    trainer.round(&jobs).map_err(failed)?;
                }
                let minibatches = PPO_EPOCHS * trainer.replay_len().div_ceil(PPO_BATCH);
                let started = Instant::now();
                trainer.learn_now().map_err(failed)?;
                minibatches as f64 / started.elapsed().as_secs_f64()
            }
            _ => {
                trainer.learn_now().map_err(failed)?; // warm-up
                let started = Instant::now();
                for _ in 0..args.updates {
                    trainer.learn_now().map_err(failed)?;
                }
                args.updates as f64 / started.elapsed().as_secs_f64()
            }
        };
        Ok((env, updates))
    })
}

/// SB3's updates per second, or why not.
fn sb3(python: &PathBuf, algo: Algo, threads: usize, updates: usize) -> Result<f64, String> {
    let script = std::env::temp_dir().join(format!("tadsl-sb3-updates-{}.py", std::process::id()));
    std::fs::write(&script, SB3_SCRIPT).map_err(|e| e.to_string())?;
    let batch = if algo == Algo::Ppo { PPO_BATCH } else { OFF_POLICY_BATCH };
    let output = Command::new(python)
        .arg(&script)
        .args(["--algo", algo.name(), "--threads", &threads.to_string(), "--updates", &updates.to_string()])
        .args([
            "--batch",
            &batch.to_string(),
            "--hidden",
            &HIDDEN.to_string(),
            "--obs",
            &OBSERVATION.width().to_string(),
        ])
        .args(["--rollout", &PPO_ROLLOUT.to_string(), "--epochs", &PPO_EPOCHS.to_string()])
        .env("OMP_NUM_THREADS", threads.to_string())
        .output()
        .map_err(|e| format!("cannot run `{}`: {e}", python.display()))?;
    let _ = std::fs::remove_file(&script);
    if !output.status.success() {
        let err = String::from_utf8_lossy(&output.stderr);
        return Err(err.lines().last().unwrap_or("failed").to_string());
    }
    let text = String::from_utf8_lossy(&output.stdout);
    let value: serde_json::Value = serde_json::from_str(text.trim()).map_err(|e| format!("its answer: {e}"))?;
    value["updates_per_s"].as_f64().ok_or_else(|| "no updates_per_s in its answer".to_string())
}

pub fn run(args: &RlArgs, progress: &mut dyn FnMut(&str)) -> Result<Report, BenchError> {
    let examples = tad_eval::examples::corpus("examples", "examples/");
    let (units, _) = tad_eval::pretrain::scenes(&examples, 2, tad_eval::pretrain::VALIDATION_SEED);
    if units.is_empty() {
        return Err(BenchError("no scene to run".into()));
    }
    let scenes: Vec<TrainScene> = units.iter().map(|u| TrainScene { scene: &u.scene, fixed: None }).collect();
    let mut report = Report::default();
    report.lines.push("| algorithm | threads | env steps/s | per core | updates/s | SB3 updates/s | ratio |".into());
    report.lines.push("|---|---|---|---|---|---|---|".into());
    for algo in Algo::ALL {
        for &threads in &args.threads {
            progress(&format!("{} on {threads} thread(s)", algo.name()));
            let (env, updates) = ours(algo, threads, &scenes, args)?;
            let peer = match &args.python {
                Some(python) => sb3(python, algo, threads, args.updates),
                None => Err("skipped".into()),
            };
            let (peer_text, ratio) = match peer {
                Ok(p) => (format!("{p:.0}"), format!("{:.2}×", updates / p)),
                Err(why) => {
                    report.notes.push(format!("SB3 {} on {threads}: {why}", algo.name()));
                    ("–".into(), "–".into())
                }
            };
            report.lines.push(format!(
                "| {} | {threads} | {env:.0} | {:.0} | {updates:.0} | {peer_text} | {ratio} |",
                algo.name(),
                env / threads as f64
            ));
        }
    }
    report.notes.push(format!(
        "networks 2 × {HIDDEN}; batches: SAC, TD3 {OFF_POLICY_BATCH}; PPO minibatches of {PPO_BATCH} over {PPO_ROLLOUT} transitions, {PPO_EPOCHS} passes; {} scenes; tad-train's products on {}",
        units.len(),
        tad_train::kernel_name()
    ));
    Ok(report)
}
