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
//! written out from them; candle-nn's fused kernels have none).

use std::collections::BTreeMap;
use std::path::Path;

use candle_core::quantized::gguf_file::Content;
use candle_core::{D, DType, Device, Tensor, Var};
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

    /// Rotates the pairs of `x` (`[heads, t, head_dim]`): `(x[2i], x[2i+1])` interleaved,
    /// else `(x[i], x[i + head_dim/2])`.
    fn apply(&self, x: &Tensor) -> candle_core::Result<Tensor> {
        let (heads, t, hd) = x.dims3()?;
        // the pair's members side by side in the last dimension (interleaved), or in two halves
        let (x, axis, angles) = match self.interleaved {
            true => (x.reshape((heads, t, hd / 2, 2))?, 3, (1, t, hd / 2, 1)),
            false => (x.reshape((heads, t, 2, hd / 2))?, 2, (1, t, 1, hd / 2)),
        };
        let (x0, x1) = (x.narrow(axis, 0, 1)?, x.narrow(axis, 1, 1)?);
        let cos = self.cos.narrow(0, 0, t)?.reshape(angles)?;
        let sin = self.sin.narrow(0, 0, t)?.reshape(angles)?;
        let y0 = (x0.broadcast_mul(&cos)? - x1.broadcast_mul(&sin)?)?;
        let y1 = (x0.broadcast_mul(&sin)? + x1.broadcast_mul(&cos)?)?;
        Tensor::cat(&[y0, y1], axis)?.reshape((heads, t, hd))
    }
}

fn rms_norm(x: &Tensor, weight: &Tensor, eps: f32) -> candle_core::Result<Tensor> {
    let mean = (x.sqr()?.sum_keepdim(D::Minus1)? / x.dim(D::Minus1)? as f64)?;
    x.broadcast_div(&(mean + eps as f64)?.sqrt()?)?.broadcast_mul(weight)
}

impl Weights {
    /// `x Wᵀ (+ scale · (x Aᵀ) Bᵀ)`.
    fn linear(&self, x: &Tensor, layer: usize, t: Target, lora: Option<&LoraSet>) -> candle_core::Result<Tensor> {
        let base = x.matmul(&self.blocks[layer].proj[t as usize].t()?)?;
        match lora.and_then(|l| Some((l.pair(layer, t)?, l.scale()))) {
            Some(((a, b), scale)) => base + (x.matmul(&a.t()?)?.matmul(&b.t()?)? * scale)?,
            None => Ok(base),
        }
    }

    /// The final hidden states (after the output norm), `[t, dim]`, of `tokens` read from
    /// the first position, attending causally.
    pub fn hidden(&self, tokens: &[u32], lora: Option<&LoraSet>, rope: &Rope) -> candle_core::Result<Tensor> {
        let Shape { dim, heads, kv_heads, head_dim, eps, .. } = self.shape;
        let n = tokens.len();
        let group = heads / kv_heads;
        let device = Device::Cpu;
        let ids = Tensor::new(tokens, &device)?;
        let mut x = self.embedding.index_select(&ids, 0)?;
        let mask: Vec<f32> = (0..n * n).map(|i| if i % n > i / n { f32::NEG_INFINITY } else { 0.0 }).collect();
        let mask = Tensor::from_vec(mask, (n, n), &device)?;
        let scale = 1.0 / (head_dim as f64).sqrt();
        for (li, block) in self.blocks.iter().enumerate() {
            let h = rms_norm(&x, &block.attn_norm, eps)?;
            let split = |y: Tensor, count: usize| y.reshape((n, count, head_dim))?.transpose(0, 1)?.contiguous();
            let qkv = |k: usize, t: Target| -> candle_core::Result<Tensor> {
                let y = self.linear(&h, li, t, lora)?;
                match &block.bias {
                    Some(bias) => y.broadcast_add(&bias[k]),
                    None => Ok(y),
                }
            };
            let q = rope.apply(&split(qkv(0, Target::Q)?, heads)?)?;
            let k = rope.apply(&split(qkv(1, Target::K)?, kv_heads)?)?;
            let v = split(qkv(2, Target::V)?, kv_heads)?;
            // query heads h = kv·group + g read key/value head kv: [kv, group·t, hd]
            let q = q.reshape((kv_heads, group * n, head_dim))?;
            let scores = (q.matmul(&k.t()?)? * scale)?.reshape((heads, n, n))?.broadcast_add(&mask)?;
            let weights = candle_nn::ops::softmax(&scores, D::Minus1)?.reshape((kv_heads, group * n, n))?;
            let attn = weights.matmul(&v)?.reshape((heads, n, head_dim))?.transpose(0, 1)?.reshape((n, dim))?;
            x = (x + self.linear(&attn, li, Target::O, lora)?)?;
            let h = rms_norm(&x, &block.ffn_norm, eps)?;
            let gate = self.linear(&h, li, Target::Gate, lora)?;
            let up = self.linear(&h, li, Target::Up, lora)?;
            let mlp = self.linear(&(gate.silu()? * up)?, li, Target::Down, lora)?;
            x = (x + mlp)?;
        }
        rms_norm(&x, &self.norm, eps)
    }

    /// The logits of `hidden` rows.
    pub fn head(&self, hidden: &Tensor) -> candle_core::Result<Tensor> {
        hidden.matmul(&self.output.as_ref().unwrap_or(&self.embedding).t()?)
    }

    /// The logits after the last of `tokens`.
    pub fn logits(&self, tokens: &[u32], lora: Option<&LoraSet>) -> Result<Vec<f32>, String> {
        if tokens.is_empty() {
            return Err("no tokens".into());
        }
        let rope = Rope::new(&self.shape, tokens.len())?;
        let hidden = self.hidden(tokens, lora, &rope).map_err(err)?;
        let last = hidden.narrow(0, tokens.len() - 1, 1).map_err(err)?;
        self.head(&last).and_then(|l| l.flatten_all()).and_then(|l| l.to_vec1()).map_err(err)
    }

    /// The mean cross-entropy of predicting `tokens[from..]`, each from the tokens before
    /// it (`from` ≥ 1): the loss on the answer only.
    pub fn loss(
        &self,
        tokens: &[u32],
        from: usize,
        lora: Option<&LoraSet>,
        rope: &Rope,
    ) -> candle_core::Result<Tensor> {
        let n = tokens.len();
        if from == 0 || from >= n {
            candle_core::bail!("no answer tokens to take the loss on");
        }
        let hidden = self.hidden(tokens, lora, rope)?;
        // only the rows that predict an answer token go through the output head
        let rows = hidden.narrow(0, from - 1, n - from)?;
        let logits = self.head(&rows)?;
        let targets = Tensor::new(&tokens[from..], &Device::Cpu)?;
        candle_nn::loss::cross_entropy(&logits, &targets)
    }
}
