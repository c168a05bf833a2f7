//! The evaluation: every unit (a scenario of a generator in a region) searched against the
//! surrogate ego (ChatScene's adversarial search, `tad-search`), then every ego run on every
//! kept scene and scored with SafeBench's metrics, one [`Row`] per episode.
//!
//! Units are numbered in a fixed order (regions, then generators, then their scenarios), so
//! `--shard I/N` takes every N-th and the shards of one command cover it once. Units are
//! evaluated in parallel (rayon); each search and episode draws from its own seed, so the
//! rows do not depend on the thread count. A unit's rows go to the journal as soon as it
//! finishes, and units already there are not run again.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use tad_base::Shard;
use tad_metrics::{EpisodeScore, Mode};
use tad_policy::EgoSpec;
use tad_runtime::Scene;

use crate::journal::{Entry, KeptScene};
use crate::results::{Results, Row, Setup};

/// One unit of work: a scenario of a generator in a region, ready to run.
pub struct Unit {
    pub region: String,
    pub generator: String,
    pub name: String,
    pub scene: Scene,
    /// Its behaviour, the key of the fine-tuning split ([`crate::corpus::behaviour`]).
    pub key: String,
}

/// The units of one generator's scenarios `texts` (name, TAD) for `region`, each set in
/// `db` as `GENERATOR/NAME.tad` and built through the [`pipeline`](crate::pipeline); a
/// scenario whose scene cannot be set up comes back as a note instead.
pub fn units(
    db: &mut tad_db::Database,
    region: &str,
    generator: &str,
    texts: Vec<(String, String)>,
) -> (Vec<Unit>, Vec<String>) {
    let (mut units, mut notes) = (Vec::new(), Vec::new());
    for (name, text) in texts {
        let path = std::path::PathBuf::from(format!("{generator}/{name}.tad"));
        let file = db.set_source(path, text, tad_db::Language::Tad, &tad_db::RealFs);
        match crate::pipeline::scene(db, file, &name) {
            None => {}
            Some(Ok(scene)) => units.push(Unit {
                region: region.to_string(),
                generator: generator.to_string(),
                key: crate::corpus::behaviour_of(db, file),
                name,
                scene,
            }),
            Some(Err(e)) => notes.push(format!("{generator}/{name}: not run: {e}")),
        }
    }
    (units, notes)
}

/// A kept scene: its unit with the search's parameters and seed.
pub struct Kept<'a> {
    pub unit: &'a Unit,
    pub params: Vec<f64>,
    pub seed: u64,
}

/// What to evaluate with: the setup, its egos parsed, the shard.
pub struct Plan {
    pub setup: Setup,
    /// The setup's egos, in order.
    pub egos: Vec<EgoSpec>,
    /// The ego the scenes are searched against.
    pub surrogate: EgoSpec,
    pub shard: Shard,
}

/// An evaluation's outcome: this shard's results and the scenes the search kept.
pub struct Evaluated<'a> {
    pub results: Results,
    pub kept: Vec<Kept<'a>>,
    /// Units this shard evaluated now, and those it found in the journal.
    pub run: usize,
    pub resumed: usize,
    /// Units not started because the run was asked to stop (their rows are missing).
    pub skipped: usize,
}

impl Plan {
    /// The search's settings.
    pub fn search(&self) -> tad_search::Config {
        tad_search::Config {
            samples: self.setup.samples,
            keep: self.setup.keep,
            seed: self.setup.seed,
            ..Default::default()
        }
    }

    /// Episodes one unit takes at most: the search's samples, then every ego on every kept scene.
    pub fn episodes_per_unit(&self) -> usize {
        self.setup.samples.max(1) + self.setup.keep * self.egos.len()
    }

    /// The units (all of them, in order) this shard takes, by index.
    pub fn mine<'u>(&self, units: &'u [Unit]) -> Vec<(usize, &'u Unit)> {
        units.iter().enumerate().filter(|(k, _)| self.shard.takes(*k)).collect()
    }

    /// Evaluate this shard's units: those in `done` (a journal's) are taken as they are, the
    /// others searched and played in parallel, each handed to `record` when it finishes;
    /// `tick` is called after every episode. Once `stop` is set no unit is started (those
    /// under way finish): the results hold the finished units only.
    pub fn evaluate<'u>(
        &self,
        units: &'u [Unit],
        done: &BTreeMap<usize, Entry>,
        record: &(dyn Fn(&Entry) + Sync),
        tick: &(dyn Fn() + Sync),
        stop: &AtomicBool,
    ) -> Evaluated<'u> {
        let mine = self.mine(units);
        let resumed = mine.iter().filter(|(k, _)| done.contains_key(k)).count();
        let entries: Vec<Option<Entry>> = mine
            .par_iter()
            .map(|&(k, u)| match done.get(&k) {
                Some(entry) => Some(entry.clone()),
                None if stop.load(Ordering::SeqCst) => None,
                None => {
                    let entry = self.unit(k, u, tick);
                    record(&entry);
                    Some(entry)
                }
            })
            .collect();
        let skipped = entries.iter().filter(|e| e.is_none()).count();
        let mut scenarios: BTreeMap<String, usize> = BTreeMap::new();
        let mut rows = Vec::new();
        let mut kept = Vec::new();
        for ((_, unit), entry) in mine.iter().zip(entries) {
            let Some(entry) = entry else { continue };
            *scenarios.entry(format!("{}/{}", unit.region, unit.generator)).or_default() += 1;
            rows.extend(entry.rows);
            kept.extend(entry.kept.into_iter().map(|s| Kept { unit, params: s.params, seed: s.seed }));
        }
        Evaluated {
            results: Results::new(self.setup.clone(), self.shard, scenarios, rows),
            kept,
            run: mine.len() - resumed - skipped,
            resumed,
            skipped,
        }
    }

    /// One unit: searched, then every ego on every kept scene.
    fn unit(&self, k: usize, u: &Unit, tick: &(dyn Fn() + Sync)) -> Entry {
        let make = || self.surrogate.make();
        let outcome = tad_search::search(&u.scene, &make, &self.search(), tick);
        let mut rows = Vec::new();
        let mut kept = Vec::new();
        for &i in &outcome.chosen {
            let trial = &outcome.trials[i];
            kept.push(KeptScene { trial: trial.index, params: trial.params.clone(), seed: trial.seed });
            for (name, ego) in self.setup.egos.iter().zip(&self.egos) {
                let score = play(&u.scene, &trial.params, trial.seed, ego);
                tick();
                if let Some(score) = score {
                    rows.push(Row {
                        region: u.region.clone(),
                        generator: u.generator.clone(),
                        ego: name.clone(),
                        scenario: u.name.clone(),
                        trial: trial.index,
                        seed: trial.seed,
                        score,
                        stop: None,
                        index: None,
                    });
                }
            }
        }
        Entry { unit: k, rows, kept }
    }
}

/// One episode of `ego` on a scene with fixed parameters, scored on its own (fixed mode);
/// `None` for an episode without a step.
pub fn play(scene: &Scene, params: &[f64], seed: u64, ego: &EgoSpec) -> Option<EpisodeScore> {
    let mut policy = ego.make();
    let episode =
        tad_runtime::run(scene, Some(seed), params.to_vec(), policy.as_mut(), &tad_runtime::Options::default());
    tad_metrics::score_episode(&episode.records, Mode::Fixed).ok()
}

/// Every driver on every held-out scene (`test` indexes `kept`): rows of region `held-out`
/// and generator `searched`, in scene order.
pub fn held_out(kept: &[Kept], test: &[usize], drivers: &[(String, EgoSpec)]) -> Vec<Row> {
    test.par_iter()
        .flat_map_iter(|&i| {
            let scene = &kept[i];
            drivers
                .iter()
                .filter_map(|(name, ego)| {
                    let score = play(&scene.unit.scene, &scene.params, scene.seed, ego)?;
                    Some(Row {
                        region: "held-out".into(),
                        generator: "searched".into(),
                        ego: name.clone(),
                        scenario: scene.unit.name.clone(),
                        trial: 0,
                        seed: scene.seed,
                        score,
                        stop: None,
                        index: None,
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The share of `ego`'s rows with a collision.
pub fn collision_rate(rows: &[Row], ego: &str) -> f64 {
    let mine: Vec<&Row> = rows.iter().filter(|r| r.ego == ego).collect();
    mine.iter().filter(|r| r.score.metrics.cr > 0.0).count() as f64 / mine.len().max(1) as f64
}
