//! Golden outputs: every example's Scenic program (CARLA, the map chosen by the backend,
//! maps next to the program) is `tests/scenic/golden/NAME.scenic`.
//!
//! `TAD_BLESS=1 cargo test -p tad-scenic --test golden` rewrites them; never when `CI` is set.

mod common;

use tad_scenic::EmitOptions;

fn bless() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

#[test]
fn examples_match_their_golden_programs() {
    let repo = common::repo();
    let golden = repo.join("tests/scenic/golden");
    let mut failures = Vec::new();
    let mut expected_files = Vec::new();
    for example in common::examples() {
        let relative = example.strip_prefix(&repo).unwrap().to_string_lossy().replace('\\', "/");
        let options = EmitOptions { source: Some(relative), ..EmitOptions::default() };
        let actual = common::build(&example, &options).text;
        let path = golden.join(format!("{}.scenic", common::stem(&example)));
        expected_files.push(path.clone());
        if bless() {
            std::fs::create_dir_all(&golden).unwrap();
            std::fs::write(&path, &actual).unwrap();
            continue;
        }
        match std::fs::read_to_string(&path) {
            Ok(expected) if expected == actual => {}
            Ok(_) => failures.push(format!("{} differs (TAD_BLESS=1 to accept)", path.display())),
            Err(_) => failures.push(format!("{} is missing (TAD_BLESS=1 to create it)", path.display())),
        }
    }
    // no stale golden files
    for entry in std::fs::read_dir(&golden).into_iter().flatten().flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|e| e == "scenic") && !expected_files.contains(&path) {
            if bless() {
                std::fs::remove_file(&path).unwrap();
            } else {
                failures.push(format!("{} belongs to no example", path.display()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn emission_is_deterministic() {
    for example in common::examples().into_iter().take(5) {
        let a = common::build(&example, &EmitOptions::default());
        let b = common::build(&example, &EmitOptions::default());
        assert_eq!(a, b);
    }
}
