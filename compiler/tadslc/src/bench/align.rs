//! `tadslc bench --align`: the recovery experiment (`tad_eval::recovery`) on the command
//! line.
//!
//! The host's part: every corpus written under `--out` (so `tadslc compare` can look
//! again), the extra corpora of `--corpus LABEL=REGION:DIR` read, the embedding of the MMD
//! and Fréchet columns (`--embedding`), the table or JSON printed.

use std::path::{Path, PathBuf};

use tad_eval::recovery::{self, Corpora, Extra};
use tad_eval::synthetic::{self, SYNTHETIC};

use crate::align::{self, Embedding};
use crate::output::Closed;
use crate::{Status, errln, outln};

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

fn write_all(dir: &Path, texts: &[String], stem: &str) -> Result<(), String> {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for (i, t) in texts.iter().enumerate() {
        let path = dir.join(format!("{stem}_{i:03}.tad"));
        std::fs::write(&path, t).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(())
}

/// Every corpus of the experiment under `out`: `REGION/{train,heldout,fitted}/` and
/// `unaligned/`.
fn write_corpora(out: &Path, corpora: &Corpora) -> Result<(), String> {
    for region in &corpora.regions {
        let base = out.join(region.label);
        write_all(&base.join("train"), &region.train, "train")?;
        write_all(&base.join("heldout"), &region.heldout, "heldout")?;
        write_all(&base.join("fitted"), &region.fitted, "fitted")?;
    }
    write_all(&out.join("unaligned"), &corpora.unaligned, "unaligned")
}

pub fn run(args: &AlignArgs) -> Status {
    crate::output::run(|status| {
        let corpora = recovery::corpora(args.n, args.seed);
        if let Err(e) = write_corpora(&args.out, &corpora) {
            *status = Status::Usage;
            return errln!("error: {e}");
        }
        let mut extra = Vec::new();
        for (label, region, dir) in &args.extra {
            let corpus = align::load(std::slice::from_ref(dir), status)?;
            let features = corpus.items.into_iter().map(|i| i.features).collect();
            extra.push(Extra { label: label.clone(), region: region.clone(), features });
        }
        let embed = |a: &[tad_stats::Features], b: &[tad_stats::Features]| align::embed(args.embedding, a, b);
        let rows = match recovery::rows(&corpora, &extra, &embed, args.resamples, args.seed) {
            Ok(rows) => rows,
            Err(e) => {
                *status = Status::Usage;
                return errln!("error: {e}");
            }
        };
        print(&rows, args.json)
    })
}

fn print(rows: &[recovery::Row], json: bool) -> Result<(), Closed> {
    if json {
        return outln!("{}", serde_json::to_string_pretty(rows).unwrap_or_default());
    }
    outln!("{}", recovery::table(rows))
}
