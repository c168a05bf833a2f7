//! `bench --lsp`: the language server as an editor feels it, over its real stdio
//! transport (`tadslc lsp`, a child process: the host names its `tadslc`), against peers
//! measured in the same run.
//!
//! - didChange → publishDiagnostics: a one-line edit of a 2,000-line file, waited for
//!   each time, p50/p99 over `samples` edits; the peers are checking that text from
//!   scratch in process (a fresh database: what reuse saves) and `tadslc check FILE` as a
//!   process (what an editor without a server runs on save).
//! - completion and hover at a value in the same file, p50/p99.
//! - memory: the server's resident set after `initialize`, then after opening every
//!   example and waiting for its diagnostics.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use serde_json::{Value, json};

use crate::{BenchError, Report, best_of, long_scenario, proc_status_kib};

struct Server<'p> {
    child: Child,
    input: ChildStdin,
    messages: mpsc::Receiver<Value>,
    next_id: i64,
    /// Where the messages go with `TADSL_BENCH_DEBUG` set.
    progress: &'p mut dyn FnMut(&str),
}

fn frame(message: &Value) -> Vec<u8> {
    let body = message.to_string();
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body.as_bytes());
    out
}

impl<'p> Server<'p> {
    fn start(exe: &Path, progress: &'p mut dyn FnMut(&str)) -> std::io::Result<Server<'p>> {
        let mut child =
            Command::new(exe).arg("lsp").stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::null()).spawn()?;
        let input = child.stdin.take().ok_or_else(|| std::io::Error::other("no stdin"))?;
        let output = child.stdout.take().ok_or_else(|| std::io::Error::other("no stdout"))?;
        let (send, messages) = mpsc::channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(output);
            loop {
                let mut length = None;
                loop {
                    let mut line = String::new();
                    if reader.read_line(&mut line).unwrap_or(0) == 0 {
                        return;
                    }
                    let line = line.trim();
                    if line.is_empty() {
                        break;
                    }
                    if let Some(v) = line.strip_prefix("Content-Length:") {
                        length = v.trim().parse::<usize>().ok();
                    }
                }
                let mut body = vec![0; length.unwrap_or(0)];
                if reader.read_exact(&mut body).is_err() {
                    return;
                }
                if let Ok(message) = serde_json::from_slice::<Value>(&body)
                    && send.send(message).is_err()
                {
                    return;
                }
            }
        });
        Ok(Server { child, input, messages, next_id: 1, progress })
    }

    fn send(&mut self, message: &Value) -> std::io::Result<()> {
        self.input.write_all(&frame(message))?;
        self.input.flush()
    }

    fn notify(&mut self, method: &str, params: Value) -> std::io::Result<()> {
        self.send(&json!({"jsonrpc": "2.0", "method": method, "params": params}))
    }

    /// The first message `pred` accepts (the server's own requests are answered).
    fn wait(&mut self, pred: impl Fn(&Value) -> bool) -> std::io::Result<Value> {
        loop {
            let message = self
                .messages
                .recv_timeout(Duration::from_secs(60))
                .map_err(|_| std::io::Error::other("the server stopped answering"))?;
            if message.get("method").is_some()
                && let Some(id) = message.get("id")
            {
                self.send(&json!({"jsonrpc": "2.0", "id": id, "result": [null]}))?;
                continue;
            }
            if std::env::var_os("TADSL_BENCH_DEBUG").is_some() {
                (self.progress)(&message.to_string().chars().take(200).collect::<String>());
            }
            if pred(&message) {
                return Ok(message);
            }
        }
    }

    fn request(&mut self, method: &str, params: Value) -> std::io::Result<Value> {
        let id = self.next_id;
        self.next_id += 1;
        self.send(&json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}))?;
        self.wait(|m| m.get("id") == Some(&json!(id)))
    }

    fn published(&mut self, uri: &str, version: i64) -> std::io::Result<Value> {
        self.wait(|m| {
            m["method"] == "textDocument/publishDiagnostics"
                && m["params"]["uri"] == uri
                && m["params"]["version"] == version
        })
    }

    /// Resident memory in bytes (Linux), if known.
    fn rss(&self) -> Option<u64> {
        proc_status_kib(&self.child.id().to_string(), "VmRSS").map(|kib| kib * 1024)
    }

    fn stop(mut self) {
        let _ = self.request("shutdown", Value::Null);
        let _ = self.notify("exit", Value::Null);
        let _ = self.child.wait();
    }
}

fn percentiles(mut times: Vec<Duration>) -> (f64, f64) {
    times.sort();
    let at =
        |q: usize| times.get((times.len() * q / 100).min(times.len().saturating_sub(1))).copied().unwrap_or_default();
    (at(50).as_secs_f64() * 1e3, at(99).as_secs_f64() * 1e3)
}

/// `bench --lsp` of `exe` (a `tadslc`: its `lsp` is measured, its `check FILE` is a peer):
/// `samples` of each measurement (at least 10), the peers the best of `runs`. The server's
/// messages go to `progress` when `TADSL_BENCH_DEBUG` is set.
pub fn run(exe: &Path, samples: usize, runs: usize, progress: &mut dyn FnMut(&str)) -> Result<Report, BenchError> {
    measure(exe, samples.max(10), runs.max(1), progress).map_err(BenchError::from)
}

fn measure(exe: &Path, samples: usize, runs: usize, progress: &mut dyn FnMut(&str)) -> std::io::Result<Report> {
    let text = long_scenario(2000);
    let lines = text.lines().count();
    let dir = std::env::temp_dir().join(format!("tadsl-bench-lsp-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("long.tad");
    std::fs::write(&path, &text)?;
    let uri = format!("file://{}", path.display());

    let mut server = Server::start(exe, progress)?;
    server.request("initialize", json!({"capabilities": {}, "processId": std::process::id()}))?;
    server.notify("initialized", json!({}))?;
    std::thread::sleep(Duration::from_millis(200));
    let idle = server.rss();

    let document = json!({"uri": uri, "languageId": "tad", "version": 1, "text": text});
    let start = Instant::now();
    server.notify("textDocument/didOpen", json!({"textDocument": document}))?;
    server.published(&uri, 1)?;
    let open = start.elapsed();

    // one line, back and forth: the speed of a group in the middle
    let line = text.lines().enumerate().filter(|(_, l)| l.contains("speed: 30 km/h")).nth(100).map_or(0, |(i, _)| i);
    let column = text.lines().nth(line).and_then(|l| l.find("30")).unwrap_or(0);
    let mut changes = Vec::with_capacity(samples);
    for k in 0..samples {
        let version = 2 + k as i64;
        let digit = if k % 2 == 0 { "1" } else { "0" };
        let range =
            json!({"start": {"line": line, "character": column + 1}, "end": {"line": line, "character": column + 2}});
        let params = json!({"textDocument": {"uri": uri, "version": version}, "contentChanges": [{"range": range, "text": digit}]});
        let start = Instant::now();
        server.notify("textDocument/didChange", params)?;
        server.published(&uri, version)?;
        changes.push(start.elapsed());
    }
    let behavior = text.lines().enumerate().filter(|(_, l)| l.contains("behavior: move_forward")).nth(100);
    let (value_line, value_column) = behavior.map_or((0, 0), |(i, l)| (i, l.find("move_forward").unwrap_or(0)));
    let at = json!({"textDocument": {"uri": uri}, "position": {"line": value_line, "character": value_column + 4}});
    let mut completion = Vec::with_capacity(samples);
    let mut hover = Vec::with_capacity(samples);
    let mut offered = 0;
    for _ in 0..samples {
        let start = Instant::now();
        let answer = server.request("textDocument/completion", at.clone())?;
        completion.push(start.elapsed());
        offered = answer["result"].as_array().map_or(0, Vec::len);
        let start = Instant::now();
        server.request("textDocument/hover", at.clone())?;
        hover.push(start.elapsed());
    }

    // memory after every example is open and checked
    let examples: Vec<&(&str, &str)> =
        tad_eval::examples::EXAMPLES.iter().filter(|(p, _)| p.ends_with(".tad")).collect();
    let mut bytes = 0;
    for (i, (path, source)) in examples.iter().enumerate() {
        bytes += source.len();
        let uri = format!("file:///tadsl-examples/{path}");
        let document = json!({"uri": uri, "languageId": "tad", "version": 1, "text": source});
        server.notify("textDocument/didOpen", json!({"textDocument": document}))?;
        if i + 1 == examples.len() {
            server.published(&uri, 1)?;
        }
    }
    let loaded = server.rss();
    server.stop();

    // peers: a check from scratch in process, and the CLI as a process
    let scratch = best_of(runs, || {
        let mut db = tad_db::Database::new(tad_check::Options::default());
        let file = db.set_source(path.clone(), text.clone(), tad_db::Language::Tad, &tad_db::NoFs);
        std::hint::black_box(tad_db::check(&db, file));
    });
    let cli = best_of(runs, || {
        let _ = Command::new(exe).arg("check").arg(&path).stdout(Stdio::null()).stderr(Stdio::null()).status();
    });
    std::fs::remove_dir_all(&dir).ok();

    let (change50, change99) = percentiles(changes);
    let (completion50, completion99) = percentiles(completion);
    let (hover50, hover99) = percentiles(hover);
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let mib = |b: Option<u64>| b.map_or("?".to_string(), |b| format!("{:.1} MiB", b as f64 / (1 << 20) as f64));
    let out = vec![
        format!("language server over stdio, {lines}-line file, {samples} samples each"),
        format!("  open → diagnostics            {:>8.2} ms", ms(open)),
        format!("  didChange → diagnostics       p50 {change50:>6.2} ms  p99 {change99:>6.2} ms   (goal: p99 < 10 ms)"),
        format!(
            "  completion ({offered:>3} items)       p50 {completion50:>6.2} ms  p99 {completion99:>6.2} ms   (goal: p99 < 5 ms)"
        ),
        format!("  hover                         p50 {hover50:>6.2} ms  p99 {hover99:>6.2} ms"),
        format!(
            "peers: check from scratch in process {:.2} ms (the p50 change is {:.2}x of it); `tadslc check FILE` as a process {:.2} ms ({:.2}x)",
            ms(scratch),
            change50 / ms(scratch).max(1e-9),
            ms(cli),
            change50 / ms(cli).max(1e-9)
        ),
        format!(
            "memory: {} after initialize, {} with the 2,000-line file and all {} examples ({} KiB of source) open",
            mib(idle),
            mib(loaded),
            examples.len(),
            bytes / 1024
        ),
    ];
    Ok(Report { lines: out, ..Report::default() })
}
