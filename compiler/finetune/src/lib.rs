//! LoRA fine-tuning of a local model (SmolLM2-135M, Qwen2.5-Coder) in candle, on the CPU: TrafficAlign
//! aligns a small model to each region's validated scenarios this way.
//!
//! ```text
//! JSONL (TRL's messages or prompt/completion) ──tokenize: ChatML as tad-local reads it──▶ samples
//! GGUF ──dequantize (f32, frozen)──▶ Weights        LoRA A (Kaiming-uniform, seeded), B = 0 ──▶ Vars
//! for each epoch, examples shuffled (seeded), one at a time (accumulated):
//!     (--frozen-prefix: the tokens all examples begin with read once by the base model,
//!      their keys and values held fixed; each example reads only what follows)
//!     forward (causal, each layer's input kept) ─▶ cross-entropy on the answer's tokens only
//!     ─▶ backward, each layer recomputed from its input, last to first ─▶ AdamW
//!     every N steps: checkpoint (adapter, optimizer moments, position, RNG) ──▶ resume
//! ──▶ adapter_model.safetensors + adapter_config.json (PEFT), base_prefix.json (the frozen
//!     prefix's tokens: the decoder reads them without the adapter) ──▶ tad-local's decoder
//! ──▶ adapter.gguf (the same adapter as llama.cpp's LoRA GGUF) ──▶ llama-server --lora
//! ```
//!
//! The optimizer is AdamW as candle-nn writes it (the same update, bias-corrected), kept
//! here so that its moments can be checkpointed: candle-nn's keeps them private, and a
//! resume without them would not continue the same run.

mod data;
mod model;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use candle_core::backprop::GradStore;
use candle_core::{Device, Tensor, Var};
use serde::{Deserialize, Serialize};

pub use data::{Example, Message, read_jsonl};
pub use model::{LoraSet, Prefix, Rng, Rope, Weights, uniform};
use tad_base::Rng as _;
pub use tad_local::{Adapter, Target};

use model::err;

/// The training run's settings.
#[derive(Clone, Debug)]
pub struct Config {
    pub rank: usize,
    pub alpha: f32,
    pub targets: Vec<Target>,
    pub learning_rate: f64,
    /// AdamW's decoupled weight decay (TRL's default: none).
    pub weight_decay: f64,
    pub epochs: usize,
    /// Tokens per example (prompt and answer); longer answers are cut, with a warning.
    pub max_len: usize,
    /// Examples per optimizer step (gradients averaged).
    pub accumulate: usize,
    /// Seeds A's initialisation and the order of the examples.
    pub seed: u64,
    /// Optimizer steps between checkpoints (0: none).
    pub checkpoint_every: usize,
    /// Continue from the checkpoint in the output directory, if there is one.
    pub resume: bool,
    /// Keep one layer's graph at a time and recompute each layer in the backward pass
    /// (activation checkpointing): a fraction of the memory for a second forward pass.
    pub recompute: bool,
    /// Read the tokens every example begins with (a shared system message) once, with the
    /// base model, and hold their keys and values fixed: an example then costs only its own
    /// tokens, and no gradient flows through the prefix.
    pub frozen_prefix: bool,
    /// Start from this adapter (of the same rank, alpha and targets) instead of B = 0: an
    /// adapter trained further on new examples. A checkpoint resumed takes precedence.
    pub from: Option<Adapter>,
    /// The adapter's `base_model_name_or_path`: the model's upstream name
    /// (`tad_models::Model::upstream`).
    pub base_model: String,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            // the paper's r = alpha = 16
            rank: 16,
            alpha: 16.0,
            targets: Target::ALL.to_vec(),
            learning_rate: 2e-4,
            weight_decay: 0.0,
            epochs: 2,
            max_len: 1024,
            accumulate: 1,
            seed: 0,
            checkpoint_every: 0,
            resume: false,
            recompute: true,
            frozen_prefix: false,
            from: None,
            base_model: tad_local::model(tad_local::ALIGN_DEFAULT).map_or("", |m| m.upstream).to_string(),
        }
    }
}

/// What the progress callback hears after each optimizer step.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Steps done (from 1), and in all.
    pub step: usize,
    pub steps: usize,
    /// The epoch under way (from 0).
    pub epoch: usize,
    /// The step's mean loss over its examples' answer tokens.
    pub loss: f32,
    /// Tokens read (prompts and answers) per second of training in this run.
    pub tokens_per_s: f64,
    /// A checkpoint was written after this step.
    pub checkpoint: Option<PathBuf>,
}

/// The run's outcome.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Optimizer steps in all (with those before a resume), and in this run.
    pub steps: usize,
    pub steps_run: usize,
    pub examples: usize,
    /// Tokens read in this run, and the answer tokens among them.
    pub tokens: usize,
    pub answer_tokens: usize,
    pub seconds: f64,
    pub tokens_per_s: f64,
    /// Each step's loss (with those before a resume).
    pub losses: Vec<f32>,
    /// The step a resumed run started after.
    pub resumed_at: Option<usize>,
    /// Tokens of the frozen prefix, read once (0 without `frozen_prefix`).
    pub prefix: usize,
    /// Examples cut or dropped, in words.
    pub warnings: Vec<String>,
    pub adapter: PathBuf,
}

/// Why training did not finish, by whose fix it needs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FinetuneError {
    /// The settings, the examples, the model or a checkpoint cannot train: the caller's to fix.
    Setup(String),
    /// A file could not be read or written.
    Io(String),
    /// Training itself failed (a loss that is not a number, a numerical error).
    Training(String),
}

impl std::fmt::Display for FinetuneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FinetuneError::Setup(m) | FinetuneError::Io(m) | FinetuneError::Training(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for FinetuneError {}

/// An example as tokens: the loss is on `tokens[answer..]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    pub tokens: Vec<u32>,
    pub answer: usize,
}

/// ChatML tokens of `example`, as tad-local's engine reads a prompt, then the answer and
/// `<|im_end|>`. Cut to `max_len` tokens (the answer's end), with a warning; `None` when
/// the prompt leaves no room for an answer token.
pub fn tokenize(
    tokenizer: &tad_local::Tokenizer,
    example: &Example,
    max_len: usize,
) -> Result<(Option<Sample>, Option<String>), String> {
    let turns: Vec<(&str, &str)> = example.prompt.iter().map(|m| (m.role.as_str(), m.content.as_str())).collect();
    let (mut tokens, _) = tad_local::chatml(tokenizer, &turns)?;
    let answer = tokens.len();
    let im_end = tokenizer.token_to_id("<|im_end|>").ok_or("the tokenizer has no `<|im_end|>`")?;
    tokens.extend(tokenizer.encode(example.completion.as_str(), false).map_err(err)?.get_ids());
    tokens.push(im_end);
    if tokens.len() <= max_len {
        return Ok((Some(Sample { tokens, answer }), None));
    }
    if answer >= max_len {
        let warning = format!("the prompt alone has {answer} tokens, max_len is {max_len}: dropped");
        return Ok((None, Some(warning)));
    }
    let warning = format!("{} tokens cut to max_len {max_len} (the answer's end is not learnt)", tokens.len());
    tokens.truncate(max_len);
    Ok((Some(Sample { tokens, answer }), Some(warning)))
}

/// Fine-tunes the model in the GGUF file `gguf` on `examples` and writes the adapter into
/// `out` (checkpoints in `out/checkpoint`).
pub fn train(
    gguf: &Path,
    examples: &[Example],
    config: &Config,
    out: &Path,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Report, FinetuneError> {
    let (weights, content) = Weights::load(gguf).map_err(FinetuneError::Setup)?;
    let tokenizer =
        tad_local::tokenizer(&content).map_err(|e| FinetuneError::Setup(format!("the model's tokenizer: {e}")))?;
    let max_len = config.max_len.min(weights.shape.context);
    let mut samples = Vec::new();
    let mut warnings = Vec::new();
    for (i, example) in examples.iter().enumerate() {
        let (sample, warning) = tokenize(&tokenizer, example, max_len).map_err(FinetuneError::Setup)?;
        if let Some(w) = warning {
            warnings.push(format!("example {}: {w}", i + 1));
        }
        samples.extend(sample);
    }
    let mut report = train_samples(&weights, &samples, config, out, progress)?;
    warnings.append(&mut report.warnings);
    report.warnings = warnings;
    Ok(report)
}

/// The checkpoint's state besides the tensors.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct State {
    /// Optimizer steps done.
    step: usize,
    /// The epoch under way, and the next example's place in its order.
    epoch: usize,
    position: usize,
    /// The generator's state when the epoch's order was drawn.
    rng: u64,
    losses: Vec<f32>,
    /// What must not change across a resume.
    seed: u64,
    rank: usize,
    alpha: f32,
    targets: Vec<String>,
    examples: usize,
    accumulate: usize,
    epochs: usize,
    /// Tokens of the frozen prefix (0: none).
    #[serde(default)]
    prefix: usize,
}

/// AdamW (candle-nn's update) with its moments kept by name, for checkpoints.
struct AdamW {
    vars: Vec<(String, Var)>,
    m: Vec<Tensor>,
    v: Vec<Tensor>,
    step: usize,
    lr: f64,
    weight_decay: f64,
}

impl AdamW {
    const BETA1: f64 = 0.9;
    const BETA2: f64 = 0.999;
    const EPS: f64 = 1e-8;

    fn new(vars: Vec<(String, Var)>, lr: f64, weight_decay: f64) -> Result<AdamW, String> {
        let zeros = |v: &Var| v.zeros_like().map_err(err);
        let m = vars.iter().map(|(_, v)| zeros(v)).collect::<Result<_, _>>()?;
        let v = vars.iter().map(|(_, v)| zeros(v)).collect::<Result<_, _>>()?;
        Ok(AdamW { vars, m, v, step: 0, lr, weight_decay })
    }

    fn apply(&mut self, grads: &[Option<Tensor>]) -> candle_core::Result<()> {
        self.step += 1;
        let scale_m = 1.0 / (1.0 - Self::BETA1.powi(self.step as i32));
        let scale_v = 1.0 / (1.0 - Self::BETA2.powi(self.step as i32));
        for (i, (_, theta)) in self.vars.iter().enumerate() {
            let Some(g) = &grads[i] else { continue };
            let m = ((&self.m[i] * Self::BETA1)? + (g * (1.0 - Self::BETA1))?)?;
            let v = ((&self.v[i] * Self::BETA2)? + (g.sqr()? * (1.0 - Self::BETA2))?)?;
            let adjusted = ((&m * scale_m)? / ((&v * scale_v)?.sqrt()? + Self::EPS)?)?;
            let next = ((theta.as_tensor() * (1.0 - self.lr * self.weight_decay))? - (adjusted * self.lr)?)?;
            theta.set(&next)?;
            self.m[i] = m;
            self.v[i] = v;
        }
        Ok(())
    }

    fn save(&self, path: &Path) -> Result<(), String> {
        let mut tensors = HashMap::new();
        for (i, (name, _)) in self.vars.iter().enumerate() {
            tensors.insert(format!("{name}.m"), self.m[i].clone());
            tensors.insert(format!("{name}.v"), self.v[i].clone());
        }
        candle_core::safetensors::save(&tensors, path).map_err(|e| format!("cannot write `{}`: {e}", path.display()))
    }

    fn load(&mut self, path: &Path, step: usize) -> Result<(), String> {
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
        let mut tensors = candle_core::safetensors::load_buffer(&bytes, &Device::Cpu)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        for (i, (name, var)) in self.vars.iter().enumerate() {
            for (suffix, slot) in [("m", &mut self.m[i]), ("v", &mut self.v[i])] {
                let t = tensors
                    .remove(&format!("{name}.{suffix}"))
                    .filter(|t| t.dims() == var.dims())
                    .ok_or_else(|| format!("{}: no fitting moment for {name}", path.display()))?;
                *slot = t;
            }
        }
        self.step = step;
        Ok(())
    }
}

const CHECKPOINT: &str = "checkpoint";
const STATE_FILE: &str = "trainer_state.json";
const OPTIMIZER_FILE: &str = "optimizer.safetensors";

fn epoch_order(count: usize, rng: &mut Rng) -> Vec<usize> {
    let mut order: Vec<usize> = (0..count).collect();
    rng.shuffle(&mut order);
    order
}

/// Writes the checkpoint into `out/checkpoint` whole or not at all (a new directory
/// renamed over the old one).
fn save_checkpoint(out: &Path, adapter: &Adapter, optimizer: &AdamW, state: &State) -> Result<PathBuf, String> {
    let dir = out.join(CHECKPOINT);
    let partial = out.join(format!("{CHECKPOINT}.part"));
    let _ = std::fs::remove_dir_all(&partial);
    adapter.save(&partial)?;
    optimizer.save(&partial.join(OPTIMIZER_FILE))?;
    let text = serde_json::to_string_pretty(state).map_err(err)?;
    std::fs::write(partial.join(STATE_FILE), text).map_err(|e| format!("cannot write the checkpoint: {e}"))?;
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::rename(&partial, &dir).map_err(|e| format!("cannot write `{}`: {e}", dir.display()))?;
    Ok(dir)
}

/// Trains on samples already tokenized (for models without a tokenizer: tests): checks
/// the settings, starts (or resumes from the checkpoint), runs the epochs, writes the adapter.
pub fn train_samples(
    weights: &Weights,
    samples: &[Sample],
    config: &Config,
    out: &Path,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Report, FinetuneError> {
    check(samples, config)?;
    std::fs::create_dir_all(out).map_err(|e| FinetuneError::Io(format!("cannot create `{}`: {e}", out.display())))?;
    let start = Instant::now();
    let longest = samples.iter().map(|s| s.tokens.len()).max().unwrap_or(1);
    let rope = Rope::new(&weights.shape, longest).map_err(FinetuneError::Setup)?;
    let (prefix, suffixes) = match config.frozen_prefix {
        true => split_prefix(samples),
        false => (&[][..], samples.to_vec()),
    };
    let samples = &suffixes[..];
    // a checkpoint of another run is refused before the prefix is read (minutes for a 1.5B)
    let mut run = Run::start(weights, samples, config, out, rope, prefix)?;
    if !prefix.is_empty() {
        run.prefix = Some(weights.prefix(prefix, None, &run.rope).map_err(training)?);
    }
    run.epochs(weights, samples, config, out, start, progress)?;
    let adapter = adapter(&run.lora, &run.prefix_tokens, weights, config).map_err(FinetuneError::Training)?;
    adapter.save(out).map_err(FinetuneError::Io)?;
    adapter.save_gguf(&out.join(tad_local::GGUF_FILE), &weights.shape).map_err(FinetuneError::Io)?;
    let Run { optimizer, state, resumed_at, counts, .. } = run;
    if config.checkpoint_every > 0 {
        save_checkpoint(out, &adapter, &optimizer, &state).map_err(FinetuneError::Io)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    Ok(Report {
        steps: state.step,
        steps_run: counts.steps_run,
        examples: samples.len(),
        tokens: counts.tokens,
        answer_tokens: counts.answer_tokens,
        seconds,
        tokens_per_s: counts.tokens as f64 / seconds.max(1e-9),
        losses: state.losses,
        resumed_at,
        prefix: prefix.len(),
        warnings: Vec::new(),
        adapter: out.to_path_buf(),
    })
}

/// The longest run of tokens every sample begins with, leaving each at least one token
/// before its answer (the one that predicts the answer's first), and the samples after it.
fn split_prefix(samples: &[Sample]) -> (&[u32], Vec<Sample>) {
    let first = &samples[0].tokens;
    let mut len = samples.iter().map(|s| s.answer.saturating_sub(1)).min().unwrap_or(0);
    for s in &samples[1..] {
        len = len.min(first.iter().zip(&s.tokens).take_while(|(a, b)| a == b).count());
    }
    let suffixes =
        samples.iter().map(|s| Sample { tokens: s.tokens[len..].to_vec(), answer: s.answer - len }).collect();
    (&first[..len], suffixes)
}

/// A numerical failure while training.
fn training(e: impl std::fmt::Display) -> FinetuneError {
    FinetuneError::Training(e.to_string())
}

/// Settings and examples that can train.
fn check(samples: &[Sample], config: &Config) -> Result<(), FinetuneError> {
    let refuse = |m: &str| Err(FinetuneError::Setup(m.into()));
    if samples.is_empty() {
        return refuse("no examples to train on");
    }
    if config.rank == 0 || config.targets.is_empty() || config.epochs == 0 || config.max_len < 2 {
        return refuse("the rank, the targets, the epochs and max_len must not be zero");
    }
    if !(config.learning_rate.is_finite() && config.learning_rate > 0.0) {
        return refuse("the learning rate must be a positive number");
    }
    Ok(())
}

/// Tokens and steps of this run (not of the run it resumed).
#[derive(Default)]
struct Counts {
    tokens: usize,
    answer_tokens: usize,
    steps_run: usize,
}

/// A training run under way: the adapters, their optimizer, the state checkpoints keep.
struct Run {
    lora: LoraSet,
    optimizer: AdamW,
    state: State,
    resumed_at: Option<usize>,
    rope: Rope,
    /// The frozen prefix every sample follows: its tokens, and their keys and values once read.
    prefix_tokens: Vec<u32>,
    prefix: Option<Prefix>,
    accumulate: usize,
    counts: Counts,
}

impl Run {
    /// A fresh run, or the checkpoint's when resuming one of the same settings.
    fn start(
        weights: &Weights,
        samples: &[Sample],
        config: &Config,
        out: &Path,
        rope: Rope,
        prefix: &[u32],
    ) -> Result<Run, FinetuneError> {
        let setup = FinetuneError::Setup;
        let shape = weights.shape;
        let accumulate = config.accumulate.max(1);
        let mut targets = config.targets.clone();
        targets.sort();
        targets.dedup();
        let mut state = State {
            step: 0,
            epoch: 0,
            position: 0,
            rng: config.seed ^ 0x005E_ED0F_0DE5,
            losses: Vec::new(),
            seed: config.seed,
            rank: config.rank,
            alpha: config.alpha,
            targets: targets.iter().map(|t| t.module().to_string()).collect(),
            examples: samples.len(),
            accumulate,
            epochs: config.epochs,
            prefix: prefix.len(),
        };
        let checkpoint = out.join(CHECKPOINT);
        let mut resumed_at = None;
        let (lora, mut optimizer);
        if config.resume && checkpoint.join(STATE_FILE).exists() {
            let text = std::fs::read_to_string(checkpoint.join(STATE_FILE))
                .map_err(|e| FinetuneError::Io(format!("cannot read the checkpoint: {e}")))?;
            let saved: State =
                serde_json::from_str(&text).map_err(|e| setup(format!("the checkpoint's state: {e}")))?;
            let same = |s: &State| (s.seed, s.rank, s.alpha, s.targets.clone(), s.examples, s.accumulate, s.prefix);
            if same(&saved) != same(&state) {
                return Err(setup(format!(
                    "the checkpoint in `{}` is of another run (seed, rank, alpha, targets, examples, accumulation or frozen prefix differ): remove it or train without --resume",
                    checkpoint.display()
                )));
            }
            let adapter = Adapter::load(&checkpoint).map_err(setup)?;
            lora = LoraSet::from_adapter(&adapter, &shape).map_err(setup)?;
            optimizer = AdamW::new(lora.named(), config.learning_rate, config.weight_decay).map_err(setup)?;
            optimizer.load(&checkpoint.join(OPTIMIZER_FILE), saved.step).map_err(setup)?;
            resumed_at = Some(saved.step);
            state.step = saved.step;
            state.epoch = saved.epoch;
            state.position = saved.position;
            state.rng = saved.rng;
            state.losses = saved.losses;
        } else if let Some(adapter) = &config.from {
            if (adapter.rank, adapter.alpha, adapter.rslora, &adapter.targets)
                != (config.rank, config.alpha, false, &targets)
            {
                return Err(setup(format!(
                    "the adapter to start from has rank {}, alpha {} and targets {}: train it further with the same",
                    adapter.rank,
                    adapter.alpha,
                    adapter.targets.iter().map(|t| t.module()).collect::<Vec<_>>().join(", ")
                )));
            }
            lora = LoraSet::from_adapter(adapter, &shape).map_err(setup)?;
            optimizer = AdamW::new(lora.named(), config.learning_rate, config.weight_decay).map_err(setup)?;
        } else {
            lora = LoraSet::new(&shape, config.rank, config.alpha, &targets, config.seed).map_err(setup)?;
            optimizer = AdamW::new(lora.named(), config.learning_rate, config.weight_decay).map_err(setup)?;
        }
        let prefix_tokens = prefix.to_vec();
        Ok(Run {
            lora,
            optimizer,
            state,
            resumed_at,
            rope,
            prefix_tokens,
            prefix: None,
            accumulate,
            counts: Counts::default(),
        })
    }

    /// Every remaining epoch, a step per `accumulate` examples, reporting each step.
    fn epochs(
        &mut self,
        weights: &Weights,
        samples: &[Sample],
        config: &Config,
        out: &Path,
        start: Instant,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<(), FinetuneError> {
        let state = &mut self.state;
        let per_epoch = samples.len().div_ceil(self.accumulate);
        let steps = per_epoch * config.epochs;
        while state.epoch < config.epochs {
            let order = epoch_order(samples.len(), &mut Rng(state.rng));
            while state.position < order.len() {
                let batch = &order[state.position..(state.position + self.accumulate).min(order.len())];
                let mut grads: Vec<Option<Tensor>> = vec![None; self.optimizer.vars.len()];
                let mut loss_sum = 0f32;
                for &i in batch {
                    let sample = &samples[i];
                    let (loss, store) =
                        sample_loss(weights, &self.lora, &self.rope, self.prefix.as_ref(), sample, config.recompute)
                            .map_err(training)?;
                    loss_sum += loss;
                    for (slot, (_, var)) in grads.iter_mut().zip(&self.optimizer.vars) {
                        if let Some(g) = store.get(var.as_tensor()) {
                            let g = (g / batch.len() as f64).map_err(training)?;
                            *slot = Some(match slot.take() {
                                Some(sum) => (sum + g).map_err(training)?,
                                None => g,
                            });
                        }
                    }
                    self.counts.tokens += sample.tokens.len();
                    self.counts.answer_tokens += sample.tokens.len() - sample.answer;
                }
                self.optimizer.apply(&grads).map_err(training)?;
                let loss = loss_sum / batch.len() as f32;
                if !loss.is_finite() {
                    return Err(training(format!(
                        "the loss is {loss} at step {}: try a lower learning rate",
                        state.step + 1
                    )));
                }
                state.step += 1;
                self.counts.steps_run += 1;
                state.position += batch.len();
                state.losses.push(loss);
                let epoch = state.epoch;
                let epoch_done = state.position >= order.len();
                if epoch_done {
                    state.epoch += 1;
                    state.position = 0;
                    // the next epoch's order is drawn from where this one's left the generator
                    let mut rng = Rng(state.rng);
                    epoch_order(samples.len(), &mut rng);
                    state.rng = rng.0;
                }
                let mut written = None;
                if config.checkpoint_every > 0
                    && state.step.is_multiple_of(config.checkpoint_every)
                    && state.step < steps
                {
                    let adapter =
                        adapter(&self.lora, &self.prefix_tokens, weights, config).map_err(FinetuneError::Training)?;
                    written = Some(save_checkpoint(out, &adapter, &self.optimizer, state).map_err(FinetuneError::Io)?);
                }
                let seconds = start.elapsed().as_secs_f64();
                progress(&Progress {
                    step: state.step,
                    steps,
                    epoch,
                    loss,
                    tokens_per_s: self.counts.tokens as f64 / seconds.max(1e-9),
                    checkpoint: written,
                });
                if epoch_done {
                    break;
                }
            }
        }
        Ok(())
    }
}

/// `lora` as a PEFT adapter, with the prefix it was trained to follow.
fn adapter(lora: &LoraSet, prefix: &[u32], weights: &Weights, config: &Config) -> Result<Adapter, String> {
    let adapter = lora.to_adapter(&weights.shape, &config.base_model)?;
    Ok(Adapter { base_prefix: prefix.to_vec(), ..adapter })
}

/// A sample's loss and its gradients, with each layer recomputed in the backward pass or
/// the whole graph kept.
fn sample_loss(
    weights: &Weights,
    lora: &LoraSet,
    rope: &Rope,
    prefix: Option<&Prefix>,
    sample: &Sample,
    recompute: bool,
) -> candle_core::Result<(f32, GradStore)> {
    let (tokens, from) = (&sample.tokens, sample.answer);
    if recompute {
        return weights.loss_recomputed(tokens, from, lora, rope, prefix);
    }
    let loss = weights.loss(tokens, from, Some(lora), rope, prefix)?;
    Ok((loss.to_scalar::<f32>()?, loss.backward()?))
}
