//! Generation: a ChatML prompt read in chunks ([`crate::llama`]), then a token at a time
//! with the KV cache, argmax at temperature 0 and seeded sampling above it.
//!
//! With a constraint (llguidance's Lark, or a JSON Schema) every step's logits are masked to
//! the tokens that keep the output in the grammar, and the end of the answer is allowed only
//! where the grammar accepts: what comes out parses. The mask is computed before the output
//! projection, which then computes only the allowed tokens' rows (Qwen2.5-Coder-1.5B's
//! untied 151,936-row head is about a sixth of a step's arithmetic). The tokens the grammar
//! forces after a decided one (llguidance's fast-forward: indentation, braces, a field's
//! colon) are not decided one at a time: they are read with that token in one pass.

use std::sync::Arc;
use std::time::Instant;

use candle_core::quantized::gguf_file;
use candle_core::quantized::tokenizer::TokenizerFromGguf;
use candle_core::{Device, Tensor};
use candle_transformers::generation::LogitsProcessor;
use llguidance::api::TopLevelGrammar;
use llguidance::{Matcher, ParserFactory};
use sha2::{Digest, Sha256};
use tad_llm::{Answer, Constraint, Error, ErrorKind, Finish, Part, Request, Usage};
use tokenizers::Tokenizer;
use toktrie::{TokEnv, TokRxInfo, TokTrie, TokenId, TokenizerEnv};

use crate::adapter::Adapter;
use crate::llama::{Cache, Last, Model};
use crate::prompts::PromptStore;

pub struct Engine {
    model: Model,
    /// How many of `held`'s tokens are the last prompt's system message (0: none): a
    /// request that starts with it reads on from the cache cut back to its length, nothing
    /// copied.
    prefix: usize,
    /// The keys and values of the last prompt and answer, from the first position.
    cache: Cache,
    /// The tokens whose keys and values `cache` holds, in order: a prompt that starts with
    /// some of them (a repair round: the last prompt and answer, then the repair) reads on
    /// after them.
    held: Vec<u32>,
    /// The sha256 of what makes this model's outputs what they are: its file, the program,
    /// the adapter, the kernels.
    identity: [u8; 32],
    /// Where system messages' caches are kept between processes, if anywhere.
    store: Option<PromptStore>,
    /// The tokens the adapter was trained to follow as the base model reads them: a
    /// prompt that starts with them reads them without the adapter.
    base_prefix: Vec<u32>,
    tokenizer: Arc<Tokenizer>,
    /// `<|im_end|>`, and the end-of-text token.
    im_end: u32,
    end_of_text: Option<u32>,
    factory: Option<Arc<ParserFactory>>,
    /// Whether forced tokens are read with the sampled one ([`Engine::set_fast_forward`]).
    fast_forward: bool,
    context: usize,
    /// Seconds spent in prefill and decode, and in masks, over the engine's life.
    pub timing: Timing,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Timing {
    /// Prompt tokens read (a cached system message is not read again).
    pub prefill_tokens: u64,
    pub prefill_s: f64,
    pub decode_tokens: u64,
    /// Of the decoded tokens, those the grammar forced (read with the token before them).
    pub forced_tokens: u64,
    pub decode_s: f64,
    pub mask_s: f64,
}

impl Timing {
    /// What was spent after `before`.
    pub fn since(&self, before: &Timing) -> Timing {
        Timing {
            prefill_tokens: self.prefill_tokens - before.prefill_tokens,
            prefill_s: self.prefill_s - before.prefill_s,
            decode_tokens: self.decode_tokens - before.decode_tokens,
            forced_tokens: self.forced_tokens - before.forced_tokens,
            decode_s: self.decode_s - before.decode_s,
            mask_s: self.mask_s - before.mask_s,
        }
    }
}

/// The model file and the program (each's path, size and time: a rebuilt decoder is
/// another), the adapter's numbers and the kernels, hashed: two engines with the same
/// identity compute the same keys and values.
fn identity(path: &std::path::Path, adapter: Option<&Adapter>, kernels: &str) -> [u8; 32] {
    let mut hash = Sha256::new();
    for file in [Some(path.to_path_buf()), std::env::current_exe().ok()].into_iter().flatten() {
        let file = file.canonicalize().unwrap_or(file);
        hash.update(file.to_string_lossy().as_bytes());
        if let Ok(meta) = std::fs::metadata(&file) {
            hash.update(meta.len().to_le_bytes());
            let time = meta.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
            hash.update(time.map_or(0, |t| t.as_nanos()).to_le_bytes());
        }
    }
    hash.update(kernels.as_bytes());
    if let Some(adapter) = adapter {
        hash.update(format!("{} {} {}", adapter.rank, adapter.alpha, adapter.rslora).as_bytes());
        adapter.base_prefix.iter().for_each(|t| hash.update(t.to_le_bytes()));
        for ((layer, target), lora) in &adapter.layers {
            hash.update(format!("{layer} {}", target.module()).as_bytes());
            lora.a.iter().chain(&lora.b).for_each(|x| hash.update(x.to_le_bytes()));
        }
    }
    hash.finalize().into()
}

fn failed(what: &str, e: impl std::fmt::Display) -> Error {
    Error::new(ErrorKind::Server, format!("the local model {what}: {e}"))
}

/// The tokens `matcher` forces next, at most `room` of them, consumed and counted.
fn take_forced(matcher: &mut Matcher, room: usize, timing: &mut Timing) -> Result<Vec<u32>, Error> {
    let mut forced = matcher.compute_ff_tokens();
    forced.truncate(room);
    if !forced.is_empty() {
        matcher.consume_tokens(&forced).map_err(|e| failed("grammar", e))?;
        timing.forced_tokens += forced.len() as u64;
    }
    Ok(forced)
}

/// The tokenizer as llguidance's token environment.
struct Env {
    trie: TokTrie,
    tokenizer: Arc<Tokenizer>,
}

impl TokenizerEnv for Env {
    fn tok_trie(&self) -> &TokTrie {
        &self.trie
    }

    fn tokenize_bytes(&self, s: &[u8]) -> Vec<TokenId> {
        let text = String::from_utf8_lossy(s);
        self.tokenizer.encode(text.as_ref(), false).map(|e| e.get_ids().to_vec()).unwrap_or_default()
    }
}

/// The GGUF's tokenizer as candle builds it from `tokenizer.ggml.pre` (Qwen2's split
/// and byte level), or with SmolLM2's pre-tokenizer for its `smollm` (digits one by one,
/// byte-level without a prefix space), which candle does not know.
pub fn tokenizer(content: &gguf_file::Content) -> Result<Tokenizer, String> {
    let mut tokenizer = Tokenizer::from_gguf(content).map_err(|e| e.to_string())?;
    let pre = content.metadata.get("tokenizer.ggml.pre").and_then(|v| v.to_string().ok()).map(String::as_str);
    if matches!(pre, None | Some("smollm")) {
        use tokenizers::pre_tokenizers::{byte_level::ByteLevel, digits::Digits, sequence::Sequence};
        tokenizer.with_pre_tokenizer(Some(Sequence::new(vec![
            Digits::new(true).into(),
            ByteLevel::new(false, true, false).into(),
        ])));
    }
    Ok(tokenizer)
}

/// ChatML's tokens as the local model reads them: `turns` as `(role, text)`, then the
/// opening of the assistant's turn; also how many tokens the first turn takes. What the
/// model answers after them ends with `<|im_end|>`.
pub fn chatml(tokenizer: &Tokenizer, turns: &[(&str, &str)]) -> Result<(Vec<u32>, usize), String> {
    let id = |t: &str| tokenizer.token_to_id(t).ok_or_else(|| format!("the tokenizer has no `{t}`"));
    let (im_start, im_end) = (id("<|im_start|>")?, id("<|im_end|>")?);
    let encode = |text: &str| -> Result<Vec<u32>, String> {
        Ok(tokenizer.encode(text, false).map_err(|e| e.to_string())?.get_ids().to_vec())
    };
    let newline = encode("\n")?;
    let mut ids = Vec::new();
    let mut first = 0;
    for (i, (role, text)) in turns.iter().enumerate() {
        ids.push(im_start);
        ids.extend(encode(&format!("{role}\n{text}"))?);
        ids.push(im_end);
        ids.extend(&newline);
        if i == 0 {
            first = ids.len();
        }
    }
    ids.push(im_start);
    ids.extend(encode("assistant\n")?);
    Ok((ids, first))
}

impl Engine {
    /// Loads the GGUF file at `path`, to run on `threads` threads.
    pub fn load(path: &std::path::Path, threads: usize) -> Result<Engine, Error> {
        Engine::load_with(path, threads, None)
    }

    /// As [`Engine::load`], with a LoRA adapter applied to the projections it targets.
    pub fn load_with(path: &std::path::Path, threads: usize, adapter: Option<&Adapter>) -> Result<Engine, Error> {
        let mut file =
            std::fs::File::open(path).map_err(|e| failed(&format!("cannot be read from `{}`", path.display()), e))?;
        let content = gguf_file::Content::read(&mut file).map_err(|e| failed("is not a GGUF file", e))?;
        let tokenizer = tokenizer(&content).map_err(|e| failed("has no usable tokenizer", e))?;
        let mut model = Model::load(&content, &mut file, threads).map_err(|e| failed("cannot be loaded", e))?;
        if let Some(adapter) = adapter {
            model.attach(adapter).map_err(|e| {
                Error::new(ErrorKind::Request, format!("the adapter does not fit the local model: {e}"))
            })?;
        }
        let identity = identity(path, adapter, model.kernels());
        let context = model.shape.context;
        let cache = model.new_cache();
        let id = |t: &str| tokenizer.token_to_id(t);
        let (Some(_), Some(im_end)) = (id("<|im_start|>"), id("<|im_end|>")) else {
            return Err(failed("has no ChatML tokens", "<|im_start|>/<|im_end|> missing"));
        };
        let end_of_text = id("<|endoftext|>");
        Ok(Engine {
            model,
            prefix: 0,
            held: Vec::new(),
            cache,
            identity,
            store: None,
            base_prefix: adapter.map(|a| a.base_prefix.clone()).unwrap_or_default(),
            tokenizer: Arc::new(tokenizer),
            im_end,
            end_of_text,
            factory: None,
            fast_forward: true,
            context,
            timing: Timing::default(),
        })
    }

    fn factory(&mut self) -> Result<Arc<ParserFactory>, Error> {
        if let Some(f) = &self.factory {
            return Ok(f.clone());
        }
        let json: serde_json::Value =
            serde_json::from_str(&self.tokenizer.to_string(false).map_err(|e| failed("tokenizer", e))?)
                .map_err(|e| failed("tokenizer", e))?;
        let mut words = llguidance::token_bytes_from_tokenizer_json(&json).map_err(|e| failed("tokenizer", e))?;
        let vocab = self.tokenizer.get_vocab_size(true).max(words.len());
        words.resize(vocab, Vec::new());
        let info = TokRxInfo::new(vocab as u32, self.im_end);
        let env: TokEnv = Arc::new(Env { trie: TokTrie::from(&info, &words), tokenizer: self.tokenizer.clone() });
        let factory = Arc::new(ParserFactory::new_simple(&env).map_err(|e| failed("grammar engine", e))?);
        self.factory = Some(factory.clone());
        Ok(factory)
    }

    /// The prompt's tokens (ChatML turns, then the opening of the assistant's), and how
    /// many of them are the first message's.
    fn prompt(&self, request: &Request) -> Result<(Vec<u32>, usize), Error> {
        let mut turns = Vec::new();
        for message in &request.messages {
            let mut text = String::new();
            for part in &message.parts {
                match part {
                    Part::Text(t) => text.push_str(t),
                    Part::Image { .. } => {
                        return Err(Error::new(
                            ErrorKind::Request,
                            "the local model reads text only: describing frames needs a multimodal server",
                        ));
                    }
                }
            }
            turns.push((message.role.name(), text));
        }
        let turns: Vec<(&str, &str)> = turns.iter().map(|(r, t)| (*r, t.as_str())).collect();
        chatml(&self.tokenizer, &turns).map_err(|e| failed("tokenizer", e))
    }

    /// The logits after `tokens`, read from the first position (the cached system
    /// message is dropped).
    pub fn logits(&mut self, tokens: &[u32]) -> Vec<f32> {
        self.prefix = 0;
        self.held.clear();
        self.cache = self.model.new_cache();
        let last = self.read(tokens);
        self.model.logits(&last, None)
    }

    /// The tokens the model reads for `request` (for a peer fed the same input).
    pub fn prompt_tokens(&self, request: &Request) -> Result<Vec<u32>, Error> {
        Ok(self.prompt(request)?.0)
    }

    /// Reads the tokens a grammar forces with the sampled one before them (`true`, the
    /// default), or decides each alone.
    pub fn set_fast_forward(&mut self, on: bool) {
        self.fast_forward = on;
    }

    /// Drops the cached system message and what followed it, so the next prompt is read
    /// whole.
    pub fn forget_prefix(&mut self) {
        self.prefix = 0;
        self.held.clear();
    }

    /// Keeps each new system message's keys and values in `dir` ([`PromptStore`]), and
    /// reads them from there when a prompt starts with one this engine has not read.
    pub fn keep_prompts(&mut self, dir: std::path::PathBuf) {
        self.store = Some(PromptStore::new(dir, self.identity));
    }

    /// Reads `prompt` into the cache and returns its last token's state: from the cached
    /// system message when the prompt starts with it (in memory, else in the store), and
    /// past whatever else of the cache it starts with (the last answer, for a repair), else
    /// from the start, remembering this prompt's first message as the new prefix (and
    /// keeping it in the store). Also returns how many tokens were read.
    fn prefill(&mut self, prompt: &[u32], first: usize) -> (Last, usize) {
        let p = self.prefix;
        let cached = p > 0 && prompt.len() > p && self.held.len() >= p && prompt[..p] == self.held[..p];
        let has_prefix = first > 0 && first < prompt.len();
        let done = if cached {
            // at least the last token is read, for its state
            let same = self.held.iter().zip(prompt).take_while(|(a, b)| a == b).count();
            let done = p.max(same.min(prompt.len() - 1));
            self.cache.truncate(done);
            done
        } else {
            self.prefix = if has_prefix { first } else { 0 };
            let width = self.model.shape.kv_heads * self.model.shape.head_dim;
            let kept = self
                .store
                .as_ref()
                .filter(|_| has_prefix)
                .and_then(|store| store.load(&prompt[..first], self.model.shape.layers, width));
            match kept {
                Some(cache) => {
                    self.cache = cache;
                    first
                }
                None => {
                    self.cache = self.model.new_cache();
                    0
                }
            }
        };
        self.held = prompt[..done].to_vec();
        let last = self.read(&prompt[done..]);
        if done == 0
            && has_prefix
            && let Some(store) = &self.store
        {
            // a cache that cannot be written costs the next process a prefill, nothing more
            let _ = store.save(&prompt[..first], &self.cache);
        }
        (last, prompt.len() - done)
    }

    /// Reads `tokens` after the cache's, noting them as held; those of the adapter's base
    /// prefix (when what is held starts with it) without the adapter.
    fn read(&mut self, tokens: &[u32]) -> Last {
        let start = self.held.len();
        self.held.extend_from_slice(tokens);
        // only a read that begins inside the prefix compares it (not every decoded token)
        let base = match start < self.base_prefix.len() && self.held.starts_with(&self.base_prefix) {
            true => (self.base_prefix.len() - start).min(tokens.len()),
            false => 0,
        };
        if base == 0 {
            return self.model.read(tokens, &mut self.cache);
        }
        let last = self.model.read_base(&tokens[..base], &mut self.cache);
        match base == tokens.len() {
            true => last,
            false => self.model.read(&tokens[base..], &mut self.cache),
        }
    }

    /// The model's weights in memory, and the dot-product kernels chosen for this CPU.
    pub fn describe(&self) -> (usize, &'static str) {
        (self.model.weight_bytes(), self.model.kernels())
    }

    /// Gives `on_text` what `out` decodes to beyond the `emitted` bytes, unless it ends in
    /// an unfinished character; returns the bytes emitted now.
    fn stream_text(&self, out: &[u32], emitted: usize, on_text: &mut dyn FnMut(&str)) -> usize {
        let Ok(text) = self.tokenizer.decode(out, true) else { return emitted };
        match text.get(emitted..) {
            Some(new) if !new.is_empty() && !new.ends_with('\u{FFFD}') => {
                on_text(new);
                text.len()
            }
            _ => emitted,
        }
    }

    /// Answers `request` (`max_tokens`, `temperature`, `seed` and the constraint honoured).
    pub fn generate(&mut self, request: &Request) -> Result<Answer, Error> {
        self.run(request, None)
    }

    /// As [`Engine::generate`], giving `on_text` the answer's text as tokens are decided
    /// (a piece ends on a whole character; the pieces concatenate to the answer's text).
    pub fn generate_streaming(&mut self, request: &Request, on_text: &mut dyn FnMut(&str)) -> Result<Answer, Error> {
        self.run(request, Some(on_text))
    }

    fn run(&mut self, request: &Request, mut on_text: Option<&mut dyn FnMut(&str)>) -> Result<Answer, Error> {
        let (prompt, first) = self.prompt(request)?;
        if prompt.len() + request.max_tokens as usize > self.context {
            return Err(Error::new(
                ErrorKind::ContextOverflow,
                format!(
                    "the prompt ({} tokens) and the answer ({}) exceed the model's context of {}",
                    prompt.len(),
                    request.max_tokens,
                    self.context
                ),
            ));
        }
        let mut matcher = match &request.constraint {
            Constraint::None => None,
            Constraint::Lark(g) => Some(TopLevelGrammar::from_lark(g.clone())),
            Constraint::JsonSchema(s) => Some(TopLevelGrammar::from_json_schema(s.clone())),
            Constraint::Gbnf(_) => {
                return Err(Error::new(
                    ErrorKind::Request,
                    "the local model takes Lark grammars (tadslc grammar --format lark), not GBNF",
                ));
            }
        }
        .map(|grammar| -> Result<Matcher, Error> {
            let factory = self.factory()?;
            let matcher = Matcher::new(factory.create_parser(grammar));
            match matcher.get_error() {
                Some(e) => Err(Error::new(ErrorKind::Request, format!("the grammar: {e}"))),
                None => Ok(matcher),
            }
        })
        .transpose()?;
        let temperature = (request.temperature > 0.0).then_some(request.temperature);
        let mut sampler = LogitsProcessor::new(request.seed.unwrap_or(0), temperature, None);

        let start = Instant::now();
        let (mut last, read) = self.prefill(&prompt, first);
        self.timing.prefill_tokens += read as u64;
        self.timing.prefill_s += start.elapsed().as_secs_f64();

        let decode_start = Instant::now();
        let mut out: Vec<u32> = Vec::new();
        let mut finish = Finish::Length;
        let mut emitted = 0;
        // what the grammar forces at the start is read at once too
        if let Some(m) = matcher.as_mut().filter(|_| self.fast_forward) {
            let forced = take_forced(m, request.max_tokens as usize, &mut self.timing)?;
            if !forced.is_empty() {
                out.extend(&forced);
                last = self.read(&forced);
            }
        }
        while out.len() < request.max_tokens as usize {
            // with a grammar, only the allowed tokens' logits are computed
            let allowed = match matcher.as_mut() {
                Some(m) => {
                    let t = Instant::now();
                    let mask = m.compute_mask().map_err(|e| failed("grammar", e))?;
                    self.timing.mask_s += t.elapsed().as_secs_f64();
                    Some(mask.to_list())
                }
                None => None,
            };
            let row = self.model.logits(&last, allowed.as_deref());
            let masked = Tensor::new(row.as_slice(), &Device::Cpu).map_err(|e| failed("logits", e))?;
            let token = sampler.sample(&masked).map_err(|e| failed("sampling", e))?;
            let end = token == self.im_end || Some(token) == self.end_of_text;
            if let Some(m) = matcher.as_mut() {
                m.consume_token(token).map_err(|e| failed("grammar", e))?;
                if end || m.is_stopped() {
                    finish = Finish::Stop;
                    if !end {
                        out.push(token);
                    }
                    break;
                }
            } else if end {
                finish = Finish::Stop;
                break;
            }
            // the tokens the grammar forces next are read with this one, in one pass
            let mut step = vec![token];
            if let Some(m) = matcher.as_mut().filter(|_| self.fast_forward) {
                let room = (request.max_tokens as usize).saturating_sub(out.len() + 1);
                step.extend(take_forced(m, room, &mut self.timing)?);
            }
            out.extend(&step);
            if let Some(f) = on_text.as_mut() {
                emitted = self.stream_text(&out, emitted, *f);
            }
            if matcher.as_ref().is_some_and(|m| m.is_stopped()) {
                finish = Finish::Stop;
                break;
            }
            if out.len() >= request.max_tokens as usize {
                break;
            }
            last = self.read(&step);
        }
        self.timing.decode_tokens += out.len() as u64;
        self.timing.decode_s += decode_start.elapsed().as_secs_f64();
        let text = self.tokenizer.decode(&out, true).map_err(|e| failed("tokenizer", e))?;
        if let (Some(f), Some(rest)) = (on_text, text.get(emitted..).filter(|r| !r.is_empty())) {
            f(rest);
        }
        Ok(Answer {
            text,
            finish,
            usage: Usage { prompt_tokens: prompt.len() as u64, completion_tokens: out.len() as u64 },
            model: "local".into(),
            attempts: 1,
        })
    }
}
