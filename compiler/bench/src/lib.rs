//! The experiments of `tadslc bench`, as a library: check throughput on one core, against
//! serde_json as a peer.
//!
//! The peer parses the same scenarios written as JSON, measured in the same run, so the
//! figures compare as a ratio whatever the machine. Each measurement is the best of
//! `runs` repetitions. The full check runs through the database, as the CLI and the
//! language server do; the incremental row edits one line of a 2,000-line file and
//! re-checks it, against checking that file from scratch. [`runtime`] measures the runtime
//! instead (`bench --runtime`), [`lsp`] the language server (`--lsp`), [`llm`] the local
//! model against llama-server (`--llm`), [`translate`] a model's faithfulness against
//! hand-written ground truth (`--translate`); [`align`] runs the alignment recovery experiment
//! (`--align`); [`hostile`] checks and formats files no one would write against a clean one
//! (`--hostile`).
//!
//! Nothing here prints: each experiment returns a [`Report`], the text lines its host
//! prints; long ones hand their progress lines to a callback as they go.

pub mod align;
pub mod hostile;
pub mod llm;
pub mod lsp;
pub mod rl;
pub mod runtime;
pub mod translate;

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};
use tad_base::plural;

use tad_db::host::{Input, Search, collect, read, register};
use tad_db::{Database, Language, NoFs};

/// What an experiment measured: the lines for standard output and the notes for standard
/// error, in order, and whether something went wrong beside the figures.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Report {
    pub lines: Vec<String>,
    pub notes: Vec<String>,
    pub outcome: Outcome,
}

/// How a run went beside its figures, in increasing precedence (the CLI's exit statuses
/// 0, 1 and 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Outcome {
    /// Everything was measured.
    #[default]
    Complete,
    /// A scenario had errors and was left out.
    InputErrors,
    /// An input could not be read, or nothing was left to measure.
    Unusable,
}

/// Why an experiment could not run (a usage or I/O problem, or a peer that failed).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BenchError(pub String);

impl std::fmt::Display for BenchError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BenchError {}

impl From<String> for BenchError {
    fn from(message: String) -> BenchError {
        BenchError(message)
    }
}

impl From<&str> for BenchError {
    fn from(message: &str) -> BenchError {
        BenchError(message.to_string())
    }
}

impl From<std::io::Error> for BenchError {
    fn from(error: std::io::Error) -> BenchError {
        BenchError(error.to_string())
    }
}

/// A field of `/proc/PID/status` in KiB (`pid` "self" for this process; Linux).
pub(crate) fn proc_status_kib(pid: &str, field: &str) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.strip_prefix(field).is_some_and(|r| r.starts_with(':')))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The shortest of `runs` timed calls of `f` (at least one).
pub fn best_of(runs: usize, mut f: impl FnMut()) -> Duration {
    (0..runs.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
}

struct Row {
    what: String,
    items: usize,
    bytes: usize,
    time: Duration,
}

impl Row {
    fn line(&self, peer: Option<Duration>) -> String {
        let secs = self.time.as_secs_f64().max(1e-9);
        let ratio = peer.map_or(String::new(), |p| format!("{:>8.2}x", secs / p.as_secs_f64().max(1e-9)));
        format!(
            "{:<34} {:>9} {:>10.1} {:>12.0} {:>9.1} {ratio}",
            self.what,
            self.items,
            self.bytes as f64 / 1e6,
            self.items as f64 / secs,
            self.bytes as f64 / 1e6 / secs,
        )
    }
}

/// `tadslc bench`: `n` generated scenarios (`seed`) checked, against serde_json parsing
/// them as JSON; the incremental re-check; with `examples`, the `*.tad` files of that
/// directory checked as `tadslc check` does. Best of `runs`.
pub fn run(n: usize, seed: u64, examples: Option<&Path>, runs: usize) -> Report {
    let corpus = tad_eval::baseline::generate(n, seed);
    let tad: Vec<&str> = corpus.iter().map(|g| g.tad.as_str()).collect();
    let json: Vec<&str> = corpus.iter().map(|g| g.json.as_str()).collect();
    let tad_bytes: usize = tad.iter().map(|t| t.len()).sum();
    let json_bytes: usize = json.iter().map(|t| t.len()).sum();

    let peer = best_of(runs, || {
        for text in &json {
            let value: serde_json::Value = serde_json::from_str(text).unwrap_or_default();
            black_box(value);
        }
    });
    let lex = best_of(runs, || {
        for text in &tad {
            black_box(tad_syntax::lexer::lex(text));
        }
    });
    let check = best_of(runs, || {
        for text in &tad {
            black_box(tad_syntax::analyze(text));
        }
    });
    // the whole checker through the database: structure, names against the standard
    // vocabulary (each module's layer built once), semantics and completeness
    let full = best_of(runs, || {
        let mut db = Database::new(tad_check::Options::default());
        for (i, text) in tad.iter().enumerate() {
            let file = db.set_source(format!("/bench/{i}.tad").into(), text.to_string(), Language::Tad, &NoFs);
            black_box(tad_db::check(&db, file));
        }
    });
    // the same checker without the database, for the database's own cost
    let prelude = tad_db::stdlib::source(tad_db::PRELUDE).unwrap_or_default();
    let (core, _) = tad_syntax::analyze(prelude);
    let (vocabulary, _) = tad_check::Vocabulary::build([(tad_db::PRELUDE, &core)]);
    let options = tad_check::Options::default();
    let direct = best_of(runs, || {
        for text in &tad {
            let (module, prior) = tad_syntax::analyze(text);
            black_box(tad_check::check(&module, &vocabulary, &options, &prior));
        }
    });
    let format = best_of(runs, || {
        for text in &tad {
            black_box(tad_syntax::format::format(text).ok());
        }
    });

    let mut report = Report::default();
    report.lines.push(format!("corpus: {n} generated scenarios, seed {seed}, best of {runs} runs, one core"));
    report.lines.push(format!(
        "{:<34} {:>9} {:>10} {:>12} {:>9} {:>9}",
        "measurement", "scenarios", "MB", "scenarios/s", "MB/s", "vs peer"
    ));
    let row = |what: &str, bytes, time| Row { what: what.into(), items: n, bytes, time };
    report.lines.push(row("peer: serde_json::Value (JSON)", json_bytes, peer).line(None));
    for (what, time) in [
        ("lex", lex),
        ("parse (lex+parse+lower)", check),
        ("check, no database", direct),
        ("check through the database", full),
        ("fmt (parse+print)", format),
    ] {
        report.lines.push(row(what, tad_bytes, time).line(Some(peer)));
    }
    report.lines.push(incremental(runs));
    if let Some(dir) = examples {
        check_examples(dir, tad_bytes, runs, &mut report);
    }
    report
}

/// The `*.tad` files of `dir` checked through the database as `tadslc check` does, a fresh
/// database per repetition, repeated to about `bytes` of text.
fn check_examples(dir: &Path, bytes: usize, runs: usize, report: &mut Report) {
    let (paths, errors) = collect(&[dir.to_path_buf()], Search::Tad);
    for e in &errors {
        report.outcome = Outcome::Unusable;
        report.notes.push(format!("error: {e}"));
    }
    let inputs: Vec<Input> = paths.iter().filter_map(|p| read(p).ok()).collect();
    let texts: Vec<&str> = inputs.iter().map(|i| i.text.as_str()).collect();
    if texts.is_empty() {
        // `collect` said why
        report.outcome = Outcome::Unusable;
        return;
    }
    // Repeat the examples to a measurable amount of work.
    let repeat = (bytes / texts.iter().map(|t| t.len()).sum::<usize>().max(1)).max(1);
    let bytes = texts.iter().map(|t| t.len()).sum::<usize>() * repeat;
    let time = best_of(runs, || {
        for _ in 0..repeat {
            let mut db = Database::new(tad_check::Options::default());
            for input in &inputs {
                let file = register(&mut db, input);
                black_box(tad_db::check(&db, file));
            }
        }
    });
    let what = format!("check examples ({} x{repeat})", plural(texts.len(), "file"));
    report.lines.push(Row { what, items: texts.len() * repeat, bytes, time }.line(None));
}

/// A scenario of about `lines` lines: the usual sections and many actor groups.
pub fn long_scenario(lines: usize) -> String {
    let mut text = String::from(
        "scenario long {\n  environment {\n    weather: clear\n    time: daytime\n  }\n  road {\n    type: straight_road\n    lanes: 3\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    speed: 40 km/h\n    lane: 2\n  }\n",
    );
    let mut i = 0;
    while text.lines().count() + 8 < lines {
        text.push_str(&format!(
            "  // group {i}\n  actor g{i}: 2 sedan {{\n    behavior: move_forward\n    speed: 30 km/h\n    position: front of ego\n    lane: {}\n  }}\n",
            1 + i % 3
        ));
        i += 1;
    }
    text.push_str("}\n");
    text
}

/// Re-checking a 2,000-line file after a one-line edit, against checking it from scratch:
/// the report's line.
fn incremental(runs: usize) -> String {
    let text = long_scenario(2000);
    let lines = text.lines().count();
    let path = std::path::PathBuf::from("/bench/long.tad");
    let scratch = best_of(runs, || {
        let mut db = Database::new(tad_check::Options::default());
        let file = db.set_source(path.clone(), text.clone(), Language::Tad, &NoFs);
        black_box(tad_db::check(&db, file));
    });
    let mut db = Database::new(tad_check::Options::default());
    let file = db.set_source(path.clone(), text.clone(), Language::Tad, &NoFs);
    black_box(tad_db::check(&db, file));
    // edit the speed of one group in the middle, back and forth
    let at = text.find("speed: 30 km/h").map_or(0, |first| first + text.len() / 2);
    let at = text[at..].find("speed: 30 km/h").map_or(0, |i| at + i);
    let edits = [text[..at].to_string() + &text[at..].replacen("30 km/h", "31 km/h", 1), text.clone()];
    let mut times: Vec<Duration> = Vec::new();
    for k in 0..200 {
        let edited = edits[k % 2].clone();
        let start = Instant::now();
        let file = db.set_source(path.clone(), edited, Language::Tad, &NoFs);
        black_box(tad_db::check(&db, file));
        times.push(start.elapsed());
    }
    times.sort();
    let p50 = times[times.len() / 2];
    let p99 = times[times.len() * 99 / 100];
    format!(
        "incremental: one-line edit of a {lines}-line file, re-checked: p50 {:.3} ms, p99 {:.3} ms; from scratch {:.3} ms ({:.2}x of it)",
        p50.as_secs_f64() * 1e3,
        p99.as_secs_f64() * 1e3,
        scratch.as_secs_f64() * 1e3,
        p50.as_secs_f64() / scratch.as_secs_f64().max(1e-9)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_check_bench_reports_every_row_and_the_examples() {
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/safety");
        let report = run(5, 1, Some(&examples), 1);
        assert_eq!(report.outcome, Outcome::Complete, "{:?}", report.notes);
        assert!(report.notes.is_empty(), "{:?}", report.notes);
        assert_eq!(report.lines.len(), 10, "{:#?}", report.lines);
        assert!(report.lines[0].starts_with("corpus: 5 generated scenarios, seed 1"), "{:?}", report.lines[0]);
        assert!(report.lines[8].starts_with("incremental: one-line edit of a "), "{:?}", report.lines[8]);
        assert!(report.lines[9].starts_with("check examples (8 files x"), "{:?}", report.lines[9]);
    }

    #[test]
    fn a_missing_examples_directory_is_unusable_and_said() {
        let missing = std::env::temp_dir().join(format!("tad-bench-missing-{}", std::process::id()));
        let report = run(2, 0, Some(&missing), 1);
        assert_eq!(report.outcome, Outcome::Unusable);
        assert_eq!(report.notes.len(), 1, "{:?}", report.notes);
        assert!(report.notes[0].starts_with("error: "), "{:?}", report.notes);
        assert_eq!(report.lines.len(), 9, "the rows without the examples': {:#?}", report.lines);
    }
}
