//! Hostile input (`tadslc bench --hostile`): files of one size that no one would write —
//! a run of one bad character, deep nesting, a hundred thousand fields, one endless line —
//! checked and formatted as `tadslc check` and `fmt` do, against a clean file of the same
//! size measured in the same run.
//!
//! Each row is what a user waits for: the database's check and the report of its first
//! [`CAP`] diagnostics (the CLI's default), and the formatter with its capped report. Time
//! is the best of `runs`; memory is the process's peak resident set during that step
//! (`VmHWM`, reset through `/proc/self/clear_refs` before each; Linux). The goal is that
//! every hostile file stays within 10× of the clean one in both.

use std::path::Path;

use tad_db::{Database, Language, NoFs};
use tad_diagnostics::render::{FileReport, human};

use crate::{BenchError, Report, best_of, proc_status_kib};

/// Diagnostics reported per file: `check`'s and `fmt`'s default `--max-diagnostics`.
pub const CAP: usize = 50;

/// One kind of file, made `size` bytes long (about).
pub struct Shape {
    pub name: &'static str,
    pub make: fn(usize) -> String,
}

/// The clean file first, then the hostile ones.
pub const SHAPES: &[Shape] = &[
    Shape { name: "clean: one scenario, many groups", make: clean },
    Shape { name: "a run of `@`", make: |size| "@".repeat(size) },
    Shape { name: "nested `{`", make: |size| format!("scenario deep {{ {}", "{".repeat(size)) },
    Shape { name: "nested `[`", make: |size| format!("scenario deep {{ ego {{ lane: {}", "[".repeat(size)) },
    Shape {
        name: "100k fields",
        make: |size| format!("scenario many {{\n  ego {{\n{}  }}\n}}\n", "lane: 1\n".repeat(size / 8)),
    },
    Shape { name: "lines of `- `", make: |size| "- \n".repeat(size / 3) },
    Shape { name: "unterminated strings", make: |size| "\"a\n".repeat(size / 3) },
    Shape { name: "one line of words", make: |size| "word ".repeat(size / 5) },
];

/// A valid scenario of about `size` bytes: an ego and numbered groups ahead of it.
fn clean(size: usize) -> String {
    let mut text = String::from(
        "scenario clean {\n  road {\n    type: straight_road\n    lanes: 3\n  }\n  ego {\n    behavior: move_forward\n    speed: 30 km/h\n    lane: 1\n  }\n",
    );
    let mut i = 0;
    while text.len() < size {
        let lane = i % 3 + 1;
        let distance = 10 + i % 150;
        text.push_str(&format!(
            "  actor car_{i}: car {{\n    behavior: move_forward\n    speed: 30 km/h\n    position: front of ego\n    distance: {distance} m\n    lane: {lane}\n  }}\n"
        ));
        i += 1;
    }
    text.push_str("}\n");
    text
}

/// What one file costs to check and to format, and what it reported.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measured {
    /// Seconds, best of the runs.
    pub check: f64,
    pub format: f64,
    /// Peak resident set (KiB) of the process while it checked, and while it formatted.
    pub check_kib: Option<u64>,
    pub format_kib: Option<u64>,
    /// Diagnostics found by the check (all of them), and those the formatter reported.
    pub diagnostics: usize,
    pub format_errors: usize,
    /// The length of the two reports (the first [`CAP`] diagnostics rendered).
    pub report_bytes: usize,
}

impl Measured {
    fn to_json(&self) -> String {
        serde_json::json!({
            "check": self.check, "format": self.format,
            "check_kib": self.check_kib, "format_kib": self.format_kib,
            "diagnostics": self.diagnostics, "format_errors": self.format_errors,
            "report_bytes": self.report_bytes,
        })
        .to_string()
    }

    fn from_json(line: &str) -> Option<Measured> {
        let v: serde_json::Value = serde_json::from_str(line).ok()?;
        let n = |k: &str| v[k].as_u64();
        Some(Measured {
            check: v["check"].as_f64()?,
            format: v["format"].as_f64()?,
            check_kib: n("check_kib"),
            format_kib: n("format_kib"),
            diagnostics: n("diagnostics")? as usize,
            format_errors: n("format_errors")? as usize,
            report_bytes: n("report_bytes")? as usize,
        })
    }
}

/// Check `text` as `tadslc check` does, and format it as `tadslc fmt` does.
pub fn measure(text: &str, runs: usize) -> Measured {
    let mut diagnostics = 0;
    let mut report_bytes = 0;
    let (check, check_kib) = peak(|| {
        best_of(runs, || {
            let mut db = Database::new(tad_check::Options::default());
            let file = db.set_source("/bench/hostile.tad".into(), text.to_string(), Language::Tad, &NoFs);
            let all = &tad_db::check(&db, file).diagnostics;
            diagnostics = all.len();
            let report = FileReport::new("hostile.tad", text, &all[..all.len().min(CAP)]);
            report_bytes = human::render(&report, false).len();
        })
    });
    let mut format_errors = 0;
    let (format, format_kib) = peak(|| {
        best_of(runs, || match tad_syntax::format::format(text) {
            Ok(formatted) => {
                std::hint::black_box(formatted);
            }
            Err(all) => {
                format_errors = all.len();
                let report = FileReport::new("hostile.tad", text, &all[..all.len().min(CAP)]);
                report_bytes += human::render(&report, false).len();
            }
        })
    });
    let (check, format) = (check.as_secs_f64(), format.as_secs_f64());
    Measured { check, format, check_kib, format_kib, diagnostics, format_errors, report_bytes }
}

/// `bench --hostile --shape I`: shape `I` measured in this process, as one JSON line.
pub fn one(shape: usize, size: usize, runs: usize) -> Result<String, BenchError> {
    let shape = SHAPES.get(shape).ok_or_else(|| format!("--shape takes 0 to {}", SHAPES.len() - 1))?;
    Ok(measure(&(shape.make)(size), runs).to_json())
}

/// `f`'s result and the peak resident set while it ran (Linux; `None` elsewhere).
fn peak<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    // "5" resets the peak to the current resident set
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let value = f();
    (value, reset.then(|| proc_status_kib("self", "VmHWM")).flatten())
}

/// `tadslc bench --hostile`: every shape at `size` bytes, best of `runs`, each in a
/// process of its own (`exe bench --hostile --shape I`), so one shape's memory is not
/// another's.
pub fn run(exe: &Path, size: usize, runs: usize, progress: &mut dyn FnMut(&str)) -> Result<Report, BenchError> {
    if !(1_000..=100_000_000).contains(&size) {
        return Err("--size takes 1000 to 100000000 bytes".into());
    }
    let mut report = Report::default();
    report.lines.push(format!(
        "{:<34} {:>9} {:>7} {:>9} {:>6} {:>6} {:>6} {:>9} {:>6} {:>6} {:>6} {:>9}",
        "file", "bytes", "found", "check ms", "×", "MiB", "×", "fmt ms", "×", "MiB", "×", "report KB"
    ));
    let mut clean: Option<Measured> = None;
    for (index, shape) in SHAPES.iter().enumerate() {
        progress(&format!("{} ...", shape.name));
        let bytes = (shape.make)(size).len();
        let m = child(exe, index, size, runs)?;
        let base = clean.as_ref().unwrap_or(&m);
        let ms = |seconds: f64| seconds * 1e3;
        let times = |a: f64, b: f64| format!("{:.1}", a / b.max(1e-9));
        let mib = |k: Option<u64>| k.map_or("-".to_string(), |k| format!("{:.0}", k as f64 / 1024.0));
        let more = |a: Option<u64>, b: Option<u64>| match (a, b) {
            (Some(a), Some(b)) => format!("{:.1}", a as f64 / b.max(1) as f64),
            _ => "-".into(),
        };
        report.lines.push(format!(
            "{:<34} {:>9} {:>7} {:>9.1} {:>6} {:>6} {:>6} {:>9.1} {:>6} {:>6} {:>6} {:>9.1}",
            shape.name,
            bytes,
            m.diagnostics,
            ms(m.check),
            times(m.check, base.check),
            mib(m.check_kib),
            more(m.check_kib, base.check_kib),
            ms(m.format),
            times(m.format, base.format),
            mib(m.format_kib),
            more(m.format_kib, base.format_kib),
            m.report_bytes as f64 / 1e3,
        ));
        clean.get_or_insert(m);
    }
    report.notes.push(format!(
        "×clean: time/peak memory against the clean file, best of {runs}; found: the check's diagnostics (reports show the first {CAP})"
    ));
    Ok(report)
}

/// One shape measured by `exe` in a child process.
fn child(exe: &Path, shape: usize, size: usize, runs: usize) -> Result<Measured, BenchError> {
    let output = std::process::Command::new(exe)
        .args(["bench", "--hostile", "--shape", &shape.to_string(), "--size", &size.to_string()])
        .args(["--runs", &runs.to_string()])
        .output()?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    stdout.lines().last().and_then(Measured::from_json).ok_or_else(|| {
        let stderr = String::from_utf8_lossy(&output.stderr);
        BenchError(format!("shape {shape} measured nothing ({}): {}", output.status, stderr.trim()))
    })
}
