//! The database reuses what did not change: an edit that changes no declaration rebuilds
//! no module's vocabulary, an edit to one file re-checks that file only, and a used
//! module's errors stay in that module's file.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use tad_check::Options;
use tad_db::{Database, FileSystem, Language, analyze, check};
use tad_diagnostics::Code;

const SCENARIO: &str = "scenario demo {\n  environment {\n    weather: sunny\n  }\n}\n";

fn executed(log: &[String], query: &str) -> usize {
    log.iter().filter(|l| l.starts_with(&format!("{query}("))).count()
}

/// Files in memory, for module resolution without a disk.
struct Memory(HashMap<PathBuf, String>);

impl FileSystem for Memory {
    fn read(&self, path: &Path) -> Option<String> {
        self.0.get(path).cloned()
    }
}

#[test]
fn an_edit_re_runs_only_the_edited_file() {
    let mut db = Database::logged(Options::default());
    let a = db.set_file("/virtual/a.tad".into(), SCENARIO.into());
    let b = db.set_file("/virtual/b.tad".into(), SCENARIO.replace("demo", "other"));
    assert_eq!(check(&db, a).diagnostics.iter().filter(|d| d.code == Code::W0401).count(), 1);
    check(&db, b);
    let first = db.take_log();
    // every standard module's (the ones out of scope name the module of an unknown name),
    // a's and b's
    let standard = tad_db::stdlib::MODULES.len();
    assert_eq!(executed(&first, "layer"), standard + 2, "{first:#?}");

    // nothing changed: nothing runs
    check(&db, a);
    check(&db, b);
    assert!(db.take_log().is_empty());

    // a field value changes: a is re-analysed and re-checked; no vocabulary is rebuilt
    db.set_file("/virtual/a.tad".into(), SCENARIO.replace("sunny", "clear"));
    let checked = check(&db, a).clone();
    check(&db, b);
    let second = db.take_log();
    assert_eq!(executed(&second, "analyze"), 1, "{second:#?}");
    assert_eq!(executed(&second, "check"), 1, "{second:#?}");
    assert_eq!(executed(&second, "layer"), 0, "{second:#?}");
    assert_eq!(executed(&second, "vocabulary"), 0, "{second:#?}");
    assert!(checked.diagnostics.iter().all(|d| d.code != Code::W0401));

    // a comment line: the same
    db.set_file("/virtual/a.tad".into(), format!("// a note\n{}", SCENARIO.replace("sunny", "clear")));
    check(&db, a);
    let third = db.take_log();
    assert_eq!(executed(&third, "layer") + executed(&third, "vocabulary") + executed(&third, "scope"), 0, "{third:#?}");
    assert_eq!(executed(&third, "check"), 1, "{third:#?}");

    // setting the same text again is not a change
    db.set_file("/virtual/a.tad".into(), format!("// a note\n{}", SCENARIO.replace("sunny", "clear")));
    check(&db, a);
    assert!(db.take_log().is_empty());
    assert!(analyze(&db, a).module.scenario.is_some());
}

#[test]
fn a_used_module_is_indexed_once_and_rebuilt_only_when_its_declarations_change() {
    let module = "weather hail {\n  aliases: [hailstorm]\n}\n".to_string();
    let scenario =
        |name: &str| format!("use local\nscenario {name} {{\n  environment {{\n    weather: hailstorm\n  }}\n}}\n");
    let mut fs = Memory(HashMap::from([(PathBuf::from("/v/local.tad"), module.clone())]));
    let mut db = Database::logged(Options::default());
    let a = db.set_source("/v/a.tad".into(), scenario("a"), Language::Tad, &fs);
    let b = db.set_source("/v/b.tad".into(), scenario("b"), Language::Tad, &fs);
    for file in [a, b] {
        let codes: Vec<Code> = check(&db, file).diagnostics.iter().map(|d| d.code).collect();
        assert_eq!(codes.iter().filter(|c| **c == Code::W0401).count(), 1, "{codes:?}");
        assert!(!codes.contains(&Code::E0400), "{codes:?}");
    }
    let first = db.take_log();
    // layers: every standard module, local, a, b
    assert_eq!(executed(&first, "layer"), tad_db::stdlib::MODULES.len() + 3, "{first:#?}");

    // editing a scenario touches neither the module's layer nor the other file
    db.set_source("/v/a.tad".into(), scenario("a").replace("hailstorm", "hail"), Language::Tad, &fs);
    check(&db, a);
    check(&db, b);
    let second = db.take_log();
    assert_eq!(executed(&second, "layer"), 0, "{second:#?}");
    assert_eq!(executed(&second, "check"), 1, "{second:#?}");

    // a comment in the module: its declarations move, so its layer is rebuilt once, and
    // the prelude's is not
    fs.0.insert(PathBuf::from("/v/local.tad"), format!("// moved\n{module}"));
    db.set_source("/v/a.tad".into(), scenario("a"), Language::Tad, &fs);
    check(&db, a);
    check(&db, b);
    let third = db.take_log();
    assert_eq!(executed(&third, "layer"), 1, "local's only: {third:#?}");
}

#[test]
fn errors_of_a_used_module_are_reported_in_its_file() {
    let fs = Memory(HashMap::from([(
        PathBuf::from("/v/broken.tad"),
        "weather hail {\n  aliases: [hailstorm\n}\nweather clear\n".to_string(),
    )]));
    let mut db = Database::new(Options::default());
    let main = db.set_source("/v/main.tad".into(), "use broken\n".into(), Language::Tad, &fs);
    let module = db.file_at(Path::new("/v/broken.tad")).expect("registered");
    let ours = check(&db, main);
    let e0404 = ours.diagnostics.iter().find(|d| d.code == Code::E0404).expect("E0404 at the use");
    assert_eq!(e0404.file, main.id(&db));
    let label = &e0404.secondary[0];
    assert_eq!(label.file, Some(module.id(&db)), "{e0404:?}");
    let theirs = check(&db, module);
    assert!(theirs.diagnostics.iter().any(|d| d.is_error() && d.file == module.id(&db)), "{theirs:?}");
    // the conflict with the prelude's `clear` is labelled in the prelude's own file
    let conflict = theirs.diagnostics.iter().find(|d| d.code == Code::E0405).expect("E0405");
    let prelude = db.standard_module("core").expect("embedded");
    assert_eq!(conflict.secondary[0].file, Some(prelude.id(&db)));
}

#[test]
fn the_language_is_an_input() {
    let mut db = Database::new(Options::default());
    let yaml = "environment:\n  weather: clear\n  time: daytime\n";
    let file = db.set_source("/v/answer.txt".into(), yaml.into(), Language::Yaml, &tad_db::NoFs);
    assert!(analyze(&db, file).module.scenario.is_some());
    db.set_source("/v/answer.txt".into(), yaml.into(), Language::Tad, &tad_db::NoFs);
    assert!(analyze(&db, file).diagnostics.iter().any(|d| d.is_error()));
}

#[test]
fn changing_options_re_checks_without_re_parsing() {
    let mut db = Database::logged(Options::default());
    let file = db.set_file(
        "/virtual/c.tad".into(),
        "scenario c {\n  actor f: car {\n    position: behind of ego\n  }\n}\n".into(),
    );
    assert!(check(&db, file).diagnostics.iter().all(|d| d.code != Code::E0510));
    db.take_log();
    db.set_options(Options { profile: tad_check::Profile::Dashcam, ..Options::default() });
    assert!(check(&db, file).diagnostics.iter().any(|d| d.code == Code::E0510));
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
