//! A learned ego: SafeBench's SAC actor (`safebench/agent/rl/sac.py::Actor`) or a
//! Stable-Baselines3 MLP policy (PPO, SAC, TD3) exported to safetensors. candle reads and
//! writes the file; the forward pass is plain `f32` arithmetic.
//!
//! The actor is an MLP: `x = relu(fcK(… relu(fc1(obs))))`, `mu = tanh(fc_mu(x))`, and a
//! std head `fc_std` that deterministic evaluation ignores (SafeBench's
//! `get_action(deterministic=True)` returns `mu`). SafeBench's sizes are 4 → 64 → 256 → 2;
//! here the hidden layers are read off the tensors: `fc1`, `fc2`, … as long as they exist,
//! each `weight` `[out, in]` and `bias` `[out]` (PyTorch's `nn.Linear`), `fc1` taking the 4
//! observation features and `fc_mu` giving 2. `mu = [acc, steer]` is applied by
//! [`crate::Action::from_unit`]: 3 m/s² forward and 0.3 of the steer as SafeBench, and
//! the negative half onto the full brake (8 m/s², SafeBench's brake normaliser).
//!
//! # Stable-Baselines3's policies
//!
//! `safetensors.torch.save_file(model.policy.state_dict(), 'policy.safetensors')` keeps
//! SB3's names; the layout tells the algorithm (`torch.nn.Sequential` numbers its linear
//! layers 0, 2, 4, … between activations):
//! - PPO (`ActorCriticPolicy`): `mlp_extractor.policy_net.{0,2,…}` with tanh (SB3's
//!   default `activation_fn`), then `action_net`: the Gaussian's mean, clipped to `[−1, 1]`
//!   as `predict` clips it to the action space;
//! - SAC: `actor.latent_pi.{0,2,…}` with ReLU, then `tanh(actor.mu)`;
//! - TD3: `actor.mu.{0,2,…}` with ReLU between, `tanh` after the last.
//!
//! The file's metadata key `activation` (`relu` or `tanh`) overrides the hidden layers'
//! default. The first layer's width tells the observation: 4, SafeBench's; 13,
//! [`crate::STATE_DIM`]'s `state`; 67, [`crate::KINEMATICS_DIM`]'s `kinematics` (what
//! `tadsl`'s Gymnasium environment calls `observation="state"` and `"kinematics"`). The environment's action space is `[−1, 1]²`, scaled as above.
//!
//! A SafeBench checkpoint converts from PyTorch with
//! `safetensors.torch.save_file(torch.load(f)['policy_net'], 'actor.safetensors')`; names
//! prefixed `policy_net.` (a whole checkpoint flattened) are accepted too. Weights of any
//! float type are computed in `f32`, as PyTorch does.
//!
//! Why not candle's matmul for the forward pass: on the CPU it asks for the machine's core
//! count on every call (reading `/proc` unless `RAYON_NUM_THREADS` is set), 0.2–0.3 ms a
//! step against a few µs for the 17 k multiply-adds themselves. The tests check this
//! forward pass against candle's.

use crate::{Action, EgoPolicy, EgoView, Observation, PolicyError};
use candle_core::{DType, Device, Tensor};
use std::collections::HashMap;
use std::path::Path;
use tad_ir::{Rng, SplitMix64};

/// The action's length (`ego_action_dim`).
const ACTION_DIM: usize = 2;

/// Where the actor's tensors may live in a file.
const PREFIXES: [&str; 2] = ["", "policy_net."];

/// A learned ego: SafeBench's SAC actor or an SB3 policy, deterministic.
#[derive(Clone, Debug, PartialEq)]
pub struct Learned {
    name: String,
    format: Format,
    hidden: Vec<Dense>,
    activation: Activation,
    mu: Dense,
    /// The std head, kept only to be saved again.
    std: Option<Dense>,
}

/// Whose layout a file has (the module's header).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    SafeBench,
    Sb3Ppo,
    Sb3Sac,
    Sb3Td3,
}

impl Format {
    fn of(tensors: &HashMap<String, Tensor>) -> Format {
        let has = |name: &str| tensors.contains_key(name);
        if has("action_net.weight") {
            Format::Sb3Ppo
        } else if has("actor.latent_pi.0.weight") || has("actor.mu.weight") {
            Format::Sb3Sac
        } else if has("actor.mu.0.weight") {
            Format::Sb3Td3
        } else {
            Format::SafeBench
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Format::SafeBench => "SafeBench SAC",
            Format::Sb3Ppo => "SB3 PPO",
            Format::Sb3Sac => "SB3 SAC",
            Format::Sb3Td3 => "SB3 TD3",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Activation {
    Relu,
    Tanh,
}

impl Activation {
    fn apply(self, v: f32) -> f32 {
        match self {
            Activation::Relu => v.max(0.0),
            Activation::Tanh => v.tanh(),
        }
    }
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
        let mut actor = Learned::from_bytes(&bytes, &shown)?;
        actor.name = format!("learned:{shown}");
        Ok(actor)
    }

    /// An actor from a safetensors file's bytes; `source` names them in errors and is the
    /// driver's name.
    pub fn from_bytes(bytes: &[u8], source: &str) -> Result<Learned, PolicyError> {
        let not_safetensors = |e: String| PolicyError::NotSafetensors { path: source.to_string(), message: e };
        let tensors =
            candle_core::safetensors::load_buffer(bytes, &Device::Cpu).map_err(|e| not_safetensors(e.to_string()))?;
        let (_, metadata) =
            safetensors::SafeTensors::read_metadata(bytes).map_err(|e| not_safetensors(e.to_string()))?;
        let mut actor = Learned::from_tensors(&tensors, source)?;
        match metadata.metadata().as_ref().and_then(|m| m.get("activation")).map(String::as_str) {
            None => {}
            Some("relu") => actor.activation = Activation::Relu,
            Some("tanh") => actor.activation = Activation::Tanh,
            Some(other) => {
                return Err(not_safetensors(format!("metadata `activation` is `{other}`, not `relu` or `tanh`")));
            }
        }
        actor.name = source.to_string();
        Ok(actor)
    }

    /// The actor in `tensors`; `path` names their source in errors.
    pub fn from_tensors(tensors: &HashMap<String, Tensor>, path: &str) -> Result<Learned, PolicyError> {
        let format = Format::of(tensors);
        let prefix = match format {
            Format::SafeBench => {
                PREFIXES.iter().find(|p| tensors.contains_key(&format!("{p}fc1.weight"))).copied().unwrap_or("")
            }
            _ => "",
        };
        let read = Reader { tensors, path, prefix };
        // SB3 stacks: `base.0`, `base.2`, … while they exist
        let stack = |base: &str| -> Vec<String> {
            (0..).step_by(2).map(|k| format!("{base}.{k}")).take_while(|n| read.has(&format!("{n}.weight"))).collect()
        };
        let (hidden_names, mu_name, activation) = match format {
            Format::SafeBench => {
                let names: Vec<String> = (1..)
                    .map(|k| format!("fc{k}"))
                    .enumerate()
                    .take_while(|(k, n)| *k == 0 || read.has(&format!("{n}.weight")))
                    .map(|(_, n)| n)
                    .collect();
                (names, "fc_mu".to_string(), Activation::Relu)
            }
            Format::Sb3Ppo => (stack("mlp_extractor.policy_net"), "action_net".to_string(), Activation::Tanh),
            Format::Sb3Sac => (stack("actor.latent_pi"), "actor.mu".to_string(), Activation::Relu),
            Format::Sb3Td3 => {
                let mut names = stack("actor.mu");
                let last = names.pop().unwrap_or_else(|| "actor.mu.0".to_string());
                (names, last, Activation::Relu)
            }
        };
        let first = hidden_names.first().unwrap_or(&mu_name);
        let mut width = read.inputs(first)?;
        let mut hidden = Vec::new();
        for name in &hidden_names {
            let layer = read.layer(name, 0, width)?;
            width = layer.outputs();
            hidden.push(layer);
        }
        let mu = read.layer(&mu_name, ACTION_DIM, width)?;
        let std = match format {
            Format::SafeBench => read.layer("fc_std", ACTION_DIM, width).ok(),
            _ => None,
        };
        Ok(Learned { name: "learned".to_string(), format, hidden, activation, mu, std })
    }

    /// Whose layout the actor was read from.
    pub fn format(&self) -> Format {
        self.format
    }

    /// The observation's length it reads (one [`Observation::width`]).
    pub fn inputs(&self) -> usize {
        self.hidden.first().unwrap_or(&self.mu).inputs
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
        let mut width = crate::OBS_DIM;
        for &h in hidden {
            layers.push(layer(h, width));
            width = h;
        }
        let mu = layer(ACTION_DIM, width);
        let std = layer(ACTION_DIM, width);
        Ok(Learned {
            name: "learned".to_string(),
            format: Format::SafeBench,
            hidden: layers,
            activation: Activation::Relu,
            mu,
            std: Some(std),
        })
    }

    /// The actor's tensors under SafeBench's names (unprefixed, `f32`); only a SafeBench
    /// actor is written (an SB3 policy's activation and head have no SafeBench names).
    pub fn tensors(&self) -> Result<HashMap<String, Tensor>, PolicyError> {
        if self.format != Format::SafeBench {
            let message = format!("an {} policy is not written as a SafeBench actor", self.format.as_str());
            return Err(PolicyError::Tensor { message });
        }
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

    /// The actor's deterministic action for an observation of [`Learned::inputs`] values,
    /// in `[−1, 1]²`: `tanh(mu(…))`, or for SB3's PPO the mean clipped.
    pub fn mu(&self, obs: &[f64]) -> [f32; ACTION_DIM] {
        let mut x: Vec<f32> = obs.iter().map(|&v| v as f32).collect();
        for layer in &self.hidden {
            x = layer.forward(&x).into_iter().map(|v| self.activation.apply(v)).collect();
        }
        let mu = self.mu.forward(&x);
        match self.format {
            Format::Sb3Ppo => [mu[0].clamp(-1.0, 1.0), mu[1].clamp(-1.0, 1.0)],
            _ => [mu[0].tanh(), mu[1].tanh()],
        }
    }
}

/// Reads named tensors, checking shapes and values.
struct Reader<'t> {
    tensors: &'t HashMap<String, Tensor>,
    path: &'t str,
    prefix: &'t str,
}

impl Reader<'_> {
    fn has(&self, name: &str) -> bool {
        self.tensors.contains_key(&format!("{}{name}", self.prefix))
    }

    /// The observation a first layer `name` reads: its weight's columns, which must be one
    /// observation's length.
    fn inputs(&self, name: &str) -> Result<usize, PolicyError> {
        let full = format!("{}{name}.weight", self.prefix);
        let dims = self.tensor(&full)?.dims().to_vec();
        match dims.as_slice() {
            [rows, cols] if *rows > 0 && Observation::of_inputs(*cols).is_some() => Ok(*cols),
            _ => {
                let widths: Vec<String> = Observation::ALL.iter().map(|(_, o)| format!("[n, {}]", o.width())).collect();
                Err(PolicyError::WrongShape {
                    path: self.path.to_string(),
                    name: full,
                    expected: format!("{} (the observation's length)", widths.join(" or ")),
                    found: dims,
                })
            }
        }
    }

    fn tensor(&self, full: &str) -> Result<&Tensor, PolicyError> {
        self.tensors.get(full).ok_or_else(|| {
            let mut found: Vec<String> = self.tensors.keys().cloned().collect();
            found.sort();
            found.truncate(8);
            PolicyError::MissingTensor { path: self.path.to_string(), name: full.to_string(), found }
        })
    }

    /// The values of `name`, which must be `[rows, cols]` (`rows` 0: any but 0) or `[rows]`
    /// (`cols` None).
    fn values(&self, name: &str, rows: usize, cols: Option<usize>) -> Result<Vec<f32>, PolicyError> {
        let full = format!("{}{name}", self.prefix);
        let t = self.tensor(&full)?;
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
                path: self.path.to_string(),
                name: full,
                expected,
                found: dims.to_vec(),
            });
        }
        let values = t.to_dtype(DType::F32).and_then(|t| t.flatten_all()?.to_vec1::<f32>()).map_err(tensor_error)?;
        if values.iter().any(|v| !v.is_finite()) {
            return Err(PolicyError::NonFinite { path: self.path.to_string(), name: full });
        }
        Ok(values)
    }

    /// One `nn.Linear` named `name` (`outputs` 0: any).
    fn layer(&self, name: &str, outputs: usize, inputs: usize) -> Result<Dense, PolicyError> {
        let weight = self.values(&format!("{name}.weight"), outputs, Some(inputs))?;
        let outputs = weight.len() / inputs;
        Ok(Dense { inputs, weight, bias: self.values(&format!("{name}.bias"), outputs, None)? })
    }
}

impl EgoPolicy for Learned {
    fn name(&self) -> &str {
        &self.name
    }

    fn act(&mut self, view: &EgoView) -> Action {
        let observation = Observation::of_inputs(self.inputs()).unwrap_or_default();
        Action::from_unit(self.mu(&observation.of(view)))
    }
}

fn tensor_error(e: candle_core::Error) -> PolicyError {
    PolicyError::Tensor { message: e.to_string() }
}
