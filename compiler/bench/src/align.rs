//! `bench --align`: the recovery experiment (`tad_eval::recovery`) for a host.
//!
//! The host's part, in two steps: [`corpora`] generates every corpus and writes it under
//! `--out` (so `tadslc compare` can look again); [`report`] compares them, with the extra
//! corpora of `--corpus LABEL=REGION:DIR` ([`parse_extra`]) the host read and the
//! embedding of the MMD and Fréchet columns it chose (`--embedding`), into the table or
//! JSON to print. Reading a corpus and embedding sentences stay the host's, shared with its
//! `stats` and `compare`.

use std::path::{Path, PathBuf};

use tad_eval::recovery::{self, Corpora, Embed, Extra};
use tad_eval::synthetic::{self, SYNTHETIC};

use crate::{BenchError, Report};

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
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    for (i, t) in texts.iter().enumerate() {
        let path = dir.join(format!("{stem}_{i:03}.tad"));
        std::fs::write(&path, t).map_err(|e| format!("cannot write `{}`: {e}", path.display()))?;
    }
    Ok(())
}

/// The experiment's corpora (`n` scenarios per sample, `seed`), each written under `out`:
/// `REGION/{train,heldout,fitted}/` and `unaligned/`.
pub fn corpora(n: usize, seed: u64, out: &Path) -> Result<Corpora, BenchError> {
    let corpora = recovery::corpora(n, seed);
    for region in &corpora.regions {
        let base = out.join(region.label);
        write_all(&base.join("train"), &region.train, "train")?;
        write_all(&base.join("heldout"), &region.heldout, "heldout")?;
        write_all(&base.join("fitted"), &region.fitted, "fitted")?;
    }
    write_all(&out.join("unaligned"), &corpora.unaligned, "unaligned")?;
    Ok(corpora)
}

/// The rows of the experiment on `corpora` and `extra`, embedded by `embed`, with
/// `resamples` bootstrap resamples: a Markdown table, or with `json` the rows as JSON.
pub fn report(
    corpora: &Corpora,
    extra: &[Extra],
    embed: &Embed,
    resamples: usize,
    seed: u64,
    json: bool,
) -> Result<Report, BenchError> {
    let rows = recovery::rows(corpora, extra, embed, resamples, seed)?;
    let text = if json { serde_json::to_string_pretty(&rows).unwrap_or_default() } else { recovery::table(&rows) };
    Ok(Report { lines: vec![text], ..Report::default() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_extra_corpus_names_a_synthetic_region() {
        let region = SYNTHETIC[0].label;
        let parsed = parse_extra(&format!("mine={region}:some/dir")).unwrap();
        assert_eq!(parsed, ("mine".to_string(), region.to_string(), PathBuf::from("some/dir")));
        assert_eq!(parse_extra("mine").unwrap_err(), "expected LABEL=REGION:DIR");
        assert!(parse_extra("mine=nowhere:dir").unwrap_err().starts_with("no synthetic region `nowhere`"));
    }
}
