//! Sentence embeddings offline: the two sentence-transformers models of `tad-models`, run
//! on the CPU with candle, giving what `SentenceTransformer.encode(texts,
//! normalize_embeddings=True)` gives.
//!
//! ```text
//! texts ──tokenizer.json (truncated to the model's max_seq_length)──▶ token ids
//!       ──sorted by length, chunks of BATCH, each padded to its longest + attention mask──▶
//!       encoder: all-MiniLM-L6-v2 → candle's BertModel; all-mpnet-base-v2 → mpnet.rs
//!       ──mean over the mask, L2 norm──▶ one unit vector per text, in the input's order
//! ```
//!
//! Three things decide whether the vectors match the published ones:
//! - the tokenizer files pad and truncate to a fixed 128 tokens; here truncation is the
//!   model's own `max_seq_length` (256 MiniLM, 384 MPNet) and padding is to the longest text
//!   of each chunk (batch-longest), done here so chunks can be sorted by length;
//! - the attention mask goes to the encoder (padding is never attended) and to pooling
//!   (padding is never averaged), so a text's vector does not depend on its batch;
//! - the mean is over real tokens, `[CLS]`/`<s>` and `[SEP]`/`</s>` included, then the
//!   vector is scaled to unit length, so a dot product is the cosine similarity.
//!
//! Which encoder runs is read from `config.json`'s `model_type`.

mod mpnet;

use std::path::Path;

use candle_core::{DType, Device, Tensor};
use candle_nn::VarBuilder;
use candle_transformers::models::bert::{BertModel, Config as BertConfig};
use tad_models::{Kind, Model};
use tokenizers::{Tokenizer, TruncationParams};

pub use mpnet::{Config as MPNetConfig, MPNetModel};

/// Texts encoded together; bounds memory (attention is batch × heads × len² floats).
const BATCH: usize = 32;

/// A loaded sentence-embedding model.
pub struct Embedder {
    name: &'static str,
    tokenizer: Tokenizer,
    encoder: Encoder,
    pad: u32,
    dim: usize,
    device: Device,
}

enum Encoder {
    Bert(Box<BertModel>),
    MPNet(Box<MPNetModel>),
}

impl Embedder {
    /// Loads an installed embedding model (see [`Model::require`] for a missing one).
    pub fn load(model: &Model) -> Result<Embedder, String> {
        if model.kind != Kind::SentenceEmbedding {
            return Err(format!("`{}` is a {}, not a sentence-embedding model", model.name, model.kind.label()));
        }
        let dir = model.require()?;
        let fail = |what: &str, e: &dyn std::fmt::Display| format!("{}: cannot load {what}: {e}", model.name);
        let read = |file: &str| {
            let path = dir.join(file);
            std::fs::read_to_string(&path).map_err(|e| fail(&path.display().to_string(), &e))
        };
        let config: serde_json::Value =
            serde_json::from_str(&read("config.json")?).map_err(|e| fail("config.json", &e))?;
        let device = Device::Cpu;
        let weights =
            load_weights(&dir.join("model.safetensors"), &device).map_err(|e| fail("model.safetensors", &e))?;
        // max_seq_length of the model's sentence_bert_config.json
        let (encoder, dim, max_tokens) = match config["model_type"].as_str() {
            Some("bert") => {
                let c: BertConfig = serde_json::from_value(config).map_err(|e| fail("config.json", &e))?;
                let bert = BertModel::load(weights, &c).map_err(|e| fail("the BERT encoder", &e))?;
                (Encoder::Bert(Box::new(bert)), c.hidden_size, 256)
            }
            Some("mpnet") => {
                let c: MPNetConfig = serde_json::from_value(config).map_err(|e| fail("config.json", &e))?;
                let mpnet = MPNetModel::load(weights, &c).map_err(|e| fail("the MPNet encoder", &e))?;
                (Encoder::MPNet(Box::new(mpnet)), c.hidden_size, 384)
            }
            other => return Err(format!("{}: no encoder for model_type {other:?}", model.name)),
        };
        let mut tokenizer =
            Tokenizer::from_file(dir.join("tokenizer.json")).map_err(|e| fail("tokenizer.json", &e.as_ref()))?;
        let pad = tokenizer.get_padding().map(|p| p.pad_id).or_else(|| tokenizer.token_to_id("[PAD]")).unwrap_or(0);
        tokenizer.with_padding(None);
        tokenizer
            .with_truncation(Some(TruncationParams { max_length: max_tokens, ..Default::default() }))
            .map_err(|e| fail("tokenizer.json", &e.as_ref()))?;
        Ok(Embedder { name: model.name, tokenizer, encoder, pad, dim, device })
    }

    /// The model's name in `tad-models`.
    pub fn name(&self) -> &str {
        self.name
    }

    /// The length of every embedding.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// One L2-normalised embedding per text, in order (none for no texts).
    pub fn embed(&self, texts: &[&str]) -> Result<Vec<Vec<f32>>, String> {
        if texts.is_empty() {
            return Ok(Vec::new());
        }
        let encodings = self.tokenizer.encode_batch(texts.to_vec(), true).map_err(|e| format!("tokenizing: {e}"))?;
        let ids: Vec<&[u32]> = encodings.iter().map(|e| e.get_ids()).collect();
        // similar lengths together, so little padding is computed
        let mut order: Vec<usize> = (0..texts.len()).collect();
        order.sort_by_key(|&i| ids[i].len());
        let mut out = vec![Vec::new(); texts.len()];
        for chunk in order.chunks(BATCH) {
            let rows: Vec<&[u32]> = chunk.iter().map(|&i| ids[i]).collect();
            let vectors = self.embed_ids(&rows).map_err(|e| format!("{}: {e}", self.name))?;
            for (&i, v) in chunk.iter().zip(vectors) {
                out[i] = v;
            }
        }
        Ok(out)
    }

    /// Pads the rows to the longest, runs the encoder, pools.
    fn embed_ids(&self, rows: &[&[u32]]) -> candle_core::Result<Vec<Vec<f32>>> {
        let len = rows.iter().map(|r| r.len()).max().unwrap_or(0);
        let padded: Vec<Vec<u32>> =
            rows.iter().map(|r| r.iter().copied().chain(std::iter::repeat(self.pad)).take(len).collect()).collect();
        let mask: Vec<u32> = rows.iter().flat_map(|r| (0..len).map(move |j| u32::from(j < r.len()))).collect();
        let mask = Tensor::from_vec(mask, (rows.len(), len), &self.device)?;
        let hidden = match &self.encoder {
            Encoder::Bert(bert) => {
                let flat: Vec<u32> = padded.into_iter().flatten().collect();
                let ids = Tensor::from_vec(flat, (rows.len(), len), &self.device)?;
                bert.forward(&ids, &ids.zeros_like()?, Some(&mask))?
            }
            Encoder::MPNet(mpnet) => mpnet.forward(&padded, &mask)?,
        };
        // mean over real tokens, then unit length
        let mask = mask.to_dtype(DType::F32)?;
        let summed = hidden.broadcast_mul(&mask.unsqueeze(2)?)?.sum(1)?;
        let counts = mask.sum_keepdim(1)?.clamp(1e-9, f64::INFINITY)?;
        mpnet::l2_normalise(&summed.broadcast_div(&counts)?)?.to_vec2::<f32>()
    }
}

/// The weights, read through candle's memory map.
fn load_weights(path: &Path, device: &Device) -> candle_core::Result<VarBuilder<'static>> {
    let tensors = candle_core::safetensors::load(path, device)?;
    Ok(VarBuilder::from_tensors(tensors, DType::F32, device))
}

/// The cosine similarity of two L2-normalised embeddings (their dot product).
pub fn cosine(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
