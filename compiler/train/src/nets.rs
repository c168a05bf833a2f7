//! The networks as candle `Var`s (for gradients), their plain `f32` copy (for acting), Adam
//! with its moments kept by name (for checkpoints), and the seeded draws (initialisation,
//! Gaussian noise). A layer is one op of candle's graph ([`Linear`]: the product, the bias
//! and ReLU, with a backward pass of its own), its products [`gemm`]'s.

use std::collections::HashMap;

use candle_core::{CpuStorage, CustomOp2, CustomOp3, D, DType, Device, Layout, Shape, Tensor, Var};
use tad_ir::{Rng, SplitMix64};

use crate::TrainError;
use crate::gemm::{self, View};

/// The action's length (SafeBench's `ego_action_dim`).
pub(crate) const ACT: usize = 2;
/// Spinning Up's (and ChatScene's) bounds on the actor's log standard deviation.
pub(crate) const LOG_STD_MIN: f32 = -20.0;
pub(crate) const LOG_STD_MAX: f32 = 2.0;

pub(crate) fn tensor_error(e: candle_core::Error) -> TrainError {
    TrainError::Tensor(e.to_string())
}

/// One `nn.Linear`: `weight` `[out, in]`, `bias` `[out]`.
#[derive(Clone, Debug)]
pub(crate) struct Layer {
    pub name: String,
    pub weight: Var,
    pub bias: Var,
}

impl Layer {
    /// PyTorch's default initialisation: weights and biases uniform in `±1/√fan_in`.
    fn random(name: &str, outputs: usize, inputs: usize, rng: &mut SplitMix64) -> Result<Layer, TrainError> {
        let bound = 1.0 / (inputs as f64).sqrt();
        let mut draw = |n: usize| -> Vec<f32> { (0..n).map(|_| ((rng.unit() * 2.0 - 1.0) * bound) as f32).collect() };
        let weight = Tensor::from_vec(draw(outputs * inputs), (outputs, inputs), &Device::Cpu).map_err(tensor_error)?;
        let bias = Tensor::from_vec(draw(outputs), outputs, &Device::Cpu).map_err(tensor_error)?;
        Ok(Layer {
            name: name.to_string(),
            weight: Var::from_tensor(&weight).map_err(tensor_error)?,
            bias: Var::from_tensor(&bias).map_err(tensor_error)?,
        })
    }

    /// `x Wᵀ + b`, with ReLU after when `relu`; `fixed`, the parameters as constants, so
    /// that a backward pass computes no gradient of theirs.
    fn forward(&self, x: &Tensor, fixed: bool, relu: bool) -> candle_core::Result<Tensor> {
        let (w, b) = (self.weight.as_tensor(), self.bias.as_tensor());
        if fixed { x.apply_op3(&w.detach(), &b.detach(), Linear { relu }) } else { x.apply_op3(w, b, Linear { relu }) }
    }

    fn outputs(&self) -> usize {
        self.bias.dims()[0]
    }
}

/// An `f32` slice of a contiguous operand.
fn contiguous<'s>(s: &'s CpuStorage, l: &Layout, what: &str) -> candle_core::Result<&'s [f32]> {
    let Some((from, to)) = l.contiguous_offsets() else { candle_core::bail!("linear: {what} must be contiguous") };
    Ok(&s.as_slice::<f32>()?[from..to])
}

/// One `nn.Linear` (`x` `[B, in]`, `W` `[out, in]`, `b` `[out]`, all `f32`), optionally
/// followed by ReLU, as one op of candle's graph: every output's sum is [`gemm`]'s chain
/// started from its bias. Its backward pass computes only what the graph tracks: no `dW`,
/// `db` for a layer held fixed, no `dx` for the batch itself; a ReLU's gradient is masked
/// by the layer's output as it is packed.
struct Linear {
    relu: bool,
}

impl CustomOp3 for Linear {
    fn name(&self) -> &'static str {
        "linear"
    }

    fn cpu_fwd(
        &self,
        s1: &CpuStorage,
        l1: &Layout,
        s2: &CpuStorage,
        l2: &Layout,
        s3: &CpuStorage,
        l3: &Layout,
    ) -> candle_core::Result<(CpuStorage, Shape)> {
        let (rows, inputs) = l1.shape().dims2()?;
        let (outputs, width) = l2.shape().dims2()?;
        if width != inputs || l3.shape().dims() != [outputs] {
            candle_core::bail!("linear: {:?} through {:?} plus {:?}", l1.shape(), l2.shape(), l3.shape())
        }
        let (x, w, b) = (contiguous(s1, l1, "the input")?, contiguous(s2, l2, "W")?, contiguous(s3, l3, "b")?);
        let mut out = Vec::with_capacity(rows * outputs);
        (0..rows).for_each(|_| out.extend_from_slice(b));
        gemm::gemm(View::rows(x, rows, inputs), View::rows(w, outputs, inputs).t(), &mut out);
        if self.relu {
            // NaN stays NaN: a diverged loss is seen as one
            out.iter_mut().for_each(|v| *v = if *v < 0.0 { 0.0 } else { *v });
        }
        Ok((CpuStorage::F32(out), Shape::from((rows, outputs))))
    }

    fn bwd(
        &self,
        x: &Tensor,
        w: &Tensor,
        b: &Tensor,
        res: &Tensor,
        grad: &Tensor,
    ) -> candle_core::Result<(Option<Tensor>, Option<Tensor>, Option<Tensor>)> {
        let grad = grad.contiguous()?;
        // through ReLU: the gradient where the output is positive (the pre-activation was)
        let grad = if self.relu { grad.apply_op2_no_bwd(res, &ReluGrad)? } else { grad };
        let of = |wrt: Wrt, other: &Tensor| grad.apply_op2_no_bwd(other, &LinearGrad(wrt));
        let dx = if x.track_op() { Some(of(Wrt::Input, w)?) } else { None };
        let dw = if w.track_op() { Some(of(Wrt::Weight, x)?) } else { None };
        let db = if b.track_op() { Some(grad.apply_op1_no_bwd(&BiasGrad)?) } else { None };
        Ok((dx, dw, db))
    }
}

#[derive(Clone, Copy)]
enum Wrt {
    Input,
    Weight,
}

/// A [`Linear`]'s gradient product from `(g, other)`, `g` the output's gradient `[B, out]`:
/// `g·W` for the input (other: `W` `[out, in]`), `gᵀ·x` for the weight (other: `x`
/// `[B, in]`).
struct LinearGrad(Wrt);

impl CustomOp2 for LinearGrad {
    fn name(&self) -> &'static str {
        "linear-grad"
    }

    fn cpu_fwd(
        &self,
        s1: &CpuStorage,
        l1: &Layout,
        s2: &CpuStorage,
        l2: &Layout,
    ) -> candle_core::Result<(CpuStorage, Shape)> {
        let (rows, outputs) = l1.shape().dims2()?;
        let (n0, n1) = l2.shape().dims2()?;
        let g = View::rows(contiguous(s1, l1, "the gradient")?, rows, outputs);
        let other = View::rows(contiguous(s2, l2, "the operand")?, n0, n1);
        let (g, shape) = match self.0 {
            Wrt::Input => (g, (rows, n1)),
            Wrt::Weight => (g.t(), (outputs, n1)),
        };
        if g.cols != other.rows {
            candle_core::bail!("linear-grad: {:?} against {:?}", l1.shape(), l2.shape())
        }
        let mut out = vec![0.0f32; shape.0 * shape.1];
        gemm::gemm(g, other, &mut out);
        Ok((CpuStorage::F32(out), Shape::from(shape)))
    }
}

/// `g` where ReLU's output `y` is positive, else 0, from `(g, y)`.
struct ReluGrad;

impl CustomOp2 for ReluGrad {
    fn name(&self) -> &'static str {
        "relu-grad"
    }

    fn cpu_fwd(
        &self,
        s1: &CpuStorage,
        l1: &Layout,
        s2: &CpuStorage,
        l2: &Layout,
    ) -> candle_core::Result<(CpuStorage, Shape)> {
        let (g, y) = (contiguous(s1, l1, "the gradient")?, contiguous(s2, l2, "the output")?);
        if g.len() != y.len() {
            candle_core::bail!("relu-grad: {:?} against {:?}", l1.shape(), l2.shape())
        }
        let out = g.iter().zip(y).map(|(g, y)| if *y > 0.0 { *g } else { 0.0 }).collect();
        Ok((CpuStorage::F32(out), l1.shape().clone()))
    }
}

/// A [`Linear`]'s bias gradient: the gradient's rows added in order from `+0`.
struct BiasGrad;

impl candle_core::CustomOp1 for BiasGrad {
    fn name(&self) -> &'static str {
        "bias-grad"
    }

    fn cpu_fwd(&self, s1: &CpuStorage, l1: &Layout) -> candle_core::Result<(CpuStorage, Shape)> {
        let (_, cols) = l1.shape().dims2()?;
        let mut sum = vec![0.0f32; cols];
        for row in contiguous(s1, l1, "the gradient")?.chunks_exact(cols) {
            sum.iter_mut().zip(row).for_each(|(s, v)| *s += v);
        }
        Ok((CpuStorage::F32(sum), Shape::from(cols)))
    }
}

/// An MLP: hidden layers `fc1 … fcN` with ReLU, then linear heads on the last hidden layer.
#[derive(Clone, Debug)]
pub(crate) struct Net {
    pub hidden: Vec<Layer>,
    pub heads: Vec<Layer>,
}

impl Net {
    pub fn random(
        inputs: usize,
        hidden: &[usize],
        heads: &[(&str, usize)],
        rng: &mut SplitMix64,
    ) -> Result<Net, TrainError> {
        if hidden.is_empty() || hidden.contains(&0) {
            return Err(TrainError::Config(format!(
                "the networks need at least one hidden layer, each of at least one unit (got {hidden:?})"
            )));
        }
        let mut layers = Vec::new();
        let mut width = inputs;
        for (k, &h) in hidden.iter().enumerate() {
            layers.push(Layer::random(&format!("fc{}", k + 1), h, width, rng)?);
            width = h;
        }
        let heads = heads.iter().map(|&(name, n)| Layer::random(name, n, width, rng)).collect::<Result<_, _>>()?;
        Ok(Net { hidden: layers, heads })
    }

    pub fn widths(&self) -> Vec<usize> {
        self.hidden.iter().map(Layer::outputs).collect()
    }

    /// Each head's output for a batch `x` `[B, inputs]`.
    pub fn forward(&self, x: &Tensor) -> candle_core::Result<Vec<Tensor>> {
        self.forward_as(x, false)
    }

    /// [`Net::forward`] as a fixed function: gradients reach `x`, not the parameters (a
    /// critic under the actor's loss, a target net).
    pub fn forward_fixed(&self, x: &Tensor) -> candle_core::Result<Vec<Tensor>> {
        self.forward_as(x, true)
    }

    fn forward_as(&self, x: &Tensor, fixed: bool) -> candle_core::Result<Vec<Tensor>> {
        let mut x = x.clone();
        for layer in &self.hidden {
            x = layer.forward(&x, fixed, true)?;
        }
        self.heads.iter().map(|h| h.forward(&x, fixed, false)).collect()
    }

    fn layers(&self) -> impl Iterator<Item = &Layer> {
        self.hidden.iter().chain(&self.heads)
    }

    /// Every parameter by name (`fc1.weight`, …), in a fixed order.
    pub fn vars(&self) -> Vec<(String, Var)> {
        self.layers()
            .flat_map(|l| {
                [(format!("{}.weight", l.name), l.weight.clone()), (format!("{}.bias", l.name), l.bias.clone())]
            })
            .collect()
    }

    /// The parameters' current values under `prefix` + their names.
    pub fn tensors(&self, prefix: &str) -> HashMap<String, Tensor> {
        self.vars().into_iter().map(|(name, var)| (format!("{prefix}{name}"), var.as_tensor().clone())).collect()
    }

    /// Set every parameter from `tensors[prefix + name]`, which must have its shape.
    pub fn set(&self, tensors: &HashMap<String, Tensor>, prefix: &str, source: &str) -> Result<(), TrainError> {
        for (name, var) in self.vars() {
            let full = format!("{prefix}{name}");
            let t = tensors.get(&full).ok_or_else(|| TrainError::Checkpoint {
                path: source.to_string(),
                message: format!("no tensor `{full}`"),
            })?;
            if t.dims() != var.dims() {
                return Err(TrainError::Checkpoint {
                    path: source.to_string(),
                    message: format!("tensor `{full}` has shape {:?}, expected {:?}", t.dims(), var.dims()),
                });
            }
            // a copy: the source may be this very variable's tensor
            let t = t.to_dtype(DType::F32).and_then(|t| t.copy()).map_err(tensor_error)?;
            var.set(&t).map_err(tensor_error)?;
        }
        Ok(())
    }

    /// A copy whose parameters are new `Var`s with the same values (a target network).
    pub fn copy(&self) -> Result<Net, TrainError> {
        let copy = |l: &Layer| -> Result<Layer, TrainError> {
            Ok(Layer {
                name: l.name.clone(),
                weight: Var::from_tensor(&l.weight.as_tensor().copy().map_err(tensor_error)?).map_err(tensor_error)?,
                bias: Var::from_tensor(&l.bias.as_tensor().copy().map_err(tensor_error)?).map_err(tensor_error)?,
            })
        };
        Ok(Net {
            hidden: self.hidden.iter().map(copy).collect::<Result<_, _>>()?,
            heads: self.heads.iter().map(copy).collect::<Result<_, _>>()?,
        })
    }

    /// `self ← polyak·self + (1 − polyak)·source`, parameter by parameter.
    /// The stochastic head (`fc_std`, the second) set to give `std` everywhere: weights
    /// 0, biases `ln std`. Nothing without one.
    pub fn constant_std(&self, std: f64) -> Result<(), TrainError> {
        let Some(head) = self.heads.get(1) else { return Ok(()) };
        let zeros = head.weight.zeros_like().map_err(tensor_error)?;
        head.weight.set(&zeros).map_err(tensor_error)?;
        let bias = (head.bias.ones_like().map_err(tensor_error)? * std.max(1e-6).ln()).map_err(tensor_error)?;
        head.bias.set(&bias).map_err(tensor_error)
    }

    /// `θ_target ← ρ·θ_target + (1 − ρ)·θ`, in one pass per parameter: the `f32` arithmetic
    /// of the `affine`s and the `+` it replaces, as [`Adam`]'s step (`polyak_is_the_tensor_expression`).
    pub fn polyak_from(&self, source: &Net, polyak: f64) -> candle_core::Result<()> {
        let (keep, take) = (polyak as f32, (1.0 - polyak) as f32);
        for ((_, target), (_, var)) in self.vars().iter().zip(source.vars()) {
            let mut next = target.as_tensor().flatten_all()?.to_vec1::<f32>()?;
            let from = var.as_tensor().flatten_all()?.to_vec1::<f32>()?;
            next.iter_mut().zip(&from).for_each(|(t, s)| *t = (*t * keep + 0.0) + (s * take + 0.0));
            target.set(&Tensor::from_vec(next, target.shape(), target.device())?)?;
        }
        Ok(())
    }
}

/// `f` of a CPU `f32` tensor's values in place (a copy only when it is not contiguous).
fn read<R>(t: &Tensor, f: impl FnOnce(&[f32]) -> R) -> candle_core::Result<R> {
    let (storage, layout) = t.storage_and_layout();
    if let (candle_core::Storage::Cpu(cpu), Some((from, to))) = (&*storage, layout.contiguous_offsets()) {
        return Ok(f(&cpu.as_slice::<f32>()?[from..to]));
    }
    drop(storage);
    Ok(f(&t.flatten_all()?.to_vec1::<f32>()?))
}

/// One layer as plain numbers, row-major `[out, in]`.
#[derive(Clone, Debug, Default)]
struct Dense {
    inputs: usize,
    weight: Vec<f32>,
    bias: Vec<f32>,
}

impl Dense {
    fn of(layer: &Layer) -> candle_core::Result<Dense> {
        Ok(Dense {
            inputs: layer.weight.dims()[1],
            weight: layer.weight.as_tensor().flatten_all()?.to_vec1::<f32>()?,
            bias: layer.bias.as_tensor().to_vec1::<f32>()?,
        })
    }

    fn forward(&self, x: &[f32], out: &mut Vec<f32>) {
        out.clear();
        let rows = self.weight.chunks_exact(self.inputs);
        out.extend(rows.zip(&self.bias).map(|(row, b)| row.iter().zip(x).map(|(w, v)| w * v).sum::<f32>() + b));
    }
}

/// The actor as plain `f32` arithmetic, for acting step by step: the same sums as
/// `tad_policy::Learned::mu`, so the deterministic action is the saved actor's.
#[derive(Clone, Debug, Default)]
pub(crate) struct PlainActor {
    hidden: Vec<Dense>,
    mu: Dense,
    /// SAC's and PPO's `fc_std`; TD3's actor has none.
    log_std: Option<Dense>,
}

impl PlainActor {
    pub fn of(actor: &Net) -> Result<PlainActor, TrainError> {
        let dense = |l: &Layer| Dense::of(l).map_err(tensor_error);
        Ok(PlainActor {
            hidden: actor.hidden.iter().map(dense).collect::<Result<_, _>>()?,
            mu: dense(&actor.heads[0])?,
            log_std: actor.heads.get(1).map(dense).transpose()?,
        })
    }

    /// `(mu, log_std)` before squashing (log_std clamped).
    /// `mu` and the clamped log standard deviation (0 without an `fc_std` head).
    pub fn heads(&self, obs: &[f64]) -> ([f32; ACT], [f32; ACT]) {
        let mut x: Vec<f32> = obs.iter().map(|&v| v as f32).collect();
        let mut y = Vec::new();
        for layer in &self.hidden {
            layer.forward(&x, &mut y);
            x.clear();
            x.extend(y.iter().map(|v| v.max(0.0)));
        }
        self.mu.forward(&x, &mut y);
        let mu = [y[0], y[1]];
        let Some(log_std) = &self.log_std else { return (mu, [0.0; ACT]) };
        log_std.forward(&x, &mut y);
        let ls = [y[0].clamp(LOG_STD_MIN, LOG_STD_MAX), y[1].clamp(LOG_STD_MIN, LOG_STD_MAX)];
        (mu, ls)
    }
}

/// A standard normal pair by Box–Muller from two uniform draws.
pub(crate) fn normal_pair(rng: &mut SplitMix64) -> [f64; 2] {
    let u1 = 1.0 - rng.unit(); // (0, 1]
    let u2 = rng.unit();
    let r = (-2.0 * u1.ln()).sqrt();
    let a = 2.0 * std::f64::consts::PI * u2;
    [r * a.cos(), r * a.sin()]
}

/// `n` standard normal draws as `f32`.
pub(crate) fn normals(rng: &mut SplitMix64, n: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(n + 1);
    while out.len() < n {
        let [a, b] = normal_pair(rng);
        out.push(a as f32);
        out.push(b as f32);
    }
    out.truncate(n);
    out
}

/// The squashed Gaussian policy on a batch `obs` `[B, 4]` with noise `eps` `[B, 2]`:
/// the action `tanh(mu + σ·ε)` and its log-density with the tanh correction
/// (`log N(u) − Σ log(1 − tanh²u)`, the latter as `2(log 2 − u − softplus(−2u))`), `[B, 1]`.
pub(crate) fn sample_actions(actor: &Net, obs: &Tensor, eps: &Tensor) -> candle_core::Result<(Tensor, Tensor)> {
    let heads = actor.forward(obs)?;
    let (mu, log_std) = (&heads[0], heads[1].clamp(LOG_STD_MIN, LOG_STD_MAX)?);
    let u = (mu + (log_std.exp()? * eps)?)?;
    let action = u.tanh()?;
    let half_log_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
    // log N(u; mu, σ) with u − mu = σ·ε: −ε²/2 − log σ − ½ log 2π
    let gauss = ((eps.sqr()?.affine(-0.5, -half_log_2pi))? - &log_std)?;
    let minus_2u = u.affine(-2.0, 0.0)?;
    let softplus = (minus_2u.relu()? + (minus_2u.abs()?.neg()?.exp()? + 1.0)?.log()?)?;
    let correction = ((u.neg()? + std::f64::consts::LN_2)? - softplus)?.affine(2.0, 0.0)?;
    let logp = (gauss - correction)?.sum_keepdim(D::Minus1)?;
    Ok((action, logp))
}

/// The smaller of two critics' values of `(obs, action)`, and each, `[B, 1]`.
/// The Gaussian log-density of pre-tanh samples `u` under the actor at `obs`, summed over
/// the action (PPO's ratio: the tanh correction depends on `u` alone and cancels).
pub(crate) fn gaussian_log_prob(actor: &Net, obs: &Tensor, u: &Tensor) -> candle_core::Result<Tensor> {
    let heads = actor.forward(obs)?;
    let (mu, log_std) = (&heads[0], heads[1].clamp(LOG_STD_MIN, LOG_STD_MAX)?);
    let z = ((u - mu)? / log_std.exp()?)?;
    let half_log_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
    (z.sqr()?.affine(-0.5, -half_log_2pi)? - log_std)?.sum_keepdim(D::Minus1)
}

/// The deterministic action `tanh(mu(obs))`.
pub(crate) fn deterministic(actor: &Net, obs: &Tensor) -> candle_core::Result<Tensor> {
    actor.forward(obs)?[0].tanh()
}

pub(crate) fn q_values(q1: &Net, q2: &Net, obs: &Tensor, action: &Tensor) -> candle_core::Result<(Tensor, Tensor)> {
    let x = Tensor::cat(&[obs, action], 1)?;
    let a = q1.forward(&x)?.remove(0);
    let b = q2.forward(&x)?.remove(0);
    Ok((a, b))
}

/// `Q(obs, action)` of a critic held fixed ([`Net::forward_fixed`]).
pub(crate) fn q_fixed(q: &Net, obs: &Tensor, action: &Tensor) -> candle_core::Result<Tensor> {
    Ok(q.forward_fixed(&Tensor::cat(&[obs, action], 1)?)?.remove(0))
}

/// Adam (PyTorch's, bias-corrected, no weight decay) with its moments kept by name, so a
/// checkpoint holds them: candle-nn's optimizers keep theirs private.
///
/// A step is one pass over each parameter's elements instead of a dozen tensor operations
/// (each a new tensor): the same `f32` arithmetic in the same order, so the same bits, as
/// `candle`'s `affine` (`x · a + b`, `a` and `b` rounded to `f32`), `sqr`, `sqrt` and the
/// element-wise `+`, `−`, `/` that wrote it before (`fused_adam_is_the_tensor_expression`).
pub(crate) struct Adam {
    pub vars: Vec<(String, Var)>,
    m: Vec<Vec<f32>>,
    v: Vec<Vec<f32>>,
    pub step: u64,
    pub lr: f64,
}

impl Adam {
    const BETA1: f64 = 0.9;
    const BETA2: f64 = 0.999;
    const EPS: f64 = 1e-8;

    pub fn new(vars: Vec<(String, Var)>, lr: f64) -> Result<Adam, TrainError> {
        let m: Vec<Vec<f32>> = vars.iter().map(|(_, v)| vec![0.0; v.elem_count()]).collect();
        let v = m.clone();
        Ok(Adam { vars, m, v, step: 0, lr })
    }

    /// One step from the gradients of `loss` (those of other parameters are ignored).
    pub fn minimise(&mut self, loss: &Tensor) -> candle_core::Result<()> {
        let grads = loss.backward()?;
        self.step += 1;
        let step = i32::try_from(self.step).unwrap_or(i32::MAX);
        let k = Step::new(self.lr, step);
        for (i, (_, theta)) in self.vars.iter().enumerate() {
            let Some(g) = grads.get(theta.as_tensor()) else { continue };
            let mut values = read(theta.as_tensor(), <[f32]>::to_vec)?;
            read(g, |g| k.apply(&mut values, &mut self.m[i], &mut self.v[i], g))?;
            theta.set(&Tensor::from_vec(values, theta.shape(), theta.device())?)?;
        }
        Ok(())
    }
    /// The moments as `{prefix}{name}.m` / `.v`.
    pub fn tensors(&self, prefix: &str, into: &mut HashMap<String, Tensor>) {
        for (i, (name, var)) in self.vars.iter().enumerate() {
            for (suffix, moment) in [("m", &self.m[i]), ("v", &self.v[i])] {
                if let Ok(t) = Tensor::from_slice(moment, var.shape(), var.device()) {
                    into.insert(format!("{prefix}{name}.{suffix}"), t);
                }
            }
        }
    }

    pub fn set(&mut self, tensors: &HashMap<String, Tensor>, prefix: &str, source: &str) -> Result<(), TrainError> {
        for (i, (name, var)) in self.vars.iter().enumerate() {
            for (suffix, slot) in [("m", &mut self.m[i]), ("v", &mut self.v[i])] {
                let full = format!("{prefix}{name}.{suffix}");
                let t = tensors.get(&full).filter(|t| t.dims() == var.dims()).ok_or_else(|| {
                    TrainError::Checkpoint { path: source.to_string(), message: format!("no fitting moment `{full}`") }
                })?;
                *slot = t.to_dtype(DType::F32).and_then(|t| t.flatten_all()?.to_vec1()).map_err(tensor_error)?;
            }
        }
        Ok(())
    }
}

/// One Adam step's coefficients, each rounded to `f32` where `candle`'s `affine` rounds it.
struct Step {
    beta1: f32,
    rest1: f32,
    beta2: f32,
    rest2: f32,
    scale_m: f32,
    scale_v: f32,
    eps: f32,
    lr: f32,
}

impl Step {
    fn new(lr: f64, step: i32) -> Step {
        Step {
            beta1: Adam::BETA1 as f32,
            rest1: (1.0 - Adam::BETA1) as f32,
            beta2: Adam::BETA2 as f32,
            rest2: (1.0 - Adam::BETA2) as f32,
            scale_m: (1.0 / (1.0 - Adam::BETA1.powi(step))) as f32,
            scale_v: (1.0 / (1.0 - Adam::BETA2.powi(step))) as f32,
            eps: Adam::EPS as f32,
            lr: lr as f32,
        }
    }

    /// `theta`, `m` and `v` after the step with gradient `g`. Each `· a + 0` and `· 1 + b`
    /// is kept as written: they are what the tensor operations computed (`−0 + 0` is `+0`).
    fn apply(&self, theta: &mut [f32], m: &mut [f32], v: &mut [f32], g: &[f32]) {
        let Step { beta1, rest1, beta2, rest2, scale_m, scale_v, eps, lr } = *self;
        for (((theta, m), v), &g) in theta.iter_mut().zip(m.iter_mut()).zip(v.iter_mut()).zip(g) {
            *m = (*m * beta1 + 0.0) + (g * rest1 + 0.0);
            *v = (*v * beta2 + 0.0) + ((g * g) * rest2 + 0.0);
            let adjusted = (*m * scale_m + 0.0) / ((*v * scale_v + 0.0).sqrt() * 1.0 + eps);
            *theta -= adjusted * lr + 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::Device;

    /// The step as the tensor operations wrote it before [`Step`] fused them.
    fn tensor_step(
        theta: &Tensor,
        m: &Tensor,
        v: &Tensor,
        g: &Tensor,
        lr: f64,
        step: i32,
    ) -> candle_core::Result<(Tensor, Tensor, Tensor)> {
        let scale_m = 1.0 / (1.0 - Adam::BETA1.powi(step));
        let scale_v = 1.0 / (1.0 - Adam::BETA2.powi(step));
        let m = ((m * Adam::BETA1)? + (g * (1.0 - Adam::BETA1))?)?;
        let v = ((v * Adam::BETA2)? + (g.sqr()? * (1.0 - Adam::BETA2))?)?;
        let adjusted = ((&m * scale_m)? / ((&v * scale_v)?.sqrt()? + Adam::EPS)?)?;
        Ok(((theta - (adjusted * lr)?)?, m, v))
    }

    /// `relu(x Wᵀ + b)`'s value and gradients, as candle's own operations write it
    /// (close, not equal: candle's matmul sums in another order), and a fixed layer's
    /// backward pass gives no gradient of its parameters.
    #[test]
    fn linear_is_candles_expression() {
        let mut rng = SplitMix64::new(3);
        let device = Device::Cpu;
        let (rows, cols, inputs) = (37, 19, 5);
        let mut values = |n: usize| -> Vec<f32> { (0..n).map(|_| (rng.unit() as f32 - 0.5) * 4.0).collect() };
        let x = Var::from_vec(values(rows * inputs), (rows, inputs), &device).unwrap();
        let w = Var::from_vec(values(cols * inputs), (cols, inputs), &device).unwrap();
        let b = Var::from_vec(values(cols), cols, &device).unwrap();
        let scale = Tensor::from_vec(values(rows * cols), (rows, cols), &device).unwrap();
        let run = |ours: bool, relu: bool| {
            let (xt, wt, bt) = (x.as_tensor(), w.as_tensor(), b.as_tensor());
            let y = if ours {
                xt.apply_op3(wt, bt, Linear { relu }).unwrap()
            } else {
                let y = xt.matmul(&wt.t().unwrap()).unwrap().broadcast_add(bt).unwrap();
                if relu { y.relu().unwrap() } else { y }
            };
            let grads = (&y * &scale).unwrap().sum_all().unwrap().backward().unwrap();
            let flat = |t: &Tensor| t.flatten_all().unwrap().to_vec1::<f32>().unwrap();
            [flat(&y), flat(grads.get(xt).unwrap()), flat(grads.get(wt).unwrap()), flat(grads.get(bt).unwrap())]
        };
        for relu in [false, true] {
            for (i, (ours, theirs)) in run(true, relu).iter().zip(run(false, relu)).enumerate() {
                for (a, b) in ours.iter().zip(&theirs) {
                    assert!((a - b).abs() <= 1e-4 * (1.0 + b.abs()), "part {i}, relu {relu}: {a} against {b}");
                }
            }
        }
        let fixed = x.as_tensor().apply_op3(&w.as_tensor().detach(), &b.as_tensor().detach(), Linear { relu: true });
        let grads = (fixed.unwrap() * &scale).unwrap().sum_all().unwrap().backward().unwrap();
        assert!(grads.get(x.as_tensor()).is_some());
        assert!(grads.get(w.as_tensor()).is_none() && grads.get(b.as_tensor()).is_none());
    }

    #[test]
    fn polyak_is_the_tensor_expression() {
        let mut rng = SplitMix64::new(11);
        let mut net = || Net::random(7, &[16, 16], &[("q", 1)], &mut rng).unwrap();
        let (target, source) = (net(), net());
        let before: Vec<Tensor> = target.vars().iter().map(|(_, v)| v.as_tensor().copy().unwrap()).collect();
        target.polyak_from(&source, 0.995).unwrap();
        for ((t, (_, s)), (name, fused)) in before.iter().zip(source.vars()).zip(target.vars()) {
            let expected = (t.affine(0.995, 0.0).unwrap() + s.as_tensor().affine(1.0 - 0.995, 0.0).unwrap()).unwrap();
            let bits = |t: &Tensor| -> Vec<u32> {
                t.flatten_all().unwrap().to_vec1::<f32>().unwrap().iter().map(|v| v.to_bits()).collect()
            };
            assert_eq!(bits(fused.as_tensor()), bits(&expected), "{name}");
        }
    }

    #[test]
    fn fused_adam_is_the_tensor_expression() {
        let mut rng = SplitMix64::new(7);
        let mut draw = |scale: f32| (rng.unit() as f32 - 0.5) * scale;
        let n = 4096;
        let mut theta: Vec<f32> = (0..n).map(|_| draw(2.0)).collect();
        // zeros of both signs, tiny and huge gradients
        theta[..4].copy_from_slice(&[0.0, -0.0, 1e-30, -1e30]);
        let (mut m, mut v) = (vec![0.0f32; n], vec![0.0f32; n]);
        let device = Device::Cpu;
        let as_tensor = |x: &[f32]| Tensor::from_slice(x, n, &device).unwrap();
        let (mut tt, mut tm, mut tv) = (as_tensor(&theta), as_tensor(&m), as_tensor(&v));
        for step in 1..=30 {
            let mut g: Vec<f32> = (0..n).map(|_| draw(if step % 3 == 0 { 1e-6 } else { 4.0 })).collect();
            g[..4].copy_from_slice(&[0.0, -0.0, 1e20, -1e-38]);
            let lr = if step % 2 == 0 { 3e-4 } else { 1e-3 };
            Step::new(lr, step).apply(&mut theta, &mut m, &mut v, &g);
            (tt, tm, tv) = tensor_step(&tt, &tm, &tv, &as_tensor(&g), lr, step).unwrap();
            let bits = |x: &[f32]| x.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            let tensor_bits = |t: &Tensor| bits(&t.to_vec1::<f32>().unwrap());
            assert_eq!(bits(&theta), tensor_bits(&tt), "theta at step {step}");
            assert_eq!(bits(&m), tensor_bits(&tm), "m at step {step}");
            assert_eq!(bits(&v), tensor_bits(&tv), "v at step {step}");
        }
    }
}
