//! Measures training on the real model: `cargo run -p tad-finetune --example measure --
//! GGUF OUT [MAX_LEN] [EXAMPLES] [RANK]`. The examples are the repository's TAD files as
//! answers to "Write a TAD scenario for the region …" (also written to OUT/train.jsonl);
//! prints each step's loss and tokens/s, then the peak resident memory (VmHWM).

use std::path::PathBuf;

use tad_finetune::{Config, Example, Message};

fn vm_hwm() -> String {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .map(|l| l.split_whitespace().skip(1).collect::<Vec<_>>().join(" "))
        })
        .unwrap_or_else(|| "unknown".into())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let gguf = PathBuf::from(&args[1]);
    let out = PathBuf::from(&args[2]);
    let max_len: usize = args.get(3).map_or(512, |a| a.parse().unwrap());
    let count: usize = args.get(4).map_or(20, |a| a.parse().unwrap());
    let rank: usize = args.get(5).map_or(16, |a| a.parse().unwrap());
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut files = Vec::new();
    for dir in ["regions", "safety"] {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "tad"))
            .collect();
        entries.sort();
        files.extend(entries.into_iter().map(|p| (dir, p)));
    }
    let mut examples = Vec::new();
    for i in 0..count {
        let (dir, path) = &files[i % files.len()];
        let name = path.file_stem().unwrap().to_string_lossy().replace('_', " ");
        let ask = match (dir, i / files.len()) {
            (&"regions", 0) => format!("Write a TAD scenario for the region {name}."),
            (&"regions", _) => format!("Write a TAD scenario set in {name}."),
            (_, 0) => format!("Write a TAD scenario for the safety case {name}."),
            (_, _) => format!("Write a TAD scenario testing {name}."),
        };
        examples.push(Example {
            prompt: vec![
                Message { role: "system".into(), content: "You write traffic scenarios in TAD.".into() },
                Message { role: "user".into(), content: ask },
            ],
            completion: std::fs::read_to_string(path).unwrap(),
        });
    }
    std::fs::create_dir_all(&out).unwrap();
    let jsonl: Vec<String> = examples
        .iter()
        .map(|e| {
            let mut messages: Vec<serde_json::Value> =
                e.prompt.iter().map(|m| serde_json::json!({"role": m.role, "content": m.content})).collect();
            messages.push(serde_json::json!({"role": "assistant", "content": e.completion}));
            serde_json::json!({ "messages": messages }).to_string()
        })
        .collect();
    std::fs::write(out.join("train.jsonl"), jsonl.join("\n") + "\n").unwrap();
    let config = Config { rank, alpha: 2.0 * rank as f32, epochs: 1, max_len, seed: 0, ..Config::default() };
    eprintln!(
        "{} examples, rank {rank}, max_len {max_len}, all seven targets; after loading: VmHWM {}",
        examples.len(),
        vm_hwm()
    );
    let start = std::time::Instant::now();
    let report = tad_finetune::train(&gguf, &examples, &config, &out.join("adapter"), &mut |p| {
        eprintln!(
            "step {}/{} loss {:.4} tokens/s {:.1} ({:.0} s) VmHWM {}",
            p.step,
            p.steps,
            p.loss,
            p.tokens_per_s,
            start.elapsed().as_secs_f64(),
            vm_hwm()
        );
    })
    .unwrap();
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "steps {} tokens {} (answer {}) in {:.1} s: {:.1} tokens/s; losses {:?}; VmHWM {}",
        report.steps,
        report.tokens,
        report.answer_tokens,
        report.seconds,
        report.tokens_per_s,
        report.losses,
        vm_hwm()
    );
}
