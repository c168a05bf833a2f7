//! `tadslc`, the TADSL compiler command line.
//!
//! This crate owns everything the core crates must not do: reading and writing files,
//! the terminal, exit codes. Each subcommand lives in its own module of `tadslc::cmd`
//! and returns `Result<Status, CliError>`; `main` only parses arguments, dispatches and
//! turns the result into the exit status.
//!
//! Exit statuses: `tadslc::EXIT_STATUSES`. A closed standard output or error (a broken
//! pipe) stops the output quietly and leaves the status as the run had it
//! (`spec/output.md`).

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use std::process::ExitCode;
use tadslc::cmd;
use tadslc::output::finish;

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
    Check(cmd::check::Args),
    /// Format TAD files in place in the canonical layout
    Fmt(cmd::fmt::Args),
    /// Compile checked scenarios to Scenic 3 programs for a simulator, or to bytecode
    Build(cmd::build::BuildArgs),
    /// Convert a YAML scenario or LLM answer to canonical TAD
    ///
    /// Reads TrafficAlign's YAML form, TrafficComposer's IR, or a whole LLM answer around
    /// one, whatever the file's extension.
    Import(cmd::import::Args),
    /// Print a TAD scenario in TrafficAlign's YAML form
    Export(cmd::export::Args),
    /// Run scenarios in the runtime against ego policies and print SafeBench's metrics
    ///
    /// Scenario files are compiled in memory; `.tadc` files are loaded. Each file, ego and
    /// seed is one episode, its parameters sampled from the seed.
    Run(cmd::run::RunArgs),
    /// Search each scenario's parameters for the scenes that challenge an ego most
    /// (ChatScene's adversarial search) and write them as TAD with the parameters fixed
    ///
    /// Per scenario: 50 scenes sampled in rounds of 10; after each round every parameter's
    /// range is re-fitted to mean ± std of the colliding scenes so far; the 2 kept are the
    /// colliding ones with the lowest OS, then the lowest-OS others. Also writes
    /// `search.json` (ranges by round, collision rates, the chosen scenes).
    Search(cmd::search::SearchArgs),
    /// The paper's results table: generators × egos × SafeBench's ten metrics and OS,
    /// per region
    ///
    /// For each region (default: every region of the corpus with 3 scenarios or more) and
    /// generator: scenarios generated (`fitted` on the region's scenarios, `baseline` the
    /// region-agnostic generator) or taken from a directory, checked, searched against the
    /// search ego (ChatScene's search), and the kept scenes run by every ego.
    Eval(cmd::eval::EvalArgs),
    /// Combine the results files of `eval --shard` (or `run --shard --out`) into one table
    Merge(cmd::merge::Args),
    /// Print the listing of a bytecode program (`.tadc`), checking every byte
    Disasm(cmd::disasm::Args),
    /// Serve the language server protocol on stdin and stdout, for editors
    ///
    /// The packages in `editors/` (VS Code, Neovim, Helix, Emacs) start it; settings come
    /// from the client (`spec/lsp.md`).
    Lsp(cmd::lsp::Args),
    /// Explain a diagnostic code, e.g. `tadslc explain E0203`
    Explain(cmd::explain::Args),
    /// Measure check throughput, or with `--runtime` the runtime against Scenic
    ///
    /// Check throughput is measured on a generated corpus and on the examples, against
    /// serde_json parsing the same scenarios as JSON.
    ///
    /// `--runtime` times 300-step episodes with 1, 14 and 50 actors against Scenic's
    /// Newtonian simulator on the same scenarios, and ChatScene's parameter search over the
    /// safety examples; on one core. `--rl` times PPO's, SAC's and TD3's environment steps
    /// and learning steps against Stable-Baselines3.
    Bench(cmd::bench::Args),
    /// Translate a description into a TAD program with a language model, the compiler in
    /// the loop
    ///
    /// The answer's program is checked; every diagnostic goes back for a corrected program,
    /// an incomplete scenario gets the refinement request, until the program is valid or the
    /// rounds run out. Exit status: 0 complete, 1 invalid or no program, 3 incomplete,
    /// 4 non-scenario, 5 the server could not be used, 2 usage or I/O.
    Translate(cmd::translate::Args),
    /// Turn a driving video (or a directory of frames) into validated scenarios
    ///
    /// A frame every 15 s (ffmpeg), described by a multimodal model, translated, checked,
    /// repaired; incomplete ones described again with the refinement request. One `.tad`
    /// per frame with its provenance, a JSONL manifest; resumable; `--shard i/n` for job arrays.
    Synth(cmd::synth::Args),
    /// Generate scenarios for a region: with the fitted generator, or with a language
    /// model through the same check-and-repair loop
    ///
    /// `--generator fitted:MODEL` samples a model made by `tadslc fit` (no language model,
    /// no GPU; each scenario drawn again until it checks without errors); `--generator llm`
    /// (the default) asks the language model, with the region's examples (aligned), its
    /// name only (`--baseline`), or the short prompt a fine-tuned model learnt (`--tuned`).
    Gen(cmd::generate::Args),
    /// The statistics of corpora: the corpus table and a histogram per attribute
    ///
    /// Each path is one corpus (a directory of scenarios, e.g. one per region); only
    /// scenarios without errors count.
    Stats(cmd::stats::Args),
    /// Distances between two corpora, each with a bootstrap interval
    ///
    /// Jensen-Shannon divergence per attribute (and their mean), the Wasserstein distance of
    /// actors per scenario, and the MMD² and Fréchet distance of sentence embeddings of the
    /// scenarios.
    Compare(cmd::compare::Args),
    /// Fit the generator to a corpus: a probabilistic model of its choices, for
    /// `tadslc gen --generator fitted:MODEL`
    Fit(cmd::fit::Args),
    /// Write a corpus as fine-tuning data: TRL's messages and prompt/completion JSONL
    ///
    /// Each scenario is the answer to the short generation prompt (`generate-tuned.v1`),
    /// which `tadslc gen --tuned` asks; for `tadslc finetune`, or Unsloth and TRL.
    SftExport(cmd::sft_export::Args),
    /// Fine-tune the local model on a corpus with LoRA (in process, on the CPU), saving a
    /// PEFT adapter for `tadslc gen --tuned --adapter DIR`
    ///
    /// The data is what `tadslc sft-export` writes (TRL's messages or prompt/completion
    /// JSONL); the loss is on the answers only. Checkpoints let a stopped run resume.
    Finetune(cmd::finetune::FinetuneArgs),
    /// Train a learned ego with SAC (SafeBench's actor and critics) on scenarios; use it as
    /// `--ego learned:OUT`
    TrainEgo(cmd::train_ego::TrainEgoArgs),
    /// Fetch or list the local models (TADSL's default language model, run in process)
    Model(cmd::model::Args),
    /// Print TAD's grammar for constrained decoding: GBNF (llama.cpp, XGrammar), Lark
    /// (llguidance) or the YAML form's JSON Schema, the vocabulary as closed sets
    Grammar(cmd::grammar::Args),
    /// Print the shell completion script for a shell
    ///
    /// For example `tadslc completions bash > ~/.local/share/bash-completion/completions/tadslc`.
    Completions(cmd::completions::Args),
    /// Print the manual page, or write every page into a directory
    Man(cmd::man::Args),
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Color {
    Auto,
    Always,
    Never,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // the commands that train small networks: before any thread is started
    let trains = match &cli.command {
        Command::TrainEgo(_) | Command::Eval(_) => true,
        Command::Bench(args) => args.rl,
        _ => false,
    };
    if trains {
        tad_train::set_up_threads();
    }
    let color = match cli.color {
        Color::Always => true,
        Color::Never => false,
        Color::Auto => {
            use std::io::IsTerminal;
            std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty()) && std::io::stderr().is_terminal()
        }
    };
    let result = match &cli.command {
        Command::Check(args) => cmd::check::run(args, color),
        Command::Fmt(args) => cmd::fmt::run(args, color),
        Command::Build(args) => cmd::build::run(args, color),
        Command::Import(args) => cmd::import::run(args, color),
        Command::Export(args) => cmd::export::run(args, color),
        Command::Run(args) => cmd::run::run(args, color),
        Command::Search(args) => cmd::search::run(args, color),
        Command::Eval(args) => cmd::eval::run(args),
        Command::Merge(args) => cmd::merge::run(args),
        Command::Disasm(args) => cmd::disasm::run(args),
        Command::Lsp(args) => cmd::lsp::run(args),
        Command::Explain(args) => cmd::explain::run(args),
        Command::Bench(args) => cmd::bench::run(args),
        Command::Translate(args) => cmd::translate::run(args),
        Command::Synth(args) => cmd::synth::run(args),
        Command::Gen(args) => cmd::generate::run(args),
        Command::Stats(args) => cmd::stats::run(args),
        Command::Compare(args) => cmd::compare::run(args),
        Command::Fit(args) => cmd::fit::run(args),
        Command::SftExport(args) => cmd::sft_export::run(args),
        Command::Finetune(args) => cmd::finetune::run(args),
        Command::TrainEgo(args) => cmd::train_ego::run(args, color),
        Command::Model(args) => cmd::model::run(args),
        Command::Grammar(args) => cmd::grammar::run(args),
        Command::Completions(args) => cmd::completions::run(args, Cli::command()),
        Command::Man(args) => cmd::man::run(args, Cli::command()),
    };
    finish(result).into()
}
