//! Corpora and alignment: `tadslc stats`, `compare`, `fit`, `gen --generator fitted:` and
//! `sft-export`.
//!
//! A corpus is a directory (or file) of scenarios (`tad_eval::corpus`): only scenarios
//! without errors count, the others are noted once and skipped. `tad-stats` counts and
//! compares them, `tad-fit` fits the generator that `tad-eval` draws from, `tad-embed`
//! gives compare its sentence embeddings, `tad-frontend` writes the fine-tuning data.

use std::path::{Path, PathBuf};

use tad_eval::Corpus;
use tad_stats::{Features, Stats};

use crate::output::CliError;
use crate::{Status, errln, out, outln, plural};

/// Every scenario under `paths` that counts, as one corpus, and the status reading it
/// reached: the paths that could not be read are reported and make it 2.
pub fn read(paths: &[PathBuf]) -> Result<(Corpus, Status), CliError> {
    let (corpus, errors) = tad_eval::corpus::read(paths);
    for e in &errors {
        errln!("error: {e}")?;
    }
    Ok((corpus, if errors.is_empty() { Status::Ok } else { Status::Usage }))
}

/// [`read`], then [`counted`].
pub fn load(paths: &[PathBuf]) -> Result<(Corpus, Status), CliError> {
    let (corpus, status) = read(paths)?;
    Ok((counted(corpus)?, status))
}

/// `corpus`, after a note on its files that did not count; a corpus where none did is an
/// error.
pub fn counted(corpus: Corpus) -> Result<Corpus, CliError> {
    if let Some(note) = corpus.skipped_note() {
        errln!("note: {note}")?;
    }
    if corpus.items.is_empty() {
        return Err(CliError::usage(format!("corpus `{}` has no valid scenario", corpus.name)));
    }
    Ok(corpus)
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
    crate::output::finish(stats_in(args))
}

fn stats_in(args: &StatsArgs) -> Result<Status, CliError> {
    let mut status = Status::Ok;
    let mut corpora = Vec::new();
    for path in args.corpora {
        match load(std::slice::from_ref(path)) {
            Ok((corpus, read)) => {
                status = status.max(read);
                corpora.push(corpus);
            }
            // the other corpora are still counted
            Err(CliError::Exit(s, message)) => {
                status = status.max(s);
                errln!("error: {message}")?;
            }
            Err(e) => return Err(e),
        }
    }
    tad_eval::corpus::unique_names(&mut corpora);
    if corpora.is_empty() {
        return Ok(status);
    }
    let all: Vec<Stats> = corpora.iter().map(|c| Stats::of(&c.name, &features(c))).collect();
    match args.format {
        TableFormat::Table => out!("{}", tad_stats::stats::markdown(&all))?,
        TableFormat::Csv => out!("{}", tad_stats::stats::csv(&all))?,
        TableFormat::Json => outln!("{}", serde_json::to_string_pretty(&all).unwrap_or_default())?,
    }
    if let Some(dir) = args.plot {
        std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create {}: {e}", dir.display())))?;
        let plots = tad_stats::plot::corpora(&all);
        for (name, svg) in &plots {
            let path = dir.join(format!("{name}.svg"));
            std::fs::write(&path, svg).map_err(|e| CliError::usage(format!("cannot write {}: {e}", path.display())))?;
        }
        errln!("wrote {} to {}", plural(plots.len(), "plot"), dir.display())?;
    }
    Ok(status)
}

fn features(corpus: &Corpus) -> Vec<Features> {
    corpus.items.iter().map(|i| i.features.clone()).collect()
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
    crate::output::finish(compare_in(args))
}

fn compare_in(args: &CompareArgs) -> Result<Status, CliError> {
    let ((a, read_a), (b, read_b)) = (load(args.a)?, load(args.b)?);
    let status = read_a.max(read_b);
    let mut corpora = vec![a, b];
    tad_eval::corpus::unique_names(&mut corpora);
    let (a, b) = (features(&corpora[0]), features(&corpora[1]));
    let embedded = embed(args.embedding, &a, &b).map_err(CliError::usage)?;
    let comparison = tad_stats::compare(
        (&corpora[0].name, &a),
        (&corpora[1].name, &b),
        embedded.as_ref().map(|(model, a, b)| tad_stats::compare::Embeddings { model: model.clone(), a, b }),
        tad_stats::Options { resamples: args.resamples, seed: args.seed },
    );
    match args.format {
        CompareFormat::Table => out!("{}", comparison.markdown())?,
        CompareFormat::Json => outln!("{}", serde_json::to_string_pretty(&comparison).unwrap_or_default())?,
    }
    if let Some(path) = args.plot {
        let Some((model, a, b)) = &embedded else {
            return Err(CliError::usage("--plot needs embeddings (not --embedding none)"));
        };
        let pooled: Vec<Vec<f32>> = a.iter().chain(b).cloned().collect();
        let projected = tad_stats::plot::pca(&pooled);
        let (pa, pb) = projected.split_at(a.len());
        let svg = tad_stats::plot::scatter(
            &format!("{} embeddings, first two principal components", model),
            &[(&corpora[0].name, pa.to_vec()), (&corpora[1].name, pb.to_vec())],
        );
        std::fs::write(path, svg).map_err(|e| CliError::usage(format!("cannot write {}: {e}", path.display())))?;
    }
    Ok(status)
}

/// `tadslc fit DIR... -o FILE`.
pub fn fit(paths: &[PathBuf], output: &Path) -> Status {
    crate::output::finish(fit_in(paths, output))
}

fn fit_in(paths: &[PathBuf], output: &Path) -> Result<Status, CliError> {
    let (corpus, status) = load(paths)?;
    let (fitted, fitted_from) = tad_eval::generator::fit(corpus.items.iter());
    tad_frontend::store::write_atomic(output, fitted.to_json().as_bytes())
        .map_err(|e| CliError::usage(format!("cannot write {}: {e}", output.display())))?;
    errln!(
        "fitted {} of {} ({} fields, region {}) into {}",
        plural(fitted_from, "scenario"),
        corpus.name,
        fitted.tables.len(),
        fitted.region.as_deref().unwrap_or("none"),
        output.display()
    )?;
    Ok(status)
}

pub struct FittedGen<'a> {
    pub model: &'a Path,
    pub n: usize,
    pub seed: u64,
    pub out: Option<&'a Path>,
    /// Draws per scenario before giving up on it.
    pub attempts: usize,
}

/// `tadslc gen --generator fitted:MODEL`: item `i` is drawn with seed `seed + i`, again
/// until it checks without errors (at most `attempts` draws).
pub fn generate_fitted(g: &FittedGen) -> Status {
    crate::output::finish(generate_fitted_in(g))
}

fn generate_fitted_in(g: &FittedGen) -> Result<Status, CliError> {
    let text = std::fs::read_to_string(g.model)
        .map_err(|e| CliError::usage(format!("cannot read {}: {e}", g.model.display())))?;
    let fitted =
        tad_fit::Fitted::from_json(&text).map_err(|e| CliError::usage(format!("{}: {e}", g.model.display())))?;
    let stem = fitted.region.clone().unwrap_or_else(|| tad_eval::corpus::name_of(g.model));
    let generator = format!("fitted:{}", g.model.display());
    let run =
        tad_eval::generator::Draws { generator: &generator, stem: &stem, n: g.n, seed: g.seed, attempts: g.attempts };
    let mut status = Status::Ok;
    let summary = tad_eval::generator::draw_many(&fitted, &run, |drawn| -> Result<(), CliError> {
        let Some(text) = drawn.text else {
            status = status.max(Status::Failed);
            errln!("warning: scenario {} not generated: {} drawn, none valid", drawn.index + 1, g.attempts)?;
            return Ok(());
        };
        let provenance = tad_frontend::Provenance {
            comments: vec![format!(
                "generated by tadslc {} from the fitted model {} ({} scenarios), seed {}",
                env!("CARGO_PKG_VERSION"),
                g.model.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                fitted.scenarios,
                drawn.seed
            )],
            region: fitted.region.clone(),
            ..Default::default()
        };
        let program = tad_frontend::with_provenance(&text, &provenance);
        match g.out {
            Some(dir) => {
                let path = dir.join(format!("{}.tad", drawn.name));
                tad_frontend::store::write_atomic(&path, program.as_bytes())
                    .map_err(|e| CliError::usage(format!("cannot write {}: {e}", path.display())))?;
            }
            None => out!("{program}\n")?,
        }
        Ok(())
    })?;
    if let Some(dir) = g.out {
        let json = serde_json::to_string_pretty(&summary).unwrap_or_default();
        tad_frontend::store::write_atomic(&dir.join("summary.json"), json.as_bytes()).map_err(CliError::usage)?;
    }
    errln!(
        "generated {} ({} complete, {} incomplete) from {} draws ({} rejected by the checker)",
        plural(summary.generated, "scenario"),
        summary.complete,
        summary.incomplete,
        summary.draws,
        summary.rejected
    )?;
    Ok(status)
}

/// `tadslc sft-export DIR... -o OUT`: the corpus as supervised fine-tuning data
/// (`tad_frontend::sft`).
pub fn sft_export(paths: &[PathBuf], output: &Path, region: Option<&str>) -> Status {
    crate::output::finish(sft_export_in(paths, output, region))
}

fn sft_export_in(paths: &[PathBuf], output: &Path, region: Option<&str>) -> Result<Status, CliError> {
    let (corpus, status) = load(paths)?;
    let examples = corpus.items.iter().map(|item| tad_frontend::sft::Example {
        name: &item.name,
        tad: &item.tad,
        region: item.region.as_deref(),
    });
    let export = tad_frontend::sft::export(examples, region);
    for name in &export.no_region {
        errln!("warning: {name} states no region (give --region); skipped")?;
    }
    for (name, text) in [("messages.jsonl", &export.messages), ("prompt_completion.jsonl", &export.prompt_completion)] {
        let path = output.join(name);
        tad_frontend::store::write_atomic(&path, text.as_bytes())
            .map_err(|e| CliError::usage(format!("cannot write {}: {e}", path.display())))?;
    }
    let total: usize = export.regions.values().sum();
    errln!(
        "wrote {} to {} (messages.jsonl, prompt_completion.jsonl; prompt {}): {}",
        plural(total, "example"),
        output.display(),
        tad_frontend::prompt::GENERATE_TUNED.id,
        export.regions.iter().map(|(r, n)| format!("{r} {n}")).collect::<Vec<_>>().join(", ")
    )?;
    Ok(status)
}
