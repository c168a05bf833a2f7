//! Descriptions to programs: one description through the session's loop, or a batch into
//! a directory with a manifest (`translate.jsonl`) and a summary (`summary.json`).
//!
//! A program that ended invalid is kept, under `rejected/`; every program carries its
//! provenance (tool, description, model, rounds, prompt). A description that cannot be
//! read is reported and skipped; the batch goes on.

use std::path::{Path, PathBuf};

use crate::shots::Pool;
use crate::{Outcome, Round, Session, Summary, store};

/// The description files of `paths` (directories searched for `*.txt`), in order.
pub fn descriptions(paths: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for path in paths {
        if path.is_dir() {
            let found = tad_db::host::with_extension(path, "txt");
            if found.is_empty() {
                return Err(format!("{} holds no .txt descriptions", path.display()));
            }
            out.extend(found);
        } else {
            out.push(path.clone());
        }
    }
    Ok(out)
}

/// A description's text, trimmed (`-` is standard input); an empty one is refused.
pub fn read_description(path: &Path) -> Result<String, String> {
    let text = if path == Path::new("-") {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut std::io::stdin(), &mut s)
            .map_err(|e| format!("cannot read standard input: {e}"))?;
        s
    } else {
        std::fs::read_to_string(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?
    };
    if text.trim().is_empty() {
        return Err(format!("{} is empty: there is nothing to translate", path.display()));
    }
    Ok(text.trim().to_string())
}

/// Who translates: the session, and what the provenance says about the run.
pub struct Translator<'a> {
    pub session: &'a Session<'a>,
    pub runtime: &'a tokio::runtime::Runtime,
    pub region: Option<&'a str>,
    /// The tool and its version, for the provenance (`tadslc 0.1.0`).
    pub tool: &'a str,
    /// Translations shown before each description: the pool, and how many of its nearest.
    pub shots: Option<(&'a Pool, usize)>,
}

impl Translator<'_> {
    /// One description through the loop: the outcome and the program with its provenance.
    pub fn one(&self, path: &Path, text: &str, on_round: &mut dyn FnMut(&Round)) -> (Outcome, Option<String>) {
        let item = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "stdin".into());
        let mut messages = crate::translate_messages(text, self.session.checker);
        let mut comments = Vec::new();
        if let Some((pool, k)) = self.shots {
            let shots = pool.nearest(text, k);
            let ask = |d: &str| crate::prompt::TRANSLATE.render(&[("description", d)]).user;
            messages = crate::shots::interleave(messages, &shots, ask);
            let names: Vec<&str> = shots.iter().map(|s| s.name.as_str()).collect();
            comments.push(format!("shown first: {}", names.join(", ")));
        }
        let outcome = self.runtime.block_on(self.session.run(&item, messages, crate::prompt::TRANSLATE.id, on_round));
        let provenance = crate::Provenance {
            comments: vec![format!(
                "translated by {} from {} with model {}, {} round{}, prompt {}",
                self.tool,
                path.display(),
                self.session.client.label(),
                outcome.rounds,
                if outcome.rounds == 1 { "" } else { "s" },
                crate::prompt::TRANSLATE.id
            )]
            .into_iter()
            .chain(comments)
            .chain(outcome.suggested_line())
            .collect(),
            region: self.region.map(String::from),
            description: Some(text.to_string()),
            ..Default::default()
        };
        let program = outcome.program.as_ref().map(|p| crate::with_provenance(p, &provenance));
        (outcome, program)
    }

    /// Every description of `files` into `dir`: programs (invalid ones under `rejected/`),
    /// one manifest record each, and `on_item` after each (a description that cannot be
    /// read comes as `Err`). Returns the summary and how many items could not reach the
    /// model.
    pub fn batch(
        &self,
        files: &[PathBuf],
        dir: &Path,
        on_round: &mut dyn FnMut(&Round),
        on_item: &mut dyn FnMut(Result<&Outcome, String>),
    ) -> Result<(Summary, usize), String> {
        let mut manifest = store::Jsonl::append(&dir.join("translate.jsonl"))
            .map_err(|e| format!("cannot write the manifest: {e}"))?;
        let mut summary = Summary::default();
        let mut unreachable = 0;
        for path in files {
            let text = match read_description(path) {
                Ok(t) => t,
                Err(e) => {
                    on_item(Err(e));
                    continue;
                }
            };
            let (outcome, program) = self.one(path, &text, on_round);
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            let mut file = None;
            if let Some(p) = &program {
                let sub = if outcome.class == Some("invalid") { dir.join("rejected") } else { dir.to_path_buf() };
                let target = store::inside(&sub, &stem, "tad");
                store::write_atomic(&target, p.as_bytes())
                    .map_err(|e| format!("cannot write `{}`: {e}", target.display()))?;
                file = Some(target.display().to_string());
            }
            unreachable += usize::from(outcome.unreachable());
            summary.add(&outcome);
            let record =
                serde_json::json!({ "description": path.display().to_string(), "file": file, "outcome": outcome });
            manifest.write(&record).map_err(|e| format!("cannot write the manifest: {e}"))?;
            on_item(Ok(&outcome));
        }
        Ok((summary, unreachable))
    }
}

/// `dir/summary.json`: the summary with `extra`'s fields beside its own.
pub fn write_summary(dir: &Path, summary: &Summary, extra: serde_json::Value) -> Result<(), String> {
    let mut value = serde_json::to_value(summary).unwrap_or_default();
    if let (Some(map), serde_json::Value::Object(extra)) = (value.as_object_mut(), extra) {
        map.extend(extra);
    }
    let text = serde_json::to_string_pretty(&value).unwrap_or_default() + "\n";
    store::write_atomic(&dir.join("summary.json"), text.as_bytes())
        .map_err(|e| format!("cannot write the summary: {e}"))
}
