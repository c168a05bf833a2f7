//! `tadslc lsp` with a real editor as its client: headless Neovim (Debian's 0.7.2 in CI)
//! runs `lsp/tests/nvim/e2e.lua` on an example and a broken file, checking diagnostics,
//! hover, completion, a quick fix and formatting. Skipped loudly without `nvim`, unless
//! `TAD_REQUIRE_EDITORS=1` (CI), which makes a missing editor a failure.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

fn nvim() -> Option<std::path::PathBuf> {
    let found = std::env::var_os("PATH")
        .and_then(|paths| std::env::split_paths(&paths).map(|d| d.join("nvim")).find(|p| p.is_file()));
    if found.is_none() {
        assert!(
            std::env::var_os("TAD_REQUIRE_EDITORS").is_none_or(|v| v != "1"),
            "nvim is missing and TAD_REQUIRE_EDITORS=1"
        );
        eprintln!("SKIPPED: nvim is not installed (TAD_REQUIRE_EDITORS=1 makes this a failure)");
    }
    found
}

fn run(plugin: bool) {
    let Some(nvim) = nvim() else { return };
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap();
    let dir = common::scratch(&format!("nvim-e2e-{plugin}"));
    let example = std::fs::read_to_string(repo.join("examples/safety/right_turn.tad")).unwrap();
    let clean = dir.join("right_turn.tad");
    std::fs::write(&clean, &example).unwrap();
    let broken_text = example
        .replace("weather: clear", "weather: sunny")
        .replace("    time: dusk", "          time: daytime")
        .replace("context: urban", "context: urbann");
    let broken = dir.join("broken.tad");
    std::fs::write(&broken, broken_text).unwrap();

    let mut command = Command::new(nvim);
    command
        .args(["--headless", "-u", "NONE", "-i", "NONE", "-n"])
        .env("TADSLC", env!("CARGO_BIN_EXE_tadslc"))
        .env("TAD_CLEAN", &clean)
        .env("TAD_BROKEN", &broken)
        .env("XDG_STATE_HOME", dir.join("state"))
        .env("XDG_DATA_HOME", dir.join("data"))
        .env("XDG_CONFIG_HOME", dir.join("config"));
    if plugin {
        let setup = format!(
            "lua vim.opt.runtimepath:prepend('{}'); require('tadsl').setup({{ cmd = {{ '{}', 'lsp' }} }})",
            repo.join("editors/nvim").display(),
            env!("CARGO_BIN_EXE_tadslc")
        );
        command.env("TAD_NVIM_PLUGIN", "1").args(["-c", &setup]);
    }
    command.args(["-c", &format!("luafile {}", repo.join("lsp/tests/nvim/e2e.lua").display())]);
    let mut child = command.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().ok();
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let output = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        output.status.success() && stdout.contains("PASS"),
        "nvim e2e failed\nstdout:\n{stdout}\nstderr:\n{stderr}"
    );
    for check in ["diagnostics-clean", "hover", "completion", "diagnostics-broken", "quickfix", "formatting"] {
        assert!(stdout.contains(&format!("ok {check}")), "{check} did not run:\n{stdout}");
    }
}

#[test]
fn neovim_as_the_client() {
    run(false);
}

#[test]
fn neovim_with_the_editor_package() {
    run(true);
}
