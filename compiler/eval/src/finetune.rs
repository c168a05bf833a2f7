//! The "after fine-tuning" stage of `eval --finetune`: a learned ego trained with SAC
//! ([`crate::train`]) on 3/5 of each behaviour's kept scenes (ChatScene's split), then it,
//! the ego it started from and the evaluation's egos on the held-out 2/5.

use tad_policy::{EgoSpec, Learned};
use tad_train::{Config, TrainError};

use crate::harness::{Kept, Plan};
use crate::results::{Results, Setup};
use crate::train::{Start, TrainScene};

/// The learned ego's names in the table.
pub const BEFORE: &str = "learned (before)";
pub const AFTER: &str = "learned (fine-tuned)";

/// Why fine-tuning did not finish.
#[derive(Debug)]
pub enum FinetuneError {
    /// The start (`--finetune-from`) could not be loaded.
    Start(TrainError),
    /// Training stopped.
    Training(TrainError),
    /// The trained actor could not be taken out.
    Actor(TrainError),
}

/// The trained ego, and the one it started from (none from scratch).
pub struct Tuned {
    pub after: Learned,
    pub before: Option<Learned>,
}

/// Kept scenes split per behaviour: indexes to train on and to hold out.
pub fn split(kept: &[Kept], seed: u64) -> (Vec<usize>, Vec<usize>) {
    let keys: Vec<String> = kept.iter().map(|k| k.unit.key.clone()).collect();
    tad_train::split(&keys, seed)
}

/// A learned ego from `start` trained for `config.episodes` more episodes on the kept
/// scenes `train`, each with its kept parameters and seed; `on_episode` after each.
pub fn tune(
    kept: &[Kept],
    train: &[usize],
    start: Start,
    config: Config,
    mut on_episode: impl FnMut(),
) -> Result<Tuned, FinetuneError> {
    let episodes = config.episodes;
    let (mut trainer, before) = start.trainer(config).map_err(FinetuneError::Start)?;
    let first = trainer.episodes() as usize;
    let scenes: Vec<TrainScene> = train
        .iter()
        .map(|&i| TrainScene { scene: &kept[i].unit.scene, fixed: Some((kept[i].params.clone(), kept[i].seed)) })
        .collect();
    crate::train::train(&mut trainer, first + episodes, &scenes, |_, _| -> Result<(), TrainError> {
        on_episode();
        Ok(())
    })
    .map_err(FinetuneError::Training)?;
    let after = trainer.actor().map_err(FinetuneError::Actor)?;
    Ok(Tuned { after, before })
}

/// The held-out table: every driver on the scenes `test`, and the learned ego's collision
/// rate before and after (before: `None` when it started from scratch).
pub struct HeldOut {
    pub results: Results,
    pub collision_rates: Option<(f64, f64)>,
}

/// The tuned ego, the one it started from and the plan's egos on the held-out scenes.
pub fn held_out(plan: &Plan, kept: &[Kept], test: &[usize], tuned: Tuned) -> HeldOut {
    let mut drivers: Vec<(String, EgoSpec)> = Vec::new();
    let had_before = tuned.before.is_some();
    if let Some(actor) = tuned.before {
        drivers.push((BEFORE.into(), EgoSpec::Learned(actor)));
    }
    drivers.push((AFTER.into(), EgoSpec::Learned(tuned.after)));
    drivers.extend(plan.setup.egos.iter().cloned().zip(plan.egos.iter().cloned()));
    let rows = crate::harness::held_out(kept, test, &drivers);
    let setup = Setup {
        regions: vec!["held-out".into()],
        generators: vec!["searched".into()],
        egos: drivers.iter().map(|(n, _)| n.clone()).collect(),
        ..plan.setup.clone()
    };
    let collision_rates = had_before
        .then(|| (crate::harness::collision_rate(&rows, BEFORE), crate::harness::collision_rate(&rows, AFTER)));
    let scenarios = [("held-out/searched".to_string(), test.len())].into_iter().collect();
    HeldOut { results: Results::new(setup, tad_base::Shard::ALL, scenarios, rows), collision_rates }
}
