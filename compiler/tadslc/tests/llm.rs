//! `translate`, `synth`, `gen` and `grammar` as a user runs them, against a scripted
//! OpenAI-compatible server on 127.0.0.1 (and a real video made with ffmpeg); with
//! `TADSL_LLAMA_SERVER` and `TADSL_SMOLLM2_GGUF` set, against llama.cpp's server too.

mod common;
use common::*;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use serde_json::Value;
use tad_test_support::fake_llm::{FakeLlm, Reply, last_user_text};

const COMPLETE: &str = "scenario bus_ahead {\n  environment {\n    weather: clear\n    time: daytime\n  }\n  road {\n    type: straight_road\n    lanes: 1\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    speed: 30 km/h\n    lane: 1\n  }\n  actor bus: 1 bus {\n    behavior: move_forward\n    speed: 25 km/h\n    position: front of ego\n    lane: 1\n  }\n}\n";

/// `tadslc` with a clean LLM environment plus `env`, and no configuration file.
fn run(args: &[&str], env: &[(&str, &str)]) -> Output {
    let home = scratch("llm-home");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tadslc"));
    cmd.args(args).current_dir(repo()).env("HOME", &home).env("XDG_CONFIG_HOME", home.join(".config"));
    // no server and no local model unless the test gives one
    for var in [
        "TADSL_LLM_BASE_URL",
        "TADSL_LLM_API_KEY",
        "TADSL_LLM_MODEL",
        "TADSL_LLM_DIALECT",
        "TADSL_LLM_CONFIG",
        "TADSL_MODEL_DIR",
        "XDG_CACHE_HOME",
    ] {
        cmd.env_remove(var);
    }
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.stdin(Stdio::null()).output().expect("tadslc runs")
}

fn served(server: &FakeLlm) -> Vec<(&'static str, String)> {
    vec![("TADSL_LLM_BASE_URL", server.base_url.clone()), ("TADSL_LLM_MODEL", "fake".into())]
}

fn env_of<'a>(pairs: &'a [(&'static str, String)]) -> Vec<(&'static str, &'a str)> {
    pairs.iter().map(|(k, v)| (*k, v.as_str())).collect()
}

fn description(dir: &Path, text: &str) -> String {
    let path = dir.join("desc.txt");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn fenced(program: &str) -> Reply {
    Reply::chat(format!("Here is the program:\n```tad\n{program}```\n"))
}

#[test]
fn a_broken_program_is_repaired_in_round_two_from_every_diagnostic() {
    let dir = scratch("llm-repair");
    let broken = COMPLETE.replace("weather: clear", "weather: sunnyish").replace("speed: 25 km/h", "speed: 25 kmh");
    let server = FakeLlm::script(vec![fenced(&broken), fenced(COMPLETE)]);
    let out_file = dir.join("bus.tad");
    let transcript = dir.join("t.jsonl");
    let desc = description(&dir, "A bus drives ahead of the ego car on a clear day.");
    let out = run(
        &["translate", &desc, "-o", out_file.to_str().unwrap(), "--transcript", transcript.to_str().unwrap()],
        &env_of(&served(&server)),
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let requests = server.requests();
    assert_eq!(requests.len(), 2);
    let repair = last_user_text(&requests[1]);
    assert!(repair.contains("E0500") || repair.contains("sunnyish"), "{repair}");
    assert!(repair.lines().filter(|l| l.starts_with('E')).count() >= 2, "every error is sent back: {repair}");
    assert_eq!(requests[1]["messages"][2]["role"], "assistant", "the broken answer is in the conversation");
    let written = std::fs::read_to_string(&out_file).unwrap();
    assert!(written.contains("A bus drives ahead of the ego car on a clear day.") && written.contains("2 rounds"));
    let rounds: Vec<Value> =
        std::fs::read_to_string(&transcript).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(rounds.iter().map(|r| r["class"].as_str().unwrap()).collect::<Vec<_>>(), ["invalid", "complete"]);
    assert_eq!(rounds[1]["kind"], "repair");
}

/// A regional name without its `use` line is fixed by the compiler, not sent back to the
/// model: one round, and the program carries the line.
#[test]
fn a_missing_use_line_is_the_compilers_fix_not_a_repair_round() {
    let dir = scratch("llm-use");
    let deer = COMPLETE.replace("actor bus: 1 bus", "actor deer: 1 deer");
    let server = FakeLlm::script(vec![fenced(&deer)]);
    let out = run(&["translate", &description(&dir, "A deer ahead.")], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stdout(&out).contains("use rural\n"), "{}", stdout(&out));
    assert!(stderr(&out).contains("complete after 1 round"), "{}", stderr(&out));
}

/// `--text` takes the description itself.
#[test]
fn translate_takes_the_description_as_text() {
    let server = FakeLlm::script(vec![fenced(COMPLETE)]);
    let out = run(&["translate", "--text", "A bus ahead of the ego."], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stdout(&out).contains("scenario bus_ahead"), "{}", stdout(&out));
    assert!(server.requests().iter().any(|r| last_user_text(r).contains("A bus ahead of the ego.")));
    assert_eq!(code(&run(&["translate", "--text", "  "], &[])), 2);
}

/// `--pool` shows the translations whose descriptions read most like this one as earlier
/// turns, the nearest last, and names them in the provenance; programs without a
/// description or with an error are left out with a warning.
#[test]
fn translate_shows_the_pools_nearest_translations_first() {
    let dir = scratch("llm-pool");
    let pool = dir.join("pool");
    std::fs::create_dir_all(&pool).unwrap();
    let with = |name: &str, description: &str| {
        let source = format!("scenario {name} {{\n  source {{\n    description: \"{description}\"\n  }}");
        COMPLETE.replacen("scenario bus_ahead {", &source, 1)
    };
    std::fs::write(pool.join("bus.tad"), with("bus", "A red bus drives ahead of the ego in town.")).unwrap();
    std::fs::write(pool.join("deer.tad"), with("deer", "Deer cross a foggy country road at dawn.")).unwrap();
    std::fs::write(pool.join("truck.tad"), with("truck", "A truck merges onto a rainy highway.")).unwrap();
    std::fs::write(pool.join("bare.tad"), COMPLETE).unwrap();
    std::fs::write(pool.join("broken.tad"), with("broken", "A bus.").replace("clear", "sunnyish")).unwrap();
    let server = FakeLlm::script(vec![fenced(COMPLETE)]);
    let args = ["translate", "--text", "A bus ahead of the ego in town.", "--pool", pool.to_str().unwrap()];
    let out = run(&args, &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let messages = server.requests()[0]["messages"].as_array().unwrap().clone();
    let roles: Vec<&str> = messages.iter().map(|m| m["role"].as_str().unwrap()).collect();
    assert_eq!(roles, ["system", "user", "assistant", "user", "assistant", "user"]);
    let text = |i: usize| messages[i]["content"].as_str().map(String::from).unwrap_or_else(|| messages[i].to_string());
    assert!(text(3).contains("A red bus drives ahead") && text(4).contains("scenario bus {"), "the nearest last");
    assert!(!text(4).contains("source") && text(5).contains("A bus ahead of the ego in town."));
    assert!(stdout(&out).contains("// shown first: ") && stdout(&out).contains(", bus\n"), "{}", stdout(&out));
    let warning = stderr(&out);
    assert!(warning.contains("leaves out 2 programs") && warning.contains("bare.tad (no description)"), "{warning}");
    assert!(warning.contains("broken.tad (1 error)"), "{warning}");

    assert_eq!(code(&run(&["translate", "--text", "A bus.", "--pool", "no/such/dir"], &[])), 2);
    assert_eq!(code(&run(&["translate", "--text", "A bus.", "--shots", "3"], &[])), 2, "--shots needs a pool");
}

#[test]
fn an_incomplete_scenario_gets_the_refinement_request() {
    let dir = scratch("llm-refine");
    let incomplete = COMPLETE.replace("    weather: clear\n", "");
    let server = FakeLlm::script(vec![fenced(&incomplete), fenced(COMPLETE)]);
    let out = run(&["translate", &description(&dir, "A bus ahead.")], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let request = last_user_text(&server.requests()[1]);
    assert!(
        request.contains("weather") && request.contains("clear, cloudy"),
        "names come from the vocabulary: {request}"
    );
    assert!(stdout(&out).starts_with("// translated by tadslc"));
}

#[test]
fn exit_statuses_name_the_class_it_ended_in() {
    let dir = scratch("llm-classes");
    let desc = description(&dir, "A title card.");
    let non_scenario = FakeLlm::script(vec![fenced("scenario title_card {\n  ego {\n    lane: 1\n  }\n}\n")]);
    assert_eq!(code(&run(&["translate", &desc], &env_of(&served(&non_scenario)))), 4);
    let incomplete = FakeLlm::script(vec![fenced(&COMPLETE.replace("    weather: clear\n", ""))]);
    let out = run(&["translate", &desc, "--max-rounds", "2"], &env_of(&served(&incomplete)));
    assert_eq!((code(&out), incomplete.requests().len()), (3, 3));
    let prose = FakeLlm::script(vec![Reply::chat("I am sorry, I cannot write programs.")]);
    let out = run(&["translate", &desc, "--max-rounds", "1"], &env_of(&served(&prose)));
    assert_eq!((code(&out), prose.requests().len()), (1, 2), "{}", stderr(&out));
    assert!(stderr(&out).contains("no program"));
}

#[test]
fn an_answer_that_never_becomes_valid_stops_at_the_bound_and_keeps_the_last_program() {
    let dir = scratch("llm-never");
    let server = FakeLlm::script(vec![fenced("scenario x {\n  road {\n    lanes: many\n  }\n}\n")]);
    let out = run(&["translate", &description(&dir, "x"), "--max-rounds", "3"], &env_of(&served(&server)));
    assert_eq!(code(&out), 1);
    assert_eq!(server.requests().len(), 4, "one answer and three repairs");
    assert!(stdout(&out).contains("lanes: many"), "the last program is kept");
}

#[test]
fn after_the_last_round_the_checkers_guess_makes_a_program_valid_and_is_said() {
    let dir = scratch("llm-suggested");
    let walker = "  actor walker: 1 pedestrian {\n    behavior: cross\n    position: behind of parked_bus\n    lane: 1\n  }\n}\n";
    let guessed = COMPLETE.strip_suffix("}\n").unwrap().to_string() + walker;
    let server = FakeLlm::script(vec![fenced(&guessed)]);
    let out = run(&["translate", &description(&dir, "A bus ahead."), "--max-rounds", "1"], &env_of(&served(&server)));
    // E0402's guess is maybe-incorrect: it is not applied while the model can still repair
    assert_eq!(server.requests().len(), 2, "one answer and one repair");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stdout(&out).contains("position: behind of bus\n"), "{}", stdout(&out));
    let said = "the checker's suggestions applied after the last round: E0402 `parked_bus` → `bus`";
    assert!(stderr(&out).contains(said) && stdout(&out).contains(said), "{}", stderr(&out));
    // a guess that leaves errors is not taken
    let unfixable = guessed.replace("lanes: 1", "lanes: many");
    let server = FakeLlm::script(vec![fenced(&unfixable)]);
    let out = run(&["translate", &description(&dir, "A bus ahead."), "--max-rounds", "0"], &env_of(&served(&server)));
    assert_eq!(code(&out), 1);
    assert!(stdout(&out).contains("behind of parked_bus") && !stderr(&out).contains("suggestions applied"));
}

#[test]
fn no_server_and_a_dead_server_are_clear_errors() {
    let dir = scratch("llm-none");
    let desc = description(&dir, "x");
    let out = run(&["translate", &desc], &[]);
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("TADSL_LLM_BASE_URL"), "{}", stderr(&out));
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let url = format!("http://{}/v1", listener.local_addr().unwrap());
    drop(listener);
    let out = run(&["translate", &desc, "--max-retries", "0"], &[("TADSL_LLM_BASE_URL", &url)]);
    assert_eq!(code(&out), 5, "{}", stderr(&out));
    assert!(stderr(&out).contains("is the server running"));
}

#[test]
fn a_rate_limited_server_is_waited_for() {
    let dir = scratch("llm-429");
    let server = FakeLlm::script(vec![Reply::status(429, "{}").with_header("retry-after", "1"), fenced(COMPLETE)]);
    let out = run(&["translate", &description(&dir, "x")], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(server.requests().len(), 2);
}

#[test]
fn constrain_sends_the_grammar_in_the_servers_field() {
    let dir = scratch("llm-constrain");
    let server = FakeLlm::script(vec![Reply::chat(COMPLETE)]);
    let mut env = served(&server);
    env.push(("TADSL_LLM_DIALECT", "llama-cpp".into()));
    let out = run(&["translate", &description(&dir, "x"), "--constrain", "--region", "yellowstone"], &env_of(&env));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let grammar = server.requests()[0]["grammar"].as_str().unwrap().to_string();
    assert!(grammar.contains("root ::=") && grammar.contains("\"bison\""), "the region's names are in the grammar");
    let openai = FakeLlm::script(vec![Reply::chat(COMPLETE)]);
    let out = run(&["translate", &description(&dir, "x"), "--constrain"], &env_of(&served(&openai)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(openai.requests()[0]["response_format"]["type"], "json_schema");
}

/// `bench --translate` over the repository's descriptions, the server constrained: one that
/// answers each with its own ground truth scores 100 %; one that answers with one fixed
/// program scores what that program gets right, and its answers are kept.
#[test]
fn bench_translate_scores_answers_against_the_ground_truth() {
    let truth_dir = repo().join("tests/llm/truth");
    let truth_of = move |body: &Value| {
        let text = last_user_text(body);
        let descriptions = std::fs::read_dir(repo().join("tests/llm/descriptions")).unwrap();
        let stem = descriptions
            .filter_map(|e| e.ok())
            .find(|e| text.contains(std::fs::read_to_string(e.path()).unwrap().trim()))
            .map(|e| e.path().file_stem().unwrap().to_string_lossy().into_owned())
            .expect("the request holds a description");
        std::fs::read_to_string(truth_dir.join(format!("{stem}.tad"))).unwrap()
    };
    let server = FakeLlm::start(move |_, body| fenced(&truth_of(body)));
    let out = run(&["bench", "--translate", "--max-rounds", "0"], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let report = stdout(&out);
    assert!(report.contains("on 88 descriptions"), "{report}");
    assert!(report.contains("| **overall** |") && report.contains("**100.0 %**"), "{report}");
    // every model is measured constrained, a server as `translate --constrain` asks it
    assert!(server.requests().iter().all(|r| r["response_format"]["type"] == "json_schema"));

    let dir = scratch("bench-translate");
    let fixed = FakeLlm::start(|_, _| fenced(COMPLETE));
    let args = ["bench", "--translate", "--max-rounds", "0", "--out", dir.to_str().unwrap()];
    let out = run(&args, &env_of(&served(&fixed)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let overall = stdout(&out).lines().find(|l| l.starts_with("| **overall**")).unwrap().to_string();
    let percent: f64 = overall.rsplit("**").nth(1).unwrap().trim_end_matches(" %").parse().unwrap();
    assert!(percent > 5.0 && percent < 40.0, "{overall}");
    assert!(dir.join("faithfulness.jsonl").exists() && dir.join("06_los_angeles_boulevard_red_light.tad").exists());
    // the kept answers score the same without a model
    let rescored = run(&["bench", "--translate", "--answers", dir.to_str().unwrap()], &[]);
    assert_eq!(code(&rescored), 0, "{}", stderr(&rescored));
    assert!(stdout(&rescored).lines().any(|l| l == overall), "{}", stdout(&rescored));
    assert!(stdout(&rescored).lines().any(|l| l.starts_with("overall ") && l.contains("95 % interval")));
    // against itself: no difference, on every description
    let dir_arg = dir.to_str().unwrap();
    let paired = run(&["bench", "--translate", "--answers", dir_arg, "--against", dir_arg], &[]);
    assert_eq!(code(&paired), 0, "{}", stderr(&paired));
    assert!(
        stdout(&paired).contains("+0.0 points [+0.0, +0.0] on the 88 descriptions both scored"),
        "{}",
        stdout(&paired)
    );
    // valid@1, after repair and rounds; tokens and seconds are the run's own
    let validity = |out: &std::process::Output| {
        stdout(out).lines().find(|l| l.starts_with("valid@1 ")).map(|l| l.split(" rounds").next().unwrap().to_string())
    };
    assert_eq!(validity(&rescored), validity(&out));
    // without the run's manifest, what only the run knew is not made up
    std::fs::remove_file(dir.join("faithfulness.jsonl")).unwrap();
    let bare = run(&["bench", "--translate", "--answers", dir.to_str().unwrap()], &[]);
    assert!(stdout(&bare).lines().any(|l| l == overall), "{}", stdout(&bare));
    assert!(validity(&bare).is_none() && stdout(&bare).contains("not recorded"), "{}", stdout(&bare));
    // an adapter goes to the model as `translate --adapter` gives it: a server takes none
    let adapter = run(&["bench", "--translate", "--adapter", dir_arg], &env_of(&served(&fixed)));
    assert_eq!(code(&adapter), 2, "{}", stderr(&adapter));
    assert!(stderr(&adapter).contains("--adapter applies to the local model only"), "{}", stderr(&adapter));
}

#[test]
fn a_batch_writes_programs_a_manifest_and_a_summary() {
    let dir = scratch("llm-batch");
    let descs = dir.join("descs");
    std::fs::create_dir_all(&descs).unwrap();
    for (name, text) in [("a", "A bus ahead."), ("b", "A title card."), ("c", "A bus again.")] {
        std::fs::write(descs.join(format!("{name}.txt")), text).unwrap();
    }
    let server = FakeLlm::start(|_, body| {
        if last_user_text(body).contains("title card") {
            Reply::chat("```tad\nscenario card {\n}\n```")
        } else {
            Reply::chat(COMPLETE)
        }
    });
    let out_dir = dir.join("out");
    let out = run(&["translate", descs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!((summary["items"].as_u64(), summary["classes"]["complete"].as_u64()), (Some(3), Some(2)));
    assert_eq!(summary["syntax_valid_first"], 3);
    assert!(out_dir.join("a.tad").exists() && out_dir.join("c.tad").exists());
    assert!(stderr(&out).contains("3 items: syntax-valid at round 1 3 (100%)"), "{}", stderr(&out));
}

fn ffmpeg() -> bool {
    let found = Command::new("ffmpeg").arg("-version").output().is_ok_and(|o| o.status.success());
    if !found && std::env::var_os("TAD_REQUIRE_EDITORS").is_some() {
        panic!("ffmpeg is required (TAD_REQUIRE_EDITORS is set)");
    }
    found
}

/// A 40-second test video: frames at 0, 15 and 30 s.
fn video(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("Dash Cam #1.mp4");
    let status = Command::new("ffmpeg")
        .args([
            "-v",
            "error",
            "-y",
            "-f",
            "lavfi",
            "-i",
            "testsrc=duration=40:size=320x240:rate=5",
            "-pix_fmt",
            "yuv420p",
        ])
        .arg(&path)
        .status()
        .unwrap();
    assert!(status.success());
    path
}

/// A server for synth: a description per frame (the second frame a title card), programs
/// for descriptions; counts the images it saw.
fn synth_server(images: Arc<AtomicUsize>) -> FakeLlm {
    synth_server_with(images, std::time::Duration::ZERO)
}

/// The same, answering each request after `delay`.
fn synth_server_with(images: Arc<AtomicUsize>, delay: std::time::Duration) -> FakeLlm {
    FakeLlm::start(move |_, body| Reply::Delay(delay, Box::new(synth_reply(&images, body))))
}

fn synth_reply(images: &AtomicUsize, body: &Value) -> Reply {
    {
        let has_image = body["messages"]
            .as_array()
            .unwrap()
            .iter()
            .any(|m| m["content"].to_string().contains("data:image/jpeg;base64,"));
        let text = last_user_text(body);
        if has_image && text.starts_with("Describe") {
            let n = images.fetch_add(1, Ordering::SeqCst);
            let what =
                if n == 1 { "A black title card with white text." } else { "A bus drives ahead of the ego car." };
            Reply::chat(format!("<ANALYSIS>I look.</ANALYSIS>\n<DESCRIPTION>\n{what}\n</DESCRIPTION>"))
        } else if text.contains("title card") {
            Reply::chat("```tad\nscenario card {\n}\n```")
        } else {
            Reply::chat(COMPLETE)
        }
    }
}

#[test]
fn synth_turns_a_video_into_scenarios_and_resumes_without_redoing_anything() {
    if !ffmpeg() {
        eprintln!("SKIPPED: ffmpeg is not installed");
        return;
    }
    let dir = scratch("llm-synth");
    let video = video(&dir);
    let out_dir = dir.join("out");
    let images = Arc::new(AtomicUsize::new(0));
    let server = synth_server(images.clone());
    let args =
        ["synth", "--video", video.to_str().unwrap(), "--region", "yellowstone", "--out", out_dir.to_str().unwrap()];
    let out = run(&args, &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(images.load(Ordering::SeqCst), 3, "frames at 0, 15 and 30 s");
    let manifest: Vec<Value> = std::fs::read_to_string(out_dir.join("manifest.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let statuses: Vec<&str> = manifest.iter().map(|r| r["status"].as_str().unwrap()).collect();
    assert_eq!(statuses, ["complete", "non_scenario", "complete"]);
    assert_eq!(manifest[1]["frame"], "dash_cam_1_t00015");
    let tads = tad_files(&out_dir);
    assert_eq!(tads.len(), 2, "{tads:?}");
    let first = std::fs::read_to_string(out_dir.join("dash_cam_1_t00000.tad")).unwrap();
    assert!(first.contains("video: \"Dash Cam #1.mp4\"") && first.contains("region: yellowstone"), "{first}");
    assert!(first.contains("A bus drives ahead of the ego car."));
    let check = run(&["check", out_dir.to_str().unwrap()], &[]);
    assert_eq!(code(&check), 0, "{}", stdout(&check));

    // nothing is redone; a frame whose manifest line was lost (a killed run) is redone
    let before = server.requests().len();
    assert_eq!(code(&run(&args, &env_of(&served(&server)))), 0);
    assert_eq!(server.requests().len(), before);
    let text = std::fs::read_to_string(out_dir.join("manifest.jsonl")).unwrap();
    let kept: Vec<&str> = text.lines().take(2).collect();
    std::fs::write(out_dir.join("manifest.jsonl"), format!("{}\n{{\"frame\":\"dash_c", kept.join("\n"))).unwrap();
    let out = run(&args, &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stderr(&out).contains("2 done before, 1 now"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(out_dir.join("manifest.jsonl")).unwrap().lines().count(), 3);
}

/// Without a server, synth refuses at once and says what to configure: no frame is taken.
#[test]
fn synth_without_a_multimodal_server_refuses_before_any_frame() {
    let dir = scratch("synth-local");
    let out_dir = dir.join("out");
    for extra in [&[][..], &["--model", "local"]] {
        let mut args =
            vec!["synth", "--video", "missing.mp4", "--region", "yellowstone", "--out", out_dir.to_str().unwrap()];
        args.extend_from_slice(extra);
        let out = run(&args, &[]);
        assert_eq!(code(&out), 2, "{}", stderr(&out));
        assert!(
            stderr(&out).contains("the local model reads text only: configure a multimodal server"),
            "{}",
            stderr(&out)
        );
        assert!(!out_dir.exists());
    }
}

#[test]
fn synth_shards_split_the_frames() {
    if !ffmpeg() {
        eprintln!("SKIPPED: ffmpeg is not installed");
        return;
    }
    let dir = scratch("llm-shards");
    let video = video(&dir);
    let out_dir = dir.join("out");
    let server = synth_server(Arc::new(AtomicUsize::new(0)));
    for shard in ["0/2", "1/2"] {
        let out = run(
            &[
                "synth",
                "--video",
                video.to_str().unwrap(),
                "--region",
                "los_angeles",
                "--out",
                out_dir.to_str().unwrap(),
                "--shard",
                shard,
            ],
            &env_of(&served(&server)),
        );
        assert_eq!(code(&out), 0, "{}", stderr(&out));
    }
    let frames = |file: &str| -> Vec<String> {
        std::fs::read_to_string(out_dir.join(file))
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str::<Value>(l).unwrap()["frame"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(frames("manifest.0-of-2.jsonl"), ["dash_cam_1_t00000", "dash_cam_1_t00030"]);
    assert_eq!(frames("manifest.1-of-2.jsonl"), ["dash_cam_1_t00015"]);
    let bad = run(&["synth", "--video", "x.mp4", "--region", "los_angeles", "--out", "o", "--shard", "2/2"], &[]);
    assert_eq!(code(&bad), 2);
}

#[test]
fn gen_writes_checked_scenarios_and_the_baseline_names_the_region_only() {
    let dir = scratch("llm-gen");
    let server = FakeLlm::script(vec![fenced(COMPLETE)]);
    let out_dir = dir.join("aligned");
    let out = run(
        &["gen", "--region", "yellowstone", "-n", "3", "--seed", "7", "--out", out_dir.to_str().unwrap()],
        &env_of(&served(&server)),
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(tad_files(&out_dir).len(), 3);
    let requests = server.requests();
    let seeds: Vec<u64> = requests.iter().map(|r| r["seed"].as_u64().unwrap()).collect();
    let mut sorted = seeds.clone();
    sorted.sort();
    assert_eq!(sorted, [7, 8, 9]);
    let system = requests[0]["messages"][0]["content"].as_str().unwrap();
    assert!(
        system.contains("bison") && system.contains("A scenario of this region"),
        "aligned: the region's vocabulary and examples"
    );
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!((summary["mode"].as_str(), summary["valid_after_repair"].as_u64()), (Some("aligned"), Some(3)));

    let baseline = FakeLlm::script(vec![fenced(COMPLETE)]);
    let out = run(&["gen", "--region", "yellowstone", "-n", "1", "--baseline"], &env_of(&served(&baseline)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stdout(&out).contains("scenario bus_ahead"));
    let system = baseline.requests()[0]["messages"][0]["content"].as_str().unwrap().to_string();
    assert!(!system.contains("A scenario of this region"));
    assert!(last_user_text(&baseline.requests()[0]).contains("yellowstone"));
}

#[test]
fn eval_generates_with_the_model_and_tables_its_scenarios() {
    let dir = scratch("llm-eval");
    let server = FakeLlm::script(vec![fenced(&COMPLETE.replace("speed: 25 km/h", "speed: 10..40 km/h"))]);
    let args = [
        "eval",
        "examples",
        "--region",
        "los_angeles",
        "--generators",
        "llm,llm-baseline,fitted",
        "--egos",
        "idm,naive",
        "-n",
        "2",
        "--samples",
        "10",
        "--format",
        "json",
        "--out",
        dir.to_str().unwrap(),
    ];
    let out = run(&args, &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let rows: Vec<Value> = stdout(&out).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let generators: Vec<&str> = rows.iter().map(|r| r["generator"].as_str().unwrap()).collect();
    assert_eq!(generators, ["llm", "llm", "llm-baseline", "llm-baseline", "fitted", "fitted"]);
    // each model scenario has a speed range: the search keeps two scenes of each
    assert_eq!(rows[0]["episodes"], 4, "{}", rows[0]);
    assert_eq!(tad_files(&dir.join("generated/los_angeles/llm")).len(), 2);
    let systems: Vec<String> =
        server.requests().iter().map(|r| r["messages"][0]["content"].as_str().unwrap().to_string()).collect();
    assert_eq!(systems.iter().filter(|s| s.contains("A scenario of this region")).count(), 2, "two aligned prompts");

    // without a server or a local model the command stops with the model's error
    let out = run(&["eval", "examples", "--region", "los_angeles", "--generators", "llm", "-n", "1"], &[]);
    assert_ne!(code(&out), 0);
    assert!(stderr(&out).contains("the language model generated nothing usable"), "{}", stderr(&out));
}

#[test]
fn grammar_prints_each_notation() {
    for (format, marker) in [("gbnf", "root ::= "), ("lark", "start: "), ("json-schema", "\"$schema\"")] {
        let out = run(&["grammar", "--format", format], &[]);
        assert_eq!(code(&out), 0);
        assert!(stdout(&out).contains(marker), "{format}");
    }
    assert_eq!(code(&run(&["grammar", "--region", "atlantis"], &[])), 2);
}

/// llama.cpp's server with SmolLM2-135M, when `TADSL_LLAMA_SERVER` (the binary) and
/// `TADSL_SMOLLM2_GGUF` (the model) are set: protocol facts only — a 135M model cannot
/// be held to translate well, but with `--constrain` every answer parses.
#[test]
fn a_real_llama_server_answers_and_constrained_answers_parse() {
    let (Some(server), Some(model)) = (std::env::var_os("TADSL_LLAMA_SERVER"), std::env::var_os("TADSL_SMOLLM2_GGUF"))
    else {
        eprintln!("SKIPPED: set TADSL_LLAMA_SERVER and TADSL_SMOLLM2_GGUF to run against llama.cpp");
        return;
    };
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let mut child = Command::new(server)
        .args(["-m".as_ref(), model.as_os_str()])
        .args(["--host", "127.0.0.1", "--port", &port.to_string(), "-c", "4096", "-t", "1", "-np", "1", "--offline"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("llama-server starts");
    let url = format!("http://127.0.0.1:{port}/v1");
    let ready = (0..100).any(|_| {
        std::thread::sleep(std::time::Duration::from_millis(200));
        std::net::TcpStream::connect(("127.0.0.1", port)).is_ok()
    });
    assert!(ready, "llama-server listens");
    std::thread::sleep(std::time::Duration::from_secs(2));
    let dir = scratch("llm-real");
    let desc =
        description(&dir, "A clear day on a two-lane road. The ego car drives at 40 km/h behind a bus doing 30 km/h.");
    let env =
        [("TADSL_LLM_BASE_URL", url.as_str()), ("TADSL_LLM_DIALECT", "llama-cpp"), ("TADSL_LLM_MODEL", "smollm2")];
    let transcript = dir.join("t.jsonl");
    let out = run(
        &[
            "translate",
            &desc,
            "--constrain",
            "--max-tokens",
            "400",
            "--max-rounds",
            "1",
            "--transcript",
            transcript.to_str().unwrap(),
        ],
        &env,
    );
    let _ = child.kill();
    let _ = child.wait();
    assert!([0, 1, 3, 4].contains(&code(&out)), "{}", stderr(&out));
    let rounds: Vec<Value> =
        std::fs::read_to_string(&transcript).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert!(rounds.iter().all(|r| r["syntax_valid"] == true), "every constrained answer parses: {rounds:?}");
}

#[test]
fn ctrl_c_finishes_the_frame_under_way_and_a_rerun_does_the_rest() {
    if !ffmpeg() {
        eprintln!("SKIPPED: ffmpeg is not installed");
        return;
    }
    let dir = scratch("llm-interrupt");
    let video = video(&dir);
    let out_dir = dir.join("out");
    let delayed = synth_server_with(Arc::new(AtomicUsize::new(0)), std::time::Duration::from_millis(400));
    let args =
        ["synth", "--video", video.to_str().unwrap(), "--region", "yellowstone", "--out", out_dir.to_str().unwrap()];
    let home = scratch("llm-interrupt-home");
    let child = Command::new(env!("CARGO_BIN_EXE_tadslc"))
        .args(args)
        .current_dir(repo())
        .env("HOME", &home)
        .env("TADSL_LLM_BASE_URL", &delayed.base_url)
        .env_remove("TADSL_LLM_CONFIG")
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let manifest = out_dir.join("manifest.jsonl");
    let lines = || std::fs::read_to_string(&manifest).map(|t| t.lines().count()).unwrap_or(0);
    for _ in 0..200 {
        if lines() >= 1 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert_eq!(lines(), 1, "the first frame is done");
    let _ = Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    let output = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(err.contains("run the same command again"), "{err}");
    let done = lines();
    assert!((1..3).contains(&done), "{done} frames done");
    let out = run(&args, &env_of(&served(&delayed)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stderr(&out).contains(&format!("{done} done before")), "{}", stderr(&out));
    assert_eq!(lines(), 3);
}

#[test]
fn a_round_that_makes_things_worse_loses_nothing() {
    let dir = scratch("llm-worse");
    let incomplete = COMPLETE.replace("    weather: clear\n", "");
    let worse = "scenario broken {\n  road {\n    lanes: many\n  }\n}\n";
    let server = FakeLlm::script(vec![fenced(&incomplete), fenced(worse)]);
    let out = run(&["translate", &description(&dir, "A bus ahead."), "--max-rounds", "1"], &env_of(&served(&server)));
    assert_eq!(code(&out), 3, "the incomplete program of round 1 is the result: {}", stderr(&out));
    assert!(stdout(&out).contains("scenario bus_ahead") && !stdout(&out).contains("lanes: many"));
    assert_eq!(server.requests().len(), 2);
}

#[test]
fn stream_shows_each_answer_on_stderr_as_it_arrives_and_keeps_stdout_the_program() {
    let dir = scratch("llm-stream");
    let broken = COMPLETE.replace("weather: clear", "weather: sunnyish");
    let first = format!("```tad\n{broken}```\n");
    let second = format!("```tad\n{COMPLETE}```\n");
    let server = FakeLlm::script(vec![Reply::Stream(first.clone()), Reply::Stream(second.clone())]);
    let desc = description(&dir, "A bus drives ahead of the ego car on a clear day.");
    let out = run(&["translate", &desc, "--stream"], &env_of(&served(&server)));
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let requests = server.requests();
    assert!(requests.iter().all(|r| r["stream"] == true), "{requests:?}");
    let err = stderr(&out);
    let (a, b) = (err.find(&first).expect("round 1 streamed"), err.find(&second).expect("round 2 streamed"));
    let round_one = err.find("round 1: invalid").expect("round 1's verdict");
    assert!(a < round_one && round_one < b, "each answer, then its verdict: {err}");
    assert!(stdout(&out).starts_with("// translated by tadslc") && stdout(&out).contains("weather: clear"));
    assert!(!stdout(&out).contains("```"), "stdout holds the program only");
    // a batch has no single stream to show
    let other = dir.join("more");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("a.txt"), "A bus.").unwrap();
    let batch = run(&["translate", other.to_str().unwrap(), "-o", dir.join("o").to_str().unwrap(), "--stream"], &[]);
    assert_eq!(code(&batch), 2);
    assert!(stderr(&batch).contains("--stream shows one description"), "{}", stderr(&batch));
}
