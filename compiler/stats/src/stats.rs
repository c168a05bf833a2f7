//! A corpus's statistics, and the tables that show them.
//!
//! The corpus table is the paper's (scenarios, mean actors per scenario) with mean groups;
//! each attribute of [`ATTRIBUTES`] gets a histogram. Tables print as Markdown (one
//! column per corpus, each cell `count (share)`), as long-form CSV
//! (`corpus,attribute,value,count,share`) or as JSON.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::features::{ATTRIBUTES, Features};

/// Value → count.
pub type Histogram = BTreeMap<String, u32>;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stats {
    pub corpus: String,
    pub scenarios: usize,
    pub mean_actors: f64,
    pub mean_groups: f64,
    /// Actors per scenario → scenarios.
    pub actor_counts: BTreeMap<u32, u32>,
    /// Attribute key → histogram.
    pub histograms: BTreeMap<&'static str, Histogram>,
}

impl Stats {
    pub fn of(corpus: &str, scenarios: &[Features]) -> Stats {
        let n = scenarios.len();
        let mean = |f: &dyn Fn(&Features) -> u32| {
            if n == 0 { 0.0 } else { scenarios.iter().map(|s| f(s) as f64).sum::<f64>() / n as f64 }
        };
        let mut actor_counts = BTreeMap::new();
        for s in scenarios {
            *actor_counts.entry(s.actors).or_insert(0) += 1;
        }
        Stats {
            corpus: corpus.to_string(),
            scenarios: n,
            mean_actors: mean(&|s| s.actors),
            mean_groups: mean(&|s| s.groups),
            actor_counts,
            histograms: ATTRIBUTES.iter().map(|a| (a.key, histogram(scenarios, a.key))).collect(),
        }
    }
}

pub fn histogram<'a>(scenarios: impl IntoIterator<Item = &'a Features>, key: &str) -> Histogram {
    let mut h = Histogram::new();
    for s in scenarios {
        for v in s.values.get(key).into_iter().flatten() {
            *h.entry(v.clone()).or_insert(0) += 1;
        }
    }
    h
}

fn share(h: &Histogram, value: &str) -> (u32, f64) {
    let total: u32 = h.values().sum();
    let count = h.get(value).copied().unwrap_or(0);
    (count, if total == 0 { 0.0 } else { count as f64 / total as f64 })
}

/// The corpus table and every attribute's histogram, as Markdown.
pub fn markdown(all: &[Stats]) -> String {
    let mut out =
        String::from("| corpus | scenarios | actors per scenario | groups per scenario |\n|---|---:|---:|---:|\n");
    for s in all {
        out.push_str(&format!("| {} | {} | {:.1} | {:.1} |\n", s.corpus, s.scenarios, s.mean_actors, s.mean_groups));
    }
    for a in ATTRIBUTES {
        out.push_str(&format!("\n### {} (`{}`, per {})\n\n", a.title, a.key, per(a.per)));
        let mut values: Vec<&String> = all.iter().flat_map(|s| s.histograms[a.key].keys()).collect();
        values.sort();
        values.dedup();
        // most frequent first, over all corpora
        values.sort_by_key(|v| std::cmp::Reverse(all.iter().map(|s| share(&s.histograms[a.key], v).0).sum::<u32>()));
        out.push_str("| value |");
        for s in all {
            out.push_str(&format!(" {} |", s.corpus));
        }
        out.push_str("\n|---|");
        out.push_str(&"---:|".repeat(all.len()));
        out.push('\n');
        for v in values {
            out.push_str(&format!("| {v} |"));
            for s in all {
                let (count, p) = share(&s.histograms[a.key], v);
                out.push_str(&format!(" {count} ({:.0}%) |", p * 100.0));
            }
            out.push('\n');
        }
    }
    out
}

fn per(p: crate::features::Per) -> &'static str {
    match p {
        crate::features::Per::Scenario => "scenario",
        crate::features::Per::Item => "listed name",
        crate::features::Per::Actor => "actor",
    }
}

/// Long-form CSV: the corpus table as attribute `scenarios`/`mean_actors`/`mean_groups`,
/// then one row per (corpus, attribute, value).
pub fn csv(all: &[Stats]) -> String {
    let mut out = String::from("corpus,attribute,value,count,share\n");
    for s in all {
        let c = field(&s.corpus);
        out.push_str(&format!("{c},scenarios,,{},\n", s.scenarios));
        out.push_str(&format!("{c},mean_actors,,,{:.4}\n", s.mean_actors));
        out.push_str(&format!("{c},mean_groups,,,{:.4}\n", s.mean_groups));
        for (n, count) in &s.actor_counts {
            out.push_str(&format!("{c},actors,{n},{count},{:.4}\n", *count as f64 / s.scenarios.max(1) as f64));
        }
        for a in ATTRIBUTES {
            let h = &s.histograms[a.key];
            for v in h.keys() {
                let (count, p) = share(h, v);
                out.push_str(&format!("{c},{},{},{count},{p:.4}\n", a.key, field(v)));
            }
        }
    }
    out
}

fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}
