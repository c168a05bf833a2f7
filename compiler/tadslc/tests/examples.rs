//! Every example checks without errors, is formatted, and has its expected completeness
//! class; the set is complete.

mod common;
use common::*;

/// The examples the paper leaves incomplete: it never states these lanes.
const INCOMPLETE: &[&str] = &["paper/extraction_prompt_example.tad", "paper/nl_description_example_2.tad"];

#[test]
fn every_example_checks_and_is_formatted() {
    let root = repo().join("examples");
    let files = tad_files(&root);
    assert!(files.len() >= 14, "at least 14 examples, found {}", files.len());
    let mut db = tad_db::Database::new(tad_check::Options::default());
    for path in &files {
        let relative = path.strip_prefix(&root).unwrap().to_str().unwrap().to_string();
        let input = tad_db::host::read(path).unwrap();
        let checked = tad_db::host::diagnose_in(&mut db, &input);
        let unexpected: Vec<_> =
            checked.diagnostics.iter().filter(|d| d.code != tad_diagnostics::Code::W0600).collect();
        assert!(unexpected.is_empty(), "{relative}: {unexpected:#?}");
        let expected = if INCOMPLETE.contains(&relative.as_str()) {
            tad_check::Class::Incomplete
        } else {
            tad_check::Class::Complete
        };
        assert_eq!(checked.class, Some(expected), "{relative}");
        let (module, _) = tad_syntax::analyze(&input.text);
        let stem = path.file_stem().unwrap().to_str().unwrap();
        assert_eq!(module.scenario.and_then(|s| s.name).map(|n| n.text).as_deref(), Some(stem), "named after its file");
        assert_eq!(
            tad_syntax::format::format(&input.text).as_deref(),
            Ok(input.text.as_str()),
            "{relative} is not formatted"
        );
    }
}

#[test]
fn the_cli_checks_and_formats_the_examples() {
    let out = tadslc(&["check", "examples"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stderr(&out).contains("scenarios: 17 complete, 2 incomplete"), "{}", stderr(&out));
    let out = tadslc(&["fmt", "--check", "examples"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
}

#[test]
fn the_stdlib_checks_clean_and_is_formatted() {
    let out = tadslc(&["check", "--deny-warnings", "stdlib"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let out = tadslc(&["fmt", "--check", "stdlib"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
}
