//! `--shard I/N`: one job of an array (Slurm's `$SLURM_ARRAY_TASK_ID`, a Kubernetes Indexed
//! Job's `$JOB_COMPLETION_INDEX`) takes every N-th unit of work from I, counting from 0.
//!
//! Units are numbered the same way in every job, so the shards of one command cover its work
//! exactly once; each writes its own files, named by [`Shard::file_name`].

use std::fmt;
use std::str::FromStr;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole work: shard 0 of 1.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Whether unit `k` is this shard's.
    pub fn takes(self, k: usize) -> bool {
        k % self.count == self.index
    }

    /// `results.json` for the whole work, `results.2-of-4.json` for a shard.
    pub fn file_name(self, stem: &str, ext: &str) -> String {
        if self.count == 1 { format!("{stem}.{ext}") } else { format!("{stem}.{}-of-{}.{ext}", self.index, self.count) }
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// `I/N` with `0 <= I < N`; the error says how to write one.
impl FromStr for Shard {
    type Err = String;

    fn from_str(text: &str) -> Result<Shard, String> {
        let bad =
            || format!("`{text}` is not a shard: write I/N, the job's index from 0 and the number of jobs (0/4 … 3/4)");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) =
            (i.trim().parse::<usize>().map_err(|_| bad())?, n.trim().parse::<usize>().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_cover_the_work_once() {
        assert_eq!("1/3".parse(), Ok(Shard { index: 1, count: 3 }));
        for bad in ["3/3", "0/0", "a/2", "2", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let shards: Vec<Shard> = (0..3).map(|index| Shard { index, count: 3 }).collect();
        for k in 0..20 {
            assert_eq!(shards.iter().filter(|s| s.takes(k)).count(), 1);
        }
        assert_eq!(Shard::ALL.file_name("results", "json"), "results.json");
        assert_eq!(shards[2].file_name("results", "json"), "results.2-of-3.json");
    }
}
