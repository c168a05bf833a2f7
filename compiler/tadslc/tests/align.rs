//! Corpora and alignment: `stats`, `compare`, `fit`, `gen --generator fitted:`,
//! `sft-export`, and the recovery experiment (`bench --align`) that proves the fitted
//! generator comes closer to its own region than to the others and than the unaligned
//! baseline.

mod common;
use common::*;

use std::path::Path;

use serde_json::Value;

fn json(output: &std::process::Output) -> Value {
    serde_json::from_str(&stdout(output))
        .unwrap_or_else(|e| panic!("JSON ({e}):\n{}\n{}", stdout(output), stderr(output)))
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn stats_prints_the_corpus_table_csv_json_and_plots() {
    let plots = scratch("align-plots");
    let out = tadslc(&["stats", "examples/regions", "examples/safety", "--plot", path(&plots)], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.contains("| regions | 6 | 10.2 | 3.8 |"), "{table}");
    assert!(table.contains("| safety | 8 |"), "{table}");
    assert!(table.contains("### Actor types (`actor_type`, per actor)"), "{table}");
    // the Yellowstone example's five bison count as five actors
    assert!(table.contains("| bison | 5 ("), "{table}");
    for name in ["weather", "actor_type", "type_behavior", "actors"] {
        let svg = std::fs::read_to_string(plots.join(format!("{name}.svg"))).expect("a plot per attribute");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{name}");
        assert!(svg.contains("regions") && svg.contains("safety"), "both corpora in the legend");
    }

    let out = tadslc(&["stats", "examples/regions", "--format", "json"], "");
    let stats = json(&out);
    assert_eq!(stats[0]["scenarios"], 6);
    assert_eq!(stats[0]["histograms"]["actor_type"]["bison"], 5);

    let out = tadslc(&["stats", "examples/safety", "--format", "csv"], "");
    let csv = stdout(&out);
    assert!(csv.starts_with("corpus,attribute,value,count,share\n"));
    assert!(csv.contains("safety,scenarios,,8,\n"), "{csv}");
}

#[test]
fn stats_skips_invalid_files_and_fails_on_an_empty_corpus() {
    let dir = scratch("align-invalid");
    std::fs::write(dir.join("broken.tad"), "scenario x { road { lanes: banana } }").unwrap();
    let out = tadslc(&["stats", path(&dir)], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("1 file skipped") && stderr(&out).contains("no valid scenario"), "{}", stderr(&out));
}

#[test]
fn compare_gives_every_distance_with_an_interval_and_is_seeded() {
    let args = [
        "compare",
        "examples/regions",
        "examples/safety",
        "--embedding",
        "features",
        "--format",
        "json",
        "--resamples",
        "50",
    ];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let c = json(&out);
    for key in ["actor_count_wasserstein", "mmd", "frechet"] {
        let (v, lo, hi) =
            (c[key]["value"].as_f64().unwrap(), c[key]["low"].as_f64().unwrap(), c[key]["high"].as_f64().unwrap());
        assert!(lo <= v && v <= hi, "{key}: {v} not in [{lo}, {hi}]");
    }
    let mean = c["jsd"]["mean"]["value"].as_f64().unwrap();
    assert!(mean > 0.05 && mean < 1.0, "{mean}");
    assert!(c["jsd"]["road_type"]["value"].as_f64().unwrap() > 0.0);
    assert_eq!(stdout(&tadslc(&args, "")), stdout(&out), "the same seed gives the same intervals");

    // a corpus against itself: nothing differs
    let out =
        tadslc(&["compare", "examples/regions", "examples/regions", "--embedding", "features", "--format", "json"], "");
    let c = json(&out);
    assert_eq!(c["jsd"]["mean"]["value"].as_f64(), Some(0.0));
    assert_eq!(c["actor_count_wasserstein"]["value"].as_f64(), Some(0.0));
    assert!(c["frechet"]["value"].as_f64().unwrap().abs() < 1e-6);

    let plot = scratch("align-scatter").join("pca.svg");
    let out = tadslc(
        &["compare", "examples/regions", "examples/safety", "--embedding", "features", "--plot", path(&plot)],
        "",
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert_eq!(svg.matches("<circle").count(), 14, "one point per scenario");
}

#[test]
fn the_fitted_generator_samples_valid_scenarios_reproducibly() {
    let dir = scratch("align-fit");
    let model = dir.join("regions.model");
    let out = tadslc(&["fit", "examples/regions", "examples/safety", "-o", path(&model)], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let generate = |seed: &str, out_dir: &Path| {
        let generator = format!("fitted:{}", model.display());
        tadslc(&["gen", "--generator", &generator, "-n", "6", "--seed", seed, "--out", path(out_dir)], "")
    };
    let (a, b, c) = (dir.join("a"), dir.join("b"), dir.join("c"));
    for (seed, d) in [("4", &a), ("4", &b), ("5", &c)] {
        let out = generate(seed, d);
        assert_eq!(code(&out), 0, "{}", stderr(&out));
    }
    let read = |d: &Path| tad_files(d).iter().map(|f| std::fs::read_to_string(f).unwrap()).collect::<Vec<_>>();
    assert_eq!(read(&a).len(), 6);
    assert_eq!(read(&a), read(&b), "same seed, same scenarios");
    assert_ne!(read(&a), read(&c));
    let check = tadslc(&["check", path(&a)], "");
    assert_eq!(code(&check), 0, "every generated scenario checks:\n{}", stdout(&check));
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(a.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["generated"], 6);

    // a model file is untrusted input
    let bad = dir.join("bad.model");
    for text in ["not json", r#"{"format": "tadsl-fitted/9"}"#, r#"{"format": "tadsl-fitted/1", "tables": 3}"#] {
        std::fs::write(&bad, text).unwrap();
        let out = tadslc(&["gen", "--generator", &format!("fitted:{}", bad.display()), "-n", "1"], "");
        assert_eq!(code(&out), 2, "{text}: {}", stderr(&out));
        assert!(stderr(&out).contains("bad.model"), "{}", stderr(&out));
    }
    let out = tadslc(&["gen", "--generator", "markov", "-n", "1"], "");
    assert_eq!(code(&out), 2);
}

#[test]
fn sft_export_writes_trl_conversations_with_checked_answers() {
    let dir = scratch("align-sft");
    let out = tadslc(&["sft-export", "examples/regions", "-o", path(&dir)], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let messages = std::fs::read_to_string(dir.join("messages.jsonl")).unwrap();
    let lines: Vec<Value> = messages.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 6);
    for line in &lines {
        let roles: Vec<&str> =
            line["messages"].as_array().unwrap().iter().map(|m| m["role"].as_str().unwrap()).collect();
        assert_eq!(roles, ["system", "user", "assistant"]);
        let program = line["messages"][2]["content"].as_str().unwrap();
        assert!(program.starts_with("use ") || program.starts_with("scenario "), "the bare program: {program}");
        assert!(!program.contains("description"), "answers carry no source description");
        let check = tadslc(&["check", "-"], program);
        assert_eq!(code(&check), 0, "{}", stdout(&check));
        let user = line["messages"][1]["content"].as_str().unwrap();
        let region = program.lines().find_map(|l| l.trim().strip_prefix("region: ")).unwrap();
        assert!(user.contains(region), "the prompt names the scenario's region");
    }
    let pc = std::fs::read_to_string(dir.join("prompt_completion.jsonl")).unwrap();
    let first: Value = serde_json::from_str(pc.lines().next().unwrap()).unwrap();
    assert_eq!(first["prompt"].as_array().unwrap().len(), 2);
    assert_eq!(first["completion"][0]["role"], "assistant");
}

#[test]
fn sft_export_translate_answers_each_description_with_its_truth() {
    let descriptions = scratch("align-sft-translate-desc");
    for name in ["41_la_freeway_carpool_lane", "52_nyc_queens_snow_t_junction"] {
        let from = repo().join(format!("tests/llm/descriptions/{name}.txt"));
        std::fs::copy(from, descriptions.join(format!("{name}.txt"))).unwrap();
    }
    let dir = scratch("align-sft-translate");
    let args = ["sft-export", "--translate", "--truth", "tests/llm/truth", path(&descriptions), "-o", path(&dir)];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let messages = std::fs::read_to_string(dir.join("messages.jsonl")).unwrap();
    let lines: Vec<Value> = messages.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 2);
    // every pair begins with the same system message: what --frozen-prefix reads once
    assert_eq!(lines[0]["messages"][0], lines[1]["messages"][0]);
    assert!(lines[0]["messages"][0]["content"].as_str().unwrap().contains("road users"));
    let user = lines[1]["messages"][1]["content"].as_str().unwrap();
    assert!(user.contains("Snowing at dusk in Queens"), "{user}");
    let answer = lines[1]["messages"][2]["content"].as_str().unwrap();
    let (users, program) = answer.split_once('\n').unwrap();
    assert_eq!(users, "// road users: snowplow; following bus; waiting car");
    assert!(program.starts_with("scenario nyc_queens_snow_t_junction {"), "{program}");
    assert!(!program.contains("//") && !program.contains("source"), "{program}");
    let check = tadslc(&["check", "-"], program);
    assert_eq!(code(&check), 0, "{}", stdout(&check));

    // a description without a truth, and a truth the checker rejects, stop the export
    std::fs::write(descriptions.join("99_no_truth.txt"), "A car waits at a light.").unwrap();
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("no truth `99_no_truth.tad`"), "{}", stderr(&out));
    std::fs::remove_file(descriptions.join("99_no_truth.txt")).unwrap();
    let truth = scratch("align-sft-translate-truth");
    for name in ["41_la_freeway_carpool_lane", "52_nyc_queens_snow_t_junction"] {
        let text = std::fs::read_to_string(repo().join(format!("tests/llm/truth/{name}.tad"))).unwrap();
        std::fs::write(truth.join(format!("{name}.tad")), text.replace("weather: snowy", "weather: sleet")).unwrap();
    }
    // the first directory holding a truth gives it
    let dirs = ["--truth", path(&truth), "--truth", "tests/llm/truth"];
    let args = [&["sft-export", "--translate"][..], &dirs, &[path(&descriptions), "-o", path(&dir)]].concat();
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("the truth is not valid"), "{}", stderr(&out));
}

/// The recovery test: corpora drawn from three labelled synthetic regions; the generator
/// fitted to each region's training sample must be at least 3× closer to the region's
/// held-out sample than the unaligned baseline, and closer than the other regions'
/// generators, on every distance.
#[test]
fn the_fitted_generator_recovers_each_synthetic_region() {
    let dir = scratch("align-recovery");
    let out = tadslc(
        &["bench", "--align", "--per-region", "60", "--resamples", "40", "--seed", "3", "--json", "--out", path(&dir)],
        "",
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let rows = json(&out);
    let rows = rows.as_array().unwrap();
    let get = |region: &str, generator: &str, key: &str| -> f64 {
        let row = rows.iter().find(|r| r["region"] == region && r["generator"] == generator).unwrap();
        let c = &row["comparison"];
        if key == "jsd" { c["jsd"]["mean"]["value"].as_f64().unwrap() } else { c[key]["value"].as_f64().unwrap() }
    };
    for region in ["metro", "park", "alpine"] {
        for key in ["jsd", "mmd", "frechet"] {
            let fitted = get(region, "fitted", key);
            let baseline = get(region, "unaligned baseline", key);
            assert!(fitted * 3.0 < baseline, "{region} {key}: fitted {fitted} vs baseline {baseline}");
            for other in ["metro", "park", "alpine"].iter().filter(|o| **o != region) {
                let theirs = get(region, &format!("fitted on {other}"), key);
                assert!(fitted < theirs, "{region} {key}: own {fitted} vs {other}'s {theirs}");
            }
        }
    }
}

#[test]
fn compare_with_minilm_sentence_embeddings() {
    if tad_models::for_tests("all-minilm-l6-v2").is_none() {
        return;
    }
    let out = tadslc(&["compare", "examples/regions", "examples/safety", "--format", "json", "--resamples", "20"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let c = json(&out);
    assert_eq!(c["embedding"], "all-minilm-l6-v2");
    let frechet = c["frechet"]["value"].as_f64().unwrap();
    assert!(frechet > 0.01, "{frechet}");
    let out = tadslc(&["compare", "examples/regions", "examples/regions", "--format", "json", "--resamples", "20"], "");
    let same = json(&out);
    assert!(same["frechet"]["value"].as_f64().unwrap() < 1e-3, "{}", same["frechet"]);
    assert!(same["mmd"]["value"].as_f64().unwrap() < c["mmd"]["value"].as_f64().unwrap());
}

#[test]
fn finetune_and_adapters_refuse_bad_input_with_status_2() {
    let dir = scratch("align-finetune");
    let out = tadslc(&["finetune", path(&dir.join("missing.jsonl")), "-o", path(&dir.join("a"))], "");
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("missing.jsonl"), "{}", stderr(&out));
    // a directory without examples says which files it was looked in for
    let out = tadslc(&["finetune", path(&dir), "-o", path(&dir.join("a"))], "");
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("`messages.jsonl`, `prompt_completion.jsonl`, `train.jsonl`"), "{}", stderr(&out));
    std::fs::write(dir.join("data.jsonl"), "{\"messages\": []}\n").unwrap();
    let out =
        tadslc(&["finetune", path(&dir.join("data.jsonl")), "-o", path(&dir.join("a")), "--targets", "q,wrong"], "");
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("wrong"), "{}", stderr(&out));
    // an adapter directory that is not one: an error before any model is loaded
    let adapter = dir.join("not-an-adapter");
    std::fs::create_dir_all(&adapter).unwrap();
    std::fs::write(adapter.join("adapter_config.json"), "{ nonsense").unwrap();
    let out = tadslc(&["gen", "--region", "yellowstone", "--tuned", "--adapter", path(&adapter), "-n", "1"], "");
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("adapter_config.json"), "{}", stderr(&out));
    // so is one to train further, whether or not the model is installed
    let out =
        tadslc(&["finetune", path(&dir.join("data.jsonl")), "-o", path(&dir.join("a")), "--from", path(&adapter)], "");
    assert_eq!(code(&out), 2, "{}", stderr(&out));
    assert!(stderr(&out).contains("adapter_config.json"), "{}", stderr(&out));
}
