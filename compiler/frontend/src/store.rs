//! Files the pipelines write: names a model cannot steer outside the output directory,
//! writes that are atomic (a temporary file renamed), and JSON Lines that a killed run
//! leaves readable (a torn last line is dropped on reading and cut off before appending).

use std::fs::{self, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

/// A file name from untrusted text: ASCII letters, digits and `_` only, lower case, at
/// most 64 characters, never empty, never a dot name.
pub fn file_stem(text: &str) -> String {
    let mut out = String::new();
    for c in text.chars() {
        let c = c.to_ascii_lowercase();
        if c.is_ascii_alphanumeric() {
            out.push(c);
        } else if !out.ends_with('_') && !out.is_empty() {
            out.push('_');
        }
        if out.len() >= 64 {
            break;
        }
    }
    let out = out.trim_matches('_').to_string();
    if out.is_empty() { "scenario".into() } else { out }
}

/// `dir/stem.ext`, the stem sanitised; the result is always inside `dir`.
pub fn inside(dir: &Path, stem: &str, ext: &str) -> PathBuf {
    dir.join(format!("{}.{ext}", file_stem(stem)))
}

/// Writes `bytes` to `path` through a temporary file in the same directory.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
    }
    fs::rename(&tmp, path)
}

/// An append-only JSON Lines file; each record is one `write` of one line.
pub struct Jsonl {
    file: fs::File,
}

impl Jsonl {
    /// Opens `path` for appending, first cutting off a torn last line.
    pub fn append(path: &Path) -> io::Result<Jsonl> {
        if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            fs::create_dir_all(dir)?;
        }
        if let Ok(text) = fs::read(path)
            && !text.is_empty()
            && !text.ends_with(b"\n")
        {
            let keep = text.iter().rposition(|&b| b == b'\n').map(|i| i + 1).unwrap_or(0);
            OpenOptions::new().write(true).open(path)?.set_len(keep as u64)?;
        }
        Ok(Jsonl { file: OpenOptions::new().create(true).append(true).open(path)? })
    }

    pub fn write<T: Serialize>(&mut self, record: &T) -> io::Result<()> {
        let mut line = serde_json::to_string(record).map_err(io::Error::other)?;
        line.push('\n');
        self.file.write_all(line.as_bytes())?;
        self.file.flush()
    }
}

/// The records of a JSON Lines file that parse (none if it does not exist).
pub fn read_jsonl(path: &Path) -> Vec<serde_json::Value> {
    let Ok(text) = fs::read_to_string(path) else { return Vec::new() };
    text.lines().filter_map(|l| serde_json::from_str(l).ok()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_from_a_model_stay_inside() {
        assert_eq!(file_stem("../../etc/passwd"), "etc_passwd");
        assert_eq!(file_stem("Bison Crossing!"), "bison_crossing");
        assert_eq!(file_stem(".."), "scenario");
        assert_eq!(file_stem("/"), "scenario");
        assert_eq!(file_stem(&"a".repeat(500)).len(), 64);
        let dir = Path::new("/out");
        assert_eq!(inside(dir, "../x", "tad"), PathBuf::from("/out/x.tad"));
    }

    #[test]
    fn a_torn_line_is_cut_before_appending() {
        let dir = std::env::temp_dir().join(format!("tad-store-{}", std::process::id()));
        let path = dir.join("m.jsonl");
        fs::create_dir_all(&dir).unwrap();
        fs::write(&path, "{\"a\":1}\n{\"a\":").unwrap();
        assert_eq!(read_jsonl(&path).len(), 1);
        let mut j = Jsonl::append(&path).unwrap();
        j.write(&serde_json::json!({"a": "line\nbreak"})).unwrap();
        let records = read_jsonl(&path);
        assert_eq!(records.len(), 2);
        assert_eq!(records[1]["a"], "line\nbreak");
        write_atomic(&dir.join("x.tad"), b"scenario").unwrap();
        assert_eq!(fs::read_to_string(dir.join("x.tad")).unwrap(), "scenario");
        fs::remove_dir_all(&dir).unwrap();
    }
}
