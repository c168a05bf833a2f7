//! Corpora and alignment: `tadslc stats`, `compare`, `fit`, `gen --generator fitted:` and
//! `sft-export`.
//!
//! A corpus is a directory (or file) of scenarios. Every file is checked through the
//! database; only scenarios without errors (complete or incomplete) count, the others are
//! reported once and skipped. `tad-stats` counts and compares them, `tad-fit` fits and
//! samples the generator, `tad-embed` gives compare its sentence embeddings.

use std::path::{Path, PathBuf};

use serde::Serialize;
use tad_check::{Class, Options};
use tad_db::Database;
use tad_eval::Corpus;
use tad_stats::{Features, Stats};

use crate::files::{self, Search};
use crate::output::Closed;
use crate::{Status, errln, out, outln, plural};

/// The corpus's name: the directory's or file's name.
fn corpus_name(path: &Path) -> String {
    let base = if path.is_dir() { path.file_name() } else { path.file_stem() };
    base.map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string())
}

/// Every scenario under `paths` that counts, as one corpus named after the first; files
/// that cannot be read are reported.
pub fn read(paths: &[PathBuf], status: &mut Status) -> Result<Corpus, Closed> {
    let name = paths.first().map(|p| corpus_name(p)).unwrap_or_default();
    let sources = files::load(paths, Search::Scenarios, status)?
        .into_iter()
        .map(|input| tad_eval::corpus::Source {
            path: input.path.unwrap_or_else(|| PathBuf::from(input.name)),
            text: input.text,
        })
        .collect();
    Ok(Corpus::new(name, sources))
}

/// [`read`], then a note on the files that did not count and an error when none did.
pub fn load(paths: &[PathBuf], status: &mut Status) -> Result<Corpus, Closed> {
    let corpus = read(paths, status)?;
    report(corpus, status)
}

/// A note on `corpus`'s files that did not count, and an error (status 2) when none did.
pub fn report(corpus: Corpus, status: &mut Status) -> Result<Corpus, Closed> {
    if corpus.skipped() > 0 {
        errln!(
            "note: corpus `{}`: {} skipped ({} with errors, {} not scenarios; `tadslc check` says why)",
            corpus.name,
            plural(corpus.skipped(), "file"),
            corpus.invalid,
            corpus.non_scenarios
        )?;
    }
    if corpus.items.is_empty() {
        *status = (*status).max(Status::Usage);
        errln!("error: corpus `{}` has no valid scenario", corpus.name)?;
    }
    Ok(corpus)
}

fn unique_names(corpora: &mut [Corpus]) {
    for i in 0..corpora.len() {
        let taken = corpora[..i].iter().filter(|c| c.name == corpora[i].name).count();
        if taken > 0 {
            corpora[i].name = format!("{}#{}", corpora[i].name, taken + 1);
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TableFormat {
    /// Markdown tables
    Table,
    Csv,
    Json,
}

pub struct StatsArgs<'a> {
    pub corpora: &'a [PathBuf],
    pub format: TableFormat,
    pub plot: Option<&'a Path>,
}

/// `tadslc stats DIR...`: each directory is a corpus.
pub fn stats(args: &StatsArgs) -> Status {
    crate::output::run(|status| {
        let mut corpora = Vec::new();
        for path in args.corpora {
            corpora.push(load(std::slice::from_ref(path), status)?);
        }
        unique_names(&mut corpora);
        corpora.retain(|c| !c.items.is_empty());
        if corpora.is_empty() {
            return Ok(());
        }
        let all: Vec<Stats> = corpora
            .iter()
            .map(|c| Stats::of(&c.name, &c.items.iter().map(|i| i.features.clone()).collect::<Vec<_>>()))
            .collect();
        match args.format {
            TableFormat::Table => out!("{}", tad_stats::stats::markdown(&all))?,
            TableFormat::Csv => out!("{}", tad_stats::stats::csv(&all))?,
            TableFormat::Json => outln!("{}", serde_json::to_string_pretty(&all).unwrap_or_default())?,
        }
        if let Some(dir) = args.plot {
            match plots(dir, &all) {
                Ok(n) => errln!("wrote {} to {}", plural(n, "plot"), dir.display())?,
                Err(e) => {
                    *status = (*status).max(Status::Usage);
                    errln!("error: {e}")?;
                }
            }
        }
        Ok(())
    })
}

fn plots(dir: &Path, all: &[Stats]) -> Result<usize, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut written = 0;
    let mut write = |name: &str, svg: String| -> Result<(), String> {
        let path = dir.join(format!("{name}.svg"));
        std::fs::write(&path, svg).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        written += 1;
        Ok(())
    };
    for a in tad_stats::ATTRIBUTES {
        let sets: Vec<(&str, &tad_stats::stats::Histogram)> =
            all.iter().map(|s| (s.corpus.as_str(), &s.histograms[a.key])).collect();
        write(a.key, tad_stats::plot::bars(a.title, &sets, 20))?;
    }
    let counts: Vec<(String, tad_stats::stats::Histogram)> = all
        .iter()
        .map(|s| (s.corpus.clone(), s.actor_counts.iter().map(|(n, c)| (format!("{n:>3}"), *c)).collect()))
        .collect();
    let sets: Vec<(&str, &tad_stats::stats::Histogram)> = counts.iter().map(|(n, h)| (n.as_str(), h)).collect();
    write("actors", tad_stats::plot::bars("Actors per scenario", &sets, 30))?;
    Ok(written)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CompareFormat {
    Table,
    Json,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Embedding {
    /// all-MiniLM-L6-v2 (384 dimensions), the light default
    Minilm,
    /// all-mpnet-base-v2 (768 dimensions), the paper's model
    Mpnet,
    /// The scenarios' attribute shares as a vector: no language model
    Features,
    /// Attribute distances only
    None,
}

pub struct CompareArgs<'a> {
    pub a: &'a [PathBuf],
    pub b: &'a [PathBuf],
    pub embedding: Embedding,
    pub resamples: usize,
    pub seed: u64,
    pub format: CompareFormat,
    pub plot: Option<&'a Path>,
}

/// The model's name and the embeddings of both corpora's scenarios.
pub type Embedded = (String, Vec<Vec<f32>>, Vec<Vec<f32>>);

pub fn embed(kind: Embedding, a: &[Features], b: &[Features]) -> Result<Option<Embedded>, String> {
    match kind {
        Embedding::None => Ok(None),
        Embedding::Features => {
            let vocabulary = tad_stats::features::vocabulary(a.iter().chain(b));
            let f = |s: &[Features]| s.iter().map(|x| tad_stats::features::one_hot(x, &vocabulary)).collect();
            Ok(Some(("attribute shares".into(), f(a), f(b))))
        }
        Embedding::Minilm | Embedding::Mpnet => {
            let name = if kind == Embedding::Minilm { "all-minilm-l6-v2" } else { "all-mpnet-base-v2" };
            let model = tad_models::model(name).ok_or_else(|| format!("no model `{name}`"))?;
            let embedder = tad_embed::Embedder::load(model)
                .map_err(|e| format!("{e}; or compare without a language model: --embedding features"))?;
            let texts = |s: &[Features]| -> Result<Vec<Vec<f32>>, String> {
                let sentences: Vec<&str> = s.iter().map(|x| x.sentence.as_str()).collect();
                let mut out = Vec::with_capacity(sentences.len());
                for chunk in sentences.chunks(32) {
                    out.extend(embedder.embed(chunk)?);
                }
                Ok(out)
            };
            Ok(Some((name.to_string(), texts(a)?, texts(b)?)))
        }
    }
}

/// `tadslc compare A B`.
pub fn compare(args: &CompareArgs) -> Status {
    crate::output::run(|status| {
        let mut corpora = vec![load(args.a, status)?, load(args.b, status)?];
        unique_names(&mut corpora);
        if corpora.iter().any(|c| c.items.is_empty()) {
            return Ok(());
        }
        let features: Vec<Vec<Features>> =
            corpora.iter().map(|c| c.items.iter().map(|i| i.features.clone()).collect()).collect();
        let embedded = match embed(args.embedding, &features[0], &features[1]) {
            Ok(e) => e,
            Err(e) => {
                *status = Status::Usage;
                errln!("error: {e}")?;
                return Ok(());
            }
        };
        let comparison = tad_stats::compare(
            (&corpora[0].name, &features[0]),
            (&corpora[1].name, &features[1]),
            embedded.as_ref().map(|(model, a, b)| tad_stats::compare::Embeddings { model: model.clone(), a, b }),
            tad_stats::Options { resamples: args.resamples, seed: args.seed },
        );
        match args.format {
            CompareFormat::Table => out!("{}", comparison.markdown())?,
            CompareFormat::Json => outln!("{}", serde_json::to_string_pretty(&comparison).unwrap_or_default())?,
        }
        if let Some(path) = args.plot {
            let Some((model, a, b)) = &embedded else {
                *status = Status::Usage;
                errln!("error: --plot needs embeddings (not --embedding none)")?;
                return Ok(());
            };
            let pooled: Vec<Vec<f32>> = a.iter().chain(b).cloned().collect();
            let projected = tad_stats::plot::pca(&pooled);
            let (pa, pb) = projected.split_at(a.len());
            let svg = tad_stats::plot::scatter(
                &format!("{} embeddings, first two principal components", model),
                &[(&corpora[0].name, pa.to_vec()), (&corpora[1].name, pb.to_vec())],
            );
            if let Err(e) = std::fs::write(path, svg) {
                *status = Status::Usage;
                errln!("error: cannot write {}: {e}", path.display())?;
            }
        }
        Ok(())
    })
}

/// `tadslc fit DIR... -o FILE`.
pub fn fit(paths: &[PathBuf], output: &Path) -> Status {
    crate::output::run(|status| {
        let corpus = load(paths, status)?;
        if corpus.items.is_empty() {
            return Ok(());
        }
        let (fitted, fitted_from) = tad_eval::generator::fit(corpus.items.iter());
        if let Err(e) = tad_frontend::store::write_atomic(output, fitted.to_json().as_bytes()) {
            *status = Status::Usage;
            errln!("error: cannot write {}: {e}", output.display())?;
            return Ok(());
        }
        errln!(
            "fitted {} of {} ({} fields, region {}) into {}",
            plural(fitted_from, "scenario"),
            corpus.name,
            fitted.tables.len(),
            fitted.region.as_deref().unwrap_or("none"),
            output.display()
        )?;
        Ok(())
    })
}

pub struct FittedGen<'a> {
    pub model: &'a Path,
    pub n: usize,
    pub seed: u64,
    pub out: Option<&'a Path>,
    /// Draws per scenario before giving up on it.
    pub attempts: usize,
}

#[derive(Serialize)]
struct GenSummary<'a> {
    generator: String,
    region: Option<&'a str>,
    requested: usize,
    generated: usize,
    complete: usize,
    incomplete: usize,
    draws: usize,
    rejected: usize,
    seed: u64,
}

/// `tadslc gen --generator fitted:MODEL`: item `i` is drawn with seed `seed + i`, again
/// until it checks without errors (at most `attempts` draws).
pub fn generate_fitted(g: &FittedGen) -> Status {
    crate::output::run(|status| {
        let fitted = match std::fs::read_to_string(g.model)
            .map_err(|e| format!("cannot read {}: {e}", g.model.display()))
            .and_then(|t| tad_fit::Fitted::from_json(&t).map_err(|e| format!("{}: {e}", g.model.display())))
        {
            Ok(f) => f,
            Err(e) => {
                *status = Status::Usage;
                errln!("error: {e}")?;
                return Ok(());
            }
        };
        let region = fitted.region.clone();
        let stem = region.clone().unwrap_or_else(|| corpus_name(g.model));
        let mut db = Database::new(Options::default());
        let mut summary = GenSummary {
            generator: format!("fitted:{}", g.model.display()),
            region: region.as_deref(),
            requested: g.n,
            generated: 0,
            complete: 0,
            incomplete: 0,
            draws: 0,
            rejected: 0,
            seed: g.seed,
        };
        for i in 0..g.n {
            let seed = g.seed.wrapping_add(i as u64);
            let name = format!("{stem}_fitted_{:03}", i + 1);
            let (accepted, draws) = tad_eval::generator::draw_fitted(&mut db, &fitted, &name, seed, g.attempts);
            summary.draws += draws;
            summary.rejected += draws - usize::from(accepted.is_some());
            let Some((text, class)) = accepted else {
                *status = (*status).max(Status::Failed);
                errln!("warning: scenario {} not generated: {} drawn, none valid", i + 1, g.attempts)?;
                continue;
            };
            summary.generated += 1;
            if class == Class::Complete {
                summary.complete += 1;
            } else {
                summary.incomplete += 1;
            }
            let provenance = tad_frontend::Provenance {
                comments: vec![format!(
                    "generated by tadslc {} from the fitted model {} ({} scenarios), seed {seed}",
                    env!("CARGO_PKG_VERSION"),
                    g.model.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                    fitted.scenarios
                )],
                region: region.clone(),
                ..Default::default()
            };
            let program = tad_frontend::with_provenance(&text, &provenance);
            match g.out {
                Some(dir) => {
                    let path = dir.join(format!("{name}.tad"));
                    if let Err(e) = tad_frontend::store::write_atomic(&path, program.as_bytes()) {
                        *status = Status::Usage;
                        errln!("error: cannot write {}: {e}", path.display())?;
                        return Ok(());
                    }
                }
                None => out!("{program}\n")?,
            }
        }
        if let Some(dir) = g.out {
            let json = serde_json::to_string_pretty(&summary).unwrap_or_default();
            if let Err(e) = tad_frontend::store::write_atomic(&dir.join("summary.json"), json.as_bytes()) {
                *status = Status::Usage;
                errln!("error: {e}")?;
            }
        }
        errln!(
            "generated {} ({} complete, {} incomplete) from {} draws ({} rejected by the checker)",
            plural(summary.generated, "scenario"),
            summary.complete,
            summary.incomplete,
            summary.draws,
            summary.rejected
        )?;
        Ok(())
    })
}

/// `tadslc sft-export DIR... -o OUT`: the corpus as supervised fine-tuning data, each
/// scenario (the bare program) the answer to the tuned generation prompt
/// (`generate-tuned.v1`): TRL's conversational `messages.jsonl` and prompt/completion
/// `prompt_completion.jsonl`.
pub fn sft_export(paths: &[PathBuf], output: &Path, region: Option<&str>) -> Status {
    crate::output::run(|status| {
        let corpus = load(paths, status)?;
        if corpus.items.is_empty() {
            return Ok(());
        }
        let mut messages = String::new();
        let mut completions = String::new();
        let mut regions = std::collections::BTreeMap::<String, usize>::new();
        for (i, item) in corpus.items.iter().enumerate() {
            let (module, _) = tad_syntax::analyze(&item.tad);
            let written = module
                .scenario
                .as_ref()
                .and_then(|s| s.attr("source", "region"))
                .and_then(|a| a.symbol())
                .map(|s| s.name.clone());
            let Some(r) = region.map(str::to_string).or(written) else {
                errln!("warning: {} states no region (give --region); skipped", item.name)?;
                continue;
            };
            *regions.entry(r.clone()).or_insert(0) += 1;
            let program = tad_frontend::with_provenance(
                &item.tad,
                &tad_frontend::Provenance { region: Some(r.clone()), ..Default::default() },
            );
            let prompt = tad_frontend::generate::tuned_messages(&r, i);
            // the bare program: what the grammar-constrained decoder writes (no code fence)
            let answer = program;
            let json = |m: &tad_llm::Message| serde_json::json!({"role": m.role.name(), "content": m.plain()});
            let prompt_json: Vec<serde_json::Value> = prompt.iter().map(json).collect();
            let assistant = serde_json::json!({"role": "assistant", "content": answer});
            let mut all = prompt_json.clone();
            all.push(assistant.clone());
            messages.push_str(&serde_json::json!({ "messages": all }).to_string());
            messages.push('\n');
            completions.push_str(&serde_json::json!({ "prompt": prompt_json, "completion": [assistant] }).to_string());
            completions.push('\n');
        }
        for (name, text) in [("messages.jsonl", &messages), ("prompt_completion.jsonl", &completions)] {
            if let Err(e) = tad_frontend::store::write_atomic(&output.join(name), text.as_bytes()) {
                *status = Status::Usage;
                errln!("error: cannot write {}: {e}", output.join(name).display())?;
                return Ok(());
            }
        }
        let total: usize = regions.values().sum();
        errln!(
            "wrote {} to {} (messages.jsonl, prompt_completion.jsonl; prompt {}): {}",
            plural(total, "example"),
            output.display(),
            tad_frontend::prompt::GENERATE_TUNED.id,
            regions.iter().map(|(r, n)| format!("{r} {n}")).collect::<Vec<_>>().join(", ")
        )?;
        Ok(())
    })
}
