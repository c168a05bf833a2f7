//! The driving environment over the runtime, stepped from outside as reinforcement-learning
//! libraries step one (Gymnasium's `reset`/`step`); the `tadsl` Python package binds it.
//!
//! ```text
//! scenario files ──load (tad-eval's pipeline; .tadc decoded)──▶ Scenarios (shared, Arc)
//!   Env: reset ──▶ tad_runtime::Sim (the episode's scene, seed, parameters) ──view──▶ observation
//!        step(action in [−1, 1]²) ──Sim::act──▶ record ──tad-train's Rewarder──▶ reward, ended?
//!   Batch: n Envs stepped together on rayon's threads, each reset at the call after it ends
//! ```
//!
//! An episode is the runtime's: the same scene, seed and actions give `tadslc run`'s
//! records, because both step [`tad_runtime::Sim`].
//!
//! **Which episode.** Episodes are numbered `e = 0, 1, 2, …` after `reset(seed = s)`; episode
//! `e` runs scenario `e mod N` (of the `N` given, in order) with seed `s + e`, its
//! parameters sampled from that seed as `tadslc run --seeds` samples them. Without a seed,
//! `s` is 0. A [`Batch`] of `n` environments reset with `s` numbers environment `i`'s
//! episodes `i, i + n, i + 2n, …`, so no two run the same seed, and what each environment
//! does never depends on how many threads step them.
//!
//! **Observation** ([`Observation`]): SafeBench's four features, the 13-value `state`
//! ([`tad_policy::EgoView::state`]) or the `kinematics` (the `state` and the six actors
//! nearest the ego, [`tad_policy::EgoView::kinematics`]), as `f32`. **Action**: `[acc, steer]` in `[−1, 1]²`,
//! scaled as SafeBench scales its actors' ([`tad_policy::Action::from_unit`]), so a policy
//! trained here drives under `tadslc run --ego learned:`. **Reward**: SafeBench's
//! ([`tad_train::Rewarder`]). **End**: a collision, off road, the route completed or a
//! failed driver *terminate*; the step, distance and time limits *truncate*. The step that
//! ends an episode repeats the last observation.

use std::path::PathBuf;
use std::sync::Arc;

use rayon::prelude::*;
use tad_db::host::Search;
use tad_metrics::StopReason;
use tad_policy::{Action, EgoView};
use tad_runtime::{Options, Scene, Sim};
use tad_train::Rewarder;

/// A scenario ready to run, named for people.
#[derive(Clone)]
pub struct Scenario {
    pub name: String,
    pub scene: Arc<Scene>,
}

/// Why the environment cannot do what it was asked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GymError {
    /// Scenario files that do not load: each one's report (diagnostics included).
    Load(Vec<String>),
    /// No scenario to run.
    NoScenario,
    /// `step` before `reset`, or after the episode ended.
    NotRunning,
    /// An action or output of the wrong length, or a scenario index out of range.
    Shape(String),
    /// An observation name other than `safebench` or `state`.
    Observation(String),
}

impl std::fmt::Display for GymError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GymError::Load(reports) => write!(f, "{}", reports.join("\n")),
            GymError::NoScenario => write!(f, "no scenario to run: give scenario files or directories"),
            GymError::NotRunning => write!(f, "no episode under way: call reset() first, and again after one ends"),
            GymError::Shape(why) => write!(f, "{why}"),
            GymError::Observation(name) => {
                write!(f, "unknown observation `{name}` (expected `safebench` or `state`)")
            }
        }
    }
}

impl std::error::Error for GymError {}

/// Scenario files (`.tad`, `.yaml`, `.tadc`) and directories of them as scenarios: sources
/// checked, resolved, laid out and lowered; `.tadc` files decoded and verified. Every file
/// that does not load is reported; any such file makes the whole load an error.
pub fn load(paths: &[PathBuf]) -> Result<Vec<Scenario>, GymError> {
    let (bytecode, sources): (Vec<PathBuf>, Vec<PathBuf>) =
        paths.iter().cloned().partition(|p| p.extension().is_some_and(|e| e == "tadc"));
    let (inputs, mut reports) =
        if sources.is_empty() { (Vec::new(), Vec::new()) } else { tad_db::host::load(&sources, Search::Scenarios) };
    let mut programs = Vec::new();
    let mut db = tad_db::Database::new(tad_check::Options::default());
    for input in &inputs {
        match tad_eval::pipeline::compile(&mut db, input) {
            Ok(program) => programs.push((input.name.clone(), program)),
            Err(refusal) => reports.push(refusal.render(input, "loaded", false).trim_end().to_string()),
        }
    }
    for path in bytecode {
        let name = path.display().to_string();
        match std::fs::read(&path)
            .map_err(|e| e.to_string())
            .and_then(|b| tad_bytecode::decode(&b).map_err(|e| e.to_string()))
        {
            Ok(program) => programs.push((name, program)),
            Err(why) => reports.push(format!("{name}: not loaded: {why}")),
        }
    }
    let mut scenarios = Vec::new();
    for (name, program) in programs {
        match Scene::new(&program) {
            Ok(scene) => scenarios.push(Scenario { name, scene: Arc::new(scene) }),
            Err(e) => reports.push(format!("{name}: not loaded: {e}")),
        }
    }
    match (reports.is_empty(), scenarios.is_empty()) {
        (false, _) => Err(GymError::Load(reports)),
        (true, true) => Err(GymError::NoScenario),
        (true, false) => Ok(scenarios),
    }
}

pub use tad_policy::Observation;

/// The observation a name means, or why not.
pub fn observation(name: &str) -> Result<Observation, GymError> {
    Observation::parse(name).ok_or_else(|| GymError::Observation(name.to_string()))
}

/// `observation` of `view` into `out`, without allocating.
fn write(observation: Observation, view: &EgoView, out: &mut [f32]) {
    observation.with(view, |values| out.iter_mut().zip(values).for_each(|(o, &v)| *o = v as f32));
}

/// What a step returns besides the observation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Transition {
    pub reward: f64,
    pub terminated: bool,
    pub truncated: bool,
}

/// Whether a stop ends the task (`terminated`) or only cuts it short (`truncated`).
pub fn terminates(reason: StopReason) -> bool {
    !matches!(reason, StopReason::MaxSteps | StopReason::MaxDistance | StopReason::Timeout)
}

/// The episode under way.
struct Current {
    scenario: usize,
    seed: u64,
    sim: Sim<Arc<Scene>>,
    rewarder: Rewarder<Arc<Scene>>,
    /// The observation shown last (repeated by the step that ends the episode).
    last: Vec<f32>,
    total: f64,
}

/// One environment: scenarios, an observation, the episode under way.
pub struct Env {
    scenarios: Arc<[Scenario]>,
    observation: Observation,
    opts: Options,
    /// Episode `e`'s seed is `base + e`.
    base: u64,
    /// The next episode's number, and how far each reset moves it.
    next: u64,
    stride: u64,
    current: Option<Current>,
}

impl Env {
    /// An environment over `scenarios` (at least one) showing `observation`.
    pub fn new(scenarios: Arc<[Scenario]>, observation: Observation) -> Result<Env, GymError> {
        if scenarios.is_empty() {
            return Err(GymError::NoScenario);
        }
        Ok(Env { scenarios, observation, opts: Options::default(), base: 0, next: 0, stride: 1, current: None })
    }

    pub fn observation(&self) -> Observation {
        self.observation
    }

    pub fn scenarios(&self) -> &[Scenario] {
        &self.scenarios
    }

    /// Start the next episode (the module's header says which), or with `seed` the first
    /// of a new numbering; `scenario` pins the scenario by index. Writes its first
    /// observation into `obs`.
    pub fn reset(&mut self, seed: Option<u64>, scenario: Option<usize>, obs: &mut [f32]) -> Result<(), GymError> {
        self.check_obs(obs)?;
        if let Some(index) = scenario.filter(|&i| i >= self.scenarios.len()) {
            return Err(GymError::Shape(format!(
                "scenario {index} is out of range (there are {})",
                self.scenarios.len()
            )));
        }
        if let Some(seed) = seed {
            self.base = seed;
            self.next %= self.stride;
        }
        let number = self.next;
        self.next += self.stride;
        let index = scenario.unwrap_or((number % self.scenarios.len() as u64) as usize);
        let scene = Arc::clone(&self.scenarios[index].scene);
        let episode_seed = self.base.wrapping_add(number);
        let params = tad_runtime::sample::sample(&scene.program.params, Some(episode_seed));
        let mut sim = Sim::start(Arc::clone(&scene), Some(episode_seed), params, self.opts);
        let rewarder = Rewarder::new(scene, sim.desired_speed());
        let mut last = vec![0.0; self.observation.width()];
        if let Some(view) = sim.view() {
            write(self.observation, view, &mut last);
        }
        obs.copy_from_slice(&last);
        self.current = Some(Current { scenario: index, seed: episode_seed, sim, rewarder, last, total: 0.0 });
        Ok(())
    }

    /// One step with `action` (`[acc, steer]` in `[−1, 1]`, clamped; not finite: 0); the
    /// next observation goes into `obs`.
    pub fn step(&mut self, action: [f32; 2], obs: &mut [f32]) -> Result<Transition, GymError> {
        self.check_obs(obs)?;
        let observation = self.observation;
        let current = self.current.as_mut().filter(|c| c.sim.stop_reason().is_none()).ok_or(GymError::NotRunning)?;
        let finite = action.map(|a| if a.is_finite() { a } else { 0.0 });
        let applied = Action::from_unit(finite);
        let stop = current.sim.act(applied);
        let reward = match current.sim.records().last() {
            Some(record) => current.rewarder.step(record, applied.steer).total(),
            None => 0.0,
        };
        current.total += reward;
        if let Some(view) = current.sim.view().filter(|_| stop.is_none()) {
            write(observation, view, &mut current.last);
        }
        obs.copy_from_slice(&current.last);
        let ended = current.sim.stop_reason();
        Ok(Transition {
            reward,
            terminated: ended.is_some_and(terminates),
            truncated: ended.is_some_and(|r| !terminates(r)),
        })
    }

    /// The episode under way or just ended: its scenario's name, seed, stop reason (once
    /// stopped), steps and return so far.
    pub fn info(&self) -> Option<Info<'_>> {
        self.current.as_ref().map(|c| Info {
            scenario: &self.scenarios[c.scenario].name,
            index: c.scenario,
            seed: c.seed,
            stop_reason: c.sim.stop_reason(),
            steps: c.sim.records().len(),
            total_reward: c.total,
            records: c.sim.records(),
        })
    }

    fn check_obs(&self, obs: &[f32]) -> Result<(), GymError> {
        let want = self.observation.width();
        if obs.len() == want {
            Ok(())
        } else {
            Err(GymError::Shape(format!("the observation holds {want} values, not {}", obs.len())))
        }
    }
}

/// The episode under way, as [`Env::info`] shows it.
#[derive(Clone, Copy, Debug)]
pub struct Info<'a> {
    pub scenario: &'a str,
    pub index: usize,
    pub seed: u64,
    pub stop_reason: Option<StopReason>,
    pub steps: usize,
    pub total_reward: f64,
    pub records: &'a [tad_metrics::StepRecord],
}

/// `n` environments stepped together. An environment whose episode ended is reset at the
/// next [`Batch::step`], which ignores its action and returns its first observation with
/// reward 0 (Gymnasium's next-step autoreset).
pub struct Batch {
    envs: Vec<Env>,
    ended: Vec<bool>,
}

impl Batch {
    pub fn new(scenarios: Arc<[Scenario]>, observation: Observation, n: usize) -> Result<Batch, GymError> {
        if n == 0 {
            return Err(GymError::Shape("a batch holds at least one environment".to_string()));
        }
        let mut envs = Vec::with_capacity(n);
        for i in 0..n {
            let mut env = Env::new(Arc::clone(&scenarios), observation)?;
            (env.next, env.stride) = (i as u64, n as u64);
            envs.push(env);
        }
        Ok(Batch { envs, ended: vec![false; n] })
    }

    pub fn len(&self) -> usize {
        self.envs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    pub fn env(&self, i: usize) -> &Env {
        &self.envs[i]
    }

    /// Reset every environment (numbered from `seed` as the module's header says); the
    /// first observations go into `obs`, row by row.
    pub fn reset(&mut self, seed: Option<u64>, obs: &mut [f32]) -> Result<(), GymError> {
        let width = self.check(obs)?;
        let jobs = self.envs.par_iter_mut().zip(obs.par_chunks_mut(width));
        jobs.map(|(env, row)| env.reset(seed, None, row)).collect::<Result<(), GymError>>()?;
        self.ended.iter_mut().for_each(|e| *e = false);
        Ok(())
    }

    /// Step every environment with its row of `actions` (`[acc, steer]` each); observations,
    /// rewards and the ended flags go into the outputs, one row or value per environment.
    pub fn step(&mut self, actions: &[f32], out: Outputs<'_>) -> Result<(), GymError> {
        let n = self.envs.len();
        if actions.len() != n * 2 {
            return Err(GymError::Shape(format!("actions hold {n} × 2 values, not {}", actions.len())));
        }
        let width = self.check(out.obs)?;
        if [out.rewards.len(), out.terminated.len(), out.truncated.len()] != [n; 3] {
            return Err(GymError::Shape(format!("rewards and flags hold one value for each of {n} environments")));
        }
        let rows = out.obs.par_chunks_mut(width).zip(actions.par_chunks(2));
        let flags = out.rewards.par_iter_mut().zip(out.terminated.par_iter_mut()).zip(out.truncated.par_iter_mut());
        let envs = self.envs.par_iter_mut().zip(self.ended.par_iter_mut());
        envs.zip(rows)
            .zip(flags)
            .map(|(((env, ended), (obs, action)), ((reward, term), trunc))| {
                let t = if *ended {
                    env.reset(None, None, obs)?;
                    Transition::default()
                } else {
                    env.step([action[0], action[1]], obs)?
                };
                (*reward, *term, *trunc) = (t.reward, u8::from(t.terminated), u8::from(t.truncated));
                *ended = t.terminated || t.truncated;
                Ok(())
            })
            .collect::<Result<(), GymError>>()
    }

    /// The observation width, after checking `obs` holds a row per environment.
    fn check(&self, obs: &[f32]) -> Result<usize, GymError> {
        let n = self.envs.len();
        let width = self.envs[0].observation.width();
        if obs.len() != n * width {
            return Err(GymError::Shape(format!("observations hold {n} × {width} values, not {}", obs.len())));
        }
        Ok(width)
    }
}

/// Where [`Batch::step`] writes: `obs` row by row, then per environment a reward and the
/// terminated and truncated flags (0 or 1).
pub struct Outputs<'a> {
    pub obs: &'a mut [f32],
    pub rewards: &'a mut [f64],
    pub terminated: &'a mut [u8],
    pub truncated: &'a mut [u8],
}

#[cfg(test)]
mod tests;
