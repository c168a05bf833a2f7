//! `tadsl._tadsl`: the native half of the `tadsl` Python package. It binds tad-gym's
//! [`tad_gym::Env`] and [`tad_gym::Batch`] and tad-policy's learned-policy loader; the
//! Gymnasium classes around them are Python (`python/tadsl/`).
//!
//! Arrays cross the boundary as Python buffers (NumPy arrays the Python side owns and
//! reuses): observations, rewards and flags are written into them, actions read from them,
//! so a step allocates nothing on either side. A batch steps with the GIL released.
//! The environments are `unsendable` (rapier's event queues are not `Sync`): each lives on
//! the Python thread that made it.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::buffer::PyBuffer;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tad_gym::{Batch, GymError, Outputs, Scenario};

fn value_error(e: GymError) -> PyErr {
    match e {
        GymError::NotRunning => PyRuntimeError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

fn scenarios(paths: Vec<PathBuf>) -> PyResult<Arc<[Scenario]>> {
    Ok(tad_gym::load(&paths).map_err(value_error)?.into())
}

/// Copy `values` into the writable buffer `out` (a NumPy array of the same length).
fn write<T: pyo3::buffer::Element + Copy>(py: Python<'_>, out: &PyBuffer<T>, values: &[T]) -> PyResult<()> {
    out.copy_from_slice(py, values)
}

/// An episode's `info` as Python sees it: `scenario`, `scenario_index`, `seed`,
/// `stop_reason` (None while it runs), `steps`, `return`; empty before the first reset.
fn info_dict<'py>(py: Python<'py>, info: Option<tad_gym::Info<'_>>) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    if let Some(info) = info {
        dict.set_item("scenario", info.scenario)?;
        dict.set_item("scenario_index", info.index)?;
        dict.set_item("seed", info.seed)?;
        dict.set_item("stop_reason", info.stop_reason.map(|r| r.as_str()))?;
        dict.set_item("steps", info.steps)?;
        dict.set_item("return", info.total_reward)?;
    }
    Ok(dict)
}

/// One environment: `Env(paths, observation)`; `reset(seed, scenario, obs)` and
/// `step(acc, steer, obs) -> (reward, terminated, truncated)` write the observation into
/// `obs` (float32, its length `obs_len`).
#[pyclass(module = "tadsl._tadsl", unsendable)]
struct Env {
    env: tad_gym::Env,
    obs: Vec<f32>,
}

#[pymethods]
impl Env {
    #[new]
    fn new(paths: Vec<PathBuf>, observation: &str) -> PyResult<Env> {
        let observation = tad_gym::observation(observation).map_err(value_error)?;
        let env = tad_gym::Env::new(scenarios(paths)?, observation).map_err(value_error)?;
        Ok(Env { obs: vec![0.0; observation.width()], env })
    }

    #[getter]
    fn obs_len(&self) -> usize {
        self.env.observation().width()
    }

    /// The scenarios' names, in the order episodes take them.
    #[getter]
    fn scenarios(&self) -> Vec<String> {
        self.env.scenarios().iter().map(|s| s.name.clone()).collect()
    }

    #[pyo3(signature = (seed, scenario, obs))]
    fn reset(
        &mut self,
        py: Python<'_>,
        seed: Option<u64>,
        scenario: Option<usize>,
        obs: PyBuffer<f32>,
    ) -> PyResult<()> {
        self.env.reset(seed, scenario, &mut self.obs).map_err(value_error)?;
        write(py, &obs, &self.obs)
    }

    fn step(&mut self, py: Python<'_>, acc: f32, steer: f32, obs: PyBuffer<f32>) -> PyResult<(f64, bool, bool)> {
        let t = self.env.step([acc, steer], &mut self.obs).map_err(value_error)?;
        write(py, &obs, &self.obs)?;
        Ok((t.reward, t.terminated, t.truncated))
    }

    /// The episode under way or just ended: `scenario`, `scenario_index`, `seed`,
    /// `stop_reason` (None while it runs), `steps`, `return`.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        info_dict(py, self.env.info())
    }

    /// The episode's step records, as `tadslc run` keeps them: one tuple per step,
    /// `(time, x, y, yaw_deg, speed, collision, route_complete)`.
    fn records(&self) -> Vec<(f64, f64, f64, f64, f64, bool, f64)> {
        let Some(info) = self.env.info() else { return Vec::new() };
        let row = |r: &tad_metrics::StepRecord| {
            (r.time, r.position[0], r.position[1], r.yaw_deg, r.velocity, r.collision, r.route_complete)
        };
        info.records.iter().map(row).collect()
    }
}

/// `n` environments stepped together: `reset(seed, obs)` and `step(actions, obs, rewards,
/// terminated, truncated)` over arrays of `n` rows (float32 observations and actions,
/// float64 rewards, uint8 flags). An environment whose episode ended is reset at the next
/// step (its action ignored, reward 0).
#[pyclass(module = "tadsl._tadsl", unsendable)]
struct VecEnv {
    batch: Batch,
    obs: Vec<f32>,
    rewards: Vec<f64>,
    terminated: Vec<u8>,
    truncated: Vec<u8>,
}

#[pymethods]
impl VecEnv {
    #[new]
    fn new(paths: Vec<PathBuf>, observation: &str, n: usize) -> PyResult<VecEnv> {
        let observation = tad_gym::observation(observation).map_err(value_error)?;
        let batch = Batch::new(scenarios(paths)?, observation, n).map_err(value_error)?;
        Ok(VecEnv {
            obs: vec![0.0; n * observation.width()],
            rewards: vec![0.0; n],
            terminated: vec![0; n],
            truncated: vec![0; n],
            batch,
        })
    }

    #[getter]
    fn obs_len(&self) -> usize {
        self.obs.len() / self.batch.len()
    }

    #[getter]
    fn num_envs(&self) -> usize {
        self.batch.len()
    }

    #[pyo3(signature = (seed, obs))]
    fn reset(&mut self, py: Python<'_>, seed: Option<u64>, obs: PyBuffer<f32>) -> PyResult<()> {
        let (batch, rows) = (&mut self.batch, &mut self.obs);
        py.detach(|| batch.reset(seed, rows)).map_err(value_error)?;
        write(py, &obs, &self.obs)
    }

    fn step(
        &mut self,
        py: Python<'_>,
        actions: PyBuffer<f32>,
        obs: PyBuffer<f32>,
        rewards: PyBuffer<f64>,
        terminated: PyBuffer<u8>,
        truncated: PyBuffer<u8>,
    ) -> PyResult<()> {
        let actions = actions.to_vec(py)?;
        let out = Outputs {
            obs: &mut self.obs,
            rewards: &mut self.rewards,
            terminated: &mut self.terminated,
            truncated: &mut self.truncated,
        };
        let batch = &mut self.batch;
        py.detach(|| batch.step(&actions, out)).map_err(value_error)?;
        write(py, &obs, &self.obs)?;
        write(py, &rewards, &self.rewards)?;
        write(py, &terminated, &self.terminated)?;
        write(py, &truncated, &self.truncated)
    }

    /// Environment `i`'s episode, as [`Env::info`] shows it.
    fn info<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyDict>> {
        if i >= self.batch.len() {
            return Err(PyValueError::new_err(format!(
                "environment {i} is out of range (there are {})",
                self.batch.len()
            )));
        }
        info_dict(py, self.batch.env(i).info())
    }
}

/// A learned policy as `tadslc run --ego learned:PATH` loads it (SafeBench's SAC actor or
/// an SB3 PPO, SAC or TD3 policy in safetensors): `act(obs)` is its deterministic action in
/// `[−1, 1]²`.
#[pyclass(module = "tadsl._tadsl")]
struct Policy {
    learned: tad_policy::Learned,
}

#[pymethods]
impl Policy {
    #[new]
    fn new(path: PathBuf) -> PyResult<Policy> {
        let learned = tad_policy::Learned::load(&path).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(Policy { learned })
    }

    /// `SafeBench SAC`, `SB3 PPO`, `SB3 SAC` or `SB3 TD3`.
    #[getter]
    fn format(&self) -> &'static str {
        self.learned.format().as_str()
    }

    /// The observation's length it reads (4: `safebench`, 13: `state`).
    #[getter]
    fn obs_len(&self) -> usize {
        self.learned.inputs()
    }

    fn act(&self, obs: Vec<f64>) -> PyResult<(f32, f32)> {
        if obs.len() != self.learned.inputs() {
            let want = self.learned.inputs();
            return Err(PyValueError::new_err(format!("the policy reads {want} values, not {}", obs.len())));
        }
        let [acc, steer] = self.learned.mu(&obs);
        Ok((acc, steer))
    }
}

#[pymodule]
fn _tadsl(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Env>()?;
    m.add_class::<VecEnv>()?;
    m.add_class::<Policy>()?;
    m.add("STATE_DIM", tad_policy::STATE_DIM)?;
    Ok(())
}
