//! `tadslc run` as a user runs it: the table, JSON lines of the documented shape, seeds,
//! traces and pictures, `.tadc` input, the learned ego, and bad input refused clearly.

mod common;
use common::*;

fn json_lines(out: &std::process::Output) -> Vec<serde_json::Value> {
    stdout(out).lines().map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}"))).collect()
}

const KEYS: [&str; 11] = ["CR", "RR", "SS", "OR", "RF", "Comp", "TS", "ACC", "YV", "LI", "OS"];

#[test]
fn json_has_one_object_per_episode_then_one_aggregate() {
    let out = tadslc(
        &["run", "examples/safety/red_light_running.tad", "--ego", "naive", "--seeds", "3..6", "--format", "json"],
        "",
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let lines = json_lines(&out);
    assert_eq!(lines.len(), 4, "three episodes and the aggregate");
    for (line, seed) in lines.iter().zip(3..6) {
        assert_eq!(line["file"], "examples/safety/red_light_running.tad");
        assert_eq!(line["seed"], seed, "seeds 3..6 exclude 6");
        assert_eq!(line["ego"], "naive");
        assert!(line["steps"].as_u64().is_some_and(|s| (1..=300).contains(&s)));
        assert!(line["stop_reason"].as_str().is_some());
        for key in KEYS {
            assert!(line["metrics"].get(key).is_some(), "{key} missing: {line}");
        }
    }
    let agg = &lines[3];
    assert_eq!(agg["aggregate"], true);
    assert_eq!(agg["episodes"], 3);
    assert!(agg["metrics"]["OS"].as_f64().is_some());
    // the same command again: the same bytes
    let again = tadslc(
        &["run", "examples/safety/red_light_running.tad", "--ego", "naive", "--seeds", "3..6", "--format", "json"],
        "",
    );
    assert_eq!(stdout(&out), stdout(&again));
}

#[test]
fn the_table_has_a_row_per_scenario_and_ego() {
    let out = tadslc(&["run", "examples/safety", "--seeds", "0..2"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.starts_with("scenario"), "{text}");
    for key in KEYS {
        assert!(text.lines().next().unwrap().contains(key), "{text}");
    }
    for name in ["crossing_negotiation", "vehicle_passing"] {
        for ego in ["idm", "naive"] {
            assert!(text.lines().any(|l| l.starts_with(name) && l.contains(ego)), "{name} {ego}: {text}");
        }
    }
    assert!(text.lines().any(|l| l.starts_with("all ") && l.contains("idm")), "{text}");
}

#[test]
fn bytecode_runs_like_its_source_and_traces_and_pictures_are_written() {
    let out = scratch("run-bytecode");
    let dir = out.to_string_lossy().into_owned();
    assert_eq!(
        code(&tadslc(&["build", "--target", "bytecode", "examples/safety/straight_obstacle.tad", "-o", &dir], "")),
        0
    );
    let tadc = out.join("straight_obstacle.tadc").to_string_lossy().into_owned();
    let from_source = tadslc(
        &["run", "examples/safety/straight_obstacle.tad", "--ego", "idm", "--seeds", "1", "--format", "json"],
        "",
    );
    let trace = out.join("trace.jsonl").to_string_lossy().into_owned();
    let svg = out.join("run.svg").to_string_lossy().into_owned();
    let from_bytes = tadslc(
        &["run", &tadc, "--ego", "idm", "--seeds", "1", "--format", "json", "--trace", &trace, "--render", &svg],
        "",
    );
    assert_eq!(code(&from_bytes), 0, "{}", stderr(&from_bytes));
    let (a, b) = (json_lines(&from_source), json_lines(&from_bytes));
    assert_eq!(a[0]["metrics"], b[0]["metrics"], "the .tadc runs as its source");
    assert_eq!(a[0]["steps"], b[0]["steps"]);
    let steps = b[0]["steps"].as_u64().unwrap() as usize;
    let trace = std::fs::read_to_string(&trace).unwrap();
    assert_eq!(trace.lines().count(), steps + 1, "the start and every step");
    let first: serde_json::Value = serde_json::from_str(trace.lines().next().unwrap()).unwrap();
    assert_eq!(first["actors"][0]["id"], "ego");
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let gif = out.join("run.gif").to_string_lossy().into_owned();
    assert_eq!(code(&tadslc(&["run", &tadc, "--seeds", "1", "--ego", "naive", "--render", &gif], "")), 0);
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));
    let png = out.join("run.PNG").to_string_lossy().into_owned();
    assert_eq!(code(&tadslc(&["run", &tadc, "--seeds", "1", "--ego", "naive", "--render", &png], "")), 0);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG\r\n"));
    // another extension is refused before anything runs
    let jpg = out.join("run.jpg");
    let refused = tadslc(&["run", &tadc, "--render", jpg.to_str().unwrap()], "");
    assert_eq!(code(&refused), 2);
    assert!(stderr(&refused).contains(".svg, .png or .gif") && !jpg.exists());
}

#[test]
fn a_learned_ego_drives_from_a_safetensors_file() {
    let out = scratch("run-learned");
    let actor = out.join("actor.safetensors");
    tad_policy::Learned::random(&[16, 16], 3).unwrap().save(&actor).unwrap();
    let ego = format!("learned:{}", actor.display());
    let run =
        tadslc(&["run", "examples/safety/lane_changing.tad", "--ego", &ego, "--seeds", "0..2", "--format", "json"], "");
    assert_eq!(code(&run), 0, "{}", stderr(&run));
    let lines = json_lines(&run);
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["ego"], ego.as_str());
}

#[test]
fn bad_input_is_refused_clearly() {
    let out = scratch("run-bad");
    let bad = out.join("bad.tadc");
    std::fs::write(&bad, b"TADC\x01\x00garbage").unwrap();
    let run = tadslc(
        &["run", &bad.to_string_lossy(), "examples/safety/right_turn.tad", "--seeds", "0", "--format", "json"],
        "",
    );
    assert_eq!(code(&run), 1, "a corrupt file is an input with errors, the rest still runs");
    let disasm = tadslc(&["disasm", &bad.to_string_lossy()], "");
    assert_eq!(code(&disasm), code(&run), "the same input has the same status in every command");
    assert!(stderr(&run).contains("bad.tadc"), "{}", stderr(&run));
    assert_eq!(json_lines(&run).len(), 4, "right_turn with idm and naive, then an aggregate per ego");
    let run = tadslc(&["run", "examples/safety/right_turn.tad", "--ego", "robot"], "");
    assert_eq!(code(&run), 2);
    assert!(stderr(&run).contains("robot"), "{}", stderr(&run));
    let run = tadslc(&["run", "examples/safety/right_turn.tad", "--seeds", "5..5"], "");
    assert_eq!(code(&run), 2);
    assert!(stderr(&run).contains("holds no seed"), "{}", stderr(&run));
    let run = tadslc(&["run", "examples/safety/right_turn.tad", "--ego", "learned:/nonexistent/actor.safetensors"], "");
    assert_eq!(code(&run), 2);
}

/// The CI gate: `--fail-on` makes an episode that meets a criterion status 1, and `--junit`
/// writes a JUnit report (one test suite per scenario, one test case per ego and seed, a
/// failure for each episode that met a criterion) that XML readers and CI servers accept.
#[test]
fn the_ci_gate_fails_on_a_criterion_and_writes_a_junit_report() {
    let dir = scratch("junit");
    let report = dir.join("report.xml");
    let report_arg = report.to_str().unwrap();
    // the naive ego drives into the conflict of a safety scenario
    let args = [
        "run",
        "examples/safety/crossing_negotiation.tad",
        "examples/safety/right_turn.tad",
        "--ego",
        "naive,idm",
        "--seeds",
        "0..2",
        "--fail-on",
        "collision,red_light",
        "--junit",
        report_arg,
    ];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 1, "a collision fails the gate: {}", stderr(&out));
    assert!(stderr(&out).contains("--fail-on: "), "{}", stderr(&out));
    let xml = std::fs::read_to_string(&report).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "testsuites");
    let suites: Vec<_> = root.children().filter(|n| n.has_tag_name("testsuite")).collect();
    assert_eq!(suites.len(), 2, "one suite per scenario");
    let cases: Vec<_> = doc.descendants().filter(|n| n.has_tag_name("testcase")).collect();
    assert_eq!(cases.len(), 8, "2 scenarios × 2 egos × 2 seeds");
    assert_eq!(root.attribute("tests"), Some("8"));
    let failures: Vec<_> = doc.descendants().filter(|n| n.has_tag_name("failure")).collect();
    assert!(!failures.is_empty());
    assert_eq!(root.attribute("failures"), Some(failures.len().to_string().as_str()));
    for f in &failures {
        assert!(matches!(f.attribute("type"), Some("collision" | "red_light")), "{f:?}");
        let case = f.parent().unwrap();
        assert!(case.attribute("name").is_some_and(|n| n.contains(" seed ")));
        assert!(case.attribute("time").and_then(|t| t.parse::<f64>().ok()).is_some());
    }
    for case in &cases {
        let out = case.children().find(|n| n.has_tag_name("system-out")).and_then(|n| n.text()).unwrap_or("");
        assert!(out.starts_with("stop reason: ") && out.contains("CR "), "{out}");
    }

    // the idm ego meets no criterion on the first: status 0, no failure in the report
    let quiet = [
        "run",
        "examples/safety/crossing_negotiation.tad",
        "--ego",
        "idm",
        "--seeds",
        "0",
        "--fail-on",
        "collision",
        "--junit",
        report_arg,
    ];
    let out = tadslc(&quiet, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(!std::fs::read_to_string(&report).unwrap().contains("<failure"));

    // an unknown criterion is a usage error before anything runs
    let out = tadslc(&["run", "examples/safety/right_turn.tad", "--fail-on", "crash"], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("the criteria are collision, red_light"), "{}", stderr(&out));
}

/// An ego from any process: `external:CMD` drives over JSON lines (its commas kept in a
/// comma-separated list); one that answers nonsense fails its episode (`ego_failed`) with
/// the reason, status 2, and the run goes on with the next.
#[test]
fn an_external_process_drives_and_a_misbehaving_one_fails_its_episode_only() {
    let steady = "external:while read view; do echo '[0.5, 0.0]'; done";
    let egos = format!("idm,{steady}");
    let out =
        tadslc(&["run", "examples/safety/right_turn.tad", "--ego", &egos, "--seeds", "0", "--format", "json"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let lines = json_lines(&out);
    assert_eq!(lines[1]["ego"], steady.to_string(), "the command with its comma is one ego");
    assert_ne!(lines[1]["stop_reason"], "ego_failed");
    assert!(lines[1]["steps"].as_u64().is_some_and(|s| s > 5), "{}", lines[1]);

    let broken = "external:read view; echo oops";
    let out = tadslc(
        &[
            "run",
            "examples/safety/right_turn.tad",
            "--ego",
            broken,
            "--ego",
            "idm",
            "--seeds",
            "0..2",
            "--format",
            "json",
        ],
        "",
    );
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("seed 1: the answer `oops` is not JSON"), "{}", stderr(&out));
    let lines = json_lines(&out);
    assert_eq!(lines.len(), 6, "four episodes and two aggregates: the run went on");
    assert_eq!(lines[0]["stop_reason"], "ego_failed");
    assert_eq!(lines[2]["ego"], "idm");
    assert_ne!(lines[2]["stop_reason"], "ego_failed");
}
