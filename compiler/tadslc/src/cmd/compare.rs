//! `tadslc compare`: distances between two corpora (`tad_stats::compare`), each with a
//! bootstrap interval: Jensen-Shannon per attribute, Wasserstein of actors per scenario,
//! MMD² and Fréchet of the scenarios' sentence embeddings (`tad-embed`), and their PCA
//! scatter plot.

use std::path::PathBuf;

use tad_stats::Features;

use crate::corpus;
use crate::output::CliError;
use crate::{Status, out, outln};

/// `tadslc compare`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The first corpus
    pub a: PathBuf,
    /// The second corpus
    pub b: PathBuf,
    /// The embedding model (fetched with `tadslc model fetch NAME`)
    #[arg(long, value_enum, default_value_t = Embedding::Minilm)]
    pub embedding: Embedding,
    /// Bootstrap resamples for the intervals (at most 100,000)
    #[arg(long, value_name = "N", default_value_t = 200, value_parser = crate::count::<100_000>)]
    pub resamples: usize,
    /// Seed of the resampling
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A table, or one JSON object
    #[arg(long, value_enum, default_value_t = CompareFormat::Table)]
    pub format: CompareFormat,
    /// Write both corpora's embeddings projected to 2-D (PCA) as an SVG scatter plot
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
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

pub fn run(args: &Args) -> Result<Status, CliError> {
    let ((a, read_a), (b, read_b)) =
        (corpus::load(std::slice::from_ref(&args.a))?, corpus::load(std::slice::from_ref(&args.b))?);
    let status = read_a.max(read_b);
    let mut corpora = vec![a, b];
    tad_eval::corpus::unique_names(&mut corpora);
    let (a, b) = (corpus::features(&corpora[0]), corpus::features(&corpora[1]));
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
    if let Some(path) = args.plot.as_deref() {
        let Some((model, a, b)) = &embedded else {
            return Err(CliError::usage("--plot needs embeddings (not --embedding none)"));
        };
        let pooled: Vec<Vec<f32>> = a.iter().chain(b).cloned().collect();
        let (projected, explained) = tad_stats::plot::pca_explained(&pooled);
        let (pa, pb) = projected.split_at(a.len());
        let svg = tad_stats::plot::scatter(
            &format!("{} embeddings, first two principal components", model),
            explained,
            &[(&corpora[0].name, pa.to_vec()), (&corpora[1].name, pb.to_vec())],
        );
        std::fs::write(path, svg).map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    }
    Ok(status)
}
