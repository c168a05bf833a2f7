//! A differentiable llama or qwen2 forward pass in candle, f32 on the CPU: the base
//! weights dequantized from the GGUF as plain tensors (frozen: no gradient is kept for
//! them), the LoRA pairs as `Var`s in a [`VarMap`]. qwen2 adds biases to q, k and v.
//!
//! The weights stay in the GGUF's layout. For llama, q and k rows are interleaved per head
//! and rope rotates adjacent pairs, as candle's `quantized_llama` and tad-local's decoder
//! do; the LoRA `B` of q and k is then in the GGUF's row order while training, and
//! converted to Hugging Face's (PEFT's) when written and back when read
//! ([`tad_local::hf_to_gguf_rows`]). qwen2's GGUF keeps Hugging Face's order and rope
//! rotates each head's halves.
//! Only candle operations with a backward pass are used (rope, RMSNorm and softmax are
//! written out from them; candle-nn's fused kernels have none), and one of this crate's:
//! the frozen weights' product, whose backward pass computes no weight gradient.
//! [`Weights::loss_recomputed`] keeps one layer's graph at a time and recomputes each
//! layer in the backward pass.

use std::collections::BTreeMap;
use std::path::Path;

use candle_core::backprop::GradStore;
use candle_core::quantized::gguf_file::Content;
use candle_core::{CpuStorage, CustomOp1, D, DType, Device, Layout, Tensor, Var};
use candle_nn::VarMap;
use tad_local::{Adapter, Arch, Lora, Shape, Target, gguf_to_hf_rows, hf_to_gguf_rows, tensor_name};

pub(crate) fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

use tad_base::Rng as _;
/// The seeded generator of A's initialisation and the shuffling of examples.
pub use tad_base::SplitMix64 as Rng;

/// Uniform in `[-bound, bound)`.
pub fn uniform(rng: &mut Rng, bound: f32) -> f32 {
    ((rng.unit() * 2.0 - 1.0) as f32) * bound
}

struct Block {
    attn_norm: Tensor,
    ffn_norm: Tensor,
    /// `[out, in]` per [`Target`], in the GGUF's row order.
    proj: [Tensor; 7],
    /// qwen2's biases of q, k and v.
    bias: Option<[Tensor; 3]>,
}

/// The frozen base model, f32.
pub struct Weights {
    pub shape: Shape,
    pub vocab: usize,
    embedding: Tensor,
    output: Option<Tensor>,
    norm: Tensor,
    blocks: Vec<Block>,
}

impl Weights {
    /// Dequantizes the GGUF's tensors (the llama.cpp names), each checked against the shape.
    pub fn from_gguf(content: &Content, file: &mut std::fs::File) -> Result<Weights, String> {
        let shape = Shape::from_gguf(content)?;
        let device = Device::Cpu;
        let mut load = |name: &str, dims: &[usize]| -> Result<Tensor, String> {
            let q = content.tensor(file, name, &device).map_err(|e| format!("tensor `{name}`: {e}"))?;
            let t = q.dequantize(&device).map_err(|e| format!("tensor `{name}`: {e}"))?;
            match dims.is_empty() || t.dims() == dims {
                true => Ok(t),
                false => Err(format!("tensor `{name}` is {:?}, not {dims:?}", t.dims())),
            }
        };
        let embedding = load("token_embd.weight", &[])?;
        let vocab = match embedding.dims() {
            &[v, d] if d == shape.dim && v > 0 => v,
            dims => return Err(format!("tensor `token_embd.weight` is {dims:?}, not [vocab, {}]", shape.dim)),
        };
        let output = match content.tensor_infos.contains_key("output.weight") {
            true => Some(load("output.weight", &[vocab, shape.dim])?),
            false => None,
        };
        let norm = load("output_norm.weight", &[shape.dim])?;
        let mut blocks = Vec::new();
        for i in 0..shape.layers {
            let name = |part: &str| format!("blk.{i}.{part}.weight");
            let mut proj = Vec::new();
            for (t, part) in
                Target::ALL.iter().zip(["attn_q", "attn_k", "attn_v", "attn_output", "ffn_gate", "ffn_up", "ffn_down"])
            {
                let (inputs, outputs) = t.dims(&shape);
                proj.push(load(&name(part), &[outputs, inputs])?);
            }
            let bias = match shape.arch {
                Arch::Llama => None,
                Arch::Qwen2 => {
                    let mut bias = |part: &str, t: Target| load(&format!("blk.{i}.{part}.bias"), &[t.dims(&shape).1]);
                    Some([bias("attn_q", Target::Q)?, bias("attn_k", Target::K)?, bias("attn_v", Target::V)?])
                }
            };
            blocks.push(Block {
                attn_norm: load(&name("attn_norm"), &[shape.dim])?,
                ffn_norm: load(&name("ffn_norm"), &[shape.dim])?,
                proj: proj.try_into().map_err(|_| "seven projections")?,
                bias,
            });
        }
        Ok(Weights { shape, vocab, embedding, output, norm, blocks })
    }

    /// Reads the GGUF file at `path`.
    pub fn load(path: &Path) -> Result<(Weights, Content), String> {
        let mut file = std::fs::File::open(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
        let content = Content::read(&mut file).map_err(|e| format!("{} is not a GGUF file: {e}", path.display()))?;
        Ok((Weights::from_gguf(&content, &mut file)?, content))
    }

    /// A random model of `shape` (tests): weights uniform in ±1/√in, norms 1, tied
    /// embedding; qwen2's biases uniform in ±1/2.
    pub fn random(shape: Shape, vocab: usize, seed: u64) -> Result<Weights, String> {
        let mut rng = Rng(seed);
        let device = Device::Cpu;
        let mut matrix = |rows: usize, cols: usize, bound: f32| {
            let v: Vec<f32> = (0..rows * cols).map(|_| uniform(&mut rng, bound)).collect();
            Tensor::from_vec(v, (rows, cols), &device).map_err(err)
        };
        let embedding = matrix(vocab, shape.dim, 1.0)?;
        let mut blocks = Vec::new();
        for _ in 0..shape.layers {
            let mut proj = Vec::new();
            for t in Target::ALL {
                let (inputs, outputs) = t.dims(&shape);
                proj.push(matrix(outputs, inputs, 1.0 / (inputs as f32).sqrt())?);
            }
            let bias = match shape.arch {
                Arch::Llama => None,
                Arch::Qwen2 => {
                    let mut bias =
                        |t: Target| matrix(t.dims(&shape).1, 1, 0.5).and_then(|b| b.flatten_all().map_err(err));
                    Some([bias(Target::Q)?, bias(Target::K)?, bias(Target::V)?])
                }
            };
            let ones = Tensor::ones(shape.dim, DType::F32, &device).map_err(err)?;
            blocks.push(Block {
                attn_norm: ones.clone(),
                ffn_norm: ones,
                proj: proj.try_into().map_err(|_| "seven projections")?,
                bias,
            });
        }
        let norm = Tensor::ones(shape.dim, DType::F32, &device).map_err(err)?;
        Ok(Weights { shape, vocab, embedding, output: None, norm, blocks })
    }
}

/// The LoRA pairs being trained: `A` `[r, in]`, `B` `[out, r]` (q and k rows of `B` in the
/// GGUF's order), named as PEFT names them, in a [`VarMap`].
pub struct LoraSet {
    pub rank: usize,
    pub alpha: f32,
    pub targets: Vec<Target>,
    pub vars: VarMap,
    pairs: BTreeMap<(usize, Target), (Var, Var)>,
}

impl LoraSet {
    /// `A` Kaiming-uniform as PEFT initialises it (`a = √5`: uniform in ±1/√in), seeded;
    /// `B` zero, so the adapter starts as the identity.
    pub fn new(shape: &Shape, rank: usize, alpha: f32, targets: &[Target], seed: u64) -> Result<LoraSet, String> {
        let mut rng = Rng(seed);
        let mut pairs = BTreeMap::new();
        for layer in 0..shape.layers {
            for &t in targets {
                let (inputs, outputs) = t.dims(shape);
                let bound = 1.0 / (inputs as f32).sqrt();
                let a: Vec<f32> = (0..rank * inputs).map(|_| uniform(&mut rng, bound)).collect();
                let lora = Lora { a, b: vec![0.0; outputs * rank], inputs, outputs };
                pairs.insert((layer, t), lora);
            }
        }
        LoraSet::from_pairs(rank, alpha, targets, pairs, None)
    }

    fn from_pairs(
        rank: usize,
        alpha: f32,
        targets: &[Target],
        pairs: BTreeMap<(usize, Target), Lora>,
        from_hf: Option<&Shape>,
    ) -> Result<LoraSet, String> {
        let vars = VarMap::new();
        let mut out = BTreeMap::new();
        {
            let mut data = vars.data().lock().map_err(err)?;
            for ((layer, t), lora) in pairs {
                let b = match from_hf {
                    Some(shape) => hf_to_gguf_rows(&lora.b, rank, t, shape),
                    None => lora.b,
                };
                let a = Var::from_vec(lora.a, (rank, lora.inputs), &Device::Cpu).map_err(err)?;
                let b = Var::from_vec(b, (lora.outputs, rank), &Device::Cpu).map_err(err)?;
                data.insert(tensor_name(layer, t, false), a.clone());
                data.insert(tensor_name(layer, t, true), b.clone());
                out.insert((layer, t), (a, b));
            }
        }
        let mut targets = targets.to_vec();
        targets.sort();
        targets.dedup();
        Ok(LoraSet { rank, alpha, targets, vars, pairs: out })
    }

    /// The pairs of a PEFT adapter (checked against `shape`), q and k rows of `B` in the
    /// GGUF's order.
    pub fn from_adapter(adapter: &Adapter, shape: &Shape) -> Result<LoraSet, String> {
        adapter.check(shape)?;
        if adapter.rslora {
            return Err("rank-stabilised (rsLoRA) adapters cannot be trained on".into());
        }
        LoraSet::from_pairs(adapter.rank, adapter.alpha, &adapter.targets, adapter.layers.clone(), Some(shape))
    }

    /// The adapter in PEFT's layout (q and k rows of `B` in Hugging Face's order), for the
    /// upstream model `base_model`.
    pub fn to_adapter(&self, shape: &Shape, base_model: &str) -> Result<Adapter, String> {
        let mut layers = BTreeMap::new();
        for (&(layer, t), (a, b)) in &self.pairs {
            let values = |v: &Var| -> Result<Vec<f32>, String> {
                v.as_tensor().flatten_all().and_then(|t| t.to_vec1()).map_err(err)
            };
            let a = values(a)?;
            let b = gguf_to_hf_rows(&values(b)?, self.rank, t, shape);
            let (inputs, outputs) = t.dims(shape);
            layers.insert((layer, t), Lora { a, b, inputs, outputs });
        }
        Ok(Adapter {
            rank: self.rank,
            alpha: self.alpha,
            rslora: false,
            targets: self.targets.clone(),
            base_model: base_model.to_string(),
            layers,
            base_prefix: Vec::new(),
        })
    }

    pub fn scale(&self) -> f64 {
        self.alpha as f64 / self.rank as f64
    }

    /// Every `Var` with its PEFT name, in name order.
    pub fn named(&self) -> Vec<(String, Var)> {
        let mut out: Vec<(String, Var)> = Vec::new();
        for (&(layer, t), (a, b)) in &self.pairs {
            out.push((tensor_name(layer, t, false), a.clone()));
            out.push((tensor_name(layer, t, true), b.clone()));
        }
        out.sort_by(|x, y| x.0.cmp(&y.0));
        out
    }

    /// The `Var`s of `layer`'s pairs.
    fn layer(&self, layer: usize) -> impl Iterator<Item = &Var> {
        self.pairs.iter().filter(move |((l, _), _)| *l == layer).flat_map(|(_, (a, b))| [a, b])
    }

    fn pair(&self, layer: usize, t: Target) -> Option<&(Var, Var)> {
        self.pairs.get(&(layer, t))
    }
}

/// cos and sin of each position's angle per pair, `[positions, head_dim / 2]`, and
/// which values pair up ([`Arch::interleaved`]: adjacent ones, else each head's halves).
pub struct Rope {
    cos: Tensor,
    sin: Tensor,
    interleaved: bool,
}

impl Rope {
    pub fn new(shape: &Shape, positions: usize) -> Result<Rope, String> {
        let pairs = shape.head_dim / 2;
        let (mut cos, mut sin) = (Vec::new(), Vec::new());
        for pos in 0..positions {
            for i in 0..pairs {
                let theta = 1.0 / shape.rope_base.powf((2 * i) as f32 / shape.head_dim as f32);
                let angle = pos as f32 * theta;
                cos.push(angle.cos());
                sin.push(angle.sin());
            }
        }
        let t = |v| Tensor::from_vec(v, (positions, pairs), &Device::Cpu).map_err(err);
        Ok(Rope { cos: t(cos)?, sin: t(sin)?, interleaved: shape.arch.interleaved() })
    }

    /// Rotates the pairs of `x` (`[heads, t, head_dim]`, positions from `offset`):
    /// `(x[2i], x[2i+1])` interleaved, else `(x[i], x[i + head_dim/2])`.
    fn apply(&self, x: &Tensor, offset: usize) -> candle_core::Result<Tensor> {
        let (heads, t, hd) = x.dims3()?;
        // the pair's members side by side in the last dimension (interleaved), or in two halves
        let (x, axis, angles) = match self.interleaved {
            true => (x.reshape((heads, t, hd / 2, 2))?, 3, (1, t, hd / 2, 1)),
            false => (x.reshape((heads, t, 2, hd / 2))?, 2, (1, t, 1, hd / 2)),
        };
        let (x0, x1) = (x.narrow(axis, 0, 1)?, x.narrow(axis, 1, 1)?);
        let cos = self.cos.narrow(0, offset, t)?.reshape(angles)?;
        let sin = self.sin.narrow(0, offset, t)?.reshape(angles)?;
        let y0 = (x0.broadcast_mul(&cos)? - x1.broadcast_mul(&sin)?)?;
        let y1 = (x0.broadcast_mul(&sin)? + x1.broadcast_mul(&cos)?)?;
        Tensor::cat(&[y0, y1], axis)?.reshape((heads, t, hd))
    }
}

/// The keys and values of tokens every example begins with (the system message of a
/// prompt), per layer: `[kv_heads, len, head_dim]` each, keys rotated. Held fixed while
/// training, so an example reads only its own tokens and attends to these.
pub struct Prefix {
    pub len: usize,
    layers: Vec<(Tensor, Tensor)>,
}

/// `x Wᵀ` for a frozen `W` (`[out, in]`). candle's matmul would also compute `W`'s
/// gradient in the backward pass, as large as `W` and as costly as the product itself, and
/// keep it to the end; this op's backward gives `x`'s gradient alone.
fn frozen(x: &Tensor, w: &Tensor) -> candle_core::Result<Tensor> {
    x.contiguous()?.apply_op1(Frozen(w.clone()))
}

struct Frozen(Tensor);

impl CustomOp1 for Frozen {
    fn name(&self) -> &'static str {
        "frozen-linear"
    }

    fn cpu_fwd(&self, storage: &CpuStorage, layout: &Layout) -> candle_core::Result<(CpuStorage, candle_core::Shape)> {
        let Some((start, end)) = layout.contiguous_offsets() else {
            candle_core::bail!("frozen-linear: the input is not contiguous")
        };
        let x = Tensor::from_slice(&storage.as_slice::<f32>()?[start..end], layout.shape(), &Device::Cpu)?;
        let y = x.matmul(&self.0.t()?)?;
        Ok((CpuStorage::F32(y.flatten_all()?.to_vec1()?), y.shape().clone()))
    }

    fn bwd(&self, _x: &Tensor, _y: &Tensor, grad: &Tensor) -> candle_core::Result<Option<Tensor>> {
        Ok(Some(grad.matmul(&self.0)?))
    }
}

fn rms_norm(x: &Tensor, weight: &Tensor, eps: f32) -> candle_core::Result<Tensor> {
    let mean = (x.sqr()?.sum_keepdim(D::Minus1)? / x.dim(D::Minus1)? as f64)?;
    x.broadcast_div(&(mean + eps as f64)?.sqrt()?)?.broadcast_mul(weight)
}

impl Weights {
    /// `x Wᵀ (+ scale · (x Aᵀ) Bᵀ)`.
    fn linear(&self, x: &Tensor, layer: usize, t: Target, lora: Option<&LoraSet>) -> candle_core::Result<Tensor> {
        let base = frozen(x, &self.blocks[layer].proj[t as usize])?;
        match lora.and_then(|l| Some((l.pair(layer, t)?, l.scale()))) {
            Some(((a, b), scale)) => base + (x.matmul(&a.t()?)?.matmul(&b.t()?)? * scale)?,
            None => Ok(base),
        }
    }

    /// The residual stream after the last layer (before the output norm), `[t, dim]`, of
    /// `tokens` read from the first position, attending causally.
    fn residual(
        &self,
        tokens: &[u32],
        lora: Option<&LoraSet>,
        rope: &Rope,
        prefix: Option<&Prefix>,
    ) -> candle_core::Result<Tensor> {
        let mask = causal_mask(tokens.len(), prefix.map_or(0, |p| p.len))?;
        let mut x = self.embed(tokens)?;
        for li in 0..self.blocks.len() {
            x = self.block(li, &x, lora, rope, &mask, prefix)?.0;
        }
        Ok(x)
    }

    /// The keys and values of `tokens` read from the first position, with `lora` or without
    /// (no graph is kept).
    pub fn prefix(&self, tokens: &[u32], lora: Option<&LoraSet>, rope: &Rope) -> candle_core::Result<Prefix> {
        let mask = causal_mask(tokens.len(), 0)?;
        let mut x = self.embed(tokens)?;
        let mut layers = Vec::with_capacity(self.blocks.len());
        for li in 0..self.blocks.len() {
            let (y, [k, v]) = self.block(li, &x, lora, rope, &mask, None)?;
            layers.push((k.detach(), v.detach()));
            x = y.detach();
        }
        Ok(Prefix { len: tokens.len(), layers })
    }

    /// The final hidden states (after the output norm), `[t, dim]`.
    pub fn hidden(&self, tokens: &[u32], lora: Option<&LoraSet>, rope: &Rope) -> candle_core::Result<Tensor> {
        rms_norm(&self.residual(tokens, lora, rope, None)?, &self.norm, self.shape.eps)
    }

    fn embed(&self, tokens: &[u32]) -> candle_core::Result<Tensor> {
        self.embedding.index_select(&Tensor::new(tokens, &Device::Cpu)?, 0)
    }

    /// Layer `li` applied to the residual stream `x` (`[t, dim]`) of the tokens after
    /// `prefix`, which they also attend to; and the layer's keys and values of `x`.
    fn block(
        &self,
        li: usize,
        x: &Tensor,
        lora: Option<&LoraSet>,
        rope: &Rope,
        mask: &Tensor,
        prefix: Option<&Prefix>,
    ) -> candle_core::Result<(Tensor, [Tensor; 2])> {
        let Shape { dim, heads, kv_heads, head_dim, eps, .. } = self.shape;
        let block = &self.blocks[li];
        let n = x.dim(0)?;
        let group = heads / kv_heads;
        let scale = 1.0 / (head_dim as f64).sqrt();
        let h = rms_norm(x, &block.attn_norm, eps)?;
        let split = |y: Tensor, count: usize| y.reshape((n, count, head_dim))?.transpose(0, 1)?.contiguous();
        let qkv = |k: usize, t: Target| -> candle_core::Result<Tensor> {
            let y = self.linear(&h, li, t, lora)?;
            match &block.bias {
                Some(bias) => y.broadcast_add(&bias[k]),
                None => Ok(y),
            }
        };
        let past = prefix.map_or(0, |p| p.len);
        let q = rope.apply(&split(qkv(0, Target::Q)?, heads)?, past)?;
        let k = rope.apply(&split(qkv(1, Target::K)?, kv_heads)?, past)?;
        let v = split(qkv(2, Target::V)?, kv_heads)?;
        let (keys, values) = match prefix {
            Some(p) => {
                let (pk, pv) = &p.layers[li];
                (Tensor::cat(&[pk, &k], 1)?, Tensor::cat(&[pv, &v], 1)?)
            }
            None => (k.clone(), v.clone()),
        };
        let m = past + n;
        // query heads h = kv·group + g read key/value head kv: [kv, group·t, hd]
        let q = q.reshape((kv_heads, group * n, head_dim))?;
        let scores = (q.matmul(&keys.t()?)? * scale)?.reshape((heads, n, m))?.broadcast_add(mask)?;
        let weights = candle_nn::ops::softmax(&scores, D::Minus1)?.reshape((kv_heads, group * n, m))?;
        let attn = weights.matmul(&values)?.reshape((heads, n, head_dim))?.transpose(0, 1)?.reshape((n, dim))?;
        let x = (x + self.linear(&attn, li, Target::O, lora)?)?;
        let h = rms_norm(&x, &block.ffn_norm, eps)?;
        let gate = self.linear(&h, li, Target::Gate, lora)?;
        let up = self.linear(&h, li, Target::Up, lora)?;
        let mlp = self.linear(&(gate.silu()? * up)?, li, Target::Down, lora)?;
        Ok(((x + mlp)?, [k, v]))
    }

    /// The logits of `hidden` rows.
    pub fn head(&self, hidden: &Tensor) -> candle_core::Result<Tensor> {
        frozen(hidden, self.output.as_ref().unwrap_or(&self.embedding))
    }

    /// The logits after the last of `tokens`.
    pub fn logits(&self, tokens: &[u32], lora: Option<&LoraSet>) -> Result<Vec<f32>, String> {
        self.logits_after(&[], tokens, lora)
    }

    /// The logits after `tokens`, read with `lora` after `base` read by the base model (a
    /// frozen prefix, as training reads it).
    pub fn logits_after(&self, base: &[u32], tokens: &[u32], lora: Option<&LoraSet>) -> Result<Vec<f32>, String> {
        if tokens.is_empty() {
            return Err("no tokens".into());
        }
        let rope = Rope::new(&self.shape, base.len() + tokens.len())?;
        let prefix = match base.is_empty() {
            true => None,
            false => Some(self.prefix(base, None, &rope).map_err(err)?),
        };
        let residual = self.residual(tokens, lora, &rope, prefix.as_ref()).map_err(err)?;
        let hidden = rms_norm(&residual, &self.norm, self.shape.eps).map_err(err)?;
        let last = hidden.narrow(0, tokens.len() - 1, 1).map_err(err)?;
        self.head(&last).and_then(|l| l.flatten_all()).and_then(|l| l.to_vec1()).map_err(err)
    }

    /// The mean cross-entropy of predicting `tokens[from..]`, each from the tokens before
    /// it (`from` ≥ 1) and `prefix`: the loss on the answer only.
    pub fn loss(
        &self,
        tokens: &[u32],
        from: usize,
        lora: Option<&LoraSet>,
        rope: &Rope,
        prefix: Option<&Prefix>,
    ) -> candle_core::Result<Tensor> {
        answer_tokens(tokens, from)?;
        self.answer_loss(&self.residual(tokens, lora, rope, prefix)?, tokens, from)
    }

    /// The loss of [`Weights::loss`] and its gradients in `lora`'s pairs, holding one
    /// layer's graph at a time (activation checkpointing): the forward pass keeps only each
    /// layer's input, and the backward pass recomputes each layer from it, last to first,
    /// carrying the gradient of the layer's output, at the cost of a second forward pass.
    pub fn loss_recomputed(
        &self,
        tokens: &[u32],
        from: usize,
        lora: &LoraSet,
        rope: &Rope,
        prefix: Option<&Prefix>,
    ) -> candle_core::Result<(f32, GradStore)> {
        answer_tokens(tokens, from)?;
        let mask = causal_mask(tokens.len(), prefix.map_or(0, |p| p.len))?;
        // forward: each layer's graph is dropped as soon as its output is detached
        let mut inputs = Vec::with_capacity(self.blocks.len());
        let mut x = self.embed(tokens)?;
        for li in 0..self.blocks.len() {
            let next = self.block(li, &x, Some(lora), rope, &mask, prefix)?.0.detach();
            inputs.push(x);
            x = next;
        }
        // the head, a slice of the answer's rows at a time: its logits are a vocabulary wide
        let top = Var::from_tensor(&x)?;
        let (rows, mut value) = (tokens.len() - from, 0f32);
        let mut carry = x.zeros_like()?;
        for start in (0..rows).step_by(HEAD_ROWS) {
            let len = HEAD_ROWS.min(rows - start);
            let slice = top.narrow(0, from - 1 + start, len)?;
            let targets = &tokens[from + start..from + start + len];
            let loss = (self.rows_loss(&slice, targets)? * (len as f64 / rows as f64))?;
            value += loss.to_scalar::<f32>()?;
            carry = (carry + take_grad(&mut loss.backward()?, &top)?)?;
        }
        // backward: a layer's output gradient is `carry`, so `sum(y · carry)` has its gradients
        let mut grads = GradStore::default();
        for (li, input) in inputs.into_iter().enumerate().rev() {
            // the embedding is frozen: the first layer's input needs no gradient, and as a
            // constant it spares the backward pass the products that would compute one
            let var = (li > 0).then(|| Var::from_tensor(&input)).transpose()?;
            let x = var.as_ref().map_or(&input, |v| v.as_tensor());
            let y = self.block(li, x, Some(lora), rope, &mask, prefix)?.0;
            let mut layer = (y * &carry)?.sum_all()?.backward()?;
            if let Some(var) = &var {
                carry = take_grad(&mut layer, var)?;
            }
            // only the pairs' gradients are kept: the store also holds those of constants
            // (the mask's, rope's, broadcast to the scores' size), dropped with it
            for var in lora.layer(li) {
                if let Some(g) = layer.remove(var.as_tensor()) {
                    grads.insert(var.as_tensor(), g);
                }
            }
        }
        Ok((value, grads))
    }

    /// The mean cross-entropy of `tokens[from..]` from the residual stream `x` of `tokens`.
    fn answer_loss(&self, x: &Tensor, tokens: &[u32], from: usize) -> candle_core::Result<Tensor> {
        // only the rows that predict an answer token go through the output head
        self.rows_loss(&x.narrow(0, from - 1, tokens.len() - from)?, &tokens[from..])
    }

    /// The mean cross-entropy of `targets` predicted from the residual stream's `rows`.
    fn rows_loss(&self, rows: &Tensor, targets: &[u32]) -> candle_core::Result<Tensor> {
        let logits = self.head(&rms_norm(rows, &self.norm, self.shape.eps)?)?;
        candle_nn::loss::cross_entropy(&logits, &Tensor::new(targets, &Device::Cpu)?)
    }
}

/// Answer rows the recomputed loss sends through the output head at once: 128 rows of
/// Qwen's 151,936 logits take 78 MB a copy.
const HEAD_ROWS: usize = 128;

/// Refuses a sample without answer tokens after a first one (`from` in `1..len`).
fn answer_tokens(tokens: &[u32], from: usize) -> candle_core::Result<()> {
    if from == 0 || from >= tokens.len() {
        candle_core::bail!("no answer tokens to take the loss on");
    }
    Ok(())
}

/// Removes `var`'s gradient from `grads`.
fn take_grad(grads: &mut GradStore, var: &Var) -> candle_core::Result<Tensor> {
    match grads.remove(var.as_tensor()) {
        Some(g) => Ok(g),
        None => candle_core::bail!("no gradient reached a layer's input"),
    }
}

/// `[n, past + n]`: 0 where a position may attend (the `past` positions before the first,
/// itself and those before it), −∞ after.
fn causal_mask(n: usize, past: usize) -> candle_core::Result<Tensor> {
    let m = past + n;
    let mask: Vec<f32> = (0..n * m).map(|i| if i % m > past + i / m { f32::NEG_INFINITY } else { 0.0 }).collect();
    Tensor::from_vec(mask, (n, m), &Device::Cpu)
}
