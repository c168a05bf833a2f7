//! `tadslc finetune`: LoRA fine-tuning of the local model on chat examples (`tad-finetune`),
//! with a progress bar; the adapter is a PEFT directory `--adapter` reads back.

use std::path::{Path, PathBuf};

use tad_finetune::{Config, FinetuneError, Progress, Target};

use crate::output::CliError;
use crate::{Status, errln, outln};

/// Fine-tune the local model with LoRA on chat examples
#[derive(clap::Args, Debug, Clone)]
pub struct FinetuneArgs {
    /// Examples: a JSONL file (TRL's `messages`, or `prompt` and `completion`), or a
    /// directory holding messages.jsonl or prompt_completion.jsonl (as `tadslc sft-export`
    /// writes them) or train.jsonl
    pub data: PathBuf,
    /// The adapter's directory (PEFT: adapter_model.safetensors, adapter_config.json)
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// LoRA rank
    #[arg(long, value_name = "R", default_value_t = Config::default().rank)]
    pub rank: usize,
    /// LoRA alpha (the update is scaled by alpha / rank; the paper's r = alpha = 16)
    #[arg(long, default_value_t = Config::default().alpha)]
    pub alpha: f32,
    /// Projections to adapt, from q,k,v,o,gate,up,down
    #[arg(long, value_delimiter = ',', default_value = "q,k,v,o,gate,up,down")]
    pub targets: Vec<String>,
    /// AdamW's learning rate
    #[arg(long, default_value_t = Config::default().learning_rate)]
    pub lr: f64,
    /// Passes over the examples
    #[arg(long, value_name = "N", default_value_t = Config::default().epochs)]
    pub epochs: usize,
    /// Tokens per example (longer answers are cut, with a warning)
    #[arg(long, value_name = "N", default_value_t = Config::default().max_len)]
    pub max_len: usize,
    /// Examples per optimizer step (gradients averaged)
    #[arg(long, value_name = "N", default_value_t = Config::default().accumulate)]
    pub accumulate: usize,
    /// Seed of the initialisation and of the examples' order
    #[arg(long, default_value_t = Config::default().seed)]
    pub seed: u64,
    /// Write a checkpoint every N steps (0: never)
    #[arg(long, value_name = "N", default_value_t = Config::default().checkpoint_every)]
    pub checkpoint_every: usize,
    /// Continue from the checkpoint in the output directory
    #[arg(long)]
    pub resume: bool,
    /// Keep every layer's graph for the backward pass instead of recomputing each layer:
    /// faster, more memory
    #[arg(long)]
    pub keep_graph: bool,
    /// Read the tokens every example begins with (a shared system message) once, with the
    /// base model, and hold their keys and values fixed: each example costs only its own
    /// tokens
    #[arg(long)]
    pub frozen_prefix: bool,
    /// Start from the adapter in DIR (the same rank, alpha and targets) instead of from the
    /// base model: train it further on new examples
    #[arg(long, value_name = "DIR")]
    pub from: Option<PathBuf>,
    /// The local model to adapt
    #[arg(long, default_value = tad_local::ALIGN_DEFAULT)]
    pub model: String,
}

/// The files a directory of examples is looked in for, in order: `sft-export`'s two forms
/// (either holds the same examples), then TRL's usual name.
const DATA_FILES: [&str; 3] = ["messages.jsonl", "prompt_completion.jsonl", "train.jsonl"];

/// The examples' file: `data` itself, or the first of [`DATA_FILES`] in it.
fn data_file(data: &Path) -> Result<PathBuf, String> {
    if !data.is_dir() {
        return Ok(data.to_path_buf());
    }
    DATA_FILES.iter().map(|name| data.join(name)).find(|file| file.is_file()).ok_or_else(|| {
        format!("`{}` holds none of {}", data.display(), DATA_FILES.map(|name| format!("`{name}`")).join(", "))
    })
}

impl FinetuneArgs {
    fn config(&self) -> Result<Config, String> {
        let mut targets = Vec::new();
        for name in &self.targets {
            let t = Target::parse(name.trim())
                .ok_or_else(|| format!("unknown target `{name}` (the targets are q, k, v, o, gate, up, down)"))?;
            targets.push(t);
        }
        if self.rank == 0 || self.epochs == 0 || self.max_len < 2 || targets.is_empty() {
            return Err("--rank, --epochs and --targets must not be zero or empty, --max-len at least 2".into());
        }
        if !(self.lr.is_finite() && self.lr > 0.0 && self.alpha.is_finite()) {
            return Err("--lr must be a positive number and --alpha a number".into());
        }
        Ok(Config {
            rank: self.rank,
            alpha: self.alpha,
            targets,
            learning_rate: self.lr,
            epochs: self.epochs,
            max_len: self.max_len,
            accumulate: self.accumulate.max(1),
            seed: self.seed,
            checkpoint_every: self.checkpoint_every,
            resume: self.resume,
            recompute: !self.keep_graph,
            frozen_prefix: self.frozen_prefix,
            // read before the model: a bad adapter is reported at once
            from: self.from.as_deref().map(tad_finetune::Adapter::load).transpose()?,
            ..Config::default()
        })
    }
}

/// Runs `tadslc finetune`: 0 when the adapter is written, 2 for a usage or I/O error (bad
/// flags, unreadable examples, no model, a checkpoint of another run), 1 when training fails.
pub fn run(args: &FinetuneArgs) -> Result<Status, CliError> {
    let config = args.config().map_err(CliError::usage)?;
    let file = data_file(&args.data).map_err(CliError::usage)?;
    let text = std::fs::read_to_string(&file)
        .map_err(|e| CliError::usage(format!("cannot read `{}`: {e}", file.display())))?;
    let examples = tad_finetune::read_jsonl(&text).map_err(|e| CliError::usage(format!("{}: {e}", file.display())))?;
    if examples.is_empty() {
        return Err(CliError::usage(format!("{} holds no examples", file.display())));
    }
    let model = tad_local::model(&args.model)
        .ok_or_else(|| CliError::usage(format!("unknown local model `{}`", args.model)))?;
    let gguf = model.require().map_err(CliError::usage)?;
    let config = Config { base_model: model.upstream.to_string(), ..config };
    let report = train(args, &gguf, &examples, &config).map_err(|e| match e {
        // what could not be read or written, or set up, is the caller's to fix
        FinetuneError::Setup(_) | FinetuneError::Io(_) => CliError::usage(e),
        FinetuneError::Training(_) => CliError::failed(e),
    })?;
    for w in &report.warnings {
        errln!("warning: {w}")?;
    }
    if report.prefix > 0 {
        errln!("a prefix of {} tokens shared by every example was read once and held fixed", report.prefix)?;
    }
    if let Some(step) = report.resumed_at {
        errln!("resumed after step {step}")?;
    }
    let first = report.losses.first().copied().unwrap_or(f32::NAN);
    let last = report.losses.last().copied().unwrap_or(f32::NAN);
    outln!(
        "wrote the adapter to `{}`: {} examples, {} steps, loss {first:.4} -> {last:.4}, {:.1} tokens/s",
        report.adapter.display(),
        report.examples,
        report.steps,
        report.tokens_per_s
    )?;
    Ok(Status::Ok)
}

/// Training with a progress bar at a terminal, a line per step elsewhere.
fn train(
    args: &FinetuneArgs,
    gguf: &Path,
    examples: &[tad_finetune::Example],
    config: &Config,
) -> Result<tad_finetune::Report, FinetuneError> {
    let mut progress: Option<indicatif::ProgressBar> = None;
    let terminal = {
        use std::io::IsTerminal;
        std::io::stderr().is_terminal()
    };
    let result = tad_finetune::train(gguf, examples, config, &args.out, &mut |p: &Progress| {
        let bar = progress.get_or_insert_with(|| crate::output::progress(p.steps, "steps"));
        bar.set_position(p.step as u64);
        bar.set_message(format!("epoch {} loss {:.4} {:.0} tokens/s", p.epoch + 1, p.loss, p.tokens_per_s));
        if !terminal {
            let _ = errln!(
                "step {}/{} epoch {} loss {:.4} {:.1} tokens/s",
                p.step,
                p.steps,
                p.epoch + 1,
                p.loss,
                p.tokens_per_s
            );
        }
        if let Some(dir) = &p.checkpoint {
            bar.suspend(|| errln!("checkpoint: `{}`", dir.display())).ok();
        }
    });
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    result
}
