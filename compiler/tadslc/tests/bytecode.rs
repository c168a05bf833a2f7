//! `tadslc build --target bytecode` and `tadslc disasm` as a user runs them: files written,
//! listings printed, corrupt files refused with the loader's reason and status 1.

mod common;
use common::*;

#[test]
fn every_example_builds_to_bytecode_and_disassembles() {
    let out = scratch("bytecode-examples");
    let dir = out.to_string_lossy().into_owned();
    let build = tadslc(&["build", "--target", "bytecode", "examples", "-o", &dir], "");
    assert_eq!(code(&build), 0, "{}", stderr(&build));
    let examples = tad_files(&repo().join("examples"));
    for example in &examples {
        let stem = example.file_stem().unwrap().to_string_lossy();
        let file = out.join(format!("{stem}.tadc"));
        assert!(file.is_file(), "{} not written", file.display());
        assert!(stderr(&build).contains(&format!("wrote `{}`", file.display())), "{}", stderr(&build));
        let listing = tadslc(&["disasm", &file.to_string_lossy()], "");
        assert_eq!(code(&listing), 0, "{}", stderr(&listing));
        assert!(stdout(&listing).contains(&format!("program  {stem}")), "{}", stdout(&listing));
    }
    let listing = stdout(&tadslc(&["disasm", &out.join("red_light_running.tadc").to_string_lossy()], ""));
    assert!(listing.starts_with("; TADSL bytecode, format 2\n"), "{listing}");
    assert!(listing.contains("\n  signal   arm=ego green 30.0s"), "{listing}");
    assert!(listing.contains("\n  signals  a0 ignore\n"), "{listing}");
}

#[test]
fn a_corrupt_file_is_an_error_with_its_offset_not_a_panic() {
    let out = scratch("bytecode-corrupt");
    let dir = out.to_string_lossy().into_owned();
    assert_eq!(code(&tadslc(&["build", "--target", "bytecode", "examples/safety/right_turn.tad", "-o", &dir], "")), 0);
    let good = std::fs::read(out.join("right_turn.tadc")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("text.tadc", b"scenario x {}".to_vec(), "not a TADSL bytecode file"),
        ("empty.tadc", Vec::new(), "not a TADSL bytecode file"),
        ("cut.tadc", good[..good.len() / 2].to_vec(), "truncated"),
        ("newer.tadc", [&good[..4], &[9, 0], &good[6..]].concat(), "built by a newer tadslc (format 9, this reads 2)"),
        ("trailing.tadc", [&good[..], b"x"].concat(), "1 trailing byte after the last section"),
    ];
    for (name, bytes, message) in cases {
        let path = out.join(name);
        std::fs::write(&path, bytes).unwrap();
        let run = tadslc(&["disasm", &path.to_string_lossy()], "");
        assert_eq!(code(&run), 1, "{name}: {}", stderr(&run));
        let expected = format!("error: {}: {message}", path.display());
        assert!(stderr(&run).starts_with(&expected), "{name}: {}", stderr(&run));
        assert!(stderr(&run).contains("(at byte "), "{name}: {}", stderr(&run));
        assert!(stdout(&run).is_empty());
    }
    let missing = tadslc(&["disasm", &out.join("missing.tadc").to_string_lossy()], "");
    assert_eq!(code(&missing), 2, "{}", stderr(&missing));
}

#[test]
fn files_with_errors_are_skipped_and_the_others_built() {
    let out = scratch("bytecode-errors");
    let bad = out.join("bad.tad");
    std::fs::write(&bad, "scenario bad {\n  environment {\n    weather: sunnyy\n  }\n}\n").unwrap();
    let module = out.join("names.tad");
    std::fs::write(&module, "region lyon {\n  style: metropolitan\n}\n").unwrap();
    let target = out.join("out");
    let run = tadslc(
        &[
            "build",
            "--target",
            "bytecode",
            &bad.to_string_lossy(),
            &module.to_string_lossy(),
            "examples/safety/lane_changing.tad",
            "-o",
            &target.to_string_lossy(),
        ],
        "",
    );
    assert_eq!(code(&run), 1, "{}", stderr(&run));
    let err = stderr(&run);
    assert!(err.contains("E0202") || err.contains("error["), "{err}");
    assert!(err.contains(&format!("{}: not built: it has errors", bad.display())), "{err}");
    assert!(err.contains("E0700") && err.contains(&format!("{}: not built", module.display())), "{err}");
    assert!(!target.join("bad.tadc").exists() && !target.join("names.tadc").exists());
    assert!(target.join("lane_changing.tadc").is_file(), "{err}");
}

#[test]
fn bytecode_needs_an_output_directory_and_no_scenic_options() {
    let run = tadslc(&["build", "--target", "bytecode", "examples/safety/right_turn.tad"], "");
    assert_eq!(code(&run), 2);
    assert!(stderr(&run).contains("give an output directory with -o"), "{}", stderr(&run));
    let out = scratch("bytecode-options");
    let run = tadslc(
        &[
            "build",
            "--target",
            "bytecode",
            "examples/safety/right_turn.tad",
            "--map",
            "Town01",
            "-o",
            &out.to_string_lossy(),
        ],
        "",
    );
    assert_eq!(code(&run), 2, "{}", stderr(&run));
}

#[test]
fn generated_scenarios_build_to_programs_that_load() {
    let dir = scratch("bytecode-corpus");
    let inputs = dir.join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    for (i, g) in tad_eval::baseline::generate(300, 11).into_iter().enumerate() {
        std::fs::write(inputs.join(format!("g{i:03}.tad")), g.tad).unwrap();
    }
    let out = dir.join("out");
    let run = tadslc(&["build", "--target", "bytecode", &inputs.to_string_lossy(), "-o", &out.to_string_lossy()], "");
    // some generated scenarios break the checker's rules (refused: status 1); the rest build
    assert!(code(&run) <= 1, "{}", stderr(&run));
    let built = files(&out, "tadc");
    let refused = stderr(&run).matches("not built").count();
    assert_eq!(built.len() + refused, 300, "{}", stderr(&run));
    assert!(built.len() >= 60, "only {} built", built.len());
    for file in built {
        let bytes = std::fs::read(&file).unwrap();
        let program = tad_bytecode::decode(&bytes).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert_eq!(tad_bytecode::encode(&program), bytes, "{}", file.display());
    }
}
