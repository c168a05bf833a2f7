//! Backend fixtures: every `tests/scenic/fixtures/*.tad` is built for Scenic and its
//! diagnostics judged by `tad_test_support::fixtures` (the annotations in it, in the UI
//! tests' format `// warning[W0700]: 17:13-17:22`; `NAME.stderr` beside it). A line
//! `// simulator: newtonian` or `// map: TOWN` sets that option. The files must check without
//! errors.
//!
//! `TAD_BLESS=1 cargo test -p tad-scenic --test fixtures` rewrites the annotations and the
//! `.stderr` files; never when `CI` is set.

mod common;

use std::path::{Path, PathBuf};

use tad_scenic::{EmitOptions, Simulator};

fn option(text: &str, key: &str) -> Option<String> {
    text.lines().find_map(|l| l.trim().strip_prefix(&format!("// {key}: ")).map(|v| v.trim().to_string()))
}

fn fixtures() -> Vec<PathBuf> {
    let dir = common::repo().join("tests/scenic/fixtures");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/scenic/fixtures")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "tad"))
        .collect();
    out.sort();
    out
}

fn run(path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).unwrap();
    let options = EmitOptions {
        simulator: if option(&text, "simulator").as_deref() == Some("newtonian") {
            Simulator::Newtonian
        } else {
            Simulator::Carla
        },
        map: option(&text, "map"),
        ..EmitOptions::default()
    };
    let emitted = common::build_text(path, &text, &options);
    tad_test_support::fixtures::judge(path, &text, &emitted.diagnostics)
}

#[test]
fn fixtures_report_what_they_expect() {
    let failures: Vec<String> = fixtures().iter().filter_map(|p| run(p).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn every_scenic_code_has_a_fixture() {
    let all: String = fixtures().iter().map(|p| std::fs::read_to_string(p).unwrap()).collect();
    // W071x are the OpenSCENARIO backend's
    for code in tad_diagnostics::Code::ALL.iter().filter(|c| c.as_str()[1..].starts_with("070")) {
        assert!(all.contains(&format!("[{code}]:")), "no fixture in tests/scenic/fixtures expects {code}");
    }
}
