//! The command line as a user runs it: exit codes, output formats, files and stdin.

mod common;
use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

const CLEAN: &str = "scenario demo {\n  environment {\n    weather: clear\n    time: daytime\n  }\n  road {\n    type: straight_road\n    lanes: 1\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    speed: 30 km/h\n    lane: 1\n  }\n}\n";
const WARNING_ONLY: &str = "scenario demo {\n  environment {\n  }\n}\n";

#[test]
fn three_separate_syntax_errors_give_three_located_coded_errors() {
    let out = tadslc(&["check", "--format", "json", "tests/ui/parse/three_errors.tad"], "");
    assert_eq!(code(&out), 1);
    let file: Value = serde_json::from_str(stdout(&out).trim()).expect("one JSON object");
    let diagnostics = file["diagnostics"].as_array().expect("diagnostics");
    let lines: Vec<(u64, &str)> = diagnostics
        .iter()
        .filter(|d| d["severity"] == "error")
        .map(|d| (d["span"]["start"]["line"].as_u64().unwrap(), d["code"].as_str().unwrap()))
        .collect();
    assert_eq!(lines, vec![(5, "E0100"), (9, "E0100"), (15, "E0100")]);
}

#[test]
fn json_output_has_the_documented_shape() {
    let out = tadslc(&["check", "--format", "json", "tests/ui/structure/unknown_field.tad", "-"], CLEAN);
    assert_eq!(code(&out), 1);
    let lines: Vec<Value> = stdout(&out).lines().map(|l| serde_json::from_str(l).expect("valid JSON line")).collect();
    assert_eq!(lines.len(), 2, "one object per file");
    assert_eq!(lines[1]["file"], "<stdin>");
    assert_eq!(lines[1]["diagnostics"].as_array().map(Vec::len), Some(0));
    assert_eq!(lines[1]["class"], "complete");
    assert_eq!(lines[1]["refinement"], serde_json::json!([]));
    let d = lines[0]["diagnostics"].as_array().unwrap().iter().find(|d| d["code"] == "E0203").expect("E0203");
    for key in ["code", "severity", "message", "span", "label", "labels", "notes", "help", "fixes"] {
        assert!(d.get(key).is_some(), "missing `{key}` in {d}");
    }
    assert_eq!(d["code"], "E0203");
    assert_eq!(d["severity"], "error");
    assert_eq!(d["span"]["start"], serde_json::json!({"line": 3, "column": 5}));
    assert_eq!(d["span"]["end"], serde_json::json!({"line": 3, "column": 11}));
    let (start, end) = (d["span"]["byte_start"].as_u64().unwrap(), d["span"]["byte_end"].as_u64().unwrap());
    let text = std::fs::read_to_string(repo().join("tests/ui/structure/unknown_field.tad")).unwrap();
    assert_eq!(&text[start as usize..end as usize], "wether");
    assert_eq!(d["fixes"][0]["replacement"], "weather");
    assert_eq!(d["fixes"][0]["applicability"], "maybe-incorrect");
    assert_eq!(
        d["payload"],
        serde_json::json!({
            "kind": "unknown", "namespace": "field", "name": "wether", "candidates": ["weather"], "module": null
        })
    );
    assert_eq!(d["help"], "did you mean `weather`?");
}

#[test]
fn every_diagnostic_of_every_fixture_has_a_payload_and_every_fix_an_applicability() {
    let mut yaml: Vec<String> = Vec::new();
    for dir in ["tests/yaml/answers", "tests/yaml/paper", "tests/yaml/cli"] {
        for entry in std::fs::read_dir(repo().join(dir)).into_iter().flatten().flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.ends_with(".yaml") || name.ends_with(".yml") {
                yaml.push(format!("{dir}/{name}"));
            }
        }
    }
    yaml.sort();
    let mut args = vec!["check", "--format", "json", "tests/ui"];
    args.extend(yaml.iter().map(String::as_str));
    let dashcam = ["check", "--format", "json", "--profile", "dashcam", "tests/ui/check/dashcam.tad"];
    let output = format!("{}{}", stdout(&tadslc(&args, "")), stdout(&tadslc(&dashcam, "")));
    let mut codes = std::collections::BTreeSet::new();
    for line in output.lines() {
        let file: Value = serde_json::from_str(line).expect("valid JSON line");
        for d in file["diagnostics"].as_array().unwrap() {
            codes.insert(d["code"].as_str().unwrap().to_string());
            let kind = d["payload"]["kind"].as_str().unwrap_or("");
            assert!(!kind.is_empty() && kind != "none", "{} in {}: no payload: {d}", d["code"], file["file"]);
            for fix in d["fixes"].as_array().unwrap() {
                let applicability = fix["applicability"].as_str().unwrap_or("");
                assert!(
                    ["machine-applicable", "maybe-incorrect", "has-placeholders"].contains(&applicability),
                    "{fix}"
                );
            }
        }
    }
    // the fixtures cover every code but the backend's (tested with the backend)
    let missing: Vec<&str> = tad_diagnostics::Code::ALL
        .iter()
        .map(|c| c.as_str())
        .filter(|c| !c.starts_with("E07") && !c.starts_with("W07") && !codes.contains(*c))
        .collect();
    assert!(missing.is_empty(), "codes without a fixture in the JSON run: {missing:?}");
}

#[test]
fn a_label_in_another_file_names_that_file() {
    let out = tadslc(&["check", "--format", "json", "tests/ui/check/declarations.tad"], "");
    let file: Value = serde_json::from_str(stdout(&out).trim()).expect("one JSON object");
    let conflict = file["diagnostics"].as_array().unwrap().iter().find(|d| d["code"] == "E0405").expect("E0405");
    assert_eq!(conflict["labels"][0]["file"], "<stdlib>/core.tad", "{conflict}");
    assert_eq!(conflict["payload"]["kind"], "duplicate");
    assert_eq!(conflict["payload"]["earlier_module"], "core");
    let line = conflict["labels"][0]["span"]["start"]["line"].as_u64().unwrap() as usize;
    let core = std::fs::read_to_string(repo().join("stdlib/core.tad")).unwrap();
    assert!(core.lines().nth(line - 1).unwrap().starts_with("weather clear"), "line {line}");
}

#[test]
fn errors_make_a_scenario_invalid_whatever_it_states() {
    // complete in every essential, but a reference names nothing
    let broken = CLEAN.replace(
        "  ego {",
        "  actor lead: car {\n    behavior: move_forward\n    position: front of nobody\n    lane: 1\n  }\n  ego {",
    );
    let out = tadslc(&["check", "--format", "json", "-"], &broken);
    assert_eq!(code(&out), 1);
    let file: Value = serde_json::from_str(stdout(&out).trim()).expect("one JSON object");
    assert_eq!(file["class"], "invalid");
    assert_eq!(file["refinement"], serde_json::json!([]));
    let human = tadslc(&["check", "-"], &broken);
    assert!(stderr(&human).contains("scenarios: 1 invalid"), "{}", stderr(&human));
    let sarif = tadslc(&["check", "--format", "sarif", "-"], &broken);
    let log: Value = serde_json::from_str(&stdout(&sarif)).expect("SARIF");
    assert_eq!(log["runs"][0]["artifacts"][0]["properties"]["class"], "invalid");
}

#[test]
fn human_output_caps_the_diagnostics_of_a_file() {
    let fields: String = (1..=80).map(|i| format!("    wether{i}: clear\n")).collect();
    let many = format!("scenario x {{\n  environment {{\n{fields}  }}\n}}\n");
    let out = tadslc(&["check", "-"], &many);
    assert_eq!(code(&out), 1);
    let text = stderr(&out);
    assert_eq!(text.matches("error[E0203]").count(), 48, "the first 50 diagnostics");
    assert!(text.contains("<stdin>: and 32 more diagnostics (32 errors)"), "{text}");
    assert!(text.contains("checked 1 file: 80 errors"), "the summary counts all: {text}");
    let all = tadslc(&["check", "--max-diagnostics", "0", "-"], &many);
    assert_eq!(stderr(&all).matches("error[E0203]").count(), 80);
    // every format: the first 50 and how many were left out
    let json = tadslc(&["check", "--format", "json", "-"], &many);
    let file: Value = serde_json::from_str(stdout(&json).trim()).unwrap();
    assert_eq!((file["diagnostics"].as_array().unwrap().len(), file["omitted"].as_u64()), (50, Some(32)));
    let json = tadslc(&["check", "--format", "json", "--max-diagnostics", "0", "-"], &many);
    let file: Value = serde_json::from_str(stdout(&json).trim()).unwrap();
    assert_eq!((file["diagnostics"].as_array().unwrap().len(), file["omitted"].as_u64()), (82, Some(0)));
    let sarif = tadslc(&["check", "--format", "sarif", "-"], &many);
    let log: Value = serde_json::from_str(stdout(&sarif).trim()).unwrap();
    assert_eq!(log["runs"][0]["results"].as_array().unwrap().len(), 50);
    assert_eq!(log["runs"][0]["artifacts"][0]["properties"]["omitted"], 32);
}

#[test]
fn sarif_output_is_a_valid_sarif_log() {
    let out = tadslc(&["check", "--format", "sarif", "tests/ui/structure"], "");
    assert_eq!(code(&out), 1);
    let log: Value = serde_json::from_str(&stdout(&out)).expect("one JSON document");
    assert_eq!(log["version"], "2.1.0");
    let run = &log["runs"][0];
    assert_eq!(run["tool"]["driver"]["name"], "tadslc");
    let rules = run["tool"]["driver"]["rules"].as_array().unwrap();
    let results = run["results"].as_array().unwrap();
    assert!(results.len() > 20);
    for result in results {
        let index = result["ruleIndex"].as_u64().unwrap() as usize;
        assert_eq!(rules[index]["id"], result["ruleId"], "ruleIndex points at the rule");
        assert!(matches!(result["level"].as_str(), Some("error" | "warning" | "note")));
        let region = &result["locations"][0]["physicalLocation"]["region"];
        assert!(region["startLine"].as_u64().unwrap() >= 1 && region["startColumn"].as_u64().unwrap() >= 1);
        let uri = result["locations"][0]["physicalLocation"]["artifactLocation"]["uri"].as_str().unwrap();
        assert!(uri.starts_with("tests/ui/structure/") && uri.ends_with(".tad"), "{uri}");
    }
    assert!(rules.iter().all(|r| !r["shortDescription"]["text"].as_str().unwrap().is_empty()));
}

#[test]
fn exit_codes() {
    assert_eq!(code(&tadslc(&["check", "-"], CLEAN)), 0);
    assert_eq!(code(&tadslc(&["check", "-"], "scenario {")), 1);
    // warnings pass unless denied
    assert_eq!(code(&tadslc(&["check", "-"], WARNING_ONLY)), 0);
    assert_eq!(code(&tadslc(&["check", "--deny-warnings", "-"], WARNING_ONLY)), 1);
    // usage and I/O failures
    assert_eq!(code(&tadslc(&[], "")), 2);
    assert_eq!(code(&tadslc(&["check"], "")), 2);
    assert_eq!(code(&tadslc(&["check", "--format", "xml", "-"], CLEAN)), 2);
    let out = tadslc(&["check", "no/such/file.tad", "-"], CLEAN);
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("cannot read `no/such/file.tad`"));
    assert!(stderr(&out).contains("checked 1 file: no problems"), "the other file is still checked");
}

#[test]
fn human_output_is_coloured_only_when_asked_or_on_a_terminal() {
    let plain = tadslc(&["check", "tests/ui/structure/unknown_field.tad"], "");
    assert!(!stderr(&plain).contains('\u{1b}'), "not a terminal: no escapes");
    assert!(stderr(&plain).contains("error[E0203]: unknown field `wether` in `environment`"));
    assert!(stderr(&plain).contains("checked 1 file: 5 errors"));
    let coloured = tadslc(&["check", "--color", "always", "tests/ui/structure/unknown_field.tad"], "");
    assert!(stderr(&coloured).contains('\u{1b}'));
}

/// Escape sequences and bidirectional overrides in a file are shown, not obeyed: the
/// terminal gets none of them, and the caret still points at the character.
#[test]
fn control_bytes_in_a_file_are_escaped_in_diagnostics() {
    let dir = scratch("control-bytes");
    let path = dir.join("esc.tad");
    std::fs::write(&path, "scenario x {\n  road {\n    lanes: 2\u{1b}[31m \u{202e}\n  }\n}\n").unwrap();
    let out = tadslc(&["check", path.to_str().unwrap()], "");
    let text = stderr(&out);
    assert!(!text.contains('\u{1b}') && !text.contains('\u{202e}'), "{text}");
    assert!(text.contains("lanes: 2?[31m \u{fffd}"), "{text}");
    assert!(text.contains("error[E0001]: unexpected character `\\u{1b}`"), "{text}");
}

/// One region parser for every `--region`, and towns checked: unknown names are usage
/// errors (status 2) that list what exists, before any work.
#[test]
fn unknown_regions_and_towns_are_refused_before_work() {
    let example = "examples/safety/right_turn.tad";
    for args in [
        &["check", "--region", "yelowstone", example][..],
        &["eval", "--region", "atlantis"],
        &["eval", "--region", "los_angeles,Los_Angeles"],
        &["gen", "--region", "mars", "-n", "1"],
        &["translate", "--region", "mars", example],
        &["grammar", "--region", "mars"],
    ] {
        let out = tadslc(args, "");
        assert_eq!(code(&out), 2, "{args:?}");
        assert!(stderr(&out).contains("(the regions are: los_angeles, new_york_city"), "{args:?}: {}", stderr(&out));
    }
    assert!(stderr(&tadslc(&["check", "--region", "yelowstone", example], "")).contains("did you mean `yellowstone`"));
    assert_eq!(code(&tadslc(&["check", "--region", "yellowstone", example], "")), 0);
    let town = tadslc(&["build", "--map", "Town99", example], "");
    assert_eq!(code(&town), 2);
    assert!(stderr(&town).contains("unknown town `Town99` (the towns are: Town10HD"), "{}", stderr(&town));
}

/// Counts that would only exhaust memory are refused before anything is allocated.
#[test]
fn numeric_options_are_bounded_before_any_work() {
    for (args, bound) in [
        (&["search", "--samples", "99999999999999", "examples/safety"][..], "1 to 1000000"),
        (&["train-ego", "--hidden", "100000,100000"], "1 to 4096"),
        (&["eval", "-n", "999999999999"], "1 to 100000"),
        (&["gen", "-n", "0"], "1 to 100000"),
        (&["compare", "--resamples", "lots", "a", "b"], "is not a whole number"),
    ] {
        let out = tadslc(args, "");
        assert_eq!(code(&out), 2, "{args:?}");
        assert!(stderr(&out).contains(bound), "{args:?}: {}", stderr(&out));
    }
}

/// An output directory holds one run's files: an earlier run's are refused, or removed
/// with `--force`, so later commands that read the directory see this run's only.
#[test]
fn search_refuses_an_earlier_runs_scenes_unless_forced() {
    let dir = scratch("search-stale");
    let out = dir.join("out");
    let args = ["search", "examples/safety/right_turn.tad", "--samples", "4", "--round", "2", "--keep", "1", "-o"];
    let first = tadslc(&[&args[..], &[out.to_str().unwrap()]].concat(), "");
    assert_eq!(code(&first), 0, "{}", stderr(&first));
    std::fs::write(out.join("left_over.tad"), "scenario old {}\n").unwrap();
    let again = tadslc(&[&args[..], &[out.to_str().unwrap()]].concat(), "");
    assert_eq!(code(&again), 2);
    assert!(stderr(&again).contains("from an earlier run") && stderr(&again).contains("--force"), "{}", stderr(&again));
    let forced = tadslc(&[&args[..], &[out.to_str().unwrap(), "--force"]].concat(), "");
    assert_eq!(code(&forced), 0, "{}", stderr(&forced));
    assert!(!out.join("left_over.tad").exists() && out.join("search.json").exists());
}

/// Every manual page has EXIT STATUS, and every example on the pages parses: its flags
/// exist (each is run with `--help` appended, which stops before any work).
#[test]
fn the_manual_pages_have_exit_status_and_examples_that_parse() {
    let dir = scratch("man-pages");
    assert_eq!(code(&tadslc(&["man", "-o", dir.to_str().unwrap()], "")), 0);
    let check = std::fs::read_to_string(dir.join("tadslc-check.1")).unwrap();
    assert!(check.contains(".SH \"EXIT STATUS\"") && check.contains(".SH EXAMPLES"), "{check}");
    let exe = env!("CARGO_BIN_EXE_tadslc");
    for (page, lines) in tadslc::cmd::man::EXAMPLES {
        for line in *lines {
            let command = line.split(" > ").next().unwrap();
            let command = command.split_whitespace().skip_while(|w| w.contains('=')).collect::<Vec<_>>().join(" ");
            let command = command.replacen("tadslc", exe, 1);
            let out = std::process::Command::new("sh")
                .arg("-c")
                .arg(format!("{command} --help"))
                .current_dir(repo())
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(0), "{page}: `{line}`: {}", String::from_utf8_lossy(&out.stderr));
        }
    }
}

/// Names people and other tools use (TrafficComposer's `in front of`, "day time", a
/// traffic circle, give way, a dog, a trolleybus) are TAD's, as aliases or declarations.
#[test]
fn names_people_use_are_understood() {
    let program = r#"scenario names {
  environment {
    weather: clear
    time: day_time
  }
  road {
    type: traffic_circle
    context: urban
    lanes: 1
    direction: one_way
    signs: [give_way_sign, one_way_sign]
    light: none
  }
  ego {
    behavior: give_way
    speed: 10 km/h
    lane: 1
  }
  actor pet: 1 dog {
    behavior: cross
    position: in_front_of of ego
    lane: 1
  }
  actor trolley: 1 trolleybus {
    behavior: move_forward
    speed: 20 km/h
    position: left_front of ego
    lane: 1
  }
}
"#;
    let out = tadslc(&["check", "--format", "json", "-"], program);
    assert_eq!(code(&out), 0, "{}", stdout(&out));
    let file: Value = serde_json::from_str(stdout(&out).trim()).unwrap();
    assert_eq!(file["class"], "complete");
    let codes: Vec<&str> =
        file["diagnostics"].as_array().unwrap().iter().map(|d| d["code"].as_str().unwrap()).collect();
    assert!(codes.iter().all(|c| *c == "W0401"), "only alias hints: {codes:?}");
    assert_eq!(codes.len(), 6, "day_time, traffic_circle, give_way_sign, give_way, in_front_of, trolleybus");
}

#[test]
fn invalid_utf8_is_a_located_error() {
    let out = tadslc(&["check", "--format", "json", "tests/ui/lex/not_utf8.tad"], "");
    assert_eq!(code(&out), 1);
    let file: Value = serde_json::from_str(stdout(&out).trim()).unwrap();
    assert_eq!(file["diagnostics"][0]["code"], "E0006");
    assert_eq!(file["diagnostics"][0]["span"]["start"]["line"], 1);
}

#[test]
fn explain_prints_every_code_and_rejects_unknown_ones() {
    for code_ in tad_diagnostics::Code::ALL {
        let out = tadslc(&["explain", code_.as_str()], "");
        assert_eq!(code(&out), 0, "{code_}");
        let text = stdout(&out);
        assert!(text.starts_with(&format!("{code_} {}", code_.title())), "{text}");
        assert!(text.contains("```"), "{code_} shows examples");
    }
    assert!(stdout(&tadslc(&["explain", "e0203"], "")).starts_with("E0203 unknown field"));
    let list = stdout(&tadslc(&["explain"], ""));
    assert_eq!(list.lines().count(), tad_diagnostics::Code::ALL.len());
    assert_eq!(code(&tadslc(&["explain", "E9999"], "")), 2);
}

#[test]
fn fmt_rewrites_checks_and_never_touches_broken_files() {
    let dir = scratch("fmt");
    let messy = dir.join("messy.tad");
    let broken = dir.join("broken.tad");
    std::fs::write(&messy, "scenario demo { ego { speed:30 km/h } } // end\n").unwrap();
    std::fs::write(&broken, "scenario demo { ego { speed: ] } }\n").unwrap();
    let dir_arg = dir.to_str().unwrap();

    let out = tadslc(&["fmt", "--check", dir_arg], "");
    assert_eq!(code(&out), 1);
    assert!(stderr(&out).contains("messy.tad: not formatted"));
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), "scenario demo { ego { speed:30 km/h } } // end\n");

    let out = tadslc(&["fmt", dir_arg], "");
    assert_eq!(code(&out), 1, "the broken file fails");
    assert_eq!(
        std::fs::read_to_string(&messy).unwrap(),
        "scenario demo {\n  ego {\n    speed: 30 km/h\n  }\n} // end\n"
    );
    assert_eq!(std::fs::read_to_string(&broken).unwrap(), "scenario demo { ego { speed: ] } }\n");
    assert!(stderr(&out).contains("has syntax errors; not formatted"));

    std::fs::remove_file(&broken).unwrap();
    assert_eq!(code(&tadslc(&["fmt", "--check", dir_arg], "")), 0);
    // standard input is formatted to standard output
    let out = tadslc(&["fmt", "-"], "scenario  demo{}");
    assert_eq!((code(&out), stdout(&out).as_str()), (0, "scenario demo {\n}\n"));
}

#[test]
fn directories_are_searched_recursively_for_tad_files() {
    let dir = scratch("walk");
    std::fs::create_dir_all(dir.join("a/b")).unwrap();
    std::fs::create_dir_all(dir.join(".hidden")).unwrap();
    std::fs::write(dir.join("a/b/one.tad"), CLEAN).unwrap();
    std::fs::write(dir.join("a/two.tad"), CLEAN).unwrap();
    std::fs::write(dir.join("a/notes.txt"), "not a scenario").unwrap();
    std::fs::write(dir.join(".hidden/three.tad"), "broken {").unwrap();
    let out = tadslc(&["check", "--format", "json", dir.to_str().unwrap()], "");
    assert_eq!(code(&out), 0);
    let files: Vec<String> = stdout(&out)
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap()["file"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(files.len(), 2);
    assert!(files[0].ends_with("a/b/one.tad") && files[1].ends_with("a/two.tad"), "{files:?}");
}

#[test]
fn bench_reports_throughput_against_the_peer() {
    let out = tadslc(&["bench", "--scenarios", "50", "--runs", "1", "--examples", "tests/ui/fmt"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let text = stdout(&out);
    for row in [
        "peer: serde_json::Value",
        "lex",
        "parse (lex+parse+lower)",
        "check, no database",
        "check through the database",
        "fmt (parse+print)",
        "check examples",
        "incremental: one-line edit",
    ] {
        assert!(text.contains(row), "{row} missing from\n{text}");
    }
}

#[test]
fn bench_runtime_reports_episodes_and_the_search() {
    // fewer steps through the hidden `--steps`, to stay fast in a debug build
    let args = ["bench", "--runtime", "--runs", "1", "--episodes", "16", "--no-scenic", "--steps", "20"];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let text = stdout(&out);
    for (name, actors) in [("traffic_1", 1), ("traffic_14", 14), ("traffic_50", 50)] {
        let row = text
            .lines()
            .find(|l| l.starts_with(&format!("{name} ")))
            .unwrap_or_else(|| panic!("{name} missing from\n{text}"));
        let cells: Vec<&str> = row.split_whitespace().collect();
        assert_eq!(cells[1..3], [actors.to_string(), "20".to_string()], "{row}");
        assert!(cells[3].parse::<f64>().is_ok_and(|ms| ms > 0.0), "{row}");
        assert_eq!(cells[6..], ["-", "-"], "no Scenic: {row}");
    }
    assert!(text.contains("Scenic peer skipped: --no-scenic"), "{text}");
    let search = text
        .lines()
        .find(|l| l.starts_with("search: 16 episodes of the 8 safety examples"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(search.contains("episodes/s") && search.contains("stops: "), "{search}");
    // the check benchmark's options do not apply
    assert_eq!(code(&tadslc(&["bench", "--runtime", "--scenarios", "5"], "")), 2);
    assert_eq!(code(&tadslc(&["bench", "--episodes", "5"], "")), 2);
}

#[test]
fn a_broken_module_is_reported_once_under_the_path_the_input_named() {
    let out = tadslc(&["check", "tests/ui/check/modules.tad"], "");
    assert_eq!(code(&out), 1);
    let err = stderr(&out);
    // its own report, after the input's, under the relative path the `use` resolved to
    assert_eq!(err.matches("┌─ tests/ui/check/modules/broken_vocabulary.tad:4:3").count(), 2, "{err}");
    assert!(!err.contains(&repo().display().to_string()), "{err}");
}

#[test]
fn fmt_refuses_what_check_calls_non_tad_and_caps_its_errors() {
    // prose is one E0007, as in `check`, not an error per word
    let prose = "# Notes on the drive\n\nThe ego { waits } at the light: then [turns] left.\n".repeat(200);
    let out = tadslc(&["fmt", "-"], &prose);
    assert_eq!(code(&out), 1);
    let err = stderr(&out);
    assert_eq!(err.matches("error[").count(), 1, "{err}");
    assert!(err.contains("error[E0007]"), "{err}");
    // a TAD file with hundreds of syntax errors: the first 50, then how many more
    let broken = format!("scenario demo {{\n{}}}\n", "  ego { speed: ] }\n".repeat(300));
    let out = tadslc(&["fmt", "-"], &broken);
    assert_eq!(code(&out), 1);
    let err = stderr(&out);
    assert_eq!(err.matches("error[").count(), 50, "{err}");
    assert!(err.contains("<stdin>: and ") && err.contains("more errors"), "{err}");
    let out = tadslc(&["fmt", "--max-diagnostics", "0", "-"], &broken);
    assert!(stderr(&out).matches("error[").count() > 50);
}

#[test]
fn fmt_canonicalize_applies_canonical_forms_and_then_checks_clean() {
    let dir = scratch("canonical");
    let path = dir.join("aliases.tad");
    std::fs::copy(repo().join("tests/ui/check/aliases_and_units.tad"), &path).unwrap();
    let before = std::fs::read_to_string(&path).unwrap();
    let out = tadslc(&["fmt", "--canonicalize", path.to_str().unwrap()], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let after = std::fs::read_to_string(&path).unwrap();
    assert_ne!(before, after);
    for (old, new) in [
        ("sunny", "clear"),
        ("30 mph", "48.3 km/h"),
        ("12.5 m/s", "45 km/h"),
        ("front_right of ego_vehicle", "right_front of ego"),
    ] {
        assert!(!after.contains(&format!(": {old}")) && after.contains(new), "{old} -> {new}\n{after}");
    }
    // nothing canonical is left to fix, and a second run changes nothing
    let checked = tadslc(&["check", "--format", "json", path.to_str().unwrap()], "");
    let file: Value = serde_json::from_str(stdout(&checked).trim()).unwrap();
    assert!(file["diagnostics"].as_array().unwrap().iter().all(|d| !d["code"].as_str().unwrap().starts_with("W04")));
    assert_eq!(file["class"], "complete");
    assert_eq!(code(&tadslc(&["fmt", "--check", "--canonicalize", path.to_str().unwrap()], "")), 0);
}

#[test]
fn profile_and_non_scenario_options() {
    let follower = "scenario s2 {\n  actor f: car {\n    position: behind of ego\n  }\n}\n";
    let codes = |args: &[&str], input: &str| -> Vec<String> {
        let mut all = vec!["check", "--format", "json"];
        all.extend_from_slice(args);
        all.push("-");
        let out = tadslc(&all, input);
        let file: Value = serde_json::from_str(stdout(&out).trim()).unwrap();
        file["diagnostics"].as_array().unwrap().iter().map(|d| d["code"].as_str().unwrap().to_string()).collect()
    };
    assert!(!codes(&[], follower).contains(&"E0510".to_string()));
    assert!(codes(&["--profile", "dashcam"], follower).contains(&"E0510".to_string()));
    // by default weather, time and road all missing make a non-scenario; with `weather` alone, so does this
    let no_weather = CLEAN.replace("    weather: clear\n", "");
    assert!(!codes(&[], &no_weather).contains(&"W0601".to_string()));
    assert!(codes(&["--non-scenario", "weather"], &no_weather).contains(&"W0601".to_string()));
    assert_eq!(code(&tadslc(&["check", "--non-scenario", "colour", "-"], CLEAN)), 2);
}

#[test]
fn json_carries_class_and_refinement() {
    let out =
        tadslc(&["check", "--format", "json", "tests/ui/check/incomplete.tad", "tests/ui/check/non_scenario.tad"], "");
    let files: Vec<Value> = stdout(&out).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(files[0]["class"], "incomplete");
    let refinement: Vec<&str> =
        files[0]["refinement"].as_array().unwrap().iter().map(|r| r.as_str().unwrap()).collect();
    assert!(refinement.iter().any(|r| r.contains("lane index of group `parked_right`")), "{refinement:?}");
    assert!(refinement.iter().any(|r| r.contains("how many actors group `crowd`")), "{refinement:?}");
    assert!(refinement.iter().any(|r| r.starts_with("State the number of lanes per direction")), "{refinement:?}");
    assert_eq!(files[1]["class"], "non_scenario");
    assert_eq!(files[1]["refinement"], serde_json::json!([]));
    let human = stderr(&tadslc(&["check", "tests/ui/check/incomplete.tad"], ""));
    assert!(human.contains("tests/ui/check/incomplete.tad: incomplete"), "{human}");
}

#[test]
fn yaml_answers_are_checked_at_their_own_lines() {
    let out = tadslc(
        &[
            "check",
            "--format",
            "json",
            "tests/yaml/paper/nl_to_dsl_example_1.yaml",
            "tests/yaml/paper/nl_to_dsl_example_2.yaml",
        ],
        "",
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    for line in stdout(&out).lines() {
        let file: Value = serde_json::from_str(line).unwrap();
        assert_eq!(file["class"], "complete", "{file}");
    }

    let out = tadslc(&["check", "--format", "json", "tests/yaml/cli/non_scenario.yaml"], "");
    let file: Value = serde_json::from_str(stdout(&out).trim()).unwrap();
    assert_eq!(file["class"], "non_scenario");

    let out = tadslc(&["check", "--format", "json", "tests/yaml/cli/missing_lane.yaml"], "");
    let file: Value = serde_json::from_str(stdout(&out).trim()).unwrap();
    assert_eq!(file["class"], "incomplete");
    let refinement = file["refinement"].as_array().unwrap();
    assert_eq!(refinement.len(), 1, "{refinement:?}");
    assert!(refinement[0].as_str().unwrap().contains("lane index of group `parked_right`"));
    // the W0600 for the group points at its key, the aliases at their YAML values
    let at = |code: &str| -> Vec<u64> {
        file["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["code"] == code)
            .map(|d| d["span"]["start"]["line"].as_u64().unwrap())
            .collect()
    };
    assert_eq!(at("W0600"), vec![22]);
    assert_eq!(at("W0401"), vec![5, 28], "the paper's `move forward` on line 17 is canonical");
}

#[test]
fn import_writes_canonical_tad_and_export_round_trips() {
    let dir = scratch("interchange");
    let tad = dir.join("missing_lane.tad");
    let out = tadslc(&["import", "tests/yaml/cli/missing_lane.yaml", "-o", tad.to_str().unwrap()], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let text = std::fs::read_to_string(&tad).unwrap();
    for expected in [
        "scenario missing_lane {",
        "weather: clear",
        "behavior: move_forward",
        "position: right_front of ego",
        "lane: unspecified",
    ] {
        assert!(text.contains(expected), "{expected} missing from\n{text}");
    }
    assert_eq!(code(&tadslc(&["fmt", "--check", tad.to_str().unwrap()], "")), 0, "imported TAD is formatted");

    // export then import gives back the example (every example and searched scene: below;
    // `--yaml` is the default form: `export_needs_no_format_flag`)
    for example in ["examples/paper/nl_to_dsl_example_2.tad", "examples/regions/switzerland_tram_street.tad"] {
        let (back, original) = through_yaml(&repo().join(example), &dir);
        assert_eq!(back, original, "{example}");
    }
    // a file with errors is not exported
    assert_eq!(code(&tadslc(&["export", "--yaml", "tests/ui/structure/unknown_field.tad"], "")), 1);
}

/// `file` exported to YAML and imported back, as the CLI does it (the checker included);
/// and the file without its leading comments, which the import must equal.
fn through_yaml(file: &Path, dir: &Path) -> (String, String) {
    let yaml = dir.join("exported.yaml");
    let out = tadslc(&["export", file.to_str().unwrap(), "-o", yaml.to_str().unwrap()], "");
    assert_eq!(code(&out), 0, "{}: {}", file.display(), stderr(&out));
    let back = tadslc(&["import", yaml.to_str().unwrap()], "");
    assert_eq!(code(&back), 0, "{}: {}", file.display(), stderr(&back));
    let original = std::fs::read_to_string(file).unwrap();
    let without_comments: String =
        original.lines().filter(|l| !l.starts_with("//")).collect::<Vec<_>>().join("\n").trim_start().to_string()
            + "\n";
    (stdout(&back), without_comments)
}

#[test]
fn every_example_and_every_searched_scene_round_trips_through_yaml() {
    let dir = scratch("round-trip");
    let examples = tad_test_support::examples();
    let scenes = dir.join("scenes");
    let out =
        tadslc(&["search", "examples/safety", "--ego", "naive", "-o", scenes.to_str().unwrap(), "--seed", "3"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let mut searched: Vec<PathBuf> = std::fs::read_dir(&scenes)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "tad"))
        .collect();
    searched.sort();
    // the scenes carry what search fixed: a sampled place (`offset`) or start (`delay`)
    assert!(searched.len() >= 8, "{searched:?}");
    let mut fixed = 0;
    for file in examples.iter().chain(&searched) {
        let (back, original) = through_yaml(file, &dir);
        assert_eq!(back, original, "{}", file.display());
        fixed += usize::from(["offset:", "delay:", "distance:", "trigger:"].iter().any(|k| original.contains(k)));
    }
    assert!(fixed * 2 >= searched.len(), "{fixed} files with a fixed place or start");
}

#[test]
fn a_failed_import_writes_no_file_and_keys_with_a_hash_are_read_as_meant() {
    let dir = scratch("failed-import");
    let tad = dir.join("out.tad");
    let out = tadslc(&["import", "README.md", "-o", tad.to_str().unwrap()], "");
    assert_eq!(code(&out), 1, "{}", stderr(&out));
    assert!(!tad.exists(), "a failed import wrote {}", tad.display());
    assert!(stderr(&out).contains("not written"), "{}", stderr(&out));

    let yaml = dir.join("hash.yaml");
    let lines = [
        "environment:",
        "    weather: clear",
        "    time: daytime",
        "road_network:",
        "    road_type: straight road",
        "actors:",
        "    ego_vehicle:",
        "        behavior: move forward",
        "        lane_index: 1",
        "    Cyclist #1:",
        "        type: bicycle",
        "        position_relation: front",
        "        lane_index: 2",
    ];
    std::fs::write(&yaml, lines.join("\n") + "\n").unwrap();
    let out = tadslc(&["import", yaml.to_str().unwrap()], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stdout(&out).contains("actor cyclist_1: bicycle {"), "{}", stdout(&out));

    // the camera rules: an answer that states no profile gets the dash-cam rule, `--profile` decides
    let behind = dir.join("behind.yaml");
    let answer = [&lines[..7], &["        lane_index: 1", "    car:", "        type: car"]].concat().join("\n")
        + "\n        position_relation: behind\n        lane_index: 1\n";
    std::fs::write(&behind, &answer).unwrap();
    assert!(stderr(&tadslc(&["import", behind.to_str().unwrap()], "")).contains("E0510"));
    let out = tadslc(&["import", "--profile", "default", behind.to_str().unwrap()], "");
    assert!(!stderr(&out).contains("E0510"), "{}", stderr(&out));
    std::fs::write(&behind, format!("profile: auto\n{answer}")).unwrap();
    assert!(!stderr(&tadslc(&["check", behind.to_str().unwrap()], "")).contains("E0510"));
    assert!(stderr(&tadslc(&["check", "--profile", "dashcam", behind.to_str().unwrap()], "")).contains("E0510"));
}

#[test]
fn build_writes_scenic_programs_and_refuses_broken_files() {
    let dir = scratch("build");
    let out = tadslc(&["build", "--target", "scenic", "examples/safety", "-o", dir.to_str().unwrap()], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let programs = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(programs, 8, "one program per example");
    let text = std::fs::read_to_string(dir.join("red_light_running.scenic")).unwrap();
    assert!(text.contains("model scenic.simulators.carla.model") && text.contains("param carla_map"));
    let newtonian = tadslc(&["build", "--simulator", "newtonian", "examples/safety/right_turn.tad"], "");
    assert_eq!(code(&newtonian), 0, "{}", stderr(&newtonian));
    assert!(stdout(&newtonian).contains("model scenic.simulators.newtonian.driving_model"));
    let broken = tadslc(&["build", "tests/ui/structure/unknown_field.tad"], "");
    assert_eq!(code(&broken), 1);
    assert!(stdout(&broken).is_empty(), "nothing is emitted for a file with errors");
}

/// Every subcommand, as `--help` lists them.
const SUBCOMMANDS: &[&str] =
    &["check", "fmt", "build", "import", "export", "lsp", "explain", "bench", "completions", "man"];

/// Which standard stream the reader closes.
#[derive(Clone, Copy)]
enum Stream {
    Stdout,
    Stderr,
}

/// Run `tadslc` and close `stream`'s read end, after reading `first` lines of it: the
/// rest of its writes meet a broken pipe. Returns the exit status and the other stream.
fn closed_early(args: &[&str], stdin: &str, stream: Stream, first: usize) -> (i32, String) {
    use std::io::{BufRead, Read, Write};
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_tadslc"))
        .args(args)
        .current_dir(repo())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("tadslc runs");
    let (closed, mut other): (Box<dyn Read + Send>, Box<dyn Read + Send>) = match stream {
        Stream::Stdout => (Box::new(child.stdout.take().unwrap()), Box::new(child.stderr.take().unwrap())),
        Stream::Stderr => (Box::new(child.stderr.take().unwrap()), Box::new(child.stdout.take().unwrap())),
    };
    let mut reader = std::io::BufReader::new(closed);
    for _ in 0..first {
        let mut line = String::new();
        assert!(reader.read_line(&mut line).unwrap() > 0, "{args:?}: fewer than {first} lines");
    }
    drop(reader);
    if let Some(mut input) = child.stdin.take() {
        let _ = input.write_all(stdin.as_bytes());
    }
    let drain = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = other.read_to_string(&mut text);
        text
    });
    let status = child.wait().expect("tadslc finishes");
    let other = drain.join().unwrap();
    assert!(!other.contains("panicked"), "{args:?}: {other}");
    (status.code().expect("exited normally, not by a signal"), other)
}

#[test]
fn a_closed_pipe_ends_the_run_quietly_with_its_status() {
    // more JSON than a pipe holds; the one file with errors comes last
    let dir = scratch("pipe");
    for i in 0..1500 {
        std::fs::write(dir.join(format!("clean_{i:04}.tad")), CLEAN).unwrap();
    }
    std::fs::write(dir.join("zz_broken.tad"), "scenario {").unwrap();
    let dir_arg = dir.to_str().unwrap();
    let (status, stderr_text) = closed_early(&["check", "--format", "json", dir_arg], "", Stream::Stdout, 1);
    assert_eq!(status, 1, "the status of the whole check: {stderr_text}");
    assert!(stderr_text.is_empty(), "quietly: {stderr_text}");
    assert_eq!(closed_early(&["check", "--format", "json", "-"], CLEAN, Stream::Stdout, 0).0, 0);
    assert_eq!(closed_early(&["check", "--format", "sarif", dir_arg], "", Stream::Stdout, 1).0, 1);
    assert_eq!(closed_early(&["check", dir_arg], "", Stream::Stderr, 0).0, 1);
    assert_eq!(closed_early(&["check", "-"], CLEAN, Stream::Stderr, 0).0, 0);

    // every other subcommand's printing
    let unformatted = scratch("pipe-fmt");
    std::fs::write(unformatted.join("messy.tad"), "scenario demo { ego { speed:30 km/h } }\n").unwrap();
    let out = scratch("pipe-build");
    let cases: &[(&[&str], &str, Stream, i32)] = &[
        (&["fmt", "-"], "scenario  demo{}", Stream::Stdout, 0),
        (&["fmt", "--check", unformatted.to_str().unwrap()], "", Stream::Stderr, 1),
        (&["import", "tests/yaml/cli/missing_lane.yaml"], "", Stream::Stdout, 0),
        (&["import", "tests/yaml/cli/missing_lane.yaml"], "", Stream::Stderr, 0),
        (&["export", "examples/paper/nl_to_dsl_example_2.tad"], "", Stream::Stdout, 0),
        (&["export", "tests/ui/structure/unknown_field.tad"], "", Stream::Stderr, 1),
        (&["build", "examples/safety/right_turn.tad"], "", Stream::Stdout, 0),
        (&["build", "examples/safety", "-o", out.to_str().unwrap()], "", Stream::Stderr, 0),
        (&["explain"], "", Stream::Stdout, 0),
        (&["explain", "E0203"], "", Stream::Stdout, 0),
        (&["explain", "E9999"], "", Stream::Stderr, 2),
        (&["bench", "--scenarios", "20", "--runs", "1"], "", Stream::Stdout, 0),
        (&["completions", "bash"], "", Stream::Stdout, 0),
        (&["man"], "", Stream::Stdout, 0),
        (&["--help"], "", Stream::Stdout, 0),
    ];
    for (args, stdin, stream, expected) in cases {
        assert_eq!(closed_early(args, stdin, *stream, 0).0, *expected, "{args:?}");
    }
}

#[test]
fn a_standard_output_that_cannot_be_written_is_an_io_failure() {
    let Ok(full) = std::fs::File::create("/dev/full") else {
        return; // not on this system
    };
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tadslc"))
        .args(["explain"])
        .current_dir(repo())
        .stdout(full)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("error: cannot write to standard output"), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
}

#[test]
fn a_directory_without_scenarios_is_an_error() {
    let empty = scratch("empty");
    let out = tadslc(&["check", empty.to_str().unwrap()], "");
    assert_eq!(code(&out), 2);
    assert!(
        stderr(&out).contains(&format!("error: no .tad or .yaml files in `{}`", empty.display())),
        "{}",
        stderr(&out)
    );
    assert!(!stderr(&out).contains("no problems"), "{}", stderr(&out));
    std::fs::write(empty.join("notes.txt"), "not a scenario").unwrap();
    let out = tadslc(&["check", "--format", "json", empty.to_str().unwrap(), "-"], CLEAN);
    assert_eq!(code(&out), 2);
    assert_eq!(stdout(&out).lines().count(), 1, "the other input is still checked");
    // fmt takes TAD only: a directory of answers has nothing to format
    let answers = scratch("answers-only");
    std::fs::copy(repo().join("tests/yaml/cli/missing_lane.yaml"), answers.join("a.yaml")).unwrap();
    let out = tadslc(&["fmt", answers.to_str().unwrap()], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("no .tad files in"), "{}", stderr(&out));
}

#[test]
fn directories_hold_yaml_answers_too() {
    let dir = scratch("walk-yaml");
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::write(dir.join("a/one.tad"), CLEAN).unwrap();
    std::fs::copy(repo().join("tests/yaml/paper/nl_to_dsl_example_1.yaml"), dir.join("a/two.yaml")).unwrap();
    std::fs::copy(repo().join("tests/yaml/cli/non_scenario.yaml"), dir.join("three.yml")).unwrap();
    let dir_arg = dir.to_str().unwrap();
    let out = tadslc(&["check", "--format", "json", dir_arg], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let files: Vec<Value> = stdout(&out).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let names: Vec<&str> = files.iter().map(|f| f["file"].as_str().unwrap()).collect();
    assert_eq!(names.len(), 3, "{names:?}");
    assert!(names[0].ends_with("a/one.tad") && names[1].ends_with("a/two.yaml") && names[2].ends_with("three.yml"));
    assert_eq!(files[2]["class"], "non_scenario");
    let human = tadslc(&["check", dir_arg], "");
    assert!(stderr(&human).contains("checked 3 files: "), "{}", stderr(&human));
    // fmt formats the TAD and leaves the YAML alone, quietly
    let yaml = std::fs::read(dir.join("a/two.yaml")).unwrap();
    let out = tadslc(&["fmt", dir_arg], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stderr(&out).is_empty(), "{}", stderr(&out));
    assert_eq!(std::fs::read(dir.join("a/two.yaml")).unwrap(), yaml);
}

#[test]
fn build_warns_when_the_map_is_not_where_the_program_looks() {
    let dir = scratch("build-maps");
    let out_dir = dir.join("out");
    let args = ["build", "--map", "Town10HD", "examples/safety/right_turn.tad", "-o", out_dir.to_str().unwrap()];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let text = stderr(&out);
    let missing = out_dir.join("Town10HD.xodr");
    assert!(
        text.contains(&format!(
            "{}: warning: the program loads `{}`, which does not exist",
            out_dir.join("right_turn.scenic").display(),
            missing.display()
        )),
        "{text}"
    );
    assert!(text.contains("--map-dir DIR"), "{text}");
    // one warning for a map that several programs load
    let out = tadslc(&["build", "--map", "Town10HD", "examples/safety", "-o", out_dir.to_str().unwrap()], "");
    let text = stderr(&out);
    assert_eq!(text.matches("which does not exist").count(), 1, "{text}");
    assert!(text.contains("(so do 7 other programs)"), "{text}");
    // with the maps where the program looks, nothing to say
    let maps = dir.join("maps");
    std::fs::create_dir_all(&maps).unwrap();
    std::fs::write(maps.join("Town10HD.xodr"), "").unwrap();
    let mut with_maps = args.to_vec();
    with_maps.extend(["--map-dir", maps.to_str().unwrap()]);
    let out = tadslc(&with_maps, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(!stderr(&out).contains("does not exist"), "{}", stderr(&out));
    let out = tadslc(
        &["build", "--map", "Town04", "--map-dir", maps.to_str().unwrap(), "examples/safety/right_turn.tad"],
        "",
    );
    assert!(
        stderr(&out).contains(&format!("`{}`, which does not exist", maps.join("Town04.xodr").display())),
        "{}",
        stderr(&out)
    );
    // to standard output, the map is read beside wherever the program is saved
    let out = tadslc(&["build", "examples/safety/right_turn.tad"], "");
    assert!(stderr(&out).contains("note: the program loads `"), "{}", stderr(&out));
    assert!(stderr(&out).contains("--map-dir DIR"), "{}", stderr(&out));
}

#[test]
fn export_needs_no_format_flag() {
    let example = "examples/paper/nl_to_dsl_example_2.tad";
    let plain = tadslc(&["export", example], "");
    assert_eq!(code(&plain), 0, "{}", stderr(&plain));
    assert!(!stdout(&plain).is_empty());
    for flags in [&["--yaml"][..], &["--format", "yaml"], &["--yaml", "--format", "yaml"]] {
        let mut args = vec!["export"];
        args.extend_from_slice(flags);
        args.push(example);
        let out = tadslc(&args, "");
        assert_eq!((code(&out), stdout(&out)), (0, stdout(&plain)), "{flags:?}");
    }
    assert_eq!(code(&tadslc(&["export", "--format", "json", example], "")), 2);
}

#[test]
fn explain_finds_a_code_by_its_number_whatever_its_letter() {
    for (asked, expected) in [
        ("600", "W0600"),
        ("w600", "W0600"),
        ("W0600", "W0600"),
        ("E0600", "W0600"),
        ("e203", "E0203"),
        ("203", "E0203"),
        ("w0200", "W0200"),
        ("200", "E0200"),
    ] {
        let out = tadslc(&["explain", asked], "");
        assert_eq!(code(&out), 0, "{asked}: {}", stderr(&out));
        assert!(stdout(&out).starts_with(&format!("{expected} ")), "{asked}: {}", stdout(&out));
    }
    let out = tadslc(&["explain", "299"], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("help: the closest codes are "), "{}", stderr(&out));
    assert_eq!(code(&tadslc(&["explain", "nonsense"], "")), 2);
}

#[test]
fn help_lists_every_subcommand_and_points_at_explain_and_the_spec() {
    let out = tadslc(&["--help"], "");
    assert_eq!(code(&out), 0);
    let text = stdout(&out);
    for sub in SUBCOMMANDS {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{sub} ")))
            .unwrap_or_else(|| panic!("{sub} missing from\n{text}"));
        assert!(line.len() > 2 + sub.len() + 10, "{sub} has a description: {line}");
        assert!(line.len() <= 100, "one line: {line}");
    }
    assert!(text.contains("tadslc explain") && text.contains("spec/output.md"), "{text}");
}

#[test]
fn completions_and_man_pages_name_every_subcommand() {
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        let out = tadslc(&["completions", shell], "");
        assert_eq!(code(&out), 0, "{shell}: {}", stderr(&out));
        let script = stdout(&out);
        for sub in SUBCOMMANDS {
            assert!(script.contains(sub), "{shell} completion lacks {sub}");
        }
        // the values of `--ego`: the named egos and the two with an argument
        for ego in ["idm", "naive", "ppo", "sac", "td3", "learned", "external"] {
            assert!(script.contains(ego), "{shell} completion lacks the ego `{ego}`");
        }
    }
    let bash = stdout(&tadslc(&["completions", "bash"], ""));
    assert!(bash.contains("idm naive ppo sac td3 learned: external:"), "bash completes --ego's values");
    assert_eq!(code(&tadslc(&["completions", "tcsh"], "")), 2);
    let out = tadslc(&["man"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let page = stdout(&out);
    // after the preamble that defines the apostrophe (`.ie`/`.el`), the title
    let first = page.lines().find(|l| !l.starts_with(".ie ") && !l.starts_with(".el ")).unwrap_or("");
    assert!(first.starts_with(".TH tadslc 1"), "{}", &page[..page.len().min(200)]);
    for sub in SUBCOMMANDS {
        assert!(page.contains(&format!("tadslc\\-{sub}(1)")), "the man page lacks {sub}");
    }
    let dir = scratch("man");
    let out = tadslc(&["man", "-o", dir.to_str().unwrap()], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(std::fs::read_to_string(dir.join("tadslc.1")).unwrap().contains("\n.TH tadslc 1"));
    for sub in SUBCOMMANDS {
        assert!(dir.join(format!("tadslc-{sub}.1")).is_file(), "no page for {sub}");
    }
}

#[test]
fn counts_are_singular_or_plural() {
    let dir = scratch("plural");
    std::fs::write(dir.join("messy.tad"), "scenario demo { ego { speed:30 km/h } }\n").unwrap();
    let out = tadslc(&["fmt", "--check", dir.to_str().unwrap()], "");
    assert_eq!(code(&out), 1);
    assert!(
        stderr(&out).contains("1 file would be reformatted (1 checked); run `tadslc fmt` on it"),
        "{}",
        stderr(&out)
    );
    std::fs::write(dir.join("messy2.tad"), "scenario demo { ego { speed:30 km/h } }\n").unwrap();
    let out = tadslc(&["fmt", "--check", dir.to_str().unwrap()], "");
    assert!(
        stderr(&out).contains("2 files would be reformatted (2 checked); run `tadslc fmt` on them"),
        "{}",
        stderr(&out)
    );
    // no count in the crate is written with a fixed plural
    let src = repo().join("compiler/tadslc/src");
    for path in files(&src, "rs") {
        let text = std::fs::read_to_string(&path).unwrap();
        for phrase in ["} files", "} errors", "} warnings", "} scenarios would", "of {} files"] {
            assert!(!text.contains(phrase), "{}: `{phrase}`: use `plural`", path.display());
        }
    }
}

#[test]
fn the_readme_and_the_spec_show_what_check_prints() {
    // README: `$ tadslc check FILE` followed by exactly what it prints
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let start = readme.find("```text\n$ tadslc check ").expect("a sample run in README.md") + "```text\n$ ".len();
    let block = &readme[start..start + readme[start..].find("```\n").unwrap()];
    let (command, shown) = block.split_once('\n').unwrap();
    let args: Vec<&str> = command.split_whitespace().skip(1).collect();
    let out = tadslc(&args, "");
    assert_eq!(shown, stderr(&out), "README.md's sample output of `{command}` is stale");
    // spec/output.md: the location line and a whole diagnostic as codespan prints them
    let spec = std::fs::read_to_string(repo().join("spec/output.md")).unwrap();
    assert!(spec.contains("`┌─ file:line:column`") && !spec.contains("`--> file"));
    let human = spec.find("```text\nerror[E0203]").expect("a human example in spec/output.md") + "```text\n".len();
    let example = &spec[human..human + spec[human..].find("```\n").unwrap()];
    assert!(stderr(&tadslc(&["check", "tests/ui/structure/unknown_field.tad"], "")).contains(example), "{example}");
}

#[test]
fn the_language_server_answers_garbage_and_leaves_when_its_client_does() {
    // initialize and a malformed frame, then the input ends: both are answered and the
    // server stops by itself
    let message = |body: &str| format!("Content-Length: {}\r\n\r\n{body}", body.len());
    let input = [
        message(r#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"capabilities":{}}}"#),
        message("{not json"),
    ]
    .concat();
    let out = tadslc(&["lsp"], &input);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains(r#""serverInfo":{"name":"tadslc""#), "{text}");
    assert!(text.contains("-32700"), "{text}");
    // a client that closes at once: the server stops by itself
    let out = tadslc(&["lsp"], "");
    assert_eq!(code(&out), 0);
}

#[test]
fn a_scene_that_differs_from_its_file_is_a_warning_in_check_build_and_run() {
    let dir = scratch("scene-warnings");
    let file = dir.join("crowd.tad");
    let text = CLEAN.replace(
        "  ego {",
        "  actor crowd: 500 pedestrian {\n    position: right_front of ego\n  }\n  actor far: 1 car {\n    position: front of ego\n    distance: 5000 m\n  }\n  ego {",
    );
    std::fs::write(&file, text).unwrap();
    let f = file.to_str().unwrap();
    let out_dir = dir.join("out");
    let o = out_dir.to_str().unwrap();
    for args in [
        vec!["check", f],
        vec!["run", f, "--seeds", "0", "--ego", "idm"],
        vec!["build", "--target", "bytecode", f, "-o", o],
        vec!["build", "--target", "openscenario", f, "-o", o],
    ] {
        let out = tadslc(&args, "");
        assert_eq!(code(&out), 0, "{args:?}: {}", stderr(&out));
        for code in ["W0512", "W0513"] {
            assert!(stderr(&out).contains(code), "{args:?}: no {code} in\n{}", stderr(&out));
        }
    }
}

#[test]
fn the_runtime_says_where_it_does_not_model_the_weather_or_the_night() {
    let dir = scratch("weather-note");
    let file = dir.join("night_rain.tad");
    std::fs::write(
        &file,
        CLEAN.replace("weather: clear", "weather: rainy").replace("time: daytime", "time: nighttime"),
    )
    .unwrap();
    let out = tadslc(&["run", file.to_str().unwrap(), "--seeds", "0", "--ego", "idm"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(stderr(&out).matches("W0720").count(), 2, "{}", stderr(&out));
    // a clear day, and a target that carries the weather, say nothing
    let clear = dir.join("clear.tad");
    std::fs::write(&clear, CLEAN).unwrap();
    assert!(!stderr(&tadslc(&["run", clear.to_str().unwrap(), "--seeds", "0", "--ego", "idm"], "")).contains("W0720"));
    let out_dir = dir.join("xosc");
    let out =
        tadslc(&["build", "--target", "openscenario", file.to_str().unwrap(), "-o", out_dir.to_str().unwrap()], "");
    assert!(!stderr(&out).contains("W0720"), "{}", stderr(&out));
}

#[test]
fn openscenario_on_a_town_names_its_file_and_says_what_it_lacks() {
    let Some(maps) = tad_test_support::shared().map(|s| s.join("maps/CARLA")).filter(|d| d.is_dir()) else {
        assert!(std::env::var("TAD_REQUIRE_MAPS").as_deref() != Ok("1"), "../shared/maps/CARLA is not there");
        return;
    };
    let dir = scratch("xosc-town");
    let file = repo().join("examples/safety/crossing_negotiation.tad");
    let (f, m) = (file.to_str().unwrap(), maps.to_str().unwrap());
    let out_dir = dir.join("out");
    let o = out_dir.to_str().unwrap();
    let out = tadslc(&["build", "--target", "openscenario", f, "--map", "Town10HD", "--map-dir", m, "-o", o], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    // the town's lanes and lights, said; no road of its own
    assert!(stderr(&out).contains("warning[W0712]: the ego's road has 2 + 2 lanes"), "{}", stderr(&out));
    assert!(!out_dir.join("crossing_negotiation.xodr").exists());
    let xosc = std::fs::read_to_string(out_dir.join("crossing_negotiation.xosc")).unwrap();
    let town = std::fs::canonicalize(maps.join("Town10HD.xodr")).unwrap();
    assert!(xosc.contains(&format!("<LogicFile filepath=\"{}\"/>", town.display())), "{xosc}");
    // the same output twice
    let again = tadslc(&["build", "--target", "openscenario", f, "--map", "Town10HD", "--map-dir", m, "-o", o], "");
    assert_eq!(code(&again), 0);
    assert_eq!(std::fs::read_to_string(out_dir.join("crossing_negotiation.xosc")).unwrap(), xosc);
    // without --map-dir the town is looked for beside the output, and its absence is a usage error
    let out = tadslc(&["build", "--target", "openscenario", f, "--map", "Town10HD", "-o", o], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("--map-dir DIR"), "{}", stderr(&out));
    // a town file that is not OpenDRIVE: a usage error naming it
    let bad = dir.join("maps");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("Town04.xodr"), "<OpenDRIVE><road id=\"1\" length=\"x\" junction=\"-1\"/></OpenDRIVE>")
        .unwrap();
    let out = tadslc(
        &["build", "--target", "openscenario", f, "--map", "Town04", "--map-dir", bad.to_str().unwrap(), "-o", o],
        "",
    );
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("<road> `length` is `x`, not a number"), "{}", stderr(&out));
    // --map-dir alone
    let out = tadslc(&["build", "--target", "openscenario", f, "--map-dir", m, "-o", o], "");
    assert_eq!(code(&out), 2);
}
