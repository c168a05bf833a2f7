//! LoRA adapters in PEFT's format: a directory with `adapter_config.json` and
//! `adapter_model.safetensors`, tensors named as Hugging Face's llama names them
//! (`base_model.model.model.layers.{i}.self_attn.q_proj.lora_A.weight`, `[r, in]`, and
//! `lora_B.weight`, `[out, r]`).
//!
//! [`Adapter::save_gguf`] writes the same adapter as llama.cpp's LoRA GGUF (`llama-server
//! --lora FILE`): `general.type` `adapter`, `adapter.type` `lora`, the base model's
//! architecture, and per pair `blk.{i}.attn_q.weight.lora_a` (`[in, r]` in ggml's order,
//! PEFT's `[r, in]` data) and `….lora_b` (`[r, out]`), f32, `lora_b`'s rows in the GGUF's
//! order; the scale is folded into `lora_b` and `adapter.lora.alpha` is the rank, so
//! llama.cpp's `alpha / r` is 1 and rsLoRA's `alpha / √r` carries over.
//!
//! An adapter trained with a frozen prefix (`tadslc finetune --frozen-prefix`) learned to
//! follow those tokens as the base model reads them; their ids are kept beside PEFT's files
//! in [`BASE_PREFIX_FILE`], and the decoder reads a prompt's start that matches them without
//! the adapter, as in training. PEFT and llama.cpp do not read that file: they apply the
//! adapter throughout.
//!
//! An adapter is untrusted input: [`Adapter::load`] reads the files and checks that the
//! config and the tensors agree with each other, [`Adapter::check`] that every tensor fits
//! the model; neither panics on any file.
//!
//! Hugging Face's q and k rows are in the order its rotary embedding wants (each head's
//! first halves, then its second halves); for llama, llama.cpp's converter interleaves them
//! per head so that rope rotates adjacent pairs, which is the order of the GGUF's
//! `attn_q`/`attn_k` rows and of this crate's decoder; qwen2's GGUF keeps Hugging Face's
//! ([`crate::Arch::interleaved`]). An adapter is kept in Hugging Face's order (as it is on
//! disk); [`hf_to_gguf_rows`] and [`gguf_to_hf_rows`] convert a `lora_B` to the model's.

use std::collections::BTreeMap;
use std::path::Path;

use candle_core::{DType, Device, Tensor};

use crate::llama::Shape;

/// A projection LoRA can target, in PEFT's names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Target {
    Q,
    K,
    V,
    O,
    Gate,
    Up,
    Down,
}

impl Target {
    pub const ALL: [Target; 7] = [Target::Q, Target::K, Target::V, Target::O, Target::Gate, Target::Up, Target::Down];

    /// PEFT's module name (`q_proj`, …).
    pub fn module(self) -> &'static str {
        match self {
            Target::Q => "q_proj",
            Target::K => "k_proj",
            Target::V => "v_proj",
            Target::O => "o_proj",
            Target::Gate => "gate_proj",
            Target::Up => "up_proj",
            Target::Down => "down_proj",
        }
    }

    /// The block the module is in (`self_attn` or `mlp`).
    pub fn block(self) -> &'static str {
        match self {
            Target::Q | Target::K | Target::V | Target::O => "self_attn",
            Target::Gate | Target::Up | Target::Down => "mlp",
        }
    }

    /// Reads `q`, `q_proj`, `gate`, `gate_proj`, ….
    pub fn parse(name: &str) -> Option<Target> {
        let name = name.strip_suffix("_proj").unwrap_or(name);
        Target::ALL.into_iter().find(|t| t.module().strip_suffix("_proj") == Some(name))
    }

    /// `(in, out)` features of the projection in a model of `shape`.
    pub fn dims(self, shape: &Shape) -> (usize, usize) {
        let (q, kv) = (shape.heads * shape.head_dim, shape.kv_heads * shape.head_dim);
        match self {
            Target::Q => (shape.dim, q),
            Target::K | Target::V => (shape.dim, kv),
            Target::O => (q, shape.dim),
            Target::Gate | Target::Up => (shape.dim, shape.hidden),
            Target::Down => (shape.hidden, shape.dim),
        }
    }

    /// The projection's tensor in a GGUF (`blk.{i}.attn_q.weight`, …): llama.cpp's name,
    /// the same for llama and qwen2.
    pub fn gguf(self) -> &'static str {
        match self {
            Target::Q => "attn_q",
            Target::K => "attn_k",
            Target::V => "attn_v",
            Target::O => "attn_output",
            Target::Gate => "ffn_gate",
            Target::Up => "ffn_up",
            Target::Down => "ffn_down",
        }
    }

    /// Whether rope reads the projection's rows (their order differs between HF and GGUF).
    pub fn roped(self) -> bool {
        matches!(self, Target::Q | Target::K)
    }
}

/// The name of a LoRA tensor in PEFT's file.
pub fn tensor_name(layer: usize, target: Target, b: bool) -> String {
    format!(
        "base_model.model.model.layers.{layer}.{}.{}.lora_{}.weight",
        target.block(),
        target.module(),
        if b { "B" } else { "A" }
    )
}

fn parse_name(name: &str) -> Option<(usize, Target, bool)> {
    let rest = name.strip_prefix("base_model.model.model.layers.")?;
    let (layer, rest) = rest.split_once('.')?;
    let layer: usize = layer.parse().ok()?;
    let (block, rest) = rest.split_once('.')?;
    let (module, rest) = rest.split_once('.')?;
    let target = Target::parse(module).filter(|t| t.block() == block && t.module() == module)?;
    let b = match rest {
        "lora_A.weight" => false,
        "lora_B.weight" => true,
        _ => return None,
    };
    Some((layer, target, b))
}

/// One projection's pair: `a` is `[rank, in]`, `b` is `[out, rank]`, row-major f32, in
/// Hugging Face's row order.
#[derive(Clone, Debug, PartialEq)]
pub struct Lora {
    pub a: Vec<f32>,
    pub b: Vec<f32>,
    pub inputs: usize,
    pub outputs: usize,
}

/// A LoRA adapter: `y += scale · B (A x)` on each targeted projection of each layer.
#[derive(Clone, Debug, PartialEq)]
pub struct Adapter {
    pub rank: usize,
    pub alpha: f32,
    /// `alpha / sqrt(rank)` instead of `alpha / rank` (PEFT's `use_rslora`).
    pub rslora: bool,
    pub targets: Vec<Target>,
    pub base_model: String,
    pub layers: BTreeMap<(usize, Target), Lora>,
    /// The tokens it was trained to follow as the base model reads them (empty: none).
    pub base_prefix: Vec<u32>,
}

/// The adapter's files.
pub const CONFIG_FILE: &str = "adapter_config.json";
pub const WEIGHTS_FILE: &str = "adapter_model.safetensors";
/// The frozen prefix's token ids, `{"tokens": [...]}`; absent when there is none.
pub const BASE_PREFIX_FILE: &str = "base_prefix.json";

impl Adapter {
    pub fn scale(&self) -> f32 {
        match self.rslora {
            true => self.alpha / (self.rank as f32).sqrt(),
            false => self.alpha / self.rank as f32,
        }
    }

    /// Reads a PEFT adapter directory; checks the config, and that the tensors are the
    /// config's (every one named as PEFT names it, `A` of `rank` rows, `B` of `rank`
    /// columns, A and B in pairs, every targeted module of every layer present once).
    pub fn load(dir: &Path) -> Result<Adapter, String> {
        let config_path = dir.join(CONFIG_FILE);
        let text = std::fs::read_to_string(&config_path)
            .map_err(|e| format!("cannot read the adapter's config `{}`: {e}", config_path.display()))?;
        let config: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| format!("{}: not JSON: {e}", config_path.display()))?;
        let bad = |what: &str| format!("{}: {what}", config_path.display());
        let get = |k: &str| config.get(k).filter(|v| !v.is_null());
        match get("peft_type").and_then(|v| v.as_str()) {
            Some("LORA") => {}
            other => return Err(bad(&format!("peft_type is {other:?}, not \"LORA\""))),
        }
        let rank = get("r")
            .and_then(|v| v.as_u64())
            .filter(|r| (1..=4096).contains(r))
            .ok_or_else(|| bad("`r` is not a rank from 1 to 4096"))? as usize;
        let alpha = get("lora_alpha")
            .and_then(|v| v.as_f64())
            .filter(|a| a.is_finite())
            .ok_or_else(|| bad("`lora_alpha` is not a number"))? as f32;
        let rslora = get("use_rslora").and_then(|v| v.as_bool()).unwrap_or(false);
        if get("use_dora").and_then(|v| v.as_bool()) == Some(true) {
            return Err(bad("DoRA adapters are not supported"));
        }
        if get("fan_in_fan_out").and_then(|v| v.as_bool()) == Some(true) {
            return Err(bad("fan_in_fan_out adapters are not supported"));
        }
        if let Some(bias) = get("bias").and_then(|v| v.as_str())
            && bias != "none"
        {
            return Err(bad(&format!("bias \"{bias}\": only \"none\" is supported")));
        }
        for pattern in ["rank_pattern", "alpha_pattern"] {
            if get(pattern).and_then(|v| v.as_object()).is_some_and(|o| !o.is_empty()) {
                return Err(bad(&format!("`{pattern}` is not supported")));
            }
        }
        if get("layers_to_transform").is_some() {
            return Err(bad("`layers_to_transform` is not supported"));
        }
        let targets: Vec<Target> = match get("target_modules") {
            Some(serde_json::Value::String(s)) if s == "all-linear" => Target::ALL.to_vec(),
            Some(serde_json::Value::Array(names)) => {
                let mut out = Vec::new();
                for n in names {
                    let name = n.as_str().ok_or_else(|| bad("`target_modules` holds a non-string"))?;
                    let t = Target::parse(name)
                        .filter(|t| t.module() == name)
                        .ok_or_else(|| bad(&format!("unsupported target module `{name}` (q_proj, k_proj, v_proj, o_proj, gate_proj, up_proj, down_proj)")))?;
                    if !out.contains(&t) {
                        out.push(t);
                    }
                }
                out.sort();
                out
            }
            _ => return Err(bad("`target_modules` is not a list of module names")),
        };
        if targets.is_empty() {
            return Err(bad("`target_modules` is empty"));
        }
        let base_model = get("base_model_name_or_path").and_then(|v| v.as_str()).unwrap_or_default().to_string();

        let weights_path = dir.join(WEIGHTS_FILE);
        let bytes = std::fs::read(&weights_path)
            .map_err(|e| format!("cannot read the adapter's weights `{}`: {e}", weights_path.display()))?;
        let tensors = candle_core::safetensors::load_buffer(&bytes, &Device::Cpu)
            .map_err(|e| format!("{}: not a safetensors file: {e}", weights_path.display()))?;
        let bad = |what: String| format!("{}: {what}", weights_path.display());
        let mut halves: BTreeMap<(usize, Target), (Option<Tensor>, Option<Tensor>)> = BTreeMap::new();
        for (name, tensor) in tensors {
            let (layer, target, b) = parse_name(&name).ok_or_else(|| bad(format!("unexpected tensor `{name}`")))?;
            if !targets.contains(&target) {
                return Err(bad(format!("tensor `{name}` is for a module the config does not target")));
            }
            let dims = tensor.dims().to_vec();
            let fits =
                dims.len() == 2 && dims[0] > 0 && dims[1] > 0 && if b { dims[1] == rank } else { dims[0] == rank };
            if !fits {
                return Err(bad(format!(
                    "tensor `{name}` is {dims:?}, not {} of rank {rank}",
                    if b { "[out, r]" } else { "[r, in]" }
                )));
            }
            let entry = halves.entry((layer, target)).or_default();
            let slot = if b { &mut entry.1 } else { &mut entry.0 };
            *slot = Some(tensor);
        }
        let mut layers = BTreeMap::new();
        for ((layer, target), pair) in halves {
            let (Some(a), Some(b)) = pair else {
                return Err(bad(format!("layer {layer}'s {} has only one of lora_A and lora_B", target.module())));
            };
            let values = |t: &Tensor| -> Result<Vec<f32>, String> {
                let v: Vec<f32> = t
                    .to_dtype(DType::F32)
                    .and_then(|t| t.flatten_all())
                    .and_then(|t| t.to_vec1())
                    .map_err(|e| bad(format!("layer {layer}'s {}: {e}", target.module())))?;
                match v.iter().all(|x| x.is_finite()) {
                    true => Ok(v),
                    false => Err(bad(format!("layer {layer}'s {} holds a NaN or an infinity", target.module()))),
                }
            };
            let lora = Lora { inputs: a.dims()[1], outputs: b.dims()[0], a: values(&a)?, b: values(&b)? };
            layers.insert((layer, target), lora);
        }
        let count = layers.keys().map(|(l, _)| l + 1).max().unwrap_or(0);
        for layer in 0..count {
            for &t in &targets {
                if !layers.contains_key(&(layer, t)) {
                    return Err(bad(format!("layer {layer} has no {}", t.module())));
                }
            }
        }
        if layers.is_empty() {
            return Err(bad("no LoRA tensors".into()));
        }
        let base_prefix = read_base_prefix(&dir.join(BASE_PREFIX_FILE))?;
        Ok(Adapter { rank, alpha, rslora, targets, base_model, layers, base_prefix })
    }

    /// The number of layers the adapter covers.
    pub fn layer_count(&self) -> usize {
        self.layers.keys().map(|(l, _)| l + 1).max().unwrap_or(0)
    }

    /// Checks that the adapter fits a model of `shape`: the same number of layers, and
    /// every pair's `in` and `out` the projection's.
    pub fn check(&self, shape: &Shape) -> Result<(), String> {
        if self.layer_count() != shape.layers {
            return Err(format!("the adapter has {} layers, the model {}", self.layer_count(), shape.layers));
        }
        for (&(layer, target), lora) in &self.layers {
            let (inputs, outputs) = target.dims(shape);
            if (lora.inputs, lora.outputs) != (inputs, outputs) {
                return Err(format!(
                    "the adapter's layer {layer} {} maps {} to {} features, the model's {inputs} to {outputs}",
                    target.module(),
                    lora.inputs,
                    lora.outputs
                ));
            }
        }
        Ok(())
    }

    /// Writes the adapter in PEFT's format into `dir` (created if needed).
    pub fn save(&self, dir: &Path) -> Result<(), String> {
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
        let mut tensors = std::collections::HashMap::new();
        let tensor = |v: &[f32], rows: usize, cols: usize| {
            Tensor::from_slice(v, (rows, cols), &Device::Cpu).map_err(|e| e.to_string())
        };
        for (&(layer, target), lora) in &self.layers {
            tensors.insert(tensor_name(layer, target, false), tensor(&lora.a, self.rank, lora.inputs)?);
            tensors.insert(tensor_name(layer, target, true), tensor(&lora.b, lora.outputs, self.rank)?);
        }
        let config = serde_json::json!({
            "peft_type": "LORA",
            "task_type": "CAUSAL_LM",
            "base_model_name_or_path": self.base_model,
            "r": self.rank,
            "lora_alpha": self.alpha,
            "lora_dropout": 0.0,
            "bias": "none",
            "use_rslora": self.rslora,
            "use_dora": false,
            "fan_in_fan_out": false,
            "init_lora_weights": true,
            "inference_mode": true,
            "target_modules": self.targets.iter().map(|t| t.module()).collect::<Vec<_>>(),
        });
        let weights = dir.join(WEIGHTS_FILE);
        let partial = dir.join(format!("{WEIGHTS_FILE}.part"));
        candle_core::safetensors::save(&tensors, &partial)
            .map_err(|e| format!("cannot write `{}`: {e}", partial.display()))?;
        std::fs::rename(&partial, &weights).map_err(|e| format!("cannot write `{}`: {e}", weights.display()))?;
        let text = serde_json::to_string_pretty(&config).map_err(|e| e.to_string())?;
        std::fs::write(dir.join(CONFIG_FILE), text + "\n")
            .map_err(|e| format!("cannot write `{}`: {e}", dir.join(CONFIG_FILE).display()))?;
        let prefix = dir.join(BASE_PREFIX_FILE);
        match self.base_prefix.is_empty() {
            true => match std::fs::remove_file(&prefix) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    Err(format!("cannot remove `{}`: {e}", prefix.display()))
                }
                _ => Ok(()),
            },
            false => {
                let text = serde_json::json!({ "tokens": self.base_prefix }).to_string();
                std::fs::write(&prefix, text + "\n").map_err(|e| format!("cannot write `{}`: {e}", prefix.display()))
            }
        }
    }
}

/// The frozen prefix in `path`, or none when there is no such file.
fn read_base_prefix(path: &Path) -> Result<Vec<u32>, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("cannot read `{}`: {e}", path.display())),
    };
    let bad = || format!("{}: not {{\"tokens\": [token ids]}}", path.display());
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|_| bad())?;
    let tokens = value.get("tokens").and_then(|t| t.as_array()).ok_or_else(bad)?;
    tokens.iter().map(|t| t.as_u64().and_then(|t| u32::try_from(t).ok()).ok_or_else(bad)).collect()
}

/// The adapter's file for llama.cpp, beside PEFT's in an adapter's directory.
pub const GGUF_FILE: &str = "adapter.gguf";

impl Adapter {
    /// Writes the adapter as llama.cpp's LoRA GGUF (the module's header) for a model of
    /// `shape`, whole or not at all (a `.part` file renamed over it).
    pub fn save_gguf(&self, path: &Path, shape: &Shape) -> Result<(), String> {
        self.check(shape)?;
        let scale = self.scale();
        let mut tensors = Vec::new();
        for (&(layer, target), lora) in &self.layers {
            let name = |half: &str| format!("blk.{layer}.{}.weight.lora_{half}", target.gguf());
            let b: Vec<f32> = hf_to_gguf_rows(&lora.b, self.rank, target, shape).iter().map(|v| v * scale).collect();
            tensors.push((name("a"), [lora.inputs, self.rank], lora.a.clone()));
            tensors.push((name("b"), [self.rank, lora.outputs], b));
        }
        let metadata = [
            ("general.architecture", Meta::Text(shape.arch.name())),
            ("general.type", Meta::Text("adapter")),
            ("adapter.type", Meta::Text("lora")),
            ("adapter.lora.alpha", Meta::Float(self.rank as f32)),
            ("general.alignment", Meta::Int(GGUF_ALIGNMENT as u32)),
        ];
        let bytes = gguf_bytes(&metadata, &tensors);
        let partial = path.with_extension("gguf.part");
        std::fs::write(&partial, bytes).map_err(|e| format!("cannot write `{}`: {e}", partial.display()))?;
        std::fs::rename(&partial, path).map_err(|e| format!("cannot write `{}`: {e}", path.display()))
    }
}

/// A GGUF metadata value of the kinds an adapter needs.
enum Meta<'a> {
    Int(u32),
    Float(f32),
    Text(&'a str),
}

/// The alignment of a GGUF's tensor data (ggml's default, stated in the file too).
const GGUF_ALIGNMENT: usize = 32;

/// A GGUF version 3 file: the header, the metadata, each tensor's name, dimensions
/// (ggml's order: fastest first), type (f32) and offset, then the data, each tensor's
/// start aligned, offsets running in order.
fn gguf_bytes(metadata: &[(&str, Meta)], tensors: &[(String, [usize; 2], Vec<f32>)]) -> Vec<u8> {
    fn text(out: &mut Vec<u8>, s: &str) {
        out.extend((s.len() as u64).to_le_bytes());
        out.extend(s.as_bytes());
    }
    let pad = |n: usize| n.div_ceil(GGUF_ALIGNMENT) * GGUF_ALIGNMENT;
    let mut out = Vec::new();
    out.extend(b"GGUF");
    out.extend(3u32.to_le_bytes());
    out.extend((tensors.len() as u64).to_le_bytes());
    out.extend((metadata.len() as u64).to_le_bytes());
    for (key, value) in metadata {
        text(&mut out, key);
        match value {
            Meta::Int(v) => {
                out.extend(4u32.to_le_bytes());
                out.extend(v.to_le_bytes());
            }
            Meta::Float(v) => {
                out.extend(6u32.to_le_bytes());
                out.extend(v.to_le_bytes());
            }
            Meta::Text(v) => {
                out.extend(8u32.to_le_bytes());
                text(&mut out, v);
            }
        }
    }
    let mut offset = 0;
    for (name, dims, values) in tensors {
        text(&mut out, name);
        out.extend(2u32.to_le_bytes());
        dims.iter().for_each(|d| out.extend((*d as u64).to_le_bytes()));
        out.extend(0u32.to_le_bytes()); // GGML_TYPE_F32
        out.extend((offset as u64).to_le_bytes());
        offset += pad(values.len() * 4);
    }
    out.resize(pad(out.len()), 0);
    for (_, _, values) in tensors {
        values.iter().for_each(|v| out.extend(v.to_le_bytes()));
        out.resize(pad(out.len()), 0);
    }
    out
}

/// The GGUF row of Hugging Face's row `row` in a q or k projection with heads of
/// `head_dim`: within a head, HF's `s·half + i` is GGUF's `2i + s`.
fn gguf_row(row: usize, head_dim: usize) -> usize {
    let half = head_dim / 2;
    let (head, within) = (row / head_dim, row % head_dim);
    let (s, i) = (within / half, within % half);
    head * head_dim + 2 * i + s
}

/// `b`'s rows (`[out, cols]`) of `target` from Hugging Face's order to the GGUF's of a
/// model of `shape`: interleaved for llama's q and k, else the same.
pub fn hf_to_gguf_rows(b: &[f32], cols: usize, target: Target, shape: &Shape) -> Vec<f32> {
    match target.roped() && shape.arch.interleaved() {
        true => interleave_rows(b, cols, shape.head_dim),
        false => b.to_vec(),
    }
}

/// `b`'s rows of `target` from the GGUF's order of a model of `shape` to Hugging Face's.
pub fn gguf_to_hf_rows(b: &[f32], cols: usize, target: Target, shape: &Shape) -> Vec<f32> {
    match target.roped() && shape.arch.interleaved() {
        true => deinterleave_rows(b, cols, shape.head_dim),
        false => b.to_vec(),
    }
}

/// `b`'s rows (`[out, cols]`) from Hugging Face's order to llama.cpp's per-head
/// interleaving, for heads of `head_dim`.
pub fn interleave_rows(b: &[f32], cols: usize, head_dim: usize) -> Vec<f32> {
    let mut out = vec![0f32; b.len()];
    for (row, values) in b.chunks_exact(cols).enumerate() {
        let to = gguf_row(row, head_dim);
        out[to * cols..(to + 1) * cols].copy_from_slice(values);
    }
    out
}

/// The inverse of [`interleave_rows`].
fn deinterleave_rows(b: &[f32], cols: usize, head_dim: usize) -> Vec<f32> {
    let mut out = vec![0f32; b.len()];
    for (row, values) in out.chunks_exact_mut(cols).enumerate() {
        let from = gguf_row(row, head_dim);
        values.copy_from_slice(&b[from * cols..(from + 1) * cols]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_orders_round_trip() {
        let b: Vec<f32> = (0..16 * 3).map(|x| x as f32).collect();
        let g = interleave_rows(&b, 3, 8);
        assert_ne!(g, b);
        assert_eq!(deinterleave_rows(&g, 3, 8), b);
        // HF's row 4 (the second half's first) of head 0 is GGUF's row 1
        assert_eq!(&g[3..6], &b[12..15]);
    }

    /// A two-layer llama adapter written as llama.cpp's GGUF and read back by candle's
    /// reader: the keys llama.cpp asks for, one pair per projection with ggml's dimensions,
    /// q's `lora_b` interleaved and scaled, the others scaled only.
    #[test]
    fn the_gguf_is_llama_cpps_adapter() {
        use candle_core::quantized::gguf_file::{Content, Value};
        let shape = Shape {
            arch: crate::Arch::Llama,
            layers: 2,
            dim: 8,
            hidden: 12,
            heads: 2,
            kv_heads: 1,
            head_dim: 4,
            context: 64,
            eps: 1e-5,
            rope_base: 1e4,
        };
        let rank = 2;
        let mut layers = BTreeMap::new();
        for layer in 0..2 {
            for target in [Target::Q, Target::V] {
                let (inputs, outputs) = target.dims(&shape);
                let values = |n: usize, k: usize| (0..n).map(|i| (i + 100 * k + layer) as f32).collect::<Vec<f32>>();
                layers.insert(
                    (layer, target),
                    Lora { a: values(rank * inputs, 1), b: values(outputs * rank, 2), inputs, outputs },
                );
            }
        }
        let adapter = Adapter {
            rank,
            alpha: 8.0,
            rslora: false,
            targets: vec![Target::Q, Target::V],
            base_model: "x".into(),
            layers,
            base_prefix: Vec::new(),
        };
        let dir = std::env::temp_dir().join(format!("tad-local-gguf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(GGUF_FILE);
        adapter.save_gguf(&path, &shape).unwrap();
        let mut file = std::fs::File::open(&path).unwrap();
        let content = Content::read(&mut file).unwrap();
        let text = |k: &str| content.metadata[k].to_string().unwrap().clone();
        assert_eq!(
            (text("general.architecture"), text("general.type"), text("adapter.type")),
            ("llama".into(), "adapter".into(), "lora".into())
        );
        assert!(matches!(content.metadata["adapter.lora.alpha"], Value::F32(a) if a == rank as f32));
        assert_eq!(content.tensor_infos.len(), 8);
        let mut tensor = |name: &str| {
            let t = content.tensor(&mut file, name, &Device::Cpu).unwrap().dequantize(&Device::Cpu).unwrap();
            (t.dims().to_vec(), t.flatten_all().unwrap().to_vec1::<f32>().unwrap())
        };
        let scale = adapter.scale();
        for ((layer, target), lora) in &adapter.layers {
            let name = format!("blk.{layer}.{}.weight.lora_", target.gguf());
            assert_eq!(tensor(&format!("{name}a")), (vec![rank, lora.inputs], lora.a.clone()), "{name}a");
            let b = hf_to_gguf_rows(&lora.b, rank, *target, &shape).iter().map(|v| v * scale).collect();
            assert_eq!(tensor(&format!("{name}b")), (vec![lora.outputs, rank], b), "{name}b");
        }
        // q's rows were reordered, v's not
        let (_, q) = tensor("blk.0.attn_q.weight.lora_b");
        assert_ne!(q, adapter.layers[&(0, Target::Q)].b.iter().map(|v| v * scale).collect::<Vec<_>>());
        // a model it does not fit is refused, nothing written
        let other = Shape { layers: 3, ..shape };
        let refused = dir.join("refused.gguf");
        assert!(adapter.save_gguf(&refused, &other).is_err() && !refused.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn names_round_trip() {
        for t in Target::ALL {
            assert_eq!(parse_name(&tensor_name(7, t, true)), Some((7, t, true)));
            assert_eq!(parse_name(&tensor_name(0, t, false)), Some((0, t, false)));
        }
        assert_eq!(parse_name("base_model.model.model.layers.0.mlp.q_proj.lora_A.weight"), None);
    }
}
