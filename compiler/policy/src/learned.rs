//! SafeBench's SAC actor (`safebench/agent/rl/sac.py::Actor`): candle reads and writes the
//! safetensors file; the forward pass is plain `f32` arithmetic.
//!
//! The actor is an MLP: `x = relu(fcK(… relu(fc1(obs))))`, `mu = tanh(fc_mu(x))`, and a
//! std head `fc_std` that deterministic evaluation ignores (SafeBench's
//! `get_action(deterministic=True)` returns `mu`). SafeBench's sizes are 4 → 64 → 256 → 2;
//! here the hidden layers are read off the tensors: `fc1`, `fc2`, … as long as they exist,
//! each `weight` `[out, in]` and `bias` `[out]` (PyTorch's `nn.Linear`), `fc1` taking the 4
//! observation features and `fc_mu` giving 2. `mu = [acc, steer]` is scaled as SafeBench's
//! environment does: `accel = 3·acc` m/s² (`continuous_accel_range`), `steer = 0.3·steer`
//! (`continuous_steer_range`, CARLA's sign), so the actor never brakes harder than 3 m/s².
//!
//! A checkpoint converts from PyTorch with
//! `safetensors.torch.save_file(torch.load(f)['policy_net'], 'actor.safetensors')`; names
//! prefixed `policy_net.` (a whole checkpoint flattened) are accepted too. Weights of any
//! float type are computed in `f32`, as PyTorch does.
//!
//! Why not candle's matmul for the forward pass: on the CPU it asks for the machine's core
//! count on every call (reading `/proc` unless `RAYON_NUM_THREADS` is set), 0.2–0.3 ms a
//! step against a few µs for the 17 k multiply-adds themselves. The tests check this
//! forward pass against candle's.

use crate::{Action, EgoPolicy, EgoView, PolicyError};
use candle_core::{DType, Device, Tensor};
use std::collections::HashMap;
use std::path::Path;
use tad_ir::{Rng, SplitMix64};

/// The observation's length (SafeBench's `ego_state_dim`).
const OBS_DIM: usize = 4;
/// The action's length (`ego_action_dim`).
const ACTION_DIM: usize = 2;
/// SafeBench's scaling of the actor's `[−1, 1]` outputs: m/s², normalised steer.
const ACCEL_RANGE: f64 = 3.0;
const STEER_RANGE: f64 = 0.3;

/// Where the actor's tensors may live in a file.
const PREFIXES: [&str; 2] = ["", "policy_net."];

/// A learned ego: SafeBench's SAC actor, deterministic.
#[derive(Clone, Debug, PartialEq)]
pub struct Learned {
    name: String,
    hidden: Vec<Dense>,
    mu: Dense,
    /// The std head, kept only to be saved again.
    std: Option<Dense>,
}

/// One `nn.Linear`: `weight` row-major `[outputs, inputs]`.
#[derive(Clone, Debug, PartialEq)]
struct Dense {
    inputs: usize,
    weight: Vec<f32>,
    bias: Vec<f32>,
}

impl Dense {
    fn outputs(&self) -> usize {
        self.bias.len()
    }

    fn forward(&self, x: &[f32]) -> Vec<f32> {
        let rows = self.weight.chunks_exact(self.inputs);
        rows.zip(&self.bias).map(|(row, b)| row.iter().zip(x).map(|(w, v)| w * v).sum::<f32>() + b).collect()
    }

    fn tensors(&self) -> candle_core::Result<(Tensor, Tensor)> {
        let weight = Tensor::from_vec(self.weight.clone(), (self.outputs(), self.inputs), &Device::Cpu)?;
        Ok((weight, Tensor::from_vec(self.bias.clone(), self.outputs(), &Device::Cpu)?))
    }
}

impl Learned {
    /// Load an actor from a safetensors file (see the module's header for the names).
    pub fn load(path: impl AsRef<Path>) -> Result<Learned, PolicyError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| PolicyError::Io { path: shown.clone(), message: e.to_string() })?;
        let tensors = candle_core::safetensors::load_buffer(&bytes, &Device::Cpu)
            .map_err(|e| PolicyError::NotSafetensors { path: shown.clone(), message: e.to_string() })?;
        let mut actor = Learned::from_tensors(&tensors, &shown)?;
        actor.name = format!("learned:{shown}");
        Ok(actor)
    }

    /// The actor in `tensors`; `path` names their source in errors.
    pub fn from_tensors(tensors: &HashMap<String, Tensor>, path: &str) -> Result<Learned, PolicyError> {
        let prefix = PREFIXES.iter().find(|p| tensors.contains_key(&format!("{p}fc1.weight"))).copied().unwrap_or("");
        // The values of `name`, which must be `[rows, cols]` (`rows` 0: any but 0) or
        // `[rows]` (`cols` None).
        let get = |name: &str, rows: usize, cols: Option<usize>| -> Result<Vec<f32>, PolicyError> {
            let full = format!("{prefix}{name}");
            let Some(t) = tensors.get(&full) else {
                let mut found: Vec<String> = tensors.keys().cloned().collect();
                found.sort();
                found.truncate(8);
                return Err(PolicyError::MissingTensor { path: path.to_string(), name: full, found });
            };
            let dims = t.dims();
            let fits = match cols {
                Some(c) => dims.len() == 2 && dims[1] == c && dims[0] > 0 && (rows == 0 || dims[0] == rows),
                None => dims == [rows],
            };
            if !fits {
                let expected = match (cols, rows) {
                    (Some(c), 0) => format!("[n, {c}] with n ≥ 1"),
                    (Some(c), r) => format!("[{r}, {c}]"),
                    (None, r) => format!("[{r}]"),
                };
                return Err(PolicyError::WrongShape {
                    path: path.to_string(),
                    name: full,
                    expected,
                    found: dims.to_vec(),
                });
            }
            let values =
                t.to_dtype(DType::F32).and_then(|t| t.flatten_all()?.to_vec1::<f32>()).map_err(tensor_error)?;
            if values.iter().any(|v| !v.is_finite()) {
                return Err(PolicyError::NonFinite { path: path.to_string(), name: full });
            }
            Ok(values)
        };
        let layer = |name: &str, outputs: usize, inputs: usize| -> Result<Dense, PolicyError> {
            let weight = get(&format!("{name}.weight"), outputs, Some(inputs))?;
            let outputs = weight.len() / inputs;
            Ok(Dense { inputs, weight, bias: get(&format!("{name}.bias"), outputs, None)? })
        };
        let mut hidden: Vec<Dense> = Vec::new();
        for k in 1.. {
            let name = format!("fc{k}");
            if k > 1 && !tensors.contains_key(&format!("{prefix}{name}.weight")) {
                break;
            }
            let inputs = hidden.last().map_or(OBS_DIM, Dense::outputs);
            hidden.push(layer(&name, 0, inputs)?);
        }
        let width = hidden.last().map_or(OBS_DIM, Dense::outputs);
        let mu = layer("fc_mu", ACTION_DIM, width)?;
        let std = layer("fc_std", ACTION_DIM, width).ok();
        Ok(Learned { name: "learned".to_string(), hidden, mu, std })
    }

    /// A fresh actor with these hidden widths, its weights and biases drawn uniformly from
    /// `±1/√fan_in` (PyTorch's `nn.Linear` default) by a generator seeded with `seed`.
    pub fn random(hidden: &[usize], seed: u64) -> Result<Learned, PolicyError> {
        if hidden.is_empty() || hidden.contains(&0) {
            return Err(PolicyError::BadHidden { hidden: hidden.to_vec() });
        }
        let mut rng = SplitMix64::new(seed);
        let mut layer = |outputs: usize, inputs: usize| {
            let bound = 1.0 / (inputs as f64).sqrt();
            let mut draw =
                |n: usize| -> Vec<f32> { (0..n).map(|_| ((rng.unit() * 2.0 - 1.0) * bound) as f32).collect() };
            Dense { inputs, weight: draw(outputs * inputs), bias: draw(outputs) }
        };
        let mut layers = Vec::new();
        let mut width = OBS_DIM;
        for &h in hidden {
            layers.push(layer(h, width));
            width = h;
        }
        let mu = layer(ACTION_DIM, width);
        let std = layer(ACTION_DIM, width);
        Ok(Learned { name: "learned".to_string(), hidden: layers, mu, std: Some(std) })
    }

    /// The actor's tensors under SafeBench's names (unprefixed, `f32`).
    pub fn tensors(&self) -> Result<HashMap<String, Tensor>, PolicyError> {
        let named = self.hidden.iter().enumerate().map(|(k, l)| (format!("fc{}", k + 1), l));
        let named =
            named.chain([("fc_mu".to_string(), &self.mu)]).chain(self.std.iter().map(|s| ("fc_std".to_string(), s)));
        let mut tensors = HashMap::new();
        for (name, layer) in named {
            let (weight, bias) = layer.tensors().map_err(tensor_error)?;
            tensors.insert(format!("{name}.weight"), weight);
            tensors.insert(format!("{name}.bias"), bias);
        }
        Ok(tensors)
    }

    /// Write the actor as a safetensors file ([`Learned::tensors`]).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), PolicyError> {
        let path = path.as_ref();
        candle_core::safetensors::save(&self.tensors()?, path)
            .map_err(|e| PolicyError::Io { path: path.display().to_string(), message: e.to_string() })
    }

    /// The hidden layers' widths.
    pub fn hidden(&self) -> Vec<usize> {
        self.hidden.iter().map(Dense::outputs).collect()
    }

    /// The actor's `mu = tanh(fc_mu(…))` for an observation, in `[−1, 1]²`.
    pub fn mu(&self, obs: [f64; OBS_DIM]) -> [f32; ACTION_DIM] {
        let mut x: Vec<f32> = obs.iter().map(|&v| v as f32).collect();
        for layer in &self.hidden {
            x = layer.forward(&x).into_iter().map(|v| v.max(0.0)).collect();
        }
        let mu = self.mu.forward(&x);
        [mu[0].tanh(), mu[1].tanh()]
    }
}

impl EgoPolicy for Learned {
    fn name(&self) -> &str {
        &self.name
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let [acc, steer] = self.mu(view.obs);
        Action {
            accel: (f64::from(acc) * ACCEL_RANGE).clamp(-ACCEL_RANGE, ACCEL_RANGE),
            steer: (f64::from(steer) * STEER_RANGE).clamp(-STEER_RANGE, STEER_RANGE),
        }
    }
}

fn tensor_error(e: candle_core::Error) -> PolicyError {
    PolicyError::Tensor { message: e.to_string() }
}
