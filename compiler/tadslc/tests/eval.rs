//! The evaluation harness from the command line: `search` (scenes written with fixed
//! parameters, ranges moving towards collisions), `eval` (the table's shape in every format,
//! determinism), `--shard` with `merge` (the same table as one run), `run --shard --out`.

mod common;
use common::*;

use std::path::Path;

use serde_json::Value;

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn lines(text: &str) -> Vec<Value> {
    text.lines().map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}"))).collect()
}

#[test]
fn search_writes_fixed_scenes_that_reproduce_and_moves_ranges_to_collisions() {
    let dir = scratch("eval-search");
    let input = dir.join("slow_lead.tad");
    std::fs::copy(tad_test_support::repo().join("tests/eval/slow_lead.tad"), &input).unwrap();
    let out_dir = dir.join("adv");
    let out = tadslc(&["search", path(&input), "--ego", "naive", "-o", path(&out_dir), "--seed", "4"], "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(stdout(&out).contains("slow_lead"), "{}", stdout(&out));
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("search.json")).unwrap()).unwrap();
    let scenario = &summary["scenarios"][0];
    let rates: Vec<f64> = scenario["collision_rates"].as_array().unwrap().iter().map(|r| r.as_f64().unwrap()).collect();
    assert_eq!(rates.len(), 5);
    assert!(rates[4] > rates[0], "later rounds collide more: {rates:?}");
    let chosen = scenario["chosen"].as_array().unwrap();
    assert_eq!(chosen.len(), 2);
    for c in chosen {
        assert_eq!(c["collision"], true, "{c}");
        assert_eq!(c["reproduced"], true, "{c}");
        let written = out_dir.join(c["file"].as_str().unwrap());
        let text = std::fs::read_to_string(&written).unwrap();
        assert!(text.starts_with("// tadslc search: scene "), "{text}");
        assert!(!text.contains(".."), "every parameter fixed:\n{text}");
        let check = tadslc(&["check", path(&written)], "");
        assert_eq!(code(&check), 0, "{}", stderr(&check));
    }
    // the same seed writes the same scenes
    let again = dir.join("again");
    let out = tadslc(&["search", path(&input), "--ego", "naive", "-o", path(&again), "--seed", "4"], "");
    assert_eq!(code(&out), 0);
    for name in ["slow_lead.adv1.tad", "slow_lead.adv2.tad"] {
        assert_eq!(std::fs::read(out_dir.join(name)).unwrap(), std::fs::read(again.join(name)).unwrap());
    }
}

#[test]
fn search_usage_errors() {
    let dir = scratch("eval-search-usage");
    let out = tadslc(&["search", "examples/safety", "--ego", "reckless", "-o", path(&dir)], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("unknown policy `reckless`"), "{}", stderr(&out));
    let out = tadslc(&["search", "examples/safety", "--shard", "2/2", "-o", path(&dir)], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("is not a shard"), "{}", stderr(&out));
}

#[test]
fn eval_prints_the_table_in_every_format_deterministically() {
    let args = ["eval", "examples", "--region", "los_angeles,new_york_city", "-n", "3", "--samples", "20"];
    let out = tadslc(&[&args[..], &["--format", "json"]].concat(), "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let rows = lines(&stdout(&out));
    // 2 regions × 3 generators × 5 egos (the shipped ppo, sac, td3, then idm and naive)
    assert_eq!(rows.len(), 30, "{}", stdout(&out));
    for row in &rows {
        for key in ["CR", "RR", "SS", "OR", "RF", "Comp", "TS", "ACC", "YV", "LI", "OS"] {
            assert!(row["metrics"].get(key).is_some(), "{key} in {row}");
        }
        let os = row["OS"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&os), "{row}");
        assert!(row["episodes"].as_u64().unwrap() >= 1);
    }
    let pairs: Vec<(String, String, String)> =
        rows.iter().map(|r| (r["region"].to_string(), r["generator"].to_string(), r["ego"].to_string())).collect();
    assert_eq!(pairs[0], ("\"los_angeles\"".into(), "\"chatscene\"".into(), "\"ppo\"".into()));
    assert_eq!(pairs[3], ("\"los_angeles\"".into(), "\"chatscene\"".into(), "\"idm\"".into()));
    assert_eq!(pairs[5], ("\"los_angeles\"".into(), "\"fitted\"".into(), "\"ppo\"".into()));
    assert_eq!(pairs[29], ("\"new_york_city\"".into(), "\"baseline\"".into(), "\"naive\"".into()));
    // the naive ego, blind to everything, collides at least as often as IDM overall
    let collisions = |ego: &str| -> f64 {
        rows.iter().filter(|r| r["ego"] == ego).map(|r| r["metrics"]["CR"].as_f64().unwrap()).sum()
    };
    assert!(collisions("naive") >= collisions("idm"), "{}", stdout(&out));
    let again = tadslc(&[&args[..], &["--format", "json"]].concat(), "");
    assert_eq!(stdout(&out), stdout(&again), "seeded: the same table twice");

    let dir = scratch("eval-table");
    let plot = dir.join("os.svg");
    let md = tadslc(&[&args[..], &["--plot", path(&plot)]].concat(), "");
    let table = stdout(&md);
    assert!(
        table.starts_with(
            "| region | generator | ego | scenes | CR | RR | SS | OR | RF | Comp | TS | ACC | YV | LI | OS |"
        ),
        "{table}"
    );
    assert_eq!(
        table.lines().filter(|l| l.starts_with("| los_angeles") || l.starts_with("| new_york_city")).count(),
        30
    );
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("los_angeles · fitted") && svg.contains("naive"), "{svg}");
    let csv = stdout(&tadslc(&[&args[..], &["--format", "csv"]].concat(), ""));
    assert_eq!(csv.lines().next(), Some("region,generator,ego,scenarios,episodes,CR,RR,SS,OR,RF,Comp,TS,ACC,YV,LI,OS"));
    assert_eq!(csv.lines().count(), 31);
}

#[test]
fn a_killed_run_resumes_from_its_journal_and_ends_as_an_unbroken_one() {
    let dir = scratch("eval-resume");
    let args = ["eval", "examples", "--region", "los_angeles", "-n", "3", "--samples", "10", "--format", "csv"];
    let whole = tadslc(&[&args[..], &["--out", path(&dir)]].concat(), "");
    assert_eq!(code(&whole), 0, "{}", stderr(&whole));
    assert!(!stderr(&whole).contains("resumed"), "{}", stderr(&whole));
    let results = std::fs::read(dir.join("results.json")).unwrap();
    // the kill: the results file never written, two units in the journal, a third cut short
    let journal = dir.join("results.jsonl");
    let text = std::fs::read_to_string(&journal).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let units = lines.len() - 1;
    assert!(units >= 4, "a head, then a line per scenario run: {text}");
    std::fs::write(&journal, format!("{}\n{}\n{}\n{}", lines[0], lines[1], lines[2], &lines[3][..20])).unwrap();
    std::fs::remove_file(dir.join("results.json")).unwrap();
    let again = tadslc(&[&args[..], &["--out", path(&dir)]].concat(), "");
    assert_eq!(code(&again), 0, "{}", stderr(&again));
    assert!(stderr(&again).contains(&format!("resumed 2 of {units} scenarios from")), "{}", stderr(&again));
    assert_eq!(stdout(&again), stdout(&whole), "the resumed run's table is the unbroken run's");
    assert_eq!(std::fs::read(dir.join("results.json")).unwrap(), results, "and so is its results file");
    assert_eq!(std::fs::read_to_string(&journal).unwrap().lines().count(), 1 + units, "the cut line was replaced");
    // another command's journal is not resumed from
    let other =
        tadslc(&["eval", "examples", "--region", "los_angeles", "-n", "2", "--samples", "10", "--out", path(&dir)], "");
    assert_eq!(code(&other), 0, "{}", stderr(&other));
    assert!(!stderr(&other).contains("resumed"), "{}", stderr(&other));
}

#[test]
fn shards_merge_into_the_table_of_one_run() {
    let dir = scratch("eval-shards");
    // JSON carries every bit of the aggregates: the shards' sums must be the whole run's
    let args = ["eval", "examples", "--region", "los_angeles", "-n", "3", "--samples", "10", "--format", "json"];
    let whole = tadslc(&[&args[..], &["--out", path(&dir.join("whole"))]].concat(), "");
    assert_eq!(code(&whole), 0, "{}", stderr(&whole));
    let mut files = Vec::new();
    for i in 0..3 {
        let shard = format!("{i}/3");
        let out = tadslc(&[&args[..], &["--shard", &shard, "--out", path(&dir)]].concat(), "");
        assert_eq!(code(&out), 0, "{}", stderr(&out));
        files.push(dir.join(format!("results.{i}-of-3.json")));
    }
    let names: Vec<&str> = files.iter().map(|f| path(f)).collect();
    let merged = tadslc(&[&["merge"][..], &names, &["--format", "json"]].concat(), "");
    assert_eq!(code(&merged), 0, "{}", stderr(&merged));
    assert_eq!(stdout(&merged), stdout(&whole), "the shards' table is the whole run's");
    let reversed: Vec<&str> = names.iter().rev().copied().collect();
    let backwards = tadslc(&[&["merge"][..], &reversed, &["--format", "json"]].concat(), "");
    assert_eq!(stdout(&backwards), stdout(&whole), "in any order of the files");
    // a missing shard is a warning and status 1; a repeated one, or another command's, an error
    let part = tadslc(&["merge", names[0], names[1]], "");
    assert_eq!(code(&part), 1);
    assert!(stderr(&part).contains("shards 2/3 are missing"), "{}", stderr(&part));
    let twice = tadslc(&["merge", names[0], names[0]], "");
    assert_eq!(code(&twice), 2);
    let other = tadslc(
        &[
            "eval",
            "examples",
            "--region",
            "los_angeles",
            "-n",
            "2",
            "--samples",
            "10",
            "--out",
            path(&dir.join("other")),
        ],
        "",
    );
    assert_eq!(code(&other), 0);
    let mixed = tadslc(&["merge", names[0], path(&dir.join("other/results.json"))], "");
    assert_eq!(code(&mixed), 2);
    assert!(stderr(&mixed).contains("comes from another command"), "{}", stderr(&mixed));
    std::fs::write(dir.join("bad.json"), "{}").unwrap();
    let bad = tadslc(&["merge", path(&dir.join("bad.json"))], "");
    assert_eq!(code(&bad), 2);
    assert!(stderr(&bad).contains("not a results file"), "{}", stderr(&bad));
}

#[test]
fn run_shards_write_results_that_merge() {
    let dir = scratch("run-shards");
    for i in 0..2 {
        let shard = format!("{i}/2");
        let out = tadslc(&["run", "examples/safety", "--seeds", "0..2", "--shard", &shard, "--out", path(&dir)], "");
        assert_eq!(code(&out), 0, "{}", stderr(&out));
    }
    let merged = tadslc(
        &["merge", path(&dir.join("results.0-of-2.json")), path(&dir.join("results.1-of-2.json")), "--format", "json"],
        "",
    );
    assert_eq!(code(&merged), 0, "{}", stderr(&merged));
    let rows = lines(&stdout(&merged));
    assert_eq!(rows.len(), 2);
    // 8 safety scenarios × 2 seeds per ego
    assert!(rows.iter().all(|r| r["episodes"] == 16), "{}", stdout(&merged));
    // the directory `--out` wrote merges, into the per-scenario table of the unsharded run
    let whole = tadslc(&["run", "examples/safety", "--seeds", "0..2"], "");
    assert_eq!(code(&whole), 0, "{}", stderr(&whole));
    let merged = tadslc(&["merge", path(&dir)], "");
    assert_eq!(code(&merged), 0, "{}", stderr(&merged));
    assert_eq!(stdout(&merged), stdout(&whole), "the shards' table is the whole run's, row for row");
    assert!(stdout(&merged).lines().filter(|l| l.contains(" idm ")).count() > 8, "{}", stdout(&merged));
    let empty = scratch("run-shards-empty");
    let out = tadslc(&["merge", path(&empty)], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("no results files in"), "{}", stderr(&out));
}

#[test]
fn eval_usage_errors() {
    let out = tadslc(&["eval", "examples", "--generators", "nowhere/"], "");
    assert_eq!(code(&out), 2);
    assert!(
        stderr(&out)
            .contains("is not `chatscene`, `fitted`, `baseline`, `llm`, `llm-baseline`, `llm-tuned` or a directory"),
        "{}",
        stderr(&out)
    );
    let dir = scratch("eval-no-region");
    std::fs::copy(tad_test_support::repo().join("tests/eval/slow_lead.tad"), dir.join("slow_lead.tad")).unwrap();
    let out = tadslc(&["eval", path(&dir)], "");
    assert_eq!(code(&out), 2);
    assert!(stderr(&out).contains("no region with 3 scenarios or more"), "{}", stderr(&out));
}

#[test]
fn train_ego_splits_checkpoints_resumes_and_drives() {
    let dir = scratch("train-ego");
    let out = dir.join("ego.safetensors");
    // the safety scenes' episodes are short (about 9 steps with an untrained actor): learning
    // starts within the first two episodes
    let small = ["--hidden", "16,16", "--batch", "32", "--start-training", "10", "--updates-per-episode", "2"];
    let args = |episodes: &str, extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> =
            ["train-ego", "examples/safety", "-o", path(&out), "--split", "--episodes", episodes, "--every", "2"]
                .iter()
                .map(|s| s.to_string())
                .collect();
        a.extend(small.iter().chain(extra).map(|s| s.to_string()));
        a
    };
    let run = |a: Vec<String>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        tadslc(&refs, "")
    };
    let first = run(args("4", &[]));
    assert_eq!(code(&first), 0, "{}", stderr(&first));
    assert!(stderr(&first).contains("episode 4/4: return"), "{}", stderr(&first));
    assert!(stdout(&first).contains("on the held-out scenarios"), "{}", stdout(&first));
    let split: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("ego.safetensors.split.json")).unwrap()).unwrap();
    let (train, test) = (split["train"].as_array().unwrap().len(), split["test"].as_array().unwrap().len());
    assert_eq!(train + test, 8);
    assert!(test >= 1 && train > test, "3/5 of each behaviour trains: {split}");
    let whole = std::fs::read(&out).unwrap();
    // 2 episodes, then a resume to 4, gives the same actor
    std::fs::remove_dir_all(dir.join("ego.safetensors.ckpt")).unwrap();
    assert_eq!(code(&run(args("2", &[]))), 0);
    let resumed = run(args("4", &["--resume"]));
    assert_eq!(code(&resumed), 0, "{}", stderr(&resumed));
    assert!(stderr(&resumed).contains("resumed from"), "{}", stderr(&resumed));
    assert_eq!(std::fs::read(&out).unwrap(), whole, "a resumed run is the unbroken one");
    // the actor drives in the runtime
    let ego = format!("learned:{}", path(&out));
    let drive = tadslc(&["run", "examples/safety/straight_obstacle.tad", "--ego", &ego, "--seeds", "0"], "");
    assert_eq!(code(&drive), 0, "{}", stderr(&drive));
    assert!(stdout(&drive).contains("ego.safetensors"), "{}", stdout(&drive));
    // a different seed cannot resume this checkpoint; bad settings are usage errors
    let other = run(args("6", &["--resume", "--seed", "9"]));
    assert_eq!(code(&other), 2);
    assert!(stderr(&other).contains("another seed"), "{}", stderr(&other));
    let bad = run(args("4", &["--lr", "-1"]));
    assert_eq!(code(&bad), 2);
}

#[test]
fn a_training_run_that_cannot_learn_is_refused_and_one_that_did_not_is_an_error() {
    let dir = scratch("train-ego-nothing");
    let out = dir.join("ego.safetensors");
    let train = |episodes: &str, start: &str| {
        let args = ["train-ego", "examples/safety", "-o", path(&out), "--episodes", episodes, "--hidden", "16,16"];
        tadslc(&[&args[..], &["--start-training", start]].concat(), "")
    };
    // 2 episodes of at most 300 steps cannot store 1,000 transitions: refused before work
    let refused = train("2", "1000");
    assert_eq!(code(&refused), 2, "{}", stderr(&refused));
    assert!(stderr(&refused).contains("at least 4 episodes are needed"), "{}", stderr(&refused));
    assert!(!dir.join("ego.safetensors.ckpt").exists(), "nothing ran");
    // 2 episodes might, but these end early: an error, no actor written, the checkpoint kept
    let short = train("2", "590");
    assert_eq!(code(&short), 1, "{}", stderr(&short));
    assert!(stderr(&short).contains("no learning step was taken"), "{}", stderr(&short));
    assert!(!out.exists(), "an untrained actor is not written");
    assert!(dir.join("ego.safetensors.ckpt").exists());
}

#[test]
fn eval_adds_the_after_fine_tuning_table_when_asked() {
    let dir = scratch("eval-finetune");
    let args = [
        "eval",
        "examples",
        "--region",
        "los_angeles,new_york_city",
        "-n",
        "4",
        "--samples",
        "10",
        "--finetune",
        "6",
        "--format",
        "json",
        "--out",
        path(&dir),
    ];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let rows = lines(&stdout(&out));
    let held: Vec<&Value> = rows.iter().filter(|r| r["region"] == "held-out").collect();
    let egos: Vec<&str> = held.iter().map(|r| r["ego"].as_str().unwrap()).collect();
    // each shipped model, then itself fine-tuned on each generator's scenes; idm and naive.
    // Six episodes store too few transitions to learn on most generators' (short) scenes:
    // such a run is said in a warning and its row is not called fine-tuned
    let mut expected = Vec::new();
    let mut learned = 0;
    for model in ["ppo", "sac", "td3"] {
        expected.push(model.to_string());
        for generator in ["chatscene", "fitted", "baseline"] {
            let warned = format!("`{model} (fine-tuned on {generator})` took no learning step");
            if stderr(&out).contains(&warned) {
                expected.push(format!("{model} (no learning step on {generator})"));
            } else {
                expected.push(format!("{model} (fine-tuned on {generator})"));
                learned += 1;
            }
        }
    }
    expected.extend(["idm".to_string(), "naive".to_string()]);
    assert_eq!(egos, expected, "{}", stdout(&out));
    assert!(learned > 0, "some fine-tuning learns: {}", stderr(&out));
    kept_actors_are_the_best_and_the_start_drives_as_before(&stderr(&out), &held);
    // the held-out scenes are 2/5 of the kept ones, the same for every ego
    let kept: u64 = rows
        .iter()
        .filter(|r| r["region"] != "held-out" && r["ego"] == "idm")
        .map(|r| r["episodes"].as_u64().unwrap())
        .sum();
    let test = held[0]["episodes"].as_u64().unwrap();
    assert!(held.iter().all(|r| r["episodes"] == test));
    assert!(test * 5 >= kept && test * 5 <= kept * 3, "{test} held out of {kept}");
    // each model's change, with intervals that hold the value
    let changes: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("finetune-changes.json")).unwrap()).unwrap();
    let changes = changes.as_array().unwrap();
    assert_eq!(changes.len(), 9, "{changes:?}");
    for c in changes {
        for key in ["cr_before", "cr_after", "os_before", "os_after", "cr_points"] {
            let (v, lo, hi) =
                (c[key]["value"].as_f64().unwrap(), c[key]["low"].as_f64().unwrap(), c[key]["high"].as_f64().unwrap());
            assert!(lo <= v + 1e-9 && v <= hi + 1e-9, "{key}: {c}");
        }
        assert_eq!(c["scenes"].as_u64(), Some(test));
    }
    assert!(stderr(&out).contains("held-out collision rate of ppo"), "{}", stderr(&out));
    // seeded: the same tables again
    let again = tadslc(&args[..args.len() - 2], "");
    assert_eq!(stdout(&out), stdout(&again), "the fine-tuning table is deterministic");
    let actor = dir.join("finetuned").join("td3-fine-tuned-on-baseline.safetensors");
    let driven = tadslc(
        &["run", "examples/safety/right_turn.tad", "--ego", &format!("learned:{}", path(&actor)), "--seeds", "0"],
        "",
    );
    assert_eq!(code(&driven), 0, "{}", stderr(&driven));
    // from a train-ego checkpoint: one `learned` ego, before and after
    let pre = dir.join("pre.safetensors");
    let trained = tadslc(
        &[
            "train-ego",
            "examples/safety",
            "-o",
            path(&pre),
            "--episodes",
            "2",
            "--hidden",
            "16,16",
            "--batch",
            "32",
            "--start-training",
            "50",
        ],
        "",
    );
    assert_eq!(code(&trained), 0, "{}", stderr(&trained));
    let ckpt = dir.join("pre.safetensors.ckpt");
    let args = [
        "eval",
        "examples",
        "--region",
        "los_angeles",
        "-n",
        "3",
        "--samples",
        "5",
        "--generators",
        "fitted",
        "--egos",
        "idm,naive",
        "--search-ego",
        "idm",
        "--finetune",
        "2",
        "--format",
        "json",
        "--finetune-from",
        path(&ckpt),
    ];
    let out = tadslc(&args, "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let rows = lines(&stdout(&out));
    let egos: Vec<&str> =
        rows.iter().filter(|r| r["region"] == "held-out").map(|r| r["ego"].as_str().unwrap()).collect();
    assert_eq!(egos, ["learned (before)", "learned (fine-tuned on fitted)", "idm", "naive"], "{}", stdout(&out));
    assert!(stderr(&out).contains("held-out collision rate of learned (before)"), "{}", stderr(&out));
    let sharded = tadslc(&["eval", "examples", "--finetune", "5", "--shard", "0/2"], "");
    assert_eq!(code(&sharded), 2);
    assert!(stderr(&sharded).contains("without --shard"), "{}", stderr(&sharded));
}

/// Each tuned run's line: the actor kept is the best scored on its training scenes, from
/// the start (episode 0, then it drives as before) or the end (episode 6).
fn kept_actors_are_the_best_and_the_start_drives_as_before(stderr: &str, held: &[&Value]) {
    let row = |ego: &str| held.iter().find(|r| r["ego"] == ego).map(|r| r["metrics"].clone());
    for model in ["ppo", "sac", "td3"] {
        for generator in ["chatscene", "fitted", "baseline"] {
            let tuned = format!("{model} (fine-tuned on {generator})");
            let Some(line) = stderr.lines().find(|l| l.starts_with(&format!("`{tuned}`: kept"))).map(String::from)
            else {
                continue;
            };
            let number = |after: &str| -> f64 {
                let rest = &line[line.find(after).unwrap_or_else(|| panic!("{line}")) + after.len()..];
                rest.split(|c: char| !(c.is_ascii_digit() || c == '.')).next().unwrap().parse().unwrap()
            };
            let (at, kept, start) = (number("episode "), number("(OS "), number("; OS "));
            // the kept actor's route first, the start's last
            let routes: Vec<f64> =
                line.split(", route ").skip(1).map(|r| r.split(' ').next().unwrap().parse().unwrap()).collect();
            assert!(kept >= start, "the kept actor scores no worse than the start: {line}");
            assert!(routes[0] >= 0.9 * routes[1], "the kept actor drives its routes about as far: {line}");
            match at as usize {
                0 => assert_eq!(row(&tuned), row(model), "the start kept drives as before: {line}"),
                6 => {}
                _ => panic!("kept at neither end: {line}"),
            }
        }
    }
}

#[test]
fn eval_and_gen_work_from_any_directory_on_their_embedded_defaults() {
    // run from a directory with no examples/ in it, as an installed tadslc is
    let elsewhere = scratch("eval-elsewhere");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_tadslc"))
            .args(args)
            .current_dir(&elsewhere)
            .output()
            .expect("tadslc runs")
    };
    let small = ["--region", "los_angeles", "-n", "2", "--samples", "5", "--format", "csv"];
    let there = run(&[&["eval"][..], &small].concat());
    assert_eq!(code(&there), 0, "{}", stderr(&there));
    let here = tadslc(&[&["eval", "examples"][..], &small].concat(), "");
    assert_eq!(stdout(&there), stdout(&here), "the embedded examples are the repository's");
    let model = elsewhere.join("la.model");
    let fit = tadslc(&["fit", "examples", "-o", path(&model)], "");
    assert_eq!(code(&fit), 0, "{}", stderr(&fit));
    let generated = run(&["gen", "--generator", &format!("fitted:{}", path(&model)), "-n", "2"]);
    assert_eq!(code(&generated), 0, "{}", stderr(&generated));
    assert!(stdout(&generated).contains("scenario "), "{}", stdout(&generated));
}

/// The files of `dir` (not its journals), with their contents, sorted.
fn written(dir: &Path) -> Vec<(String, String)> {
    let mut files: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| !name.ends_with(".jsonl"))
        .map(|name| {
            let text = std::fs::read_to_string(dir.join(&name)).unwrap();
            // the wall time is the one line that differs between runs
            let text = text.lines().filter(|l| !l.contains("\"seconds\"")).collect::<Vec<_>>().join("\n");
            (name, text)
        })
        .collect();
    files.sort();
    files
}

#[test]
fn an_interrupted_search_keeps_what_finished_and_a_rerun_resumes_it() {
    let dir = scratch("search-interrupt");
    let (broken, whole) = (dir.join("broken"), dir.join("whole"));
    let args = |out: &Path| -> Vec<String> {
        ["search", "examples/safety", "--samples", "600", "-o", path(out)].iter().map(|a| a.to_string()).collect()
    };
    let first = args(&broken);
    let first: Vec<&str> = first.iter().map(String::as_str).collect();
    let out = interrupted_once(&first, &broken.join("search.jsonl"), 2);
    assert_eq!(code(&out), 1, "{}", stderr(&out));
    assert!(stderr(&out).contains("run the same command again"), "{}", stderr(&out));
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(broken.join("search.json")).unwrap()).unwrap();
    assert_eq!(summary["interrupted"], true);
    let finished = summary["scenarios"].as_array().unwrap().len();
    assert!((1..8).contains(&finished), "{finished} of 8 searched before the interrupt");
    // the same command again searches the rest, and writes what an unbroken run writes
    let again = tadslc(&first, "");
    assert_eq!(code(&again), 0, "{}", stderr(&again));
    assert!(stderr(&again).contains(&format!("resumed {finished} of 8 scenarios")), "{}", stderr(&again));
    assert!(!broken.join("search.jsonl").exists(), "a whole run leaves no journal");
    let unbroken = args(&whole);
    let unbroken = tadslc(&unbroken.iter().map(String::as_str).collect::<Vec<_>>(), "");
    assert_eq!(code(&unbroken), 0, "{}", stderr(&unbroken));
    assert_eq!(stdout(&again), stdout(&unbroken));
    assert_eq!(written(&broken), written(&whole));
    // a finished run's directory is refused again, as before
    assert_eq!(code(&tadslc(&first, "")), 2);
}

#[test]
fn an_interrupted_eval_keeps_what_finished_and_a_rerun_resumes_it() {
    let dir = scratch("eval-interrupt");
    let (broken, whole) = (dir.join("broken"), dir.join("whole"));
    let args = |out: &Path| -> Vec<String> {
        ["eval", "examples", "--region", "los_angeles", "-n", "3", "--samples", "200", "--out", path(out)]
            .iter()
            .map(|a| a.to_string())
            .collect()
    };
    let first = args(&broken);
    let first: Vec<&str> = first.iter().map(String::as_str).collect();
    let out = interrupted_once(&first, &broken.join("results.jsonl"), 2);
    assert_eq!(code(&out), 1, "{}", stderr(&out));
    assert!(stderr(&out).contains("run the same command again"), "{}", stderr(&out));
    assert!(!broken.join("results.json").exists(), "no results file for part of the work");
    let again = tadslc(&first, "");
    assert_eq!(code(&again), 0, "{}", stderr(&again));
    assert!(stderr(&again).contains("resumed"), "{}", stderr(&again));
    let unbroken = args(&whole);
    let unbroken = tadslc(&unbroken.iter().map(String::as_str).collect::<Vec<_>>(), "");
    assert_eq!(stdout(&again), stdout(&unbroken), "the resumed table is the unbroken run's");
    assert_eq!(
        std::fs::read_to_string(broken.join("results.json")).unwrap(),
        std::fs::read_to_string(whole.join("results.json")).unwrap()
    );
}
