//! MPNet's encoder in candle (candle-transformers has none), as Hugging Face's
//! `modeling_mpnet.py` computes it for `MPNetModel`'s last hidden state.
//!
//! It is BERT's encoder with three differences:
//! - no token-type embeddings;
//! - position ids count real tokens from `pad + 1` (RoBERTa's convention), padding keeps `pad`;
//! - every layer's attention scores get a learned relative-position bias: the distance
//!   between two tokens falls into one of 32 buckets (exact up to 8 either way, then
//!   logarithmic up to 128), each with a value per head. The bias depends only on the
//!   sequence length, so it is computed once per batch and shared by all layers.

use candle_core::{D, DType, Device, Module, Result, Tensor};
use candle_nn::{Embedding, LayerNorm, Linear, VarBuilder, embedding, layer_norm, linear};
use serde::Deserialize;

/// The fields of `config.json` the encoder needs.
#[derive(Clone, Debug, Deserialize)]
pub struct Config {
    pub vocab_size: usize,
    pub hidden_size: usize,
    pub num_hidden_layers: usize,
    pub num_attention_heads: usize,
    pub intermediate_size: usize,
    pub max_position_embeddings: usize,
    pub layer_norm_eps: f64,
    pub pad_token_id: u32,
    #[serde(default = "buckets")]
    pub relative_attention_num_buckets: usize,
}

fn buckets() -> usize {
    32
}

/// The farthest distance the buckets tell apart; farther ones share the last bucket.
const MAX_DISTANCE: i64 = 128;

struct Layer {
    q: Linear,
    k: Linear,
    v: Linear,
    o: Linear,
    attention_norm: LayerNorm,
    intermediate: Linear,
    output: Linear,
    output_norm: LayerNorm,
    heads: usize,
}

impl Layer {
    fn load(vb: VarBuilder, c: &Config) -> Result<Layer> {
        let h = c.hidden_size;
        let attn = vb.pp("attention.attn");
        Ok(Layer {
            q: linear(h, h, attn.pp("q"))?,
            k: linear(h, h, attn.pp("k"))?,
            v: linear(h, h, attn.pp("v"))?,
            o: linear(h, h, attn.pp("o"))?,
            attention_norm: layer_norm(h, c.layer_norm_eps, vb.pp("attention.LayerNorm"))?,
            intermediate: linear(h, c.intermediate_size, vb.pp("intermediate.dense"))?,
            output: linear(c.intermediate_size, h, vb.pp("output.dense"))?,
            output_norm: layer_norm(h, c.layer_norm_eps, vb.pp("output.LayerNorm"))?,
            heads: c.num_attention_heads,
        })
    }

    /// `x`: (batch, len, hidden); `bias`: (1, heads, len, len); `mask`: (batch, 1, 1, len),
    /// 0 for tokens and a large negative number for padding.
    fn forward(&self, x: &Tensor, bias: &Tensor, mask: &Tensor) -> Result<Tensor> {
        let (b, t, h) = x.dims3()?;
        let d = h / self.heads;
        let split = |y: Tensor| y.reshape((b, t, self.heads, d))?.transpose(1, 2)?.contiguous();
        let q = split(self.q.forward(x)?)?;
        let k = split(self.k.forward(x)?)?;
        let v = split(self.v.forward(x)?)?;
        let scores = (q.matmul(&k.t()?)? / (d as f64).sqrt())?.broadcast_add(bias)?.broadcast_add(mask)?;
        let probs = candle_nn::ops::softmax_last_dim(&scores)?;
        let context = probs.matmul(&v)?.transpose(1, 2)?.reshape((b, t, h))?;
        let attended = self.attention_norm.forward(&(self.o.forward(&context)? + x)?)?;
        let inner = self.intermediate.forward(&attended)?.gelu_erf()?;
        self.output_norm.forward(&(self.output.forward(&inner)? + attended)?)
    }
}

pub struct MPNetModel {
    words: Embedding,
    positions: Embedding,
    norm: LayerNorm,
    layers: Vec<Layer>,
    relative_bias: Embedding,
    buckets: usize,
    pad: u32,
    max_positions: usize,
    device: Device,
}

impl MPNetModel {
    pub fn load(vb: VarBuilder, c: &Config) -> Result<MPNetModel> {
        // checkpoints saved from MPNetForMaskedLM prefix every name with `mpnet.`
        let vb = if vb.contains_tensor("mpnet.embeddings.word_embeddings.weight") { vb.pp("mpnet") } else { vb };
        let layers = (0..c.num_hidden_layers)
            .map(|i| Layer::load(vb.pp(format!("encoder.layer.{i}")), c))
            .collect::<Result<_>>()?;
        Ok(MPNetModel {
            words: embedding(c.vocab_size, c.hidden_size, vb.pp("embeddings.word_embeddings"))?,
            positions: embedding(c.max_position_embeddings, c.hidden_size, vb.pp("embeddings.position_embeddings"))?,
            norm: layer_norm(c.hidden_size, c.layer_norm_eps, vb.pp("embeddings.LayerNorm"))?,
            layers,
            relative_bias: embedding(
                c.relative_attention_num_buckets,
                c.num_attention_heads,
                vb.pp("encoder.relative_attention_bias"),
            )?,
            buckets: c.relative_attention_num_buckets,
            pad: c.pad_token_id,
            max_positions: c.max_position_embeddings,
            device: vb.device().clone(),
        })
    }

    /// The last hidden state, (batch, len, hidden), of right-padded `ids` (batch, len) with
    /// their attention `mask` (batch, len; 1 for tokens, 0 for padding).
    pub fn forward(&self, ids: &[Vec<u32>], mask: &Tensor) -> Result<Tensor> {
        let (b, t) = (ids.len(), ids.first().map_or(0, Vec::len));
        if t + self.pad as usize + 1 > self.max_positions {
            candle_core::bail!(
                "{t} tokens are more than MPNet's {} positions",
                self.max_positions - self.pad as usize - 1
            );
        }
        // position ids: cumsum over real tokens, offset by the padding index
        let positions: Vec<u32> = ids
            .iter()
            .flat_map(|row| {
                let mut seen = 0;
                row.iter().map(move |&id| {
                    if id == self.pad {
                        self.pad
                    } else {
                        seen += 1;
                        seen + self.pad
                    }
                })
            })
            .collect();
        let flat: Vec<u32> = ids.iter().flatten().copied().collect();
        let input = Tensor::from_vec(flat, (b, t), &self.device)?;
        let positions = Tensor::from_vec(positions, (b, t), &self.device)?;
        let mut x = self.norm.forward(&(self.words.forward(&input)? + self.positions.forward(&positions)?)?)?;
        let bias = self.position_bias(t)?;
        // 0 where attended, the most negative f32 where padded (as transformers does)
        let mask = ((mask.to_dtype(DType::F32)? - 1.0)? * f64::from(f32::MAX))?.unsqueeze(1)?.unsqueeze(1)?;
        for layer in &self.layers {
            x = layer.forward(&x, &bias, &mask)?;
        }
        Ok(x)
    }

    /// The relative-position bias for a length: (1, heads, len, len).
    fn position_bias(&self, t: usize) -> Result<Tensor> {
        let buckets: Vec<u32> = (0..t as i64)
            .flat_map(|query| (0..t as i64).map(move |key| bucket(key - query, self.buckets as i64)))
            .collect();
        let buckets = Tensor::from_vec(buckets, t * t, &self.device)?;
        let values = self.relative_bias.forward(&buckets)?; // (len·len, heads)
        values.reshape((t, t, ()))?.permute((2, 0, 1))?.unsqueeze(0)?.contiguous()
    }
}

/// The bucket of a relative position (key − query), as `relative_position_bucket` in
/// transformers: half the buckets for keys before the query, half for after; within a half,
/// distances below a quarter of the buckets are exact and the rest logarithmic up to
/// [`MAX_DISTANCE`]. Computed in f32 and truncated, as torch does.
fn bucket(relative: i64, buckets: i64) -> u32 {
    let half = buckets / 2;
    let n = -relative;
    let side = if n < 0 { half } else { 0 };
    let n = n.abs();
    let exact = half / 2;
    let within = if n < exact {
        n
    } else {
        let log = (n as f32 / exact as f32).ln() / ((MAX_DISTANCE as f64 / exact as f64).ln() as f32);
        (exact + (log * (half - exact) as f32) as i64).min(half - 1)
    };
    (side + within) as u32
}

/// The last axis's norm, for pooling's L2 normalisation.
pub(crate) fn l2_normalise(x: &Tensor) -> Result<Tensor> {
    let norm = x.sqr()?.sum_keepdim(D::Minus1)?.sqrt()?.clamp(1e-12, f64::INFINITY)?;
    x.broadcast_div(&norm)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values from transformers' `MPNetEncoder.relative_position_bucket` (32 buckets, max
    /// distance 128).
    #[test]
    fn buckets_match_transformers() {
        // keys before the query (relative < 0) fall in 0..16, keys after in 16..32
        for (relative, want) in
            [(0, 0), (-1, 1), (-7, 7), (-8, 8), (-11, 8), (-12, 9), (-16, 10), (-32, 12), (-127, 15), (-500, 15)]
        {
            assert_eq!(bucket(relative, 32), want, "relative {relative}");
        }
        for (relative, want) in [(1, 17), (7, 23), (8, 24), (16, 26), (32, 28), (1000, 31)] {
            assert_eq!(bucket(relative, 32), want, "relative {relative}");
        }
    }
}
