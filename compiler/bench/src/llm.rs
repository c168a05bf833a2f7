//! `bench --llm`: the local model (`tad-local`, candle) against llama.cpp's
//! `llama-server` on the same GGUF file, the same prompt tokens and the same thread count,
//! one after the other in one run.
//!
//! - prefill: tokens/s reading each translate prompt whole (no cached prefix on either side);
//! - decode: tokens/s writing the answer greedily, unconstrained, then constrained to TAD's
//!   grammar (the local model masks with llguidance to the Lark form, llama-server samples
//!   with the GBNF form; both printed by `tad-grammar` from the same rules);
//! - the constraint's cost: the local model's mask time per token, and each side's
//!   constrained time per token over its unconstrained one;
//! - memory: each process's peak resident set (`VmHWM`), the weights included.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tad_llm::{Constraint, Request};
use tad_local::Engine;

use crate::{BenchError, Report, proc_status_kib};

/// What `bench --llm` measures.
pub struct LlmArgs {
    /// llama.cpp's server for the peer (else `TADSL_LLAMA_SERVER`, unless empty; without one the peer is
    /// skipped).
    pub llama_server: Option<PathBuf>,
    pub threads: usize,
    pub prompts: usize,
    pub max_tokens: u32,
    pub descriptions: PathBuf,
    /// The local model (a name of `tad_local::model`; default: the embedded one).
    pub model: Option<String>,
}

/// One side's totals.
#[derive(Default, Clone, Copy)]
struct Side {
    prefill_tokens: f64,
    prefill_s: f64,
    decode_tokens: f64,
    decode_s: f64,
    constrained_tokens: f64,
    constrained_s: f64,
    /// Of the constrained tokens, those the grammar forced (the local model only).
    forced_tokens: f64,
    /// llguidance's masks (the local model only).
    mask_s: f64,
    peak_kib: Option<u64>,
}

impl Side {
    fn prefill(&self) -> f64 {
        self.prefill_tokens / self.prefill_s.max(1e-9)
    }
    fn decode(&self) -> f64 {
        self.decode_tokens / self.decode_s.max(1e-9)
    }
    fn constrained(&self) -> f64 {
        self.constrained_tokens / self.constrained_s.max(1e-9)
    }
}

fn requests(args: &LlmArgs) -> Result<(Vec<Request>, String, String), String> {
    let mut files = tad_db::host::with_extension(&args.descriptions, "txt");
    files.sort();
    if files.is_empty() {
        return Err(format!(
            "no descriptions (*.txt) in `{}`: pass --descriptions DIR (the repository's tests/llm/descriptions)",
            args.descriptions.display()
        ));
    }
    let checker = tad_frontend::Checker::default();
    let (vocabulary, modules) = tad_grammar::scope(None)?;
    let lark = tad_grammar::export(tad_grammar::Format::Lark, &vocabulary, &modules, "TAD");
    let gbnf = tad_grammar::export(tad_grammar::Format::Gbnf, &vocabulary, &modules, "TAD");
    let mut out = Vec::new();
    for path in files.iter().take(args.prompts.max(1)) {
        let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
        let mut request = Request::new(tad_frontend::translate_messages(text.trim(), &checker));
        request.max_tokens = args.max_tokens;
        request.temperature = 0.0;
        request.seed = Some(0);
        out.push(request);
    }
    Ok((out, lark, gbnf))
}

/// `bench --llm`: the local model, then llama-server, on the chosen model's GGUF; what
/// each side is about to do goes to `progress` as it starts.
pub fn run(args: &LlmArgs, progress: &mut dyn FnMut(&str)) -> Result<Report, BenchError> {
    let name = args.model.as_deref().unwrap_or(tad_local::DEFAULT);
    let model = tad_local::model(name).ok_or_else(|| BenchError(format!("no local model named {name}")))?;
    let gguf = model.require()?;
    let (requests, lark, gbnf) = requests(args)?;
    progress(&format!(
        "bench --llm: {} prompts, answers of at most {} tokens, {} thread{}, `{}`",
        requests.len(),
        args.max_tokens,
        args.threads,
        if args.threads == 1 { "" } else { "s" },
        gguf.display()
    ));

    // a peer that cannot be started is found out before the local model's minutes are spent
    let server = args
        .llama_server
        .clone()
        .or_else(|| std::env::var_os("TADSL_LLAMA_SERVER").filter(|v| !v.is_empty()).map(PathBuf::from));
    if let Some(server) = server.as_ref().filter(|s| !s.is_file()) {
        return Err(BenchError(format!("no llama-server at `{}`", server.display())));
    }

    let (local, prompts, local_texts) = measure_local(&gguf, args.threads, &requests, &lark, progress)?;
    let peer = match server {
        Some(server) => Some(measure_server(&server, &gguf, args.threads, &prompts, args.max_tokens, &gbnf)?),
        None => {
            progress("no llama-server (--llama-server PATH or TADSL_LLAMA_SERVER): the peer is skipped");
            None
        }
    };
    let mut lines = table(&local, peer.as_ref().map(|(s, _)| s), &prompts);
    if let Some((_, texts)) = &peer {
        let same = local_texts.iter().zip(texts).filter(|(a, b)| a.trim() == b.trim()).count();
        lines.push(format!("greedy answers identical to llama-server's: {same}/{}", texts.len()));
    }
    Ok(Report { lines, ..Report::default() })
}

type Local = (Side, Vec<Vec<u32>>, Vec<String>);

fn measure_local(
    gguf: &Path,
    threads: usize,
    requests: &[Request],
    lark: &str,
    progress: &mut dyn FnMut(&str),
) -> Result<Local, String> {
    let mut engine = Engine::load(gguf, threads).map_err(|e| e.to_string())?;
    let (bytes, kernels) = engine.describe();
    progress(&format!("tad-local: {:.0} MiB of weights, {kernels} kernels", bytes as f64 / 1048576.0));
    // warm-up, not counted
    let mut warm = requests[0].clone();
    warm.max_tokens = 4;
    engine.generate(&warm).map_err(|e| e.to_string())?;
    // each request read whole: no cached system message
    let mut timed = |request: &Request| -> Result<(tad_local::Timing, String), String> {
        engine.forget_prefix();
        let before = engine.timing;
        let answer = engine.generate(request).map_err(|e| e.to_string())?;
        Ok((engine.timing.since(&before), answer.text))
    };

    let mut side = Side::default();
    let mut prompts = Vec::new();
    let mut texts = Vec::new();
    for request in requests {
        let (spent, text) = timed(request)?;
        side.prefill_tokens += spent.prefill_tokens as f64;
        side.prefill_s += spent.prefill_s;
        side.decode_tokens += spent.decode_tokens as f64;
        side.decode_s += spent.decode_s;
        texts.push(text);

        let mut constrained = request.clone();
        constrained.constraint = Constraint::Lark(lark.to_string());
        let (spent, _) = timed(&constrained)?;
        side.constrained_tokens += spent.decode_tokens as f64;
        side.constrained_s += spent.decode_s;
        side.forced_tokens += spent.forced_tokens as f64;
        side.mask_s += spent.mask_s;
    }
    for request in requests {
        prompts.push(engine.prompt_tokens(request).map_err(|e| e.to_string())?);
    }
    side.peak_kib = proc_status_kib("self", "VmHWM");
    Ok((side, prompts, texts))
}

/// llama-server on a free port, stopped when dropped.
struct Server {
    child: Child,
    port: u16,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn measure_server(
    binary: &Path,
    gguf: &Path,
    threads: usize,
    prompts: &[Vec<u32>],
    max_tokens: u32,
    gbnf: &str,
) -> Result<(Side, Vec<String>), String> {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map_err(|e| format!("no free port: {e}"))?
        .port();
    let threads = threads.max(1).to_string();
    let child = Command::new(binary)
        .args(["-m"])
        .arg(gguf)
        .args(["-t", &threads, "-tb", &threads, "-c", "4096", "-np", "1", "--host", "127.0.0.1", "--port"])
        .arg(port.to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("cannot start `{}`: {e}", binary.display()))?;
    let mut server = Server { child, port };
    let start = Instant::now();
    loop {
        if let Ok((200, _)) = http(server.port, "GET", "/health", None) {
            break;
        }
        if let Ok(Some(status)) = server.child.try_wait() {
            return Err(format!("llama-server exited before it was ready ({status})"));
        }
        if start.elapsed() > Duration::from_secs(120) {
            return Err("llama-server was not ready within 120 s".into());
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    let complete = |prompt: &[u32], tokens: u32, grammar: Option<&str>| -> Result<Value, String> {
        let mut body = json!({
            "prompt": prompt, "n_predict": tokens, "temperature": 0.0, "seed": 0, "cache_prompt": false,
        });
        if let Some(g) = grammar {
            body["grammar"] = json!(g);
        }
        match http(server.port, "POST", "/completion", Some(&body.to_string()))? {
            (200, text) => serde_json::from_str(&text).map_err(|e| format!("llama-server's answer is not JSON: {e}")),
            (code, text) => {
                Err(format!("llama-server answered {code}: {}", text.chars().take(300).collect::<String>()))
            }
        }
    };
    complete(&prompts[0], 4, None)?; // warm-up
    let number = |v: &Value, k: &str| v["timings"][k].as_f64().unwrap_or(0.0);
    let mut side = Side::default();
    let mut texts = Vec::new();
    for prompt in prompts {
        let answer = complete(prompt, max_tokens, None)?;
        side.prefill_tokens += number(&answer, "prompt_n");
        side.prefill_s += number(&answer, "prompt_ms") / 1e3;
        side.decode_tokens += number(&answer, "predicted_n");
        side.decode_s += number(&answer, "predicted_ms") / 1e3;
        texts.push(answer["content"].as_str().unwrap_or_default().to_string());
        let answer = complete(prompt, max_tokens, Some(gbnf))?;
        side.constrained_tokens += number(&answer, "predicted_n");
        side.constrained_s += number(&answer, "predicted_ms") / 1e3;
    }
    side.peak_kib = proc_status_kib(&server.child.id().to_string(), "VmHWM");
    drop(server);
    Ok((side, texts))
}

/// A plain HTTP/1.1 exchange with the local server: (status, body).
fn http(port: u16, method: &str, path: &str, body: Option<&str>) -> Result<(u16, String), String> {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).map_err(|e| e.to_string())?;
    stream.set_read_timeout(Some(Duration::from_secs(600))).map_err(|e| e.to_string())?;
    let body = body.unwrap_or("");
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes()).and_then(|_| stream.write_all(body.as_bytes())).map_err(|e| e.to_string())?;
    let mut raw = Vec::new();
    stream.read_to_end(&mut raw).map_err(|e| e.to_string())?;
    let text = String::from_utf8_lossy(&raw);
    let (head, rest) = text.split_once("\r\n\r\n").ok_or("a malformed HTTP answer")?;
    let code = head.split_whitespace().nth(1).and_then(|c| c.parse().ok()).ok_or("a malformed status line")?;
    let chunked = head.lines().any(|l| l.to_ascii_lowercase().starts_with("transfer-encoding: chunked"));
    Ok((code, if chunked { dechunk(rest) } else { rest.to_string() }))
}

fn dechunk(mut rest: &str) -> String {
    let mut out = String::new();
    while let Some((size, after)) = rest.split_once("\r\n") {
        let Ok(n) = usize::from_str_radix(size.trim(), 16) else { break };
        if n == 0 || after.len() < n {
            break;
        }
        out.push_str(&after[..n]);
        rest = after[n..].trim_start_matches("\r\n");
    }
    out
}

/// The report's lines: the prompts, then a row per measurement.
fn table(local: &Side, peer: Option<&Side>, prompts: &[Vec<u32>]) -> Vec<String> {
    let mean = prompts.iter().map(Vec::len).sum::<usize>() as f64 / prompts.len().max(1) as f64;
    let mut lines = vec![
        format!("prompts: {}, {mean:.0} tokens on average, read whole on both sides", prompts.len()),
        format!("{:<34} {:>12} {:>14} {:>9}", "", "tad-local", "llama-server", "ratio"),
    ];
    let row = |what: &str, a: f64, b: Option<f64>, digits: usize| match b {
        Some(b) => format!("{what:<34} {a:>12.digits$} {b:>14.digits$} {:>8.2}x", a / b.max(1e-12)),
        None => format!("{what:<34} {a:>12.digits$} {:>14} {:>9}", "-", "-"),
    };
    lines.push(row("prefill tokens/s", local.prefill(), peer.map(Side::prefill), 1));
    lines.push(row("decode tokens/s", local.decode(), peer.map(Side::decode), 1));
    lines.push(row("decode tokens/s, constrained", local.constrained(), peer.map(Side::constrained), 1));
    let slowdown = |s: &Side| s.decode() / s.constrained().max(1e-12);
    lines.push(row("constrained/unconstrained time", slowdown(local), peer.map(slowdown), 2));
    lines.push(format!(
        "{:<34} {:>12.2} {:>14} {:>9}",
        "mask ms/token (llguidance)",
        1e3 * local.mask_s / local.constrained_tokens.max(1.0),
        "-",
        "-"
    ));
    let mib = |s: &Side| s.peak_kib.map_or(f64::NAN, |k| k as f64 / 1024.0);
    lines.push(row("peak memory MiB", mib(local), peer.map(mib), 0));
    lines.push(format!(
        "tokens: prefill {:.0}, decode {:.0}, constrained {:.0} of which {:.0} forced (tad-local){}",
        local.prefill_tokens,
        local.decode_tokens,
        local.constrained_tokens,
        local.forced_tokens,
        peer.map(|p| format!(
            "; prefill {:.0}, decode {:.0}, constrained {:.0} (llama-server)",
            p.prefill_tokens, p.decode_tokens, p.constrained_tokens
        ))
        .unwrap_or_default()
    ));
    lines
}
