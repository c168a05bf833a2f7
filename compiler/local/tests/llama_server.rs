//! An adapter as llama.cpp reads it: a seeded random LoRA adapter on each installed model
//! (SmolLM2-135M, llama; Qwen2.5-Coder-0.5B and 1.5B, qwen2) written as PEFT's files and as
//! `adapter.gguf`, then the next token's distribution after a prompt from this crate's
//! decoder with `--adapter` against `llama-server --lora adapter.gguf` on the same GGUF.
//! Runs with `TADSL_LLAMA_SERVER` (the binary); skips without it (CI's llama.cpp build is
//! opt-in, `TADSL_CI_LLAMA=1`).

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use tad_base::{Rng, SplitMix64};
use tad_local::{Adapter, Engine, Lora, Shape, Target};

/// A rank-4 adapter on every projection of every layer, drawn from `seed`: A as PEFT
/// initialises it, B large enough that the next token's distribution moves by 0.15–0.6
/// (much larger and Qwen's 24 layers amplify the two decoders' rounding apart).
fn random_adapter(shape: &Shape, seed: u64) -> Adapter {
    let mut rng = SplitMix64::new(seed);
    let rank = 4;
    let mut layers = BTreeMap::new();
    for layer in 0..shape.layers {
        for target in Target::ALL {
            let (inputs, outputs) = target.dims(shape);
            let mut draw = |n: usize, bound: f64| -> Vec<f32> {
                (0..n).map(|_| ((rng.unit() * 2.0 - 1.0) * bound) as f32).collect()
            };
            let a = draw(rank * inputs, 1.0 / (inputs as f64).sqrt());
            let b = draw(outputs * rank, 0.15);
            layers.insert((layer, target), Lora { a, b, inputs, outputs });
        }
    }
    Adapter {
        rank,
        alpha: 8.0,
        rslora: false,
        targets: Target::ALL.to_vec(),
        base_model: "test".into(),
        layers,
        base_prefix: Vec::new(),
    }
}

/// The probabilities of the whole vocabulary from logits.
fn softmax(logits: &[f32]) -> Vec<f64> {
    let max = logits.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let exp: Vec<f64> = logits.iter().map(|&l| f64::from(l - max).exp()).collect();
    let sum: f64 = exp.iter().sum();
    exp.iter().map(|e| e / sum).collect()
}

fn top(probs: &[f64], n: usize) -> Vec<(u32, f64)> {
    let mut order: Vec<(u32, f64)> = probs.iter().enumerate().map(|(i, &p)| (i as u32, p)).collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1));
    order.truncate(n);
    order
}

struct Server(Child, u16);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn serve(binary: &Path, model: &Path, lora: Option<&Path>) -> Server {
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let mut command = Command::new(binary);
    command.arg("-m").arg(model).args(["--host", "127.0.0.1", "--port", &port.to_string()]);
    command.args(["-c", "512", "-t", "1", "-np", "1", "--offline"]);
    if let Some(lora) = lora {
        command.arg("--lora").arg(lora);
    }
    let child = command.stdout(Stdio::null()).stderr(Stdio::null()).spawn().expect("llama-server starts");
    let server = Server(child, port);
    // the port answers once the model is loaded
    for _ in 0..300 {
        std::thread::sleep(std::time::Duration::from_millis(200));
        if request(port, "GET", "/health", "").is_some_and(|(status, _)| status == 200) {
            return server;
        }
    }
    panic!("llama-server did not come up on port {port}");
}

/// A plain HTTP/1.1 request; the status and the body.
fn request(port: u16, method: &str, path: &str, body: &str) -> Option<(u16, String)> {
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).ok()?;
    let request = format!(
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    stream.write_all(request.as_bytes()).ok()?;
    let mut response = String::new();
    stream.read_to_string(&mut response).ok()?;
    let (head, body) = response.split_once("\r\n\r\n")?;
    let status = head.split(' ').nth(1)?.parse().ok()?;
    Some((status, body.to_string()))
}

/// The server's ten most likely next tokens after `prompt`, with their probabilities.
fn server_top(server: &Server, prompt: &[u32]) -> Vec<(u32, f64)> {
    let body = serde_json::json!({
        "prompt": prompt, "n_predict": 1, "n_probs": 10, "temperature": 0.0, "cache_prompt": false,
        "post_sampling_probs": false
    });
    let (status, text) = request(server.1, "POST", "/completion", &body.to_string()).expect("an answer");
    assert_eq!(status, 200, "{text}");
    let value: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let first = &value["completion_probabilities"][0];
    let list = first["top_logprobs"].as_array().or_else(|| first["probs"].as_array()).expect("the top tokens");
    list.iter()
        .map(|t| {
            let id = t["id"].as_u64().or_else(|| t["tok"].as_u64()).expect("an id") as u32;
            let p = t["logprob"].as_f64().map(f64::exp).or_else(|| t["prob"].as_f64()).expect("a probability");
            (id, p)
        })
        .collect()
}

fn installed(name: &str) -> Option<PathBuf> {
    let path = tad_models::model(name)?.path();
    path.exists().then_some(path)
}

#[test]
fn llama_cpp_applies_the_adapters_gguf_as_the_decoder_does() {
    let Some(binary) = std::env::var_os("TADSL_LLAMA_SERVER").map(PathBuf::from) else {
        eprintln!("SKIPPED: set TADSL_LLAMA_SERVER to check adapter.gguf against llama.cpp");
        return;
    };
    let mut checked = 0;
    for name in ["smollm2-135m", "qwen2.5-coder-0.5b", "qwen2.5-coder-1.5b"] {
        let Some(model) = installed(name) else {
            eprintln!("{name}: not installed (tadslc model fetch {name}), skipped");
            continue;
        };
        let mut file = std::fs::File::open(&model).expect("the model reads");
        let content = candle_core::quantized::gguf_file::Content::read(&mut file).expect("a GGUF");
        let shape = Shape::from_gguf(&content).expect("its shape");
        let tokenizer = tad_local::tokenizer(&content).expect("its tokenizer");
        let (prompt, _) = tad_local::chatml(&tokenizer, &[("user", "Name a colour.")]).expect("tokens");
        let adapter = random_adapter(&shape, 7);
        let dir = tad_test_support::scratch(Path::new(env!("CARGO_TARGET_TMPDIR")), &format!("lora-gguf-{name}"));
        adapter.save(&dir).expect("PEFT's files");
        let gguf = dir.join(tad_local::GGUF_FILE);
        adapter.save_gguf(&gguf, &shape).expect("the GGUF");
        let reread = Adapter::load(&dir).expect("the adapter reads back");
        let mut tuned = Engine::load_with(&model, 1, Some(&reread)).expect("the model loads with it");

        let mut base = Engine::load(&model, 1).expect("the model loads");
        let (ours_base, ours_tuned) = (softmax(&base.logits(&prompt)), softmax(&tuned.logits(&prompt)));
        let theirs_tuned = server_top(&serve(&binary, &model, Some(&gguf)), &prompt);
        let theirs_base = server_top(&serve(&binary, &model, None), &prompt);
        eprintln!("{name}: base ours {:?} theirs {:?}", &top(&ours_base, 3), &theirs_base[..3]);
        eprintln!("{name}: tuned ours {:?} theirs {:?}", &top(&ours_tuned, 3), &theirs_tuned[..3]);

        // Over llama.cpp's ten likeliest tokens, the L1 distance between the two decoders
        // (its Q8 products against ours in f32: 0.03–0.07 without the adapter) stays far
        // under what the adapter moves.
        let apart = |ours: &[f64], theirs: &[(u32, f64)]| -> f64 {
            theirs.iter().map(|&(id, p)| (ours[id as usize] - p).abs()).sum()
        };
        let moved: f64 =
            theirs_tuned.iter().map(|&(id, _)| (ours_tuned[id as usize] - ours_base[id as usize]).abs()).sum();
        let (base_gap, tuned_gap) = (apart(&ours_base, &theirs_base), apart(&ours_tuned, &theirs_tuned));
        eprintln!(
            "{name}: the adapter moves {moved:.3}; the decoders differ by {base_gap:.3} (base), {tuned_gap:.3} (tuned)"
        );
        assert!(moved > 0.1, "{name}: the adapter barely changes the model ({moved:.3})");
        assert!(
            tuned_gap < 0.1 && tuned_gap < moved / 2.0,
            "{name}: llama.cpp applies another adapter (the decoders differ by {tuned_gap:.3}, the adapter moves {moved:.3})"
        );
        let _ = std::fs::remove_dir_all(&dir);
        checked += 1;
    }
    assert!(checked > 0 || std::env::var_os("TAD_REQUIRE_MODEL").is_none(), "no model installed");
}
