//! The Scenic backend's codes in `spec/diagnostics.md`: the scenario of each section, built,
//! gives the code; and `spec/backends/scenic.md` lists every name of the standard vocabulary.

mod common;

use std::path::Path;

use tad_diagnostics::Code;
use tad_scenic::{EmitOptions, Simulator};

#[test]
fn every_scenic_code_is_produced_by_its_example() {
    // W0700–W0709; W071x are the OpenSCENARIO backend's
    let codes: Vec<Code> = Code::ALL.iter().copied().filter(|c| c.as_str()[1..].starts_with("070")).collect();
    assert_eq!(codes.len(), 9);
    for code in codes {
        let text = tad_test_support::fixtures::tad_block(code.explanation())
            .unwrap_or_else(|| panic!("{code}: no tad example"));
        let options = match code {
            Code::W0704 => EmitOptions { simulator: Simulator::Newtonian, ..EmitOptions::default() },
            Code::W0705 => EmitOptions { map: Some("Town05".into()), ..EmitOptions::default() },
            _ => EmitOptions::default(),
        };
        let emitted = common::build_text(Path::new("/nonexistent/example.tad"), &text, &options);
        assert!(
            emitted.diagnostics.iter().any(|d| d.code == code),
            "{code}: the example gives {:#?}",
            emitted.diagnostics
        );
    }
}

#[test]
fn the_mapping_lists_every_standard_name() {
    let doc = std::fs::read_to_string(common::repo().join("spec/backends/scenic.md")).unwrap();
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file("/nonexistent/v.tad".into(), "use national_park\nweather doc_probe\n".into());
    let vocabulary = &tad_db::vocabulary(&db, file).vocabulary;
    for kind in tad_syntax::schema::DECLARATIONS.iter().map(|d| d.name) {
        for name in vocabulary.names(kind) {
            if name == "doc_probe" {
                continue;
            }
            assert!(doc.contains(&format!("| `{name}` |")), "spec/backends/scenic.md has no row for {kind} `{name}`");
        }
    }
}
