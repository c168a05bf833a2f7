//! `tadsl-eval/1`: the results file of every scored run (`tadslc eval --out`, `run --out`),
//! what `merge` reads, and the table the rows make.
//!
//! A file holds the [`Setup`] that produced it, its [`Shard`], the scenarios run per
//! region and generator, and one [`Row`] per scored episode. Shards of one command merge
//! when their setups agree and each shard is given once; [`lines`] aggregates the rows of
//! any number of files per region × generator × ego, so the shards of a command give
//! exactly the table of the unsharded run.

use std::collections::BTreeMap;
use std::fmt::{self, Write as _};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use tad_base::Shard;
use tad_metrics::{EpisodeScore, METRICS, Mode};

pub const FORMAT: &str = "tadsl-eval/1";

/// What produced a results file: shards merge only when these agree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Setup {
    pub regions: Vec<String>,
    pub generators: Vec<String>,
    pub egos: Vec<String>,
    pub search_ego: String,
    pub n: usize,
    pub samples: usize,
    pub keep: usize,
    pub seed: u64,
    /// Scored as SafeBench's scorer does (`run --compat`) rather than with the fixed
    /// formulas.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub compat: bool,
}

impl Setup {
    /// How the rows are aggregated.
    pub fn mode(&self) -> Mode {
        if self.compat { Mode::Compat } else { Mode::Fixed }
    }

    /// Whether the file is `run`'s (its scenarios are files, not generated per region).
    pub fn is_run(&self) -> bool {
        self.regions == [RUN_REGION] && self.generators == [RUN_GENERATOR]
    }
}

/// The region and generator of `run`'s rows: its scenarios are the files given.
pub const RUN_REGION: &str = "all";
pub const RUN_GENERATOR: &str = "files";

/// One scored episode: an ego on one kept scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    pub region: String,
    pub generator: String,
    pub ego: String,
    pub scenario: String,
    /// The scene's trial in the search, and the episode's seed.
    pub trial: usize,
    pub seed: u64,
    pub score: EpisodeScore,
    /// Why the episode stopped (`run`'s rows).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop: Option<String>,
    /// The scenario's place among the command's inputs, whatever the shard (`run`'s rows).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index: Option<usize>,
}

/// A results file (`results.json`, `results.I-of-N.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Results {
    pub format: String,
    pub setup: Setup,
    pub shard: Shard,
    /// Scenarios generated (or given) and run, per region and generator, in this shard.
    pub scenarios: BTreeMap<String, usize>,
    pub rows: Vec<Row>,
}

impl Results {
    pub fn new(setup: Setup, shard: Shard, scenarios: BTreeMap<String, usize>, rows: Vec<Row>) -> Results {
        Results { format: FORMAT.into(), setup, shard, scenarios, rows }
    }

    /// `DIR/results.json`, or `DIR/results.I-of-N.json` for a shard.
    pub fn path(dir: &Path, shard: Shard) -> PathBuf {
        dir.join(shard.file_name("results", "json"))
    }

    /// Write into `dir` (made if missing); the path written.
    pub fn write(&self, dir: &Path) -> std::io::Result<PathBuf> {
        let path = Results::path(dir, self.shard);
        std::fs::create_dir_all(dir)?;
        let text = serde_json::to_string(self).map_err(std::io::Error::other)? + "\n";
        std::fs::write(&path, text)?;
        Ok(path)
    }

    /// Read a results file, refusing other formats.
    pub fn read(path: &Path) -> Result<Results, String> {
        let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
        let results: Results = serde_json::from_str(&text).map_err(|e| format!("not a results file: {e}"))?;
        if results.format != FORMAT {
            return Err(format!("format `{}`, expected `{FORMAT}`", results.format));
        }
        Ok(results)
    }
}

/// Why results files do not merge; the indexes are into the files given.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MergeError {
    Empty,
    /// File `index` comes from another command than the first.
    OtherSetup {
        index: usize,
    },
    /// File `index` is a shard of another count than the first's.
    OtherCount {
        index: usize,
        shard: Shard,
        count: usize,
    },
    /// A shard is given twice.
    Twice(Shard),
}

impl fmt::Display for MergeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MergeError::Empty => f.write_str("no results file to merge"),
            MergeError::OtherSetup { .. } => {
                f.write_str("it comes from another command (regions, generators, egos, sizes or seed differ)")
            }
            MergeError::OtherCount { shard, count, .. } => write!(f, "it is shard {shard}, the others are of {count}"),
            MergeError::Twice(shard) => write!(f, "shard {shard} is given twice"),
        }
    }
}

/// Whether `all` are shards of one command, each once: the shards missing.
pub fn check_merge(all: &[Results]) -> Result<Vec<Shard>, MergeError> {
    let first = all.first().ok_or(MergeError::Empty)?;
    if let Some(index) = all.iter().position(|r| r.setup != first.setup) {
        return Err(MergeError::OtherSetup { index });
    }
    let count = first.shard.count;
    let mut seen = vec![0usize; count];
    for (index, r) in all.iter().enumerate() {
        if r.shard.count != count {
            return Err(MergeError::OtherCount { index, shard: r.shard, count });
        }
        seen[r.shard.index] += 1;
    }
    if let Some(index) = seen.iter().position(|&k| k > 1) {
        return Err(MergeError::Twice(Shard { index, count }));
    }
    Ok((0..count).filter(|&index| seen[index] == 0).map(|index| Shard { index, count }).collect())
}

/// One table line: a region, generator and ego, over the rows of all results.
pub struct Line {
    pub region: String,
    pub generator: String,
    pub ego: String,
    pub scenarios: usize,
    pub agg: tad_metrics::Aggregate,
}

/// The lines of the setup's regions × generators × egos that have rows, in that order.
pub fn lines(all: &[Results]) -> Vec<Line> {
    let Some(first) = all.first() else { return Vec::new() };
    let setup = &first.setup;
    let mut out = Vec::new();
    for region in &setup.regions {
        for generator in &setup.generators {
            let key = format!("{region}/{generator}");
            let scenarios: usize = all.iter().filter_map(|r| r.scenarios.get(&key)).sum();
            for ego in &setup.egos {
                // in one order whatever the files' (sums of floats depend on it)
                let mut rows: Vec<&Row> = all
                    .iter()
                    .flat_map(|r| &r.rows)
                    .filter(|r| &r.region == region && &r.generator == generator && &r.ego == ego)
                    .collect();
                rows.sort_by(|a, b| (&a.scenario, a.trial, a.seed).cmp(&(&b.scenario, b.trial, b.seed)));
                let scores: Vec<EpisodeScore> = rows.iter().map(|r| r.score.clone()).collect();
                if let Ok(agg) = tad_metrics::aggregate(&scores, setup.mode()) {
                    out.push(Line {
                        region: region.clone(),
                        generator: generator.clone(),
                        ego: ego.clone(),
                        scenarios,
                        agg,
                    });
                }
            }
        }
    }
    out
}

/// How a table is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TableFormat {
    Markdown,
    Csv,
    Json,
}

/// The table of `all`'s rows.
pub fn table(all: &[Results], format: TableFormat) -> String {
    let lines = lines(all);
    let value = |m: &tad_metrics::Metrics, k: usize| -> Option<f64> { m.get(METRICS[k].metric) };
    let mut out = String::new();
    match format {
        TableFormat::Json => {
            for l in &lines {
                let v = serde_json::json!({
                    "region": l.region,
                    "generator": l.generator,
                    "ego": l.ego,
                    "scenarios": l.scenarios,
                    "episodes": l.agg.episodes,
                    "metrics": l.agg.raw,
                    "normalised": l.agg.normalised,
                    "OS": l.agg.normalised.os,
                });
                let _ = writeln!(out, "{v}");
            }
        }
        TableFormat::Csv => {
            out.push_str("region,generator,ego,scenarios,episodes");
            for m in METRICS.iter() {
                let _ = write!(out, ",{}", m.key);
            }
            out.push_str(",OS\n");
            for l in &lines {
                let _ = write!(out, "{},{},{},{},{}", l.region, l.generator, l.ego, l.scenarios, l.agg.episodes);
                for k in 0..METRICS.len() {
                    match value(&l.agg.normalised, k) {
                        Some(v) => {
                            let _ = write!(out, ",{v:.4}");
                        }
                        None => out.push(','),
                    }
                }
                let _ = writeln!(out, ",{:.4}", l.agg.normalised.os);
            }
        }
        TableFormat::Markdown => {
            out.push_str("| region | generator | ego | scenes |");
            for m in METRICS.iter() {
                let _ = write!(out, " {} |", m.key);
            }
            out.push_str(" OS |\n|---|---|---|---:|");
            for _ in METRICS.iter() {
                out.push_str("---:|");
            }
            out.push_str("---:|\n");
            for l in &lines {
                let _ = write!(out, "| {} | {} | {} | {} |", l.region, l.generator, l.ego, l.agg.episodes);
                for k in 0..METRICS.len() {
                    match value(&l.agg.normalised, k) {
                        Some(v) => {
                            let _ = write!(out, " {v:.3} |");
                        }
                        None => out.push_str(" – |"),
                    }
                }
                let _ = writeln!(out, " **{:.3}** |", l.agg.normalised.os);
            }
            out.push('\n');
            if let Some(first) = all.first() {
                let setup = &first.setup;
                let scenes = if setup.keep == 0 {
                    "each scene is one scenario run with one seed (`tadslc run`)".to_string()
                } else {
                    format!(
                        "each scene is one of the {} kept per scenario by the adversarial search against `{}`",
                        setup.keep, setup.search_ego
                    )
                };
                let _ = writeln!(
                    out,
                    "Normalised as in TrafficAlign's tables ({}; lower is better but for RF and Comp; OS 1 is perfect); {scenes}.",
                    tad_metrics::normalisation()
                );
            }
        }
    }
    out
}

/// The OS of each line as an SVG bar chart, grouped by region and generator: each bar with
/// its 95 % bootstrap interval (the line's episodes resampled with replacement
/// [`crate::interval::RESAMPLES`] times, OS aggregated as the table does, the 2.5 and 97.5
/// percentiles; seeded by the setup's seed, so the plot is deterministic) and its episodes.
pub fn plot(all: &[Results]) -> String {
    use tad_ir::{Rng, SplitMix64};
    let seed = all.first().map_or(0, |r| r.setup.seed);
    let mut bars = Vec::new();
    for (k, l) in lines(all).iter().enumerate() {
        let mut rows: Vec<&Row> = all
            .iter()
            .flat_map(|r| &r.rows)
            .filter(|r| r.region == l.region && r.generator == l.generator && r.ego == l.ego)
            .collect();
        rows.sort_by(|a, b| (&a.scenario, a.trial, a.seed).cmp(&(&b.scenario, b.trial, b.seed)));
        let mut rng = SplitMix64::new(seed ^ 0x0051_A7E5 ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let mut draws: Vec<f64> = (0..crate::interval::RESAMPLES)
            .filter_map(|_| {
                let pick: Vec<EpisodeScore> =
                    (0..rows.len()).map(|_| rows[rng.below(rows.len())].score.clone()).collect();
                tad_metrics::aggregate(&pick, Mode::Fixed).ok().map(|a| a.normalised.os)
            })
            .filter(|v| v.is_finite())
            .collect();
        draws.sort_by(f64::total_cmp);
        let at = |q: f64| draws.get(((draws.len() as f64 - 1.0) * q).round() as usize).copied();
        let interval = at(0.025).zip(at(0.975));
        bars.push(tad_stats::plot::Bar {
            group: format!("{} · {}", l.region, l.generator),
            series: l.ego.clone(),
            value: l.agg.normalised.os,
            interval,
            n: l.agg.episodes,
        });
    }
    tad_stats::plot::grouped(
        "Overall score (OS) by generator and ego",
        ("region · generator", "overall score (OS, 1 is perfect)"),
        &bars,
    )
}

/// A small setup for the crate's tests, told apart by its seed.
#[cfg(test)]
pub(crate) fn test_setup(seed: u64) -> Setup {
    Setup {
        regions: vec!["r".into()],
        generators: vec!["g".into()],
        egos: vec!["idm".into()],
        search_ego: "idm".into(),
        n: 1,
        samples: 1,
        keep: 1,
        seed,
        compat: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn results(shard: Shard, seed: u64) -> Results {
        Results::new(test_setup(seed), shard, BTreeMap::new(), Vec::new())
    }

    #[test]
    fn shards_merge_once_each_and_missing_ones_are_named() {
        let of = |index| Shard { index, count: 3 };
        assert_eq!(check_merge(&[results(of(0), 0), results(of(2), 0)]), Ok(vec![of(1)]));
        assert_eq!(check_merge(&[]), Err(MergeError::Empty));
        assert_eq!(check_merge(&[results(of(0), 0), results(of(0), 0)]), Err(MergeError::Twice(of(0))));
        assert_eq!(check_merge(&[results(of(0), 0), results(of(1), 1)]), Err(MergeError::OtherSetup { index: 1 }));
        let other = Shard { index: 1, count: 2 };
        assert_eq!(
            check_merge(&[results(of(0), 0), results(other, 0)]),
            Err(MergeError::OtherCount { index: 1, shard: other, count: 3 })
        );
    }

    #[test]
    fn a_results_file_reads_back_and_other_formats_are_refused() {
        let dir = std::env::temp_dir().join(format!("tad-eval-results-{}", std::process::id()));
        let r = results(Shard { index: 1, count: 2 }, 4);
        let path = r.write(&dir).expect("written");
        assert!(path.ends_with("results.1-of-2.json"));
        assert_eq!(Results::read(&path), Ok(r.clone()));
        let mut other = r;
        other.format = "tadsl-eval/0".into();
        std::fs::write(&path, serde_json::to_string(&other).unwrap()).unwrap();
        assert!(Results::read(&path).unwrap_err().contains("expected `tadsl-eval/1`"));
        let _ = std::fs::remove_dir_all(dir);
    }
}
