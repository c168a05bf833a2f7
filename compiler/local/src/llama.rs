//! A llama-architecture decoder over ggml's quantized blocks, written for CPU inference of
//! a small model: the weights stay as they are in the GGUF file (SmolLM2: Q4_1 layers, the
//! Q8_0 embedding that is also the output projection; Qwen2.5-Coder: Q4_K, Q6_K, Q5_0 and
//! Q8_0, [`crate::kquant`]), activations are quantized to 8 bits a block before each product
//! (blocks of 32, [`crate::quant`]; super-blocks of 256 for the K formats, [`Input`]), and
//! the KV cache is appended in place, each query head reading its group's key/value head
//! directly (no copies of the cache).
//!
//! `qwen2` is llama with biases on the query, key and value projections and the rotary
//! embedding over the two halves of each head (llama's GGUF layout rotates adjacent pairs);
//! its rope base and norm epsilon come from the file, as llama's do.
//!
//! A prompt is read in chunks of tokens: a product takes the weight rows 16 at a time, and
//! four tokens' activations against each of the 16 in turn, so the rows and the activations
//! both stay in the first-level cache and each row is read from memory once per chunk: prefill
//! is compute-bound rather than memory-bound. Decoding is the same code with a chunk of one.
//! Rows are split across `threads` workers (rayon) when there is more than one.
//!
//! candle's GGUF reader parses the file; `candle_transformers`' quantized llama is the
//! reference this module is tested against (`tests::agrees_with_candles_quantized_llama`).

use std::io::{Read, Seek, SeekFrom};
use std::ops::Range;

use candle_core::quantized::GgmlDType;
use candle_core::quantized::gguf_file::Content;

use crate::adapter::{Adapter, Target, hf_to_gguf_rows};
use crate::kquant::{self, Q4K, Q5_0, Q6K, Q8K, SUPER};
use crate::quant::{self, BLOCK, Heads, Kernels, Q4_1, Q8_0, Q8_1};

/// A weight matrix: `rows` rows of `cols` values, row after row, in blocks (`per_row` of
/// them: of 32 values, or of 256 for the K formats).
enum Matrix {
    Q4_1 { blocks: Vec<Q4_1>, rows: usize, per_row: usize },
    Q8_0 { blocks: Vec<Q8_0>, rows: usize, per_row: usize },
    Q5_0 { blocks: Vec<Q5_0>, rows: usize, per_row: usize },
    Q4K { blocks: Vec<Q4K>, rows: usize, per_row: usize },
    Q6K { blocks: Vec<Q6K>, rows: usize, per_row: usize },
}

impl Matrix {
    fn rows(&self) -> usize {
        match self {
            Matrix::Q4_1 { rows, .. }
            | Matrix::Q8_0 { rows, .. }
            | Matrix::Q5_0 { rows, .. }
            | Matrix::Q4K { rows, .. }
            | Matrix::Q6K { rows, .. } => *rows,
        }
    }

    fn bytes(&self) -> usize {
        match self {
            Matrix::Q4_1 { blocks, .. } => std::mem::size_of_val(blocks.as_slice()),
            Matrix::Q8_0 { blocks, .. } => std::mem::size_of_val(blocks.as_slice()),
            Matrix::Q5_0 { blocks, .. } => std::mem::size_of_val(blocks.as_slice()),
            Matrix::Q4K { blocks, .. } => std::mem::size_of_val(blocks.as_slice()),
            Matrix::Q6K { blocks, .. } => std::mem::size_of_val(blocks.as_slice()),
        }
    }

    fn row(&self, k: &Kernels, r: usize, x: &Input) -> f32 {
        let (blocks, supers) = (x.blocks(), x.supers());
        match self {
            Matrix::Q4_1 { blocks: w, per_row, .. } => (k.q4_1.one)(&w[r * per_row..(r + 1) * per_row], blocks),
            Matrix::Q8_0 { blocks: w, per_row, .. } => (k.q8_0)(&w[r * per_row..(r + 1) * per_row], blocks),
            Matrix::Q5_0 { blocks: w, per_row, .. } => (k.q5_0.one)(&w[r * per_row..(r + 1) * per_row], blocks),
            Matrix::Q4K { blocks: w, per_row, .. } => (k.q4_k.one)(&w[r * per_row..(r + 1) * per_row], supers),
            Matrix::Q6K { blocks: w, per_row, .. } => (k.q6_k.one)(&w[r * per_row..(r + 1) * per_row], supers),
        }
    }

    /// Row `r`'s values.
    fn dequantize_row(&self, r: usize, out: &mut Vec<f32>) {
        let r = r.min(self.rows().saturating_sub(1));
        match self {
            Matrix::Q4_1 { blocks, per_row, .. } => {
                out.clear();
                for block in &blocks[r * per_row..(r + 1) * per_row] {
                    out.extend((0..16).map(|j| block.d * (block.qs[j] & 15) as f32 + block.m));
                    out.extend((0..16).map(|j| block.d * (block.qs[j] >> 4) as f32 + block.m));
                }
            }
            Matrix::Q8_0 { blocks, per_row, .. } => {
                out.clear();
                for block in &blocks[r * per_row..(r + 1) * per_row] {
                    out.extend(block.qs.iter().map(|&q| block.d * q as f32));
                }
            }
            Matrix::Q5_0 { blocks, per_row, .. } => {
                kquant::dequantize_q5_0(&blocks[r * per_row..(r + 1) * per_row], out)
            }
            Matrix::Q4K { blocks, per_row, .. } => {
                kquant::dequantize_q4_k(&blocks[r * per_row..(r + 1) * per_row], out)
            }
            Matrix::Q6K { blocks, per_row, .. } => {
                kquant::dequantize_q6_k(&blocks[r * per_row..(r + 1) * per_row], out)
            }
        }
    }

    /// Rows `rows` against every token of the chunk, row after row
    /// (`out[(r − rows.start)·n + t]`), as [`tile`] takes them.
    fn rows_all(&self, k: &Kernels, rows: Range<usize>, x: &[Input], out: &mut Vec<f32>) {
        out.clear();
        out.resize(rows.len() * x.len(), 0.0);
        let (blocks, supers) = (Input::blocks, Input::supers);
        match self {
            Matrix::Q4_1 { blocks: w, per_row, .. } => tile(w, *per_row, rows, x, blocks, k.q4_1, out),
            Matrix::Q5_0 { blocks: w, per_row, .. } => tile(w, *per_row, rows, x, blocks, k.q5_0, out),
            Matrix::Q4K { blocks: w, per_row, .. } => tile(w, *per_row, rows, x, supers, k.q4_k, out),
            Matrix::Q6K { blocks: w, per_row, .. } => tile(w, *per_row, rows, x, supers, k.q6_k, out),
            Matrix::Q8_0 { .. } => {
                for (i, r) in rows.enumerate() {
                    for (t, xt) in x.iter().enumerate() {
                        out[i * x.len() + t] = self.row(k, r, xt);
                    }
                }
            }
        }
    }

    /// Each listed row against `x` (one token), the unlisted rows −∞; listed rows past the
    /// matrix are ignored. With a pool, workers take parts of the list.
    fn product_rows(&self, k: &Kernels, x: &Input, list: &[u32], pool: Option<&rayon::ThreadPool>) -> Vec<f32> {
        let rows = self.rows();
        let list: Vec<usize> = list.iter().map(|&r| r as usize).filter(|&r| r < rows).collect();
        let mut values = vec![0f32; list.len()];
        match pool.filter(|p| p.current_num_threads() > 1 && list.len() > 1) {
            None => values.iter_mut().zip(&list).for_each(|(v, &r)| *v = self.row(k, r, x)),
            Some(pool) => {
                let per = list.len().div_ceil(pool.current_num_threads());
                pool.scope(|s| {
                    for (part, rs) in values.chunks_mut(per).zip(list.chunks(per)) {
                        s.spawn(move |_| part.iter_mut().zip(rs).for_each(|(v, &r)| *v = self.row(k, r, x)));
                    }
                });
            }
        }
        let mut out = vec![f32::NEG_INFINITY; rows];
        for (&r, v) in list.iter().zip(values) {
            out[r] = v;
        }
        out
    }

    /// `out[t·rows + r] = row r · x[t]` for each token `t` of the chunk; each row is read
    /// once for all the chunk's tokens. With a pool, workers take ranges of rows.
    fn product(&self, k: &Kernels, x: &[Input], out: &mut [f32], pool: Option<&rayon::ThreadPool>) {
        let rows = self.rows();
        let workers = pool.map_or(1, |p| p.current_num_threads());
        let per = rows.div_ceil(workers);
        let part = |w: usize| {
            let mut part = Vec::with_capacity(per * x.len());
            let mut values = Vec::new();
            let end = rows.min((w + 1) * per);
            for start in (w * per..end).step_by(TILE) {
                self.rows_all(k, start..end.min(start + TILE), x, &mut values);
                part.extend_from_slice(&values);
            }
            part
        };
        let mut parts: Vec<Vec<f32>> = vec![Vec::new(); workers];
        match pool.filter(|_| workers > 1) {
            None => parts[0] = part(0),
            Some(pool) => pool.scope(|s| {
                for (w, out) in parts.iter_mut().enumerate() {
                    let part = &part;
                    s.spawn(move |_| *out = part(w));
                }
            }),
        }
        for (w, part) in parts.iter().enumerate() {
            for (i, row) in part.chunks_exact(x.len().max(1)).enumerate() {
                for (t, v) in row.iter().enumerate() {
                    out[t * rows + w * per + i] = *v;
                }
            }
        }
    }
}

/// One token's activations quantized for the model's formats: in blocks of 32 ([`Q8_1`]),
/// and in super-blocks of 256 for the K formats ([`Q8K`]); a form no matrix of the model
/// takes stays empty.
#[derive(Clone, Default)]
struct Input {
    blocks: Vec<Q8_1>,
    supers: Vec<Q8K>,
}

/// The activation forms a model's matrices take: blocks of 32, super-blocks of 256.
#[derive(Clone, Copy, Debug, Default)]
struct Forms {
    blocks: bool,
    supers: bool,
}

impl Forms {
    fn of<'a>(matrices: impl IntoIterator<Item = &'a Matrix>) -> Forms {
        matrices.into_iter().fold(Forms::default(), |forms, m| match m {
            Matrix::Q4K { .. } | Matrix::Q6K { .. } => Forms { supers: true, ..forms },
            Matrix::Q4_1 { .. } | Matrix::Q8_0 { .. } | Matrix::Q5_0 { .. } => Forms { blocks: true, ..forms },
        })
    }
}

impl Input {
    fn set(&mut self, x: &[f32], forms: Forms) {
        match forms.blocks {
            true => quant::quantize(x, &mut self.blocks),
            false => self.blocks.clear(),
        }
        match forms.supers {
            true => kquant::quantize_k(x, &mut self.supers),
            false => self.supers.clear(),
        }
    }

    fn blocks(&self) -> &[Q8_1] {
        &self.blocks
    }

    fn supers(&self) -> &[Q8K] {
        &self.supers
    }
}

/// The last token's final state, normalized and quantized for the output projection.
pub struct Last(Input);

/// Rows of a product computed together ([`Matrix::rows_all`]): 16 rows of a 1,536-wide Q4_K
/// matrix are 14 KiB, four tokens' activations 7 KiB.
const TILE: usize = 16;

/// The rows `rows` of `w` (`per_row` blocks each) against the tokens `x` (their activations
/// `A`), four tokens at a time against every row, the rest one by one; `out` row after row.
fn tile<B, A>(
    w: &[B],
    per_row: usize,
    rows: Range<usize>,
    x: &[Input],
    activations: fn(&Input) -> &[A],
    k: quant::FormatKernels<B, A>,
    out: &mut [f32],
) {
    let n = x.len();
    let row = |r: usize| &w[r * per_row..(r + 1) * per_row];
    let fours = n - n % 4;
    for t in (0..fours).step_by(4) {
        let xs = [0, 1, 2, 3].map(|j| activations(&x[t + j]));
        for (i, r) in rows.clone().enumerate() {
            out[i * n + t..i * n + t + 4].copy_from_slice(&(k.four)(row(r), xs));
        }
    }
    for (t, xt) in x.iter().enumerate().skip(fours) {
        let xt = activations(xt);
        for (i, r) in rows.clone().enumerate() {
            out[i * n + t] = (k.one)(row(r), xt);
        }
    }
}

struct Layer {
    attn_norm: Vec<f32>,
    q: Matrix,
    k: Matrix,
    v: Matrix,
    /// qwen2's biases of q, k and v.
    bias: Option<[Vec<f32>; 3]>,
    o: Matrix,
    ffn_norm: Vec<f32>,
    gate: Matrix,
    up: Matrix,
    down: Matrix,
}

impl Layer {
    /// The layer's weight matrices.
    fn matrices(&self) -> [&Matrix; 7] {
        [&self.q, &self.k, &self.v, &self.o, &self.gate, &self.up, &self.down]
    }
}

/// The decoder architectures read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arch {
    Llama,
    Qwen2,
}

impl Arch {
    /// Every architecture by its name in a GGUF (`general.architecture`).
    pub const ALL: [(&'static str, Arch); 2] = [("llama", Arch::Llama), ("qwen2", Arch::Qwen2)];

    /// The architecture a GGUF's `general.architecture` names.
    pub fn parse(name: &str) -> Option<Arch> {
        Arch::ALL.iter().find(|(n, _)| *n == name).map(|&(_, a)| a)
    }

    /// Its name in a GGUF.
    pub fn name(self) -> &'static str {
        Arch::ALL.iter().find(|(_, a)| *a == self).map(|&(n, _)| n).unwrap_or_default()
    }

    /// Whether the GGUF's query and key rows are llama.cpp's per-head interleaving of
    /// Hugging Face's, so that rope rotates adjacent pairs (llama). qwen2's are Hugging
    /// Face's own, and rope rotates each head's halves.
    pub fn interleaved(self) -> bool {
        self == Arch::Llama
    }
}

/// The shape of the model, from the GGUF metadata.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub arch: Arch,
    pub layers: usize,
    pub dim: usize,
    pub hidden: usize,
    pub heads: usize,
    pub kv_heads: usize,
    pub head_dim: usize,
    pub context: usize,
    pub eps: f32,
    pub rope_base: f32,
}

pub struct Model {
    pub shape: Shape,
    /// The activation forms its matrices take, so a token is quantized only into those.
    forms: Forms,
    embedding: Matrix,
    output: Option<Matrix>,
    output_norm: Vec<f32>,
    layers: Vec<Layer>,
    kernels: Kernels,
    pool: Option<rayon::ThreadPool>,
    /// cos and sin of each position's angle per pair, filled as far as used.
    rope: Vec<(f32, f32)>,
    /// A LoRA adapter's pairs per layer, indexed by [`Target`] (q and k rows in the
    /// GGUF's order), and its scale.
    lora: Option<(Vec<[Option<LoraPair>; 7]>, f32)>,
}

/// `a`: `[rank, in]`; `bt`: B transposed, `[rank, out]`, so that `B h` is `rank` row
/// additions; row-major. Eight lanes per sum and per addition let the compiler vectorize
/// (a plain sum of products is a chain of dependent additions).
struct LoraPair {
    a: Vec<f32>,
    bt: Vec<f32>,
}

impl LoraPair {
    /// `out[t] += scale · B (A x[t])` for each token of the chunk, tokens split over `pool`.
    fn add(&self, scale: f32, x: &[f32], out: &mut [f32], n: usize, pool: Option<&rayon::ThreadPool>) {
        let (inputs, outputs) = (x.len() / n, out.len() / n);
        let one = |xt: &[f32], ot: &mut [f32]| {
            for (ar, btr) in self.a.chunks_exact(inputs).zip(self.bt.chunks_exact(outputs)) {
                let h = scale * dot8(ar, xt);
                let mut os = ot.chunks_exact_mut(8);
                let mut bs = btr.chunks_exact(8);
                for (o, b) in (&mut os).zip(&mut bs) {
                    for i in 0..8 {
                        o[i] += h * b[i];
                    }
                }
                os.into_remainder().iter_mut().zip(bs.remainder()).for_each(|(o, b)| *o += h * b);
            }
        };
        match pool {
            Some(pool) if n > 1 => pool.install(|| {
                use rayon::prelude::*;
                x.par_chunks_exact(inputs).zip(out.par_chunks_exact_mut(outputs)).for_each(|(xt, ot)| one(xt, ot))
            }),
            _ => x.chunks_exact(inputs).zip(out.chunks_exact_mut(outputs)).for_each(|(xt, ot)| one(xt, ot)),
        }
    }
}

/// `a · b` in eight lanes.
fn dot8(a: &[f32], b: &[f32]) -> f32 {
    let mut lanes = [0f32; 8];
    let (mut ac, mut bc) = (a.chunks_exact(8), b.chunks_exact(8));
    for (x, y) in (&mut ac).zip(&mut bc) {
        for i in 0..8 {
            lanes[i] += x[i] * y[i];
        }
    }
    let tail: f32 = ac.remainder().iter().zip(bc.remainder()).map(|(x, y)| x * y).sum();
    lanes.iter().sum::<f32>() + tail
}

impl Shape {
    /// The shape in a llama GGUF's metadata, checked for what the decoder needs.
    pub fn from_gguf(content: &Content) -> Result<Shape, String> {
        let meta = |k: &str| content.metadata.get(k).ok_or_else(|| format!("no `{k}` in the GGUF metadata"));
        let name = meta("general.architecture")?.to_string().map_err(error)?.clone();
        let arch = Arch::parse(&name).ok_or_else(|| {
            let known = Arch::ALL.map(|(n, _)| n).join(" and ");
            format!("a `{name}` model: the architectures supported are {known}")
        })?;
        // every key is under the architecture's name
        let key = |k: &str| format!("{name}.{k}");
        let int = |k: &str| meta(&key(k)).and_then(|v| v.to_u32().map_err(error)).map(|v| v as usize);
        let float = |k: &str| meta(&key(k)).and_then(|v| v.to_f32().map_err(error));
        let dim = int("embedding_length")?;
        let heads = int("attention.head_count")?;
        let shape = Shape {
            arch,
            layers: int("block_count")?,
            dim,
            hidden: int("feed_forward_length")?,
            heads,
            kv_heads: int("attention.head_count_kv").unwrap_or(heads),
            head_dim: dim / heads.max(1),
            context: int("context_length").unwrap_or(2048),
            eps: float("attention.layer_norm_rms_epsilon").unwrap_or(1e-5),
            rope_base: float("rope.freq_base").unwrap_or(10_000.0),
        };
        if heads == 0
            || shape.kv_heads == 0
            || !heads.is_multiple_of(shape.kv_heads)
            || !dim.is_multiple_of(heads)
            || !shape.head_dim.is_multiple_of(2)
            || !dim.is_multiple_of(BLOCK)
            || !shape.hidden.is_multiple_of(BLOCK)
        {
            return Err(format!("an unsupported shape: {shape:?}"));
        }
        Ok(shape)
    }
}

/// Keys and values of the positions read so far, per layer: `[position][kv head][dim]`.
#[derive(Clone)]
/// Keys and values per layer, in half precision ([`quant::Heads`]).
pub struct Cache {
    k: Vec<Vec<u16>>,
    v: Vec<Vec<u16>>,
    pub len: usize,
}

impl Cache {
    /// A cache of `len` positions from each layer's keys and values.
    pub(crate) fn from_layers(layers: Vec<(Vec<u16>, Vec<u16>)>, len: usize) -> Cache {
        let (k, v) = layers.into_iter().unzip();
        Cache { k, v, len }
    }

    pub(crate) fn layers(&self) -> usize {
        self.k.len()
    }

    /// Halves a position takes in one layer's keys (as many in its values).
    pub(crate) fn width(&self) -> usize {
        self.k.first().map_or(0, |k| k.len() / self.len.max(1))
    }

    pub(crate) fn layers_kv(&self) -> impl Iterator<Item = (&[u16], &[u16])> {
        self.k.iter().zip(&self.v).map(|(k, v)| (k.as_slice(), v.as_slice()))
    }

    /// Forgets every position from `len` on.
    pub fn truncate(&mut self, len: usize) {
        if len >= self.len {
            return;
        }
        for (k, v) in self.k.iter_mut().zip(&mut self.v) {
            let per = k.len() / self.len.max(1);
            k.truncate(len * per);
            v.truncate(len * per);
        }
        self.len = len;
    }
}

impl Model {
    pub fn load<R: Read + Seek>(content: &Content, file: &mut R, threads: usize) -> Result<Model, String> {
        let shape = Shape::from_gguf(content)?;
        let dim = shape.dim;
        // every tensor is checked against the shape, so a malformed file is a load error
        // rather than an out-of-bounds slice later
        let (kv_dim, hidden) = (shape.kv_heads * shape.head_dim, shape.hidden);
        let embedding = matrix(content, file, "token_embd.weight", None, dim)?;
        let vocab = embedding.rows();
        let output = match content.tensor_infos.contains_key("output.weight") {
            true => Some(matrix(content, file, "output.weight", Some(vocab), dim)?),
            false => None,
        };
        let output_norm = vector(content, file, "output_norm.weight", dim)?;
        let mut layers = Vec::with_capacity(shape.layers);
        for i in 0..shape.layers {
            let name = |part: &str| format!("blk.{i}.{part}.weight");
            let mut bias = |part: &str, len: usize| vector(content, file, &format!("blk.{i}.{part}.bias"), len);
            let bias = match shape.arch {
                Arch::Qwen2 => Some([bias("attn_q", dim)?, bias("attn_k", kv_dim)?, bias("attn_v", kv_dim)?]),
                Arch::Llama => None,
            };
            layers.push(Layer {
                bias,
                attn_norm: vector(content, file, &name("attn_norm"), dim)?,
                ffn_norm: vector(content, file, &name("ffn_norm"), dim)?,
                q: matrix(content, file, &name("attn_q"), Some(dim), dim)?,
                k: matrix(content, file, &name("attn_k"), Some(kv_dim), dim)?,
                v: matrix(content, file, &name("attn_v"), Some(kv_dim), dim)?,
                o: matrix(content, file, &name("attn_output"), Some(dim), dim)?,
                gate: matrix(content, file, &name("ffn_gate"), Some(hidden), dim)?,
                up: matrix(content, file, &name("ffn_up"), Some(hidden), dim)?,
                down: matrix(content, file, &name("ffn_down"), Some(dim), hidden)?,
            });
        }
        let pool = (threads > 1)
            .then(|| rayon::ThreadPoolBuilder::new().num_threads(threads).build())
            .transpose()
            .map_err(error)?;
        let forms =
            Forms::of(layers.iter().flat_map(Layer::matrices).chain(Some(output.as_ref().unwrap_or(&embedding))));
        Ok(Model {
            shape,
            forms,
            embedding,
            output,
            output_norm,
            layers,
            kernels: Kernels::detect(),
            pool,
            rope: Vec::new(),
            lora: None,
        })
    }

    /// Applies `adapter` from now on (in f32, beside the quantized products); checked
    /// against the model's shape first.
    pub fn attach(&mut self, adapter: &Adapter) -> Result<(), String> {
        adapter.check(&self.shape)?;
        let mut layers: Vec<[Option<LoraPair>; 7]> = (0..self.shape.layers).map(|_| Default::default()).collect();
        for (&(layer, target), lora) in &adapter.layers {
            let b = hf_to_gguf_rows(&lora.b, adapter.rank, target, &self.shape);
            let bt = (0..adapter.rank).flat_map(|r| b.iter().skip(r).step_by(adapter.rank).copied()).collect();
            layers[layer][target as usize] = Some(LoraPair { a: lora.a.clone(), bt });
        }
        self.lora = Some((layers, adapter.scale()));
        Ok(())
    }

    /// The bytes the weights take in memory.
    pub fn weight_bytes(&self) -> usize {
        let layers: usize = self.layers.iter().map(|l| l.matrices().iter().map(|m| m.bytes()).sum::<usize>()).sum();
        layers + self.embedding.bytes() + self.output.as_ref().map_or(0, Matrix::bytes)
    }

    pub fn kernels(&self) -> &'static str {
        self.kernels.name
    }

    pub fn new_cache(&self) -> Cache {
        Cache { k: vec![Vec::new(); self.shape.layers], v: vec![Vec::new(); self.shape.layers], len: 0 }
    }

    fn embed(&self, token: u32, out: &mut [f32]) {
        let mut row = Vec::with_capacity(out.len());
        self.embedding.dequantize_row(token as usize, &mut row);
        out.iter_mut().zip(&row).for_each(|(o, v)| *o = *v);
    }

    fn rope_upto(&mut self, positions: usize) {
        let pairs = self.shape.head_dim / 2;
        let have = self.rope.len() / pairs.max(1);
        for pos in have..positions {
            for i in 0..pairs {
                let theta = 1.0 / self.shape.rope_base.powf((2 * i) as f32 / self.shape.head_dim as f32);
                let angle = pos as f32 * theta;
                self.rope.push((angle.cos(), angle.sin()));
            }
        }
    }

    /// Reads `tokens` after what `cache` holds and returns the logits after the last one.
    #[cfg(test)]
    pub fn forward(&mut self, tokens: &[u32], cache: &mut Cache) -> Vec<f32> {
        let last = self.read(tokens, cache);
        self.logits(&last, None)
    }

    /// Reads `tokens` after what `cache` holds and returns the last one's final state, for
    /// [`Model::logits`].
    pub fn read(&mut self, tokens: &[u32], cache: &mut Cache) -> Last {
        const CHUNK: usize = 64;
        let mut last = Last(Input::default());
        for chunk in tokens.chunks(CHUNK) {
            last = self.forward_chunk(chunk, cache);
        }
        last
    }

    /// As [`Model::read`], without the adapter (the base model's keys and values).
    pub fn read_base(&mut self, tokens: &[u32], cache: &mut Cache) -> Last {
        let lora = self.lora.take();
        let last = self.read(tokens, cache);
        self.lora = lora;
        last
    }

    /// The output projection of `last`: every token's logit, or with `only`, those of the
    /// listed tokens and −∞ for the others. A listed token's logit is the one the whole
    /// projection gives, bit for bit (its row is computed alone either way), so a grammar's
    /// allowed tokens are all a constrained step needs.
    pub fn logits(&self, last: &Last, only: Option<&[u32]>) -> Vec<f32> {
        let head = self.output.as_ref().unwrap_or(&self.embedding);
        let pool = self.pool.as_ref();
        match only {
            None => {
                let mut logits = vec![0f32; head.rows()];
                head.product(&self.kernels, std::slice::from_ref(&last.0), &mut logits, pool);
                logits
            }
            Some(tokens) => head.product_rows(&self.kernels, &last.0, tokens, pool),
        }
    }

    fn forward_chunk(&mut self, tokens: &[u32], cache: &mut Cache) -> Last {
        let Shape { dim, hidden, heads, kv_heads, head_dim, eps, .. } = self.shape;
        let n = tokens.len();
        let start = cache.len;
        self.rope_upto(start + n);
        let kv_dim = kv_heads * head_dim;
        let group = heads / kv_heads;
        let (pool, k, forms) = (self.pool.as_ref(), &self.kernels, self.forms);

        let mut x = vec![0f32; n * dim];
        for (t, &token) in tokens.iter().enumerate() {
            self.embed(token, &mut x[t * dim..(t + 1) * dim]);
        }
        let mut normed = vec![0f32; n * dim];
        let mut xq = vec![Input::default(); n];
        let (mut q, mut kk, mut vv) = (vec![0f32; n * dim], vec![0f32; n * kv_dim], vec![0f32; n * kv_dim]);
        let mut attn = vec![0f32; n * dim];
        let mut proj = vec![0f32; n * dim];
        let (mut gate, mut up) = (vec![0f32; n * hidden], vec![0f32; n * hidden]);
        let mut hq = vec![Input::default(); n];
        let mut scores = Vec::new();
        let scale = 1.0 / (head_dim as f32).sqrt();
        let pairs = head_dim / 2;

        for (li, layer) in self.layers.iter().enumerate() {
            let lora = |t: Target| self.lora.as_ref().and_then(|(l, s)| Some((l[li][t as usize].as_ref()?, *s)));
            rms_norm(&x, &layer.attn_norm, eps, dim, &mut normed);
            for (t, xt) in xq.iter_mut().enumerate() {
                xt.set(&normed[t * dim..(t + 1) * dim], forms);
            }
            layer.q.product(k, &xq, &mut q, pool);
            layer.k.product(k, &xq, &mut kk, pool);
            layer.v.product(k, &xq, &mut vv, pool);
            for (target, out) in [(Target::Q, &mut q), (Target::K, &mut kk), (Target::V, &mut vv)] {
                if let Some((pair, scale)) = lora(target) {
                    pair.add(scale, &normed, out, n, pool);
                }
            }
            if let Some(biases) = &layer.bias {
                for (out, bias) in [&mut q, &mut kk, &mut vv].into_iter().zip(biases) {
                    for row in out.chunks_exact_mut(bias.len()) {
                        row.iter_mut().zip(bias).for_each(|(o, b)| *o += b);
                    }
                }
            }
            let rotate = if self.shape.arch.interleaved() { rotate_pairs } else { rotate_halves };
            for t in 0..n {
                let angles = &self.rope[(start + t) * pairs..(start + t + 1) * pairs];
                for h in 0..heads {
                    rotate(&mut q[t * dim + h * head_dim..t * dim + (h + 1) * head_dim], angles);
                }
                for h in 0..kv_heads {
                    rotate(&mut kk[t * kv_dim + h * head_dim..t * kv_dim + (h + 1) * head_dim], angles);
                }
            }
            cache.k[li].extend(kk.iter().map(|&x| quant::f32_to_f16(x)));
            cache.v[li].extend(vv.iter().map(|&x| quant::f32_to_f16(x)));
            let (keys, values) = (&cache.k[li], &cache.v[li]);
            // the query heads of one key/value head of one token, `i = t·kv_heads + kv`,
            // causal over positions 0..=start+t (they are `group` heads one after another)
            let width = group * head_dim;
            let attend = |i: usize, out: &mut [f32], scores: &mut Vec<f32>| {
                let (t, kv) = (i / kv_heads, i % kv_heads);
                let offset = kv * head_dim;
                let cache = Heads { keys, values, stride: kv_dim, offset, dim: head_dim, positions: start + t + 1 };
                (k.attend)(&q[i * width..(i + 1) * width], &cache, scale, scores, out);
            };
            match pool {
                Some(pool) => pool.install(|| {
                    use rayon::prelude::*;
                    attn.par_chunks_mut(width)
                        .enumerate()
                        .for_each_init(Vec::new, |scores, (i, out)| attend(i, out, scores))
                }),
                None => attn.chunks_mut(width).enumerate().for_each(|(i, out)| attend(i, out, &mut scores)),
            }
            for (t, xt) in xq.iter_mut().enumerate() {
                xt.set(&attn[t * dim..(t + 1) * dim], forms);
            }
            layer.o.product(k, &xq, &mut proj, pool);
            if let Some((pair, scale)) = lora(Target::O) {
                pair.add(scale, &attn, &mut proj, n, pool);
            }
            for (a, b) in x.iter_mut().zip(&proj) {
                *a += b;
            }
            rms_norm(&x, &layer.ffn_norm, eps, dim, &mut normed);
            for (t, xt) in xq.iter_mut().enumerate() {
                xt.set(&normed[t * dim..(t + 1) * dim], forms);
            }
            layer.gate.product(k, &xq, &mut gate, pool);
            layer.up.product(k, &xq, &mut up, pool);
            if let Some((pair, scale)) = lora(Target::Gate) {
                pair.add(scale, &normed, &mut gate, n, pool);
            }
            if let Some((pair, scale)) = lora(Target::Up) {
                pair.add(scale, &normed, &mut up, n, pool);
            }
            for (g, u) in gate.iter_mut().zip(&up) {
                *g = *g / (1.0 + (-*g).exp()) * u;
            }
            for (t, ht) in hq.iter_mut().enumerate() {
                ht.set(&gate[t * hidden..(t + 1) * hidden], forms);
            }
            layer.down.product(k, &hq, &mut proj, pool);
            if let Some((pair, scale)) = lora(Target::Down) {
                pair.add(scale, &gate, &mut proj, n, pool);
            }
            for (a, b) in x.iter_mut().zip(&proj) {
                *a += b;
            }
        }
        cache.len += n;

        // only the last token's logits are needed
        let last = &x[(n - 1) * dim..];
        let mut out = vec![0f32; dim];
        rms_norm(last, &self.output_norm, eps, dim, &mut out);
        let mut last = Input::default();
        last.set(&out, forms);
        Last(last)
    }
}

fn error(what: impl std::fmt::Display) -> String {
    what.to_string()
}

/// A tensor's type, shape (outermost first) and bytes.
fn read<R: Read + Seek>(
    content: &Content,
    file: &mut R,
    name: &str,
) -> Result<(GgmlDType, Vec<usize>, Vec<u8>), String> {
    let info = content.tensor_infos.get(name).ok_or_else(|| format!("no tensor `{name}`"))?;
    let dims = info.shape.dims().to_vec();
    let count: usize = dims.iter().product();
    let size = count / info.ggml_dtype.block_size() * info.ggml_dtype.type_size();
    let mut bytes = vec![0u8; size];
    file.seek(SeekFrom::Start(content.tensor_data_offset + info.offset)).map_err(error)?;
    file.read_exact(&mut bytes).map_err(|e| format!("tensor `{name}`: {e}"))?;
    Ok((info.ggml_dtype, dims, bytes))
}

/// A matrix of `cols` columns (and `rows` rows, when given).
fn matrix<R: Read + Seek>(
    content: &Content,
    file: &mut R,
    name: &str,
    rows: Option<usize>,
    cols: usize,
) -> Result<Matrix, String> {
    let (dtype, dims, bytes) = read(content, file, name)?;
    let rows = match (dims.as_slice(), rows) {
        (&[r, c], Some(want)) if r == want && c == cols => r,
        (&[r, c], None) if r > 0 && c == cols => r,
        _ => return Err(format!("tensor `{name}` is {dims:?}, not a matrix of {cols} columns fitting the model")),
    };
    let per_row = cols / BLOCK;
    let (kper_row, whole) = (cols / SUPER, cols.is_multiple_of(SUPER));
    match dtype {
        GgmlDType::Q4_1 => Ok(Matrix::Q4_1 { blocks: quant::read_q4_1(&bytes), rows, per_row }),
        GgmlDType::Q8_0 => Ok(Matrix::Q8_0 { blocks: quant::read_q8_0(&bytes), rows, per_row }),
        GgmlDType::Q5_0 => Ok(Matrix::Q5_0 { blocks: kquant::read_q5_0(&bytes), rows, per_row }),
        GgmlDType::Q4K if whole => Ok(Matrix::Q4K { blocks: kquant::read_q4_k(&bytes), rows, per_row: kper_row }),
        GgmlDType::Q6K if whole => Ok(Matrix::Q6K { blocks: kquant::read_q6_k(&bytes), rows, per_row: kper_row }),
        other => Err(format!(
            "tensor `{name}` is {other:?} with rows of {cols}: the matrices supported are Q4_1, Q8_0, Q5_0, and \
             Q4_K and Q6_K with rows of a multiple of {SUPER}"
        )),
    }
}

fn vector<R: Read + Seek>(content: &Content, file: &mut R, name: &str, len: usize) -> Result<Vec<f32>, String> {
    let (dtype, dims, bytes) = read(content, file, name)?;
    if dtype != GgmlDType::F32 || dims != [len] {
        return Err(format!("tensor `{name}` is {dtype:?} {dims:?}, not F32 [{len}]"));
    }
    Ok(bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect())
}

fn rms_norm(x: &[f32], weight: &[f32], eps: f32, dim: usize, out: &mut [f32]) {
    for (xt, ot) in x.chunks_exact(dim).zip(out.chunks_exact_mut(dim)) {
        let mean = xt.iter().map(|v| v * v).sum::<f32>() / dim as f32;
        let inv = 1.0 / (mean + eps).sqrt();
        for ((o, v), w) in ot.iter_mut().zip(xt).zip(weight) {
            *o = v * inv * w;
        }
    }
}

/// Rotates adjacent pairs `(x[2i], x[2i+1])` by the position's angles (GGUF's llama layout).
fn rotate_pairs(x: &mut [f32], angles: &[(f32, f32)]) {
    for (pair, &(cos, sin)) in x.chunks_exact_mut(2).zip(angles) {
        let (a, b) = (pair[0], pair[1]);
        pair[0] = a * cos - b * sin;
        pair[1] = a * sin + b * cos;
    }
}

/// Rotates the pairs `(x[i], x[i + d/2])` by the position's angles (qwen2's layout, GPT-NeoX's).
fn rotate_halves(x: &mut [f32], angles: &[(f32, f32)]) {
    let (first, second) = x.split_at_mut(x.len() / 2);
    for ((a, b), &(cos, sin)) in first.iter_mut().zip(second.iter_mut()).zip(angles) {
        let (x0, x1) = (*a, *b);
        *a = x0 * cos - x1 * sin;
        *b = x0 * sin + x1 * cos;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Tensor};
    use candle_transformers::models::quantized_llama::ModelWeights;

    fn gguf() -> Option<std::path::PathBuf> {
        tad_models::for_tests(crate::SMALLEST)
    }

    fn cosine(a: &[f32], b: &[f32]) -> f32 {
        let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
        let norm = |v: &[f32]| v.iter().map(|x| x * x).sum::<f32>().sqrt();
        dot / (norm(a) * norm(b))
    }

    fn argmax(v: &[f32]) -> usize {
        v.iter().enumerate().fold((0, f32::NEG_INFINITY), |(bi, bv), (i, &x)| if x > bv { (i, x) } else { (bi, bv) }).0
    }

    /// A one-layer llama GGUF in memory whose `attn_q` has `q_rows` rows.
    fn tiny_gguf(q_rows: usize) -> std::io::Cursor<Vec<u8>> {
        use candle_core::quantized::{QTensor, gguf_file::Value};
        let (dim, hidden, vocab) = (64usize, 64usize, 32usize);
        let meta: Vec<(&str, Value)> = vec![
            ("general.architecture", Value::String("llama".into())),
            ("llama.block_count", Value::U32(1)),
            ("llama.embedding_length", Value::U32(dim as u32)),
            ("llama.feed_forward_length", Value::U32(hidden as u32)),
            ("llama.attention.head_count", Value::U32(2)),
            ("llama.attention.head_count_kv", Value::U32(1)),
        ];
        let matrix = |rows: usize, cols: usize, dtype| {
            let t = Tensor::ones((rows, cols), candle_core::DType::F32, &Device::Cpu).unwrap();
            QTensor::quantize(&t, dtype).unwrap()
        };
        let vector = |n: usize| {
            QTensor::quantize(&Tensor::ones(n, candle_core::DType::F32, &Device::Cpu).unwrap(), GgmlDType::F32).unwrap()
        };
        let tensors = vec![
            ("token_embd.weight", matrix(vocab, dim, GgmlDType::Q8_0)),
            ("output_norm.weight", vector(dim)),
            ("blk.0.attn_norm.weight", vector(dim)),
            ("blk.0.ffn_norm.weight", vector(dim)),
            ("blk.0.attn_q.weight", matrix(q_rows, dim, GgmlDType::Q4_1)),
            ("blk.0.attn_k.weight", matrix(32, dim, GgmlDType::Q4_1)),
            ("blk.0.attn_v.weight", matrix(32, dim, GgmlDType::Q4_1)),
            ("blk.0.attn_output.weight", matrix(dim, dim, GgmlDType::Q4_1)),
            ("blk.0.ffn_gate.weight", matrix(hidden, dim, GgmlDType::Q4_1)),
            ("blk.0.ffn_up.weight", matrix(hidden, dim, GgmlDType::Q4_1)),
            ("blk.0.ffn_down.weight", matrix(dim, hidden, GgmlDType::Q4_1)),
        ];
        let mut out = std::io::Cursor::new(Vec::new());
        let meta: Vec<(&str, &Value)> = meta.iter().map(|(k, v)| (*k, v)).collect();
        let tensors: Vec<(&str, &QTensor)> = tensors.iter().map(|(k, v)| (*k, v)).collect();
        candle_core::quantized::gguf_file::write(&mut out, &meta, &tensors).unwrap();
        out.set_position(0);
        out
    }

    #[test]
    fn every_architecture_has_one_name() {
        for (name, arch) in Arch::ALL {
            assert_eq!((Arch::parse(name), arch.name()), (Some(arch), name));
        }
        assert_eq!(Arch::parse("mistral"), None);
    }

    #[test]
    fn a_tensor_that_does_not_fit_the_shape_is_a_load_error() {
        let mut good = tiny_gguf(64);
        let content = Content::read(&mut good).unwrap();
        let mut model = Model::load(&content, &mut good, 1).unwrap();
        let mut cache = model.new_cache();
        assert_eq!(model.forward(&[1, 2, 3], &mut cache).len(), 32);
        let mut bad = tiny_gguf(96);
        let content = Content::read(&mut bad).unwrap();
        let error = Model::load(&content, &mut bad, 1).err().expect("a 96-row attn_q does not fit a 64-wide model");
        assert!(error.contains("blk.0.attn_q.weight"), "{error}");
    }

    /// `tokens` as a batch of one for candle's models.
    fn batch(tokens: &[u32]) -> Tensor {
        Tensor::new(tokens, &Device::Cpu).unwrap().unsqueeze(0).unwrap()
    }

    /// The logits a candle model returned for a batch of one.
    fn candles(forward: candle_core::Result<Tensor>) -> Vec<f32> {
        forward.unwrap().squeeze(0).unwrap().to_vec1().unwrap()
    }

    #[test]
    fn agrees_with_candles_quantized_llama() {
        let Some(path) = gguf() else { return };
        let mut file = std::fs::File::open(&path).unwrap();
        let content = Content::read(&mut file).unwrap();
        let mut ours = Model::load(&content, &mut file, 1).unwrap();
        let mut file2 = std::fs::File::open(&path).unwrap();
        let mut reference =
            ModelWeights::from_gguf(Content::read(&mut file2).unwrap(), &mut file2, &Device::Cpu).unwrap();
        // "<|im_start|>user\nA bus drives ahead of the ego car.<|im_end|>\n<|im_start|>assistant\n"
        let tokens: Vec<u32> =
            vec![1, 4093, 198, 49, 1615, 16520, 4245, 282, 260, 23346, 1345, 30, 2, 198, 1, 520, 9531, 198];
        let expected = candles(reference.forward(&batch(&tokens), 0));

        let mut cache = ours.new_cache();
        let chunked = ours.forward(&tokens, &mut cache);
        assert_eq!(chunked.len(), expected.len());
        assert_eq!(argmax(&chunked), argmax(&expected));
        assert!(cosine(&chunked, &expected) > 0.995, "cosine {}", cosine(&chunked, &expected));

        // two threads split the rows and change nothing
        let mut file3 = std::fs::File::open(&path).unwrap();
        let mut two = Model::load(&Content::read(&mut file3).unwrap(), &mut file3, 2).unwrap();
        let mut cache = two.new_cache();
        assert_eq!(two.forward(&tokens, &mut cache), chunked);

        // the listed rows alone (a grammar's allowed tokens) are the whole projection's
        // values, on one thread and on two; the others are −∞
        let listed = [0, 7, 260, 23346, 49151, 49152, u32::MAX];
        for (model, what) in [(&mut ours, "one thread"), (&mut two, "two threads")] {
            let mut cache = model.new_cache();
            let last = model.read(&tokens, &mut cache);
            let some = model.logits(&last, Some(&listed));
            assert_eq!(some.len(), chunked.len(), "{what}");
            for (r, (&a, &b)) in some.iter().zip(&chunked).enumerate() {
                match listed.contains(&(r as u32)) {
                    true => assert_eq!(a.to_bits(), b.to_bits(), "row {r}, {what}"),
                    false => assert_eq!(a, f32::NEG_INFINITY, "row {r}, {what}"),
                }
            }
        }

        // a token at a time (decoding) reads the same as a chunk (prefill)
        let mut cache = ours.new_cache();
        let mut stepped = Vec::new();
        for &t in &tokens {
            stepped = ours.forward(&[t], &mut cache);
        }
        let diff = stepped.iter().zip(&chunked).map(|(a, b)| (a - b).abs()).fold(0f32, f32::max);
        assert!(diff < 1e-3, "chunked and stepped differ by {diff}");

        // cut back and read again: the same as reading once
        let mut cut = ours.new_cache();
        ours.forward(&tokens[..10], &mut cut);
        ours.forward(&[5, 6, 7], &mut cut);
        cut.truncate(10);
        let again = ours.forward(&tokens[10..], &mut cut);
        let diff = again.iter().zip(&chunked).map(|(a, b)| (a - b).abs()).fold(0f32, f32::max);
        assert!(diff < 1e-3, "read again after cutting back: {diff}");

        // the next token, continuing from the cache, as candle continues from its own
        let next = argmax(&expected) as u32;
        let theirs = candles(reference.forward(&batch(&[next]), tokens.len()));
        let mine = ours.forward(&[next], &mut cache);
        assert_eq!(argmax(&mine), argmax(&theirs));
        assert!(cosine(&mine, &theirs) > 0.995, "cosine {}", cosine(&mine, &theirs));
    }

    /// qwen2 (biases, the rotary embedding over halves, Q4_K/Q6_K/Q5_0/Q8_0 weights) on the
    /// real Qwen2.5-Coder-0.5B file, against candle's quantized qwen2.
    #[test]
    fn agrees_with_candles_quantized_qwen2() {
        use candle_transformers::models::quantized_qwen2::ModelWeights as Qwen2;
        let Some(path) = crate::for_tests("qwen2.5-coder-0.5b") else { return };
        let mut file = std::fs::File::open(&path).unwrap();
        let content = Content::read(&mut file).unwrap();
        let tokenizer = crate::tokenizer(&content).unwrap();
        let (tokens, _) = crate::chatml(&tokenizer, &[("user", "A bus drives ahead of the ego car.")]).unwrap();
        let mut ours = Model::load(&content, &mut file, 2).unwrap();
        assert_eq!(ours.shape.arch, Arch::Qwen2);
        let mut file2 = std::fs::File::open(&path).unwrap();
        let mut reference = Qwen2::from_gguf(Content::read(&mut file2).unwrap(), &mut file2, &Device::Cpu).unwrap();
        let expected = candles(reference.forward(&batch(&tokens), 0));
        let mut cache = ours.new_cache();
        let logits = ours.forward(&tokens, &mut cache);
        assert_eq!(logits.len(), expected.len());
        assert_eq!(argmax(&logits), argmax(&expected));
        assert!(cosine(&logits, &expected) > 0.99, "cosine {}", cosine(&logits, &expected));
        // the next token from the cache, as candle's
        let next = argmax(&expected) as u32;
        let theirs = candles(reference.forward(&batch(&[next]), tokens.len()));
        let mine = ours.forward(&[next], &mut cache);
        assert_eq!(argmax(&mine), argmax(&theirs));
        assert!(cosine(&mine, &theirs) > 0.99, "cosine {}", cosine(&mine, &theirs));
    }
}
