//! The journal of a run in progress: one JSON line per finished unit, so a job that is
//! killed (a Slurm array task past its time, a pre-empted pod) and started again redoes only
//! the units it had not written.
//!
//! `DIR/results.jsonl` (`results.I-of-N.jsonl` for a shard) starts with a head line naming
//! the format, the [`Setup`] and the shard; each further line is an [`Entry`]. A journal
//! whose head differs from the run's is another command's and is started afresh; a last line
//! cut short by the kill is ignored. Units are written as they finish, in any order; the
//! results file assembles them in the units' order, so a resumed run writes the same file
//! as an unbroken one.

use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use tad_base::Shard;

use crate::results::{Row, Setup};

pub const FORMAT: &str = "tadsl-eval-journal/1";

#[derive(Serialize, Deserialize, PartialEq)]
struct Head {
    format: String,
    setup: Setup,
    shard: Shard,
}

/// One finished unit: its index among all units, its rows, and the scenes the search kept.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    pub unit: usize,
    pub rows: Vec<Row>,
    pub kept: Vec<KeptScene>,
}

/// A scene the search kept: the trial, its parameters and its seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KeptScene {
    pub trial: usize,
    pub params: Vec<f64>,
    pub seed: u64,
}

/// An open journal, appended to from many threads.
pub struct Journal {
    path: PathBuf,
    file: Mutex<std::fs::File>,
    /// The last failure of [`Journal::record`], for the end of the run.
    failed: Mutex<Option<std::io::Error>>,
}

impl Journal {
    /// `DIR/results.jsonl`, or `DIR/results.I-of-N.jsonl` for a shard.
    pub fn path(dir: &Path, shard: Shard) -> PathBuf {
        dir.join(shard.file_name("results", "jsonl"))
    }

    /// Open the journal of `setup` and `shard` in `dir`: the entries already written (by
    /// unit), or none when there was no journal or another command's.
    pub fn open(dir: &Path, setup: &Setup, shard: Shard) -> std::io::Result<(Journal, BTreeMap<usize, Entry>)> {
        std::fs::create_dir_all(dir)?;
        let head = Head { format: FORMAT.into(), setup: setup.clone(), shard };
        let (journal, entries) = Journal::open_at(Journal::path(dir, shard), &head)?;
        Ok((journal, entries.into_iter().map(|e: Entry| (e.unit, e)).collect()))
    }

    /// Open the journal at `path` whose first line is `head`: the whole entries after a
    /// head equal to it, or none (the file started afresh) when the head differs or there
    /// is no file. A last line cut short is dropped, and the file cut back to the entries.
    pub fn open_at<H, E>(path: PathBuf, head: &H) -> std::io::Result<(Journal, Vec<E>)>
    where
        H: Serialize + DeserializeOwned + PartialEq,
        E: DeserializeOwned,
    {
        let mut done = Vec::new();
        let mut valid = 0;
        if let Ok(text) = std::fs::read_to_string(&path) {
            let mut lines = text.split_inclusive('\n');
            if lines.next().is_some_and(|first| is_head(first, head)) {
                valid = text.lines().next().map_or(0, |l| l.len() + 1);
                for line in lines {
                    // a line the kill cut short has no newline, or does not parse: it and
                    // everything after it are dropped
                    let Some(entry) = line.strip_suffix('\n').and_then(|l| serde_json::from_str::<E>(l).ok()) else {
                        break;
                    };
                    valid += line.len();
                    done.push(entry);
                }
            }
        }
        let mut file = std::fs::OpenOptions::new().create(true).read(true).write(true).truncate(false).open(&path)?;
        if valid == 0 {
            file.set_len(0)?;
            let line = serde_json::to_string(head).map_err(std::io::Error::other)? + "\n";
            file.write_all(line.as_bytes())?;
        } else {
            file.set_len(valid as u64)?;
        }
        use std::io::Seek as _;
        file.seek(std::io::SeekFrom::End(0))?;
        file.sync_data()?;
        Ok((Journal { path, file: Mutex::new(file), failed: Mutex::new(None) }, done))
    }

    /// Whether the journal at `path` has `head` for its first line (a run to resume).
    pub fn holds<H: DeserializeOwned + PartialEq>(path: &Path, head: &H) -> bool {
        let Ok(text) = std::fs::read_to_string(path) else { return false };
        text.split_inclusive('\n').next().is_some_and(|first| is_head(first, head))
    }

    pub fn file(&self) -> &Path {
        &self.path
    }

    /// Append one finished unit, durably.
    pub fn append<E: Serialize>(&self, entry: &E) -> std::io::Result<()> {
        let line = serde_json::to_string(entry).map_err(std::io::Error::other)? + "\n";
        let mut file = self.file.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        file.write_all(line.as_bytes())?;
        file.sync_data()
    }

    /// Append one finished unit from a worker that goes on whatever happens: a failure is
    /// kept for [`Journal::failure`] (the unit's result is not lost, only its resumption).
    pub fn record<E: Serialize>(&self, entry: &E) {
        if let Err(e) = self.append(entry) {
            *self.failed.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(e);
        }
    }

    /// The last failure of [`Journal::record`], if any.
    pub fn failure(&self) -> Option<std::io::Error> {
        self.failed.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take()
    }

    /// Remove the journal: its run finished, and its results file says everything.
    pub fn remove(self) -> std::io::Result<()> {
        drop(self.file);
        std::fs::remove_file(&self.path)
    }
}

/// Whether a journal's first line, whole, is `head`.
fn is_head<H: DeserializeOwned + PartialEq>(line: &str, head: &H) -> bool {
    line.strip_suffix('\n').and_then(|l| serde_json::from_str::<H>(l).ok()).is_some_and(|h| h == *head)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::results::test_setup as setup;

    fn entry(unit: usize) -> Entry {
        Entry { unit, rows: Vec::new(), kept: vec![KeptScene { trial: 3, params: vec![0.1 + 0.2, 1e-300], seed: 9 }] }
    }

    #[test]
    fn a_reopened_journal_keeps_whole_lines_of_the_same_setup_only() {
        let dir = std::env::temp_dir().join(format!("tad-eval-journal-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let shard = Shard { index: 1, count: 4 };
        let (journal, done) = Journal::open(&dir, &setup(0), shard).unwrap();
        assert!(done.is_empty());
        assert!(journal.file().ends_with("results.1-of-4.jsonl"));
        journal.append(&entry(5)).unwrap();
        journal.append(&entry(1)).unwrap();
        drop(journal);
        // a kill in the middle of a line
        let path = Journal::path(&dir, shard);
        let mut text = std::fs::read_to_string(&path).unwrap();
        text.push_str("{\"unit\":9,\"ro");
        std::fs::write(&path, &text).unwrap();
        let (journal, done) = Journal::open(&dir, &setup(0), shard).unwrap();
        assert_eq!(done.keys().copied().collect::<Vec<_>>(), [1, 5]);
        assert_eq!(done[&5], entry(5), "parameters come back to the bit");
        journal.append(&entry(9)).unwrap();
        drop(journal);
        let (_, done) = Journal::open(&dir, &setup(0), shard).unwrap();
        assert_eq!(done.keys().copied().collect::<Vec<_>>(), [1, 5, 9], "the cut line was replaced");
        // another command's journal is started afresh
        let (_, done) = Journal::open(&dir, &setup(1), shard).unwrap();
        assert!(done.is_empty());
        let _ = std::fs::remove_dir_all(dir);
    }
}
