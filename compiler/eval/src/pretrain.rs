//! The recipe of the shipped driving models (`tad_policy::pretrained`), written once:
//! `tadslc train-ego --pretrained ALGO` runs it and reproduces the shipped file byte for
//! byte (same seed; candle's sums do not depend on the thread count).
//!
//! 1. **Corpus**: for every region the embedded examples name, [`PER_REGION`] scenarios of
//!    the `fitted` generator (fitted on that region's examples) and as many of the
//!    `baseline` generator, drawn with [`CORPUS_SEED`]: ordinary scenes over every region
//!    and behaviour, never the evaluation's (which draw with the evaluation's seed, 0 by
//!    default, and are searched to collide).
//! 2. **Warm start** ([`imitation`]): DAgger from the idm driver ([`TEACHER`]).
//! 3. **Training** ([`config`]): the algorithm's SafeBench settings at the learning rate
//!    1e-4, the `state` observation (SafeBench's four values cannot see a red light or a
//!    stop line: a driver on them cannot meet the idm bar), SafeBench's episode rules
//!    (`compat`: leaving the road is no escape from the penalties), critics warmed up
//!    before the actor moves, and the demonstrations kept in the actor's loss.

use tad_db::Database;
use tad_policy::Observation;
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
        observation: Observation::State,
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
