//! `tadslc bench --align`: the recovery experiment.
//!
//! For each labelled synthetic region ([`tad_eval::synthetic::SYNTHETIC`]) a training sample and
//! a held-out sample are drawn with different seeds; the fitted generator is fitted to the
//! training sample and generates as many scenarios. Each generator's output is compared
//! with the held-out sample: the fitted generator of the region itself, the fitted
//! generators of the other regions, and the unaligned baseline (the region-agnostic
//! generator of [`tad_eval::baseline`], which knows the language but not the region).
//! Extra corpora (a language model's, a fine-tuned model's) are compared the same way
//! when given as `--corpus LABEL=REGION:DIR`. Every corpus is written under `--out`, so
//! `tadslc compare` can look again.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::align::{self, Embedding, FittedGen};
use crate::output::Closed;
use crate::{Status, errln, outln};
use tad_eval::synthetic::{self, SYNTHETIC};

pub struct AlignArgs {
    pub n: usize,
    pub seed: u64,
    pub resamples: usize,
    pub embedding: Embedding,
    pub out: PathBuf,
    /// `(label, region label, dir)`: more corpora to compare with a region's held-out set.
    pub extra: Vec<(String, String, PathBuf)>,
    pub json: bool,
}

/// `LABEL=REGION:DIR`.
pub fn parse_extra(s: &str) -> Result<(String, String, PathBuf), String> {
    let (label, rest) = s.split_once('=').ok_or("expected LABEL=REGION:DIR")?;
    let (region, dir) = rest.split_once(':').ok_or("expected LABEL=REGION:DIR")?;
    if synthetic::synthetic(region).is_none() {
        let labels: Vec<&str> = SYNTHETIC.iter().map(|r| r.label).collect();
        return Err(format!("no synthetic region `{region}` (there are {})", labels.join(", ")));
    }
    Ok((label.to_string(), region.to_string(), PathBuf::from(dir)))
}

/// One generator's distances to one region's held-out sample.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub region: String,
    pub generator: String,
    pub comparison: tad_stats::Comparison,
}

fn write_all(dir: &Path, texts: &[String], stem: &str) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for (i, t) in texts.iter().enumerate() {
        let path = dir.join(format!("{stem}_{i:03}.tad"));
        std::fs::write(&path, t).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(())
}

/// Runs the experiment; the rows in region order, the region's own generator first.
pub fn experiment(args: &AlignArgs, status: &mut Status) -> Result<Result<Vec<Row>, String>, Closed> {
    let mut corpora: Vec<(String, String, PathBuf)> = Vec::new(); // (region, generator, dir)
    for (k, region) in SYNTHETIC.iter().enumerate() {
        let base = args.out.join(region.label);
        let seed = args.seed.wrapping_add(1000 * k as u64);
        if let Err(e) = write_all(&base.join("train"), &region.sample(args.n, seed), "train")
            .and_then(|_| write_all(&base.join("heldout"), &region.sample(args.n, seed.wrapping_add(500)), "heldout"))
        {
            return Ok(Err(e));
        }
        let model = base.join("fitted.model");
        let s = align::fit(&[base.join("train")], &model);
        if s != Status::Ok {
            return Ok(Err(format!("fitting {} failed", region.label)));
        }
        let _ = std::fs::remove_dir_all(base.join("fitted"));
        let s = align::generate_fitted(&FittedGen {
            model: &model,
            n: args.n,
            seed: seed.wrapping_add(7),
            out: Some(&base.join("fitted")),
            attempts: 50,
        });
        *status = (*status).max(s);
        corpora.push((region.label.to_string(), "fitted".into(), base.join("fitted")));
    }
    let uniform = args.out.join("unaligned");
    if let Err(e) = write_all(&uniform, &unaligned(args.n, args.seed.wrapping_add(99)), "unaligned") {
        return Ok(Err(e));
    }
    let mut rows = Vec::new();
    let mut loaded: std::collections::BTreeMap<PathBuf, Vec<tad_stats::Features>> = Default::default();
    for region in SYNTHETIC {
        let heldout = load(&args.out.join(region.label).join("heldout"), status)?;
        let mut generators: Vec<(String, PathBuf)> = Vec::new();
        for (r, g, dir) in &corpora {
            let label = if r == region.label { g.clone() } else { format!("fitted on {r}") };
            generators.push((label, dir.clone()));
        }
        // the region's own generator first
        generators.sort_by_key(|(label, _)| label != "fitted");
        for (label, r, dir) in &args.extra {
            if r == region.label {
                generators.push((label.clone(), dir.clone()));
            }
        }
        generators.push(("unaligned baseline".into(), uniform.clone()));
        for (label, dir) in generators {
            if !loaded.contains_key(&dir) {
                let corpus = load(&dir, status)?;
                loaded.insert(dir.clone(), corpus);
            }
            let generated = &loaded[&dir];
            if generated.is_empty() {
                continue;
            }
            let embedded = match align::embed(args.embedding, generated, &heldout) {
                Ok(e) => e,
                Err(e) => return Ok(Err(e)),
            };
            let comparison = tad_stats::compare(
                (&label, generated),
                (&format!("{} held-out", region.label), &heldout),
                embedded.as_ref().map(|(model, a, b)| tad_stats::compare::Embeddings { model: model.clone(), a, b }),
                tad_stats::Options { resamples: args.resamples, seed: args.seed },
            );
            rows.push(Row { region: region.label.to_string(), generator: label, comparison });
        }
    }
    Ok(Ok(rows))
}

/// `n` scenarios of the baseline generator that count.
fn unaligned(n: usize, seed: u64) -> Vec<String> {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    tad_eval::baseline::sample(&mut db, n, seed, |i| format!("unaligned_{i}")).into_iter().map(|(_, t)| t).collect()
}

fn load(dir: &Path, status: &mut Status) -> Result<Vec<tad_stats::Features>, Closed> {
    let corpus = align::load(std::slice::from_ref(&dir.to_path_buf()), status)?;
    Ok(corpus.items.into_iter().map(|i| i.features).collect())
}

pub fn run(args: &AlignArgs) -> Status {
    crate::output::run(|status| {
        let rows = match experiment(args, status)? {
            Ok(rows) => rows,
            Err(e) => {
                *status = Status::Usage;
                errln!("error: {e}")?;
                return Ok(());
            }
        };
        if args.json {
            outln!("{}", serde_json::to_string_pretty(&rows).unwrap_or_default())?;
            return Ok(());
        }
        outln!("{}", table(&rows))?;
        Ok(())
    })
}

/// The rows as Markdown: each distance with its interval, and how many times farther the
/// unaligned baseline is than the region's own fitted generator.
pub fn table(rows: &[Row]) -> String {
    let fmt = |i: &tad_stats::Interval| format!("{:.4} [{:.4}, {:.4}]", i.value, i.low, i.high);
    let embedding = rows.iter().find_map(|r| r.comparison.embedding.clone());
    let mut out = String::from("| region | generator | scenarios | JSD mean | actors W1 |");
    if let Some(e) = &embedding {
        out.push_str(&format!(" MMD² ({e}) | Fréchet ({e}) |"));
    }
    out.push_str("\n|---|---|---:|---|---|");
    if embedding.is_some() {
        out.push_str("---|---|");
    }
    out.push('\n');
    for r in rows {
        let c = &r.comparison;
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} |",
            r.region,
            r.generator,
            c.scenarios[0],
            fmt(&c.jsd["mean"]),
            fmt(&c.actor_count_wasserstein)
        ));
        if let (Some(m), Some(f)) = (&c.mmd, &c.frechet) {
            out.push_str(&format!(" {} | {} |", fmt(m), fmt(f)));
        }
        out.push('\n');
    }
    out.push_str("\nbaseline ÷ fitted (how many times closer the region's fitted generator is):\n\n| region | JSD mean | actors W1 | MMD² | Fréchet |\n|---|---:|---:|---:|---:|\n");
    for region in SYNTHETIC {
        let find = |g: &str| rows.iter().find(|r| r.region == region.label && r.generator == g);
        let (Some(f), Some(b)) = (find("fitted"), find("unaligned baseline")) else { continue };
        let ratio = |x: Option<f64>, y: Option<f64>| match (x, y) {
            (Some(x), Some(y)) if y > 0.0 => format!("{:.1}×", x / y),
            // an unbiased MMD² at or below 0: no difference measured at all
            (Some(x), Some(_)) if x > 0.0 => "∞".into(),
            _ => "–".into(),
        };
        let (fc, bc) = (&f.comparison, &b.comparison);
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            region.label,
            ratio(Some(bc.jsd["mean"].value), Some(fc.jsd["mean"].value)),
            ratio(Some(bc.actor_count_wasserstein.value), Some(fc.actor_count_wasserstein.value)),
            ratio(bc.mmd.map(|i| i.value), fc.mmd.map(|i| i.value)),
            ratio(bc.frechet.map(|i| i.value), fc.frechet.map(|i| i.value)),
        ));
    }
    out
}
