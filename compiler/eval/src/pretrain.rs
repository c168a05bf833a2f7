//! The recipe of the shipped driving models (`tad_policy::pretrained`), written once:
//! `tadslc train-ego --pretrained ALGO` runs it and reproduces the shipped file byte for
//! byte (same seed; `tad-train`'s sums depend neither on the thread count nor on the
//! vector width).
//!
//! 1. **Corpus**: for every region the embedded examples name, [`PER_REGION`] scenarios of
//!    the `fitted` generator (fitted on that region's examples) and as many of the
//!    `baseline` generator, drawn with [`CORPUS_SEED`]: ordinary scenes over every region
//!    and behaviour, never the evaluation's (which draw with the evaluation's seed, 0 by
//!    default, and are searched to collide).
//! 2. **Warm start** ([`imitation`]): DAgger from the idm driver ([`TEACHER`]).
//! 3. **Training** ([`config`]): the algorithm's SafeBench settings at the learning rate
//!    1e-4, the `kinematics` observation (SafeBench's four values cannot see a red light or
//!    a stop line: a driver on them cannot meet the idm bar; the actors around the ego are
//!    what a fine-tuned model can learn to avoid), SafeBench's episode rules
//!    (`compat`: leaving the road is no escape from the penalties), critics warmed up
//!    before the actor moves, and the demonstrations kept in the actor's loss.
//! 4. **Selection**, as the paper reports its models: the actor every
//!    [`VALIDATE_EVERY`] episodes is judged on validation scenes ([`VALIDATION_SEED`]),
//!    and the best ([`Judged::better_than`]) is the shipped file. The clone is judged
//!    too, for the record, but not chosen: each shipped model is its algorithm's.

use rayon::prelude::*;
use tad_db::Database;
use tad_policy::{EgoPolicy, Observation};
use tad_train::{Algo, Config, Imitation};

use crate::corpus::Corpus;
use crate::harness::Unit;

/// Scenarios per region and generator.
pub const PER_REGION: usize = 50;
/// The corpus's seed (the evaluation's default is 0).
pub const CORPUS_SEED: u64 = 1000;
/// The driver the warm start imitates.
pub const TEACHER: &str = "idm";
/// The training's seed.
pub const SEED: u64 = 0;

/// The seed of the held-out scenes the shipped models are judged on.
pub const HELD_OUT_SEED: u64 = 2000;
/// The seed of the validation scenes that choose among a run's actors, how many per region
/// and generator, the episode seeds each, and how often an actor is judged (episodes).
pub const VALIDATION_SEED: u64 = 3000;
pub const VALIDATION_PER_REGION: usize = 8;
pub const VALIDATION_SEEDS: u64 = 3;
pub const VALIDATE_EVERY: usize = 50;

/// The corpus's scenes (see the module's header), and notes on scenarios that did not build.
pub fn corpus(examples: &Corpus) -> (Vec<Unit>, Vec<String>) {
    scenes(examples, PER_REGION, CORPUS_SEED)
}

/// Ordinary scenes as the corpus's, `per_region` per region and generator, drawn with
/// `seed` ([`HELD_OUT_SEED`]: the held-out scenes that judge the shipped models).
pub fn scenes(examples: &Corpus, per_region: usize, seed: u64) -> (Vec<Unit>, Vec<String>) {
    let mut db = Database::new(tad_check::Options::default());
    let (mut units, mut notes) = (Vec::new(), Vec::new());
    for (region, own) in examples.by_region() {
        for generator in ["fitted", "baseline"] {
            let texts = match generator {
                "fitted" => crate::generator::fitted(&mut db, &own, &region, per_region, seed),
                _ => crate::generator::baseline(&mut db, &region, per_region, seed),
            };
            let (mine, why) = crate::harness::units(&mut db, &region, generator, texts);
            units.extend(mine);
            notes.extend(why);
        }
    }
    (units, notes)
}

/// The warm start's settings.
pub fn imitation() -> Imitation {
    Imitation { rounds: 6, episodes: 96, ..Imitation::default() }
}

/// The training's settings for `algo`.
pub fn config(algo: Algo) -> Config {
    let base = Config::safebench(algo);
    let off_policy =
        Config { updates_per_episode: 20, batch: 256, critic_warmup: 1000, start_training: 1000, ..base.clone() };
    Config {
        observation: Observation::Kinematics,
        actor_lr: 1e-4,
        critic_lr: 1e-4,
        episodes: 200,
        envs: 8,
        bc_weight: 10.0,
        compat: true,
        seed: SEED,
        ..match algo {
            Algo::Ppo => Config { critic_warmup: 2, ..base },
            Algo::Sac | Algo::Td3 => off_policy,
        }
    }
}

/// How a driver did on some scenes: its collision rate and mean route completion (0..=1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Judged {
    pub collision_rate: f64,
    pub route_complete: f64,
}

impl Judged {
    /// Fewer collisions first, then further along the routes.
    pub fn better_than(&self, other: &Judged) -> bool {
        (self.collision_rate, -self.route_complete) < (other.collision_rate, -other.route_complete)
    }
}

/// A driver on `units` × seeds `0..seeds` (parameters sampled per seed), in parallel; the
/// result does not depend on the thread count.
pub fn judge(units: &[Unit], seeds: u64, make: &(dyn Fn() -> Box<dyn EgoPolicy> + Sync)) -> Judged {
    let runs: Vec<(bool, f64)> = units
        .par_iter()
        .flat_map_iter(|u| (0..seeds).map(move |seed| (u, seed)))
        .map(|(u, seed)| {
            let params = tad_runtime::sample::sample(&u.scene.program.params, Some(seed));
            let mut policy = make();
            let options = tad_runtime::Options::default();
            let episode = tad_runtime::run(&u.scene, Some(seed), params, policy.as_mut(), &options);
            let collided = episode.records.iter().any(|r| r.collision);
            (collided, episode.records.last().map_or(0.0, |r| r.route_complete / 100.0))
        })
        .collect();
    let n = runs.len().max(1) as f64;
    Judged {
        collision_rate: runs.iter().filter(|r| r.0).count() as f64 / n,
        route_complete: runs.iter().map(|r| r.1).sum::<f64>() / n,
    }
}
