//! The database reuses what did not change: editing one file re-runs that file's queries
//! only, and the vocabulary of the prelude is not rebuilt for it.

use tad_check::Options;
use tad_db::{Database, analyze, check};

const SCENARIO: &str = "scenario demo {\n  environment {\n    weather: sunny\n  }\n}\n";

fn executed(log: &[String], query: &str) -> usize {
    log.iter().filter(|l| l.starts_with(query)).count()
}

#[test]
fn an_edit_re_runs_only_the_edited_file() {
    let mut db = Database::logged(Options::default());
    let a = db.set_file("/virtual/a.tad".into(), SCENARIO.into());
    let b = db.set_file("/virtual/b.tad".into(), SCENARIO.replace("demo", "other"));
    assert_eq!(check(&db, a).diagnostics.iter().filter(|d| d.code == tad_diagnostics::Code::W0401).count(), 1);
    check(&db, b);
    let first = db.take_log();
    // a, b and the prelude were analysed once each
    assert_eq!(executed(&first, "analyze"), 3, "{first:#?}");

    // nothing changed: nothing runs
    check(&db, a);
    check(&db, b);
    assert!(db.take_log().is_empty());

    // editing a re-analyses a only; b's results are reused
    db.set_file("/virtual/a.tad".into(), SCENARIO.replace("sunny", "clear"));
    let checked = check(&db, a).clone();
    check(&db, b);
    let second = db.take_log();
    assert_eq!(executed(&second, "analyze"), 1, "{second:#?}");
    assert_eq!(executed(&second, "check"), 1, "{second:#?}");
    assert!(checked.diagnostics.iter().all(|d| d.code != tad_diagnostics::Code::W0401));

    // setting the same text again is not a change
    db.set_file("/virtual/a.tad".into(), SCENARIO.replace("sunny", "clear"));
    check(&db, a);
    assert!(db.take_log().is_empty());
    assert!(analyze(&db, a).module.scenario.is_some());
}

#[test]
fn changing_options_re_checks_without_re_parsing() {
    let mut db = Database::logged(Options::default());
    let file = db.set_file(
        "/virtual/c.tad".into(),
        "scenario c {\n  actor f: car {\n    position: behind of ego\n  }\n}\n".into(),
    );
    assert!(check(&db, file).diagnostics.iter().all(|d| d.code != tad_diagnostics::Code::E0510));
    db.take_log();
    db.set_options(Options { profile: tad_check::Profile::Dashcam, ..Options::default() });
    assert!(check(&db, file).diagnostics.iter().any(|d| d.code == tad_diagnostics::Code::E0510));
    let log = db.take_log();
    assert_eq!(executed(&log, "analyze"), 0, "{log:#?}");
}

#[test]
fn the_embedded_stdlib_is_the_stdlib_directory() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../stdlib");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "tad"))
        .map(|e| e.path().file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    let mut embedded: Vec<String> = tad_db::stdlib::MODULES.iter().map(|(n, _)| n.to_string()).collect();
    embedded.sort();
    assert_eq!(on_disk, embedded);
    for (name, text) in tad_db::stdlib::MODULES {
        assert_eq!(std::fs::read_to_string(dir.join(format!("{name}.tad"))).unwrap(), *text);
    }
}
