//! `tadslc bench`: check throughput on one core, against serde_json as a peer.
//!
//! The peer parses the same scenarios written as JSON, measured in the same run, so the
//! figures compare as a ratio whatever the machine. Each measurement is the best of
//! `runs` repetitions. The full check runs through the database, as the CLI and the
//! language server do; the incremental row edits one line of a 2,000-line file and
//! re-checks it, against checking that file from scratch. `bench --runtime` measures the
//! runtime instead ([`runtime`]), `bench --lsp` the language server ([`lsp`]), `bench --llm`
//! the local model against llama-server ([`llm`]); `bench --align` runs the alignment
//! recovery experiment ([`align`]).

pub mod align;
pub mod llm;
pub mod lsp;
pub mod runtime;

use crate::output::Closed;
use crate::{Status, errln, outln};
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};
use tad_db::{Database, Language, NoFs};

/// A field of `/proc/PID/status` in KiB (`pid` "self" for this process; Linux).
pub(crate) fn proc_status_kib(pid: &str, field: &str) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.strip_prefix(field).is_some_and(|r| r.starts_with(':')))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

pub(crate) fn best_of(runs: usize, mut f: impl FnMut()) -> Duration {
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
    fn print(&self, peer: Option<Duration>) -> Result<(), Closed> {
        let secs = self.time.as_secs_f64().max(1e-9);
        let ratio = peer.map_or(String::new(), |p| format!("{:>8.2}x", secs / p.as_secs_f64().max(1e-9)));
        outln!(
            "{:<34} {:>9} {:>10.1} {:>12.0} {:>9.1} {ratio}",
            self.what,
            self.items,
            self.bytes as f64 / 1e6,
            self.items as f64 / secs,
            self.bytes as f64 / 1e6 / secs,
        )
    }
}

pub fn run(n: usize, seed: u64, examples: Option<&Path>, runs: usize) -> Status {
    crate::output::run(|status| run_in(n, seed, examples, runs, status))
}

fn run_in(n: usize, seed: u64, examples: Option<&Path>, runs: usize, status: &mut Status) -> Result<(), Closed> {
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

    outln!("corpus: {n} generated scenarios, seed {seed}, best of {runs} runs, one core")?;
    outln!(
        "{:<34} {:>9} {:>10} {:>12} {:>9} {:>9}",
        "measurement",
        "scenarios",
        "MB",
        "scenarios/s",
        "MB/s",
        "vs peer"
    )?;
    Row { what: "peer: serde_json::Value (JSON)".into(), items: n, bytes: json_bytes, time: peer }.print(None)?;
    Row { what: "lex".into(), items: n, bytes: tad_bytes, time: lex }.print(Some(peer))?;
    Row { what: "parse (lex+parse+lower)".into(), items: n, bytes: tad_bytes, time: check }.print(Some(peer))?;
    Row { what: "check, no database".into(), items: n, bytes: tad_bytes, time: direct }.print(Some(peer))?;
    Row { what: "check through the database".into(), items: n, bytes: tad_bytes, time: full }.print(Some(peer))?;
    Row { what: "fmt (parse+print)".into(), items: n, bytes: tad_bytes, time: format }.print(Some(peer))?;
    incremental(runs)?;

    if let Some(dir) = examples {
        let (paths, errors) = crate::files::collect(&[dir.to_path_buf()], crate::files::Search::Tad);
        for e in &errors {
            *status = Status::Usage;
            errln!("error: {e}")?;
        }
        let inputs: Vec<crate::files::Input> = paths.iter().filter_map(|p| crate::files::read(p).ok()).collect();
        let texts: Vec<&str> = inputs.iter().map(|i| i.text.as_str()).collect();
        if texts.is_empty() {
            // `collect` said why
            *status = Status::Usage;
            return Ok(());
        }
        // Repeat the examples to a measurable amount of work.
        let repeat = (tad_bytes / texts.iter().map(|t| t.len()).sum::<usize>().max(1)).max(1);
        let bytes = texts.iter().map(|t| t.len()).sum::<usize>() * repeat;
        // through the database as `tadslc check` does, a fresh one per repetition
        let time = best_of(runs, || {
            for _ in 0..repeat {
                let mut db = Database::new(tad_check::Options::default());
                for input in &inputs {
                    let file = crate::check::register(&mut db, input);
                    black_box(tad_db::check(&db, file));
                }
            }
        });
        Row {
            what: format!("check examples ({} x{repeat})", crate::plural(texts.len(), "file")),
            items: texts.len() * repeat,
            bytes,
            time,
        }
        .print(None)?;
    }
    Ok(())
}

/// A scenario of about `lines` lines: the usual sections and many actor groups.
pub(crate) fn long_scenario(lines: usize) -> String {
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

/// Re-checking a 2,000-line file after a one-line edit, against checking it from scratch.
fn incremental(runs: usize) -> Result<(), Closed> {
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
    outln!(
        "incremental: one-line edit of a {lines}-line file, re-checked: p50 {:.3} ms, p99 {:.3} ms; from scratch {:.3} ms ({:.2}x of it)",
        p50.as_secs_f64() * 1e3,
        p99.as_secs_f64() * 1e3,
        scratch.as_secs_f64() * 1e3,
        p50.as_secs_f64() / scratch.as_secs_f64().max(1e-9)
    )
}
