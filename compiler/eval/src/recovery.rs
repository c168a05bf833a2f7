//! The recovery experiment (`tadslc bench --align`): does the fitted generator recover a
//! region it was fitted to?
//!
//! For each labelled synthetic region ([`SYNTHETIC`]) a training and a held-out sample are
//! drawn with different seeds; the generator fitted to the training sample generates as
//! many scenarios. Each generator's output is compared with the region's held-out sample:
//! the region's own fitted generator first, then the other regions' fitted generators, any
//! extra corpus the host gives (a language model's), and the unaligned baseline (the
//! [`baseline`](crate::baseline) generator, which knows the language, not the region).
//! Everything is in memory and seeded; the host writes the corpora where `tadslc compare`
//! can look again, and gives the embedding of the MMD and Fréchet columns.

use std::path::PathBuf;

use serde::Serialize;
use tad_stats::Features;

use crate::corpus::{Corpus, Source};
use crate::synthetic::SYNTHETIC;

/// One labelled region's corpora (TAD texts).
pub struct RegionCorpora {
    pub label: &'static str,
    pub train: Vec<String>,
    pub heldout: Vec<String>,
    /// What the generator fitted to `train` generated.
    pub fitted: Vec<String>,
}

/// The experiment's corpora: every region's (in [`SYNTHETIC`]'s order), and the unaligned
/// baseline's; `n` scenarios each, from `seed`.
pub struct Corpora {
    pub regions: Vec<RegionCorpora>,
    pub unaligned: Vec<String>,
}

/// Draw every corpus: region `k` from `seed + 1000 k` (held-out `+ 500`, fitted `+ 7`), the
/// baseline from `seed + 99`.
pub fn corpora(n: usize, seed: u64) -> Corpora {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let regions = SYNTHETIC
        .iter()
        .enumerate()
        .map(|(k, region)| {
            let seed = seed.wrapping_add(1000 * k as u64);
            let train = region.sample(n, seed);
            let heldout = region.sample(n, seed.wrapping_add(500));
            let corpus = corpus(region.label, &train);
            let (fitted, _) = crate::generator::fit(corpus.items.iter());
            let stem = fitted.region.clone().unwrap_or_else(|| region.label.to_string());
            let fitted = (0..n)
                .filter_map(|i| {
                    let name = format!("{stem}_fitted_{:03}", i + 1);
                    let seed = seed.wrapping_add(7).wrapping_add(i as u64);
                    crate::generator::draw_fitted(&mut db, &fitted, &name, seed, crate::ATTEMPTS).0.map(|(t, _)| t)
                })
                .collect();
            RegionCorpora { label: region.label, train, heldout, fitted }
        })
        .collect();
    let unaligned = crate::baseline::sample(&mut db, n, seed.wrapping_add(99), |i| format!("unaligned_{i}"))
        .into_iter()
        .map(|(_, t)| t)
        .collect();
    Corpora { regions, unaligned }
}

/// The texts as a corpus named `name` (each under a path of its own).
pub fn corpus(name: &str, texts: &[String]) -> Corpus {
    let sources = texts
        .iter()
        .enumerate()
        .map(|(i, text)| Source { path: PathBuf::from(format!("{name}/{name}_{i:03}.tad")), text: text.clone() })
        .collect();
    Corpus::new(name.to_string(), sources)
}

fn features(name: &str, texts: &[String]) -> Vec<Features> {
    corpus(name, texts).items.into_iter().map(|i| i.features).collect()
}

/// One generator's distances to one region's held-out sample.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub region: String,
    pub generator: String,
    pub comparison: tad_stats::Comparison,
}

/// Another generator's output, compared with one region's held-out sample.
pub struct Extra {
    pub label: String,
    /// The synthetic region's label.
    pub region: String,
    pub features: Vec<Features>,
}

/// The embedding of two sets of scenarios: the model's name and both sets' vectors, or
/// none (attribute distances only).
pub type Embed<'a> =
    dyn Fn(&[Features], &[Features]) -> Result<Option<(String, Vec<Vec<f32>>, Vec<Vec<f32>>)>, String> + 'a;

/// The rows, in region order, the region's own generator first.
pub fn rows(
    corpora: &Corpora,
    extra: &[Extra],
    embed: &Embed,
    resamples: usize,
    seed: u64,
) -> Result<Vec<Row>, String> {
    let fitted: Vec<Vec<Features>> = corpora.regions.iter().map(|r| features("fitted", &r.fitted)).collect();
    let unaligned = features("unaligned", &corpora.unaligned);
    let mut rows = Vec::new();
    for region in &corpora.regions {
        let heldout = features("heldout", &region.heldout);
        let mut generators: Vec<(String, &[Features])> = Vec::new();
        for (other, output) in corpora.regions.iter().zip(&fitted) {
            let label =
                if other.label == region.label { "fitted".to_string() } else { format!("fitted on {}", other.label) };
            generators.push((label, output));
        }
        generators.sort_by_key(|(label, _)| label != "fitted");
        generators
            .extend(extra.iter().filter(|e| e.region == region.label).map(|e| (e.label.clone(), &e.features[..])));
        generators.push(("unaligned baseline".into(), &unaligned));
        for (label, generated) in generators {
            if generated.is_empty() {
                continue;
            }
            let embedded = embed(generated, &heldout)?;
            let comparison = tad_stats::compare(
                (&label, generated),
                (&format!("{} held-out", region.label), &heldout),
                embedded.as_ref().map(|(model, a, b)| tad_stats::compare::Embeddings { model: model.clone(), a, b }),
                tad_stats::Options { resamples, seed },
            );
            rows.push(Row { region: region.label.to_string(), generator: label, comparison });
        }
    }
    Ok(rows)
}

/// The rows as Markdown: each distance with its interval, then how many times farther the
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_region_is_recovered_by_its_own_fitted_generator() {
        let corpora = corpora(30, 1);
        let none: &Embed = &|_, _| Ok(None);
        let rows = rows(&corpora, &[], none, 20, 1).unwrap();
        for region in SYNTHETIC {
            let jsd = |g: &str| {
                rows.iter().find(|r| r.region == region.label && r.generator == g).unwrap().comparison.jsd["mean"].value
            };
            assert!(
                jsd("fitted") < jsd("unaligned baseline"),
                "{}: {} vs {}",
                region.label,
                jsd("fitted"),
                jsd("unaligned baseline")
            );
        }
        let again = corpora_texts(&super::corpora(30, 1));
        assert_eq!(corpora_texts(&corpora), again, "seeded");
    }

    fn corpora_texts(c: &Corpora) -> Vec<String> {
        c.regions.iter().flat_map(|r| r.fitted.iter().chain(&r.heldout).cloned()).chain(c.unaligned.clone()).collect()
    }
}
