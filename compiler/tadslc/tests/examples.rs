//! Every example checks clean, is formatted, and the set is complete.

mod common;
use common::*;

#[test]
fn every_example_checks_clean_and_is_formatted() {
    let files = tad_files(&repo().join("examples"));
    assert!(files.len() >= 14, "at least 14 examples, found {}", files.len());
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let (module, diagnostics) = tad_syntax::analyze(&text);
        assert!(diagnostics.is_empty(), "{}: {diagnostics:#?}", path.display());
        let scenario = module.scenario.expect("a scenario");
        let stem = path.file_stem().unwrap().to_str().unwrap();
        assert_eq!(scenario.name.map(|n| n.text).as_deref(), Some(stem), "scenario named after its file");
        assert_eq!(
            tad_syntax::format::format(&text).as_deref(),
            Ok(text.as_str()),
            "{} is not formatted",
            path.display()
        );
    }
}

#[test]
fn the_cli_checks_and_formats_the_examples() {
    let out = tadslc(&["check", "examples"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stderr(&out).contains("no problems"));
    let out = tadslc(&["fmt", "--check", "examples"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
}
