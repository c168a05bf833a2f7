//! `tadslc bench`: check throughput on one core, against serde_json as a peer.
//!
//! The peer parses the same scenarios written as JSON, measured in the same run, so the
//! figures compare as a ratio whatever the machine. Each measurement is the best of
//! `runs` repetitions.

use crate::Status;
use crate::corpus;
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

fn best_of(runs: usize, mut f: impl FnMut()) -> Duration {
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
    fn print(&self, peer: Option<Duration>) {
        let secs = self.time.as_secs_f64().max(1e-9);
        let ratio = peer.map_or(String::new(), |p| format!("{:>8.2}x", secs / p.as_secs_f64().max(1e-9)));
        println!(
            "{:<34} {:>9} {:>10.1} {:>12.0} {:>9.1} {ratio}",
            self.what,
            self.items,
            self.bytes as f64 / 1e6,
            self.items as f64 / secs,
            self.bytes as f64 / 1e6 / secs,
        );
    }
}

pub fn run(n: usize, seed: u64, examples: Option<&Path>, runs: usize) -> Status {
    let corpus = corpus::generate(n, seed);
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
    // the whole checker: structure, names against the standard vocabulary, semantics and
    // completeness (the vocabulary is built once, as the database does)
    let prelude = tad_db::stdlib::source(tad_db::PRELUDE).unwrap_or_default();
    let (core, _) = tad_syntax::analyze(prelude);
    let (vocabulary, _) = tad_check::Vocabulary::build([(tad_db::PRELUDE, &core)]);
    let options = tad_check::Options::default();
    let full = best_of(runs, || {
        for text in &tad {
            let (module, _) = tad_syntax::analyze(text);
            black_box(tad_check::check(&module, &vocabulary, &options));
        }
    });
    let format = best_of(runs, || {
        for text in &tad {
            black_box(tad_syntax::format::format(text).ok());
        }
    });

    println!("corpus: {n} generated scenarios, seed {seed}, best of {runs} runs, one core");
    println!(
        "{:<34} {:>9} {:>10} {:>12} {:>9} {:>9}",
        "measurement", "scenarios", "MB", "scenarios/s", "MB/s", "vs peer"
    );
    Row { what: "peer: serde_json::Value (JSON)".into(), items: n, bytes: json_bytes, time: peer }.print(None);
    Row { what: "lex".into(), items: n, bytes: tad_bytes, time: lex }.print(Some(peer));
    Row { what: "parse (lex+parse+lower)".into(), items: n, bytes: tad_bytes, time: check }.print(Some(peer));
    Row { what: "check (parse+names+semantics)".into(), items: n, bytes: tad_bytes, time: full }.print(Some(peer));
    Row { what: "fmt (parse+print)".into(), items: n, bytes: tad_bytes, time: format }.print(Some(peer));

    if let Some(dir) = examples {
        let (paths, errors) = crate::files::collect(&[dir.to_path_buf()]);
        for e in &errors {
            eprintln!("error: {e}");
        }
        let texts: Vec<String> = paths.iter().filter_map(|p| crate::files::read(p).ok()).map(|i| i.text).collect();
        if texts.is_empty() {
            eprintln!("error: no .tad files in `{}`", dir.display());
            return Status::Usage;
        }
        // Repeat the examples to a measurable amount of work.
        let repeat = (tad_bytes / texts.iter().map(String::len).sum::<usize>().max(1)).max(1);
        let bytes = texts.iter().map(String::len).sum::<usize>() * repeat;
        let time = best_of(runs, || {
            for _ in 0..repeat {
                for text in &texts {
                    black_box(tad_syntax::analyze(text));
                }
            }
        });
        Row {
            what: format!("check examples ({} files x{repeat})", texts.len()),
            items: texts.len() * repeat,
            bytes,
            time,
        }
        .print(None);
    }
    Status::Ok
}
