//! What `tadslc search` writes: each chosen scene as TAD with its parameters fixed
//! (`tad_search::fix`), under a name no other scene took, with a header saying where it
//! came from; the scene run again with the same ego and seed (does it reproduce the
//! searched outcome?); and `search.json` (format `tadsl-search/1`).
//!
//! While it runs, each finished search is appended to `search.jsonl` ([`Head`], then a
//! [`Finished`] per scenario): a run interrupted (Ctrl-C, a kill) and started again with
//! the same arguments and inputs searches only what had not finished, and writes the
//! same files as an unbroken run.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use tad_base::Shard;

use tad_db::Database;
use tad_db::host::Input;
use tad_metrics::Mode;
use tad_policy::EgoSpec;
use tad_runtime::Scene;
use tad_search::{Outcome, Trial};

/// The search's result format.
pub const FORMAT: &str = "tadsl-search/1";
/// The format of its journal.
pub const JOURNAL_FORMAT: &str = "tadsl-search-journal/1";

/// What a search journal belongs to: a rerun resumes it only if all of this is the same.
#[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Head {
    pub format: String,
    pub ego: String,
    pub seed: u64,
    pub samples: usize,
    pub round: usize,
    pub keep: usize,
    pub compat: bool,
    pub shard: Shard,
    /// Each input of the shard: its name and a hash of its text.
    pub inputs: Vec<(String, u64)>,
}

/// One finished search: the input's place in the shard and what it found.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Finished {
    pub index: usize,
    pub outcome: Outcome,
}

/// `DIR/search.jsonl`, or `DIR/search.I-of-N.jsonl` for a shard.
pub fn journal_path(dir: &Path, shard: Shard) -> PathBuf {
    dir.join(shard.file_name("search", "jsonl"))
}

/// The hash of an input (its text, or a `.tadc` file's program) that a [`Head`] keeps.
pub fn input_hash(bytes: &[u8]) -> u64 {
    tad_base::fnv1a(bytes.iter().copied())
}

/// One chosen scene, as `search.json` lists it.
#[derive(serde::Serialize)]
pub struct Written {
    pub file: Option<String>,
    pub trial: usize,
    pub seed: u64,
    pub params: serde_json::Map<String, serde_json::Value>,
    pub collision: bool,
    pub os: Option<f64>,
    /// The written scene, run again, collided as the trial did and scored within 0.01.
    pub reproduced: Option<bool>,
}

/// Writes the chosen scenes of one search into a directory.
pub struct Writer<'a> {
    pub dir: &'a Path,
    /// The ego as the user named it (for the header), and as a spec.
    pub ego_name: &'a str,
    pub ego: &'a EgoSpec,
    pub mode: Mode,
    taken: HashSet<String>,
}

impl<'a> Writer<'a> {
    pub fn new(dir: &'a Path, ego_name: &'a str, ego: &'a EgoSpec, mode: Mode) -> Writer<'a> {
        Writer { dir, ego_name, ego, mode, taken: HashSet::new() }
    }

    /// Chosen scene `k` (trial `i` of `outcome`) of the scenario `input` compiled to `scene`,
    /// written as TAD and run again; with why it could not be written, if it could not.
    pub fn write(
        &mut self,
        input: Option<&Input>,
        scene: &Scene,
        outcome: &Outcome,
        (i, k): (usize, usize),
    ) -> (Written, Option<String>) {
        let trial = &outcome.trials[i];
        let written = input
            .ok_or_else(|| "a bytecode file has no source to write".to_string())
            .and_then(|input| self.write_scene(input, scene, trial, k));
        let params = scene
            .program
            .params
            .iter()
            .zip(&trial.params)
            .map(|(slot, v)| (slot.name.clone(), serde_json::json!(round(*v))))
            .collect();
        let (file, reproduced, error) = match written {
            Ok((file, reproduced)) => (Some(file), Some(reproduced), None),
            Err(e) => (None, None, Some(e)),
        };
        let written = Written {
            file,
            trial: trial.index,
            seed: trial.seed,
            params,
            collision: trial.collision,
            os: trial.score.as_ref().map(|s| round(s.metrics.os)),
            reproduced,
        };
        (written, error)
    }

    /// (file name, reproduced), or why the scene was not written.
    fn write_scene(&mut self, input: &Input, scene: &Scene, trial: &Trial, k: usize) -> Result<(String, bool), String> {
        let db = std::cell::RefCell::new(Database::new(tad_check::Options::default()));
        let compile = |text: &str| {
            let again = Input { text: text.to_string(), ..input.clone() };
            crate::pipeline::compile(&mut db.borrow_mut(), &again).ok()
        };
        let text = tad_search::fix(&input.text, &scene.program, &trial.params, &compile).map_err(|e| e.to_string())?;
        let name = self.name(input, k);
        let verdict = if trial.collision { "a collision" } else { "no collision" };
        let header = format!(
            "// tadslc search: scene {} of {} (trial seed {}), with ego {}: {verdict}, OS {}\n",
            trial.index,
            input.name,
            trial.seed,
            self.ego_name,
            trial.score.as_ref().map_or("-".into(), |s| format!("{:.3}", s.metrics.os)),
        );
        let path = self.dir.join(&name);
        std::fs::write(&path, format!("{header}{text}"))
            .map_err(|e| format!("cannot write `{}`: {e}", path.display()))?;
        let reproduced =
            compile(&text).and_then(|p| Scene::new(&p).ok()).is_some_and(|scene| self.reproduces(&scene, trial));
        Ok((name, reproduced))
    }

    /// `STEM.advK.tad`, or `STEM-2.advK.tad`, ... when another input had the same stem.
    fn name(&mut self, input: &Input, k: usize) -> String {
        let stem = input
            .path
            .as_deref()
            .and_then(Path::file_stem)
            .map_or("scenario".into(), |s| s.to_string_lossy().into_owned());
        let mut name = format!("{stem}.adv{}.tad", k + 1);
        let mut n = 2;
        while !self.taken.insert(name.clone()) {
            name = format!("{stem}-{n}.adv{}.tad", k + 1);
            n += 1;
        }
        name
    }

    /// Whether `scene`, run with the trial's seed and the ego, collides as the trial did
    /// and scores within 0.01 of it.
    fn reproduces(&self, scene: &Scene, trial: &Trial) -> bool {
        let mut policy = self.ego.make();
        let opts = tad_runtime::Options { mode: self.mode, ..Default::default() };
        let episode = tad_runtime::run(scene, Some(trial.seed), Vec::new(), policy.as_mut(), &opts);
        let collision = episode.records.iter().any(|r| r.collision);
        let os = tad_metrics::score_episode(&episode.records, self.mode).ok().map(|s| s.metrics.os);
        collision == trial.collision
            && match (os, &trial.score) {
                (Some(a), Some(b)) => (a - b.metrics.os).abs() <= 0.01,
                (a, b) => a.is_none() && b.is_none(),
            }
    }
}

/// One scenario's entry of `search.json`.
pub fn scenario_json(input: &str, scene: &Scene, outcome: &Outcome, chosen: &[Written]) -> serde_json::Value {
    serde_json::json!({
        "input": input,
        "scenario": scene.name,
        "slots": scene.program.params.iter().map(|p| serde_json::json!({"name": p.name, "min": p.min, "max": p.max})).collect::<Vec<_>>(),
        "ranges": outcome.ranges.iter().map(|r| r.iter().map(|(a, b)| [round(*a), round(*b)]).collect::<Vec<_>>()).collect::<Vec<_>>(),
        "collision_rates": outcome.collision_rates(),
        "chosen": chosen,
    })
}

/// The search's table line for one scenario: slots, episodes, collisions by round, and the
/// chosen scenes' OS.
pub fn table_line(scene: &Scene, outcome: &Outcome, chosen: &[Written]) -> String {
    let rates: Vec<String> = outcome.collision_rates().iter().map(|r| format!("{:.0}%", 100.0 * r)).collect();
    let chosen: Vec<String> = chosen
        .iter()
        .map(|w| format!("{}{}", if w.collision { "hit " } else { "" }, w.os.map_or("-".into(), |o| format!("{o:.3}"))))
        .collect();
    let name: String = scene.name.chars().take(40).collect();
    format!(
        "{name:<40} {:>5} {:>9}  {:<24} {}",
        scene.program.params.len(),
        outcome.trials.len(),
        rates.join(" "),
        chosen.join(", ")
    )
}

/// The table's header, above its [`table_line`]s.
pub fn table_header() -> String {
    format!("{:<40} {:>5} {:>9}  {:<24} chosen (OS)", "scenario", "slots", "episodes", "collisions by round")
}

pub fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}
