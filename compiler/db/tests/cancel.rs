//! Superseded work is cancelled: a reader of a snapshot whose input is being set unwinds
//! at its next query ([`tad_db::cancellable`] gives `None`) instead of finishing stale work,
//! and the writer goes on once the snapshot is dropped. The language server relies on this
//! for every request and check that an edit overtakes.

use std::sync::mpsc;

use tad_check::Options;
use tad_db::{Database, Language, NoFs, check};

#[test]
fn an_edit_cancels_a_check_of_the_old_text() {
    let mut db = Database::new(Options::default());
    let group = "  actor g: 2 sedan {\n    behavior: move_forward\n    position: front of ego\n    lane: 1\n  }\n";
    // some eight hundred groups: enough queries that an edit arriving mid-check is still
    // seen, few enough that checking the new text stays quick in a debug build
    let mut text = String::from("scenario big {\n");
    while text.len() < 64 << 10 {
        text.push_str(group);
    }
    text.push_str("}\n");
    let file = db.set_source("/virtual/big.tad".into(), text.clone(), Language::Tad, &NoFs);
    let snapshot = db.clone();
    let (started, wait) = mpsc::channel();
    let reader = std::thread::spawn(move || {
        started.send(()).unwrap();
        // the writer below is waiting for this snapshot by the time the check needs it
        std::thread::sleep(std::time::Duration::from_millis(500));
        tad_db::cancellable(std::panic::AssertUnwindSafe(|| check(&snapshot, file).diagnostics.len()))
    });
    wait.recv().unwrap();
    // blocks until the reader has unwound and dropped its snapshot
    let file = db.set_source("/virtual/big.tad".into(), text.replacen("lane: 1", "lane: 2", 1), Language::Tad, &NoFs);
    assert_eq!(reader.join().unwrap(), None, "the stale check was cancelled");
    // the new text is checked as usual
    assert!(tad_db::cancellable(std::panic::AssertUnwindSafe(|| check(&db, file).class)).is_some());
}
