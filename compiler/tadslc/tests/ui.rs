//! UI tests: every `tests/ui/**/*.tad` is one test.
//!
//! Each fixture states the diagnostics it expects inline, one comment per diagnostic:
//! `// error[E0203]: 4:5-4:11` (severity, code, 1-based start and end line:column). The
//! harness compares that set exactly with what the checker reports, then compares the
//! rendered human output (no colour) with the `.stderr` file beside the fixture. Fixtures
//! under `tests/ui/fmt/` are also formatted and compared with `NAME.formatted`. A line
//! `// profile: dashcam` checks the fixture with that profile.
//!
//! `TAD_BLESS=1 cargo test --test ui` rewrites `.stderr` and `.formatted` files; it never
//! writes when `CI` is set. Expected files without a fixture fail the run.

use libtest_mimic::{Arguments, Failed, Trial};
use std::path::{Path, PathBuf};
use tad_diagnostics::LineIndex;
use tad_diagnostics::render::human;

use tad_test_support::repo;

fn root() -> PathBuf {
    repo().join("tests/ui")
}

fn fixtures(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            fixtures(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn blessing() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

/// `(severity, code, "L:C-L:C")` from the fixture's annotations.
fn expected(text: &str) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(rest) = line.trim_start().strip_prefix("//") else {
            continue;
        };
        let rest = rest.trim();
        let Some((head, range)) = rest.split_once("]:") else {
            continue;
        };
        let Some((severity, code)) = head.split_once('[') else {
            continue;
        };
        if matches!(severity, "error" | "warning" | "hint") {
            out.push((severity.to_string(), code.to_string(), range.trim().to_string()));
        }
    }
    out.sort();
    out
}

fn annotation(severity: &str, code: &str, range: &str) -> String {
    format!("// {severity}[{code}]: {range}")
}

fn run_fixture(path: &Path) -> Result<(), Failed> {
    let input = tad_db::host::read(path).map_err(|e| format!("cannot read fixture: {e}"))?;
    let text = input.text.clone();
    let name = format!("tests/ui/{}", path.strip_prefix(root()).unwrap_or(path).display());
    let mut options = tad_check::Options::default();
    if text.lines().any(|l| l.trim() == "// profile: dashcam") {
        options.profile = tad_check::Profile::Dashcam;
    }
    let mut db = tad_db::Database::new(options);
    let file = tad_db::host::register(&mut db, &input);
    let diagnostics = tad_db::host::diagnose_in(&mut db, &input).diagnostics;
    let related = tadslc::cmd::check::related(&db, file, &diagnostics);

    let index = LineIndex::new(&text);
    let mut actual: Vec<(String, String, String)> = diagnostics
        .iter()
        .map(|d| {
            let (s, e) = index.span_range(&text, d.primary.span);
            (
                d.severity.as_str().to_string(),
                d.code.to_string(),
                format!("{}:{}-{}:{}", s.line, s.column, e.line, e.column),
            )
        })
        .collect();
    actual.sort();
    let wanted = expected(&text);
    let mut problems = Vec::new();
    // every diagnostic states its fact for programs too
    for d in diagnostics.iter().filter(|d| d.payload.is_none()) {
        problems.push(format!("{} `{}` has no payload", d.code, d.message));
    }
    if actual != wanted {
        let show = |v: &[(String, String, String)]| {
            v.iter().map(|(s, c, r)| annotation(s, c, r)).collect::<Vec<_>>().join("\n")
        };
        problems.push(format!("diagnostics differ\n--- expected\n{}\n--- actual\n{}", show(&wanted), show(&actual)));
    }

    // paths inside messages are shown relative to the repository
    let rendered = human::render(&tadslc::cmd::check::report(&name, &text, &diagnostics, &related), false)
        .replace(&format!("{}/", repo().display()), "");
    compare(&path.with_extension("stderr"), &rendered, &mut problems);

    if path.components().any(|c| c.as_os_str() == "fmt") {
        let formatted = match tad_syntax::format::format(&text) {
            Ok(formatted) => {
                let again = tad_syntax::format::format(&formatted)
                    .map_err(|e| format!("formatted output does not parse: {e:?}"))?;
                if again != formatted {
                    problems.push("formatting is not idempotent".into());
                }
                formatted
            }
            Err(_) => "(not formatted: syntax errors)\n".to_string(),
        };
        compare(&path.with_extension("formatted"), &formatted, &mut problems);
    }
    if problems.is_empty() { Ok(()) } else { Err(problems.join("\n\n").into()) }
}

fn compare(expected_path: &Path, actual: &str, problems: &mut Vec<String>) {
    let expected = std::fs::read_to_string(expected_path).unwrap_or_default();
    if expected == actual {
        return;
    }
    if blessing() {
        if let Err(e) = std::fs::write(expected_path, actual) {
            problems.push(format!("cannot bless {}: {e}", expected_path.display()));
        }
        return;
    }
    problems.push(format!(
        "{} differs (TAD_BLESS=1 to accept)\n--- expected\n{expected}\n--- actual\n{actual}",
        expected_path.display()
    ));
}

fn main() {
    let args = Arguments::from_args();
    let mut files = Vec::new();
    fixtures(&root(), &mut files);
    let mut trials = Vec::new();
    for path in &files {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let name = path.strip_prefix(root()).unwrap_or(path).display().to_string();
        match ext {
            "tad" => {
                let path = path.clone();
                trials.push(Trial::test(name, move || run_fixture(&path)));
            }
            "stderr" | "formatted" => {
                let fixture = path.with_extension("tad");
                trials.push(Trial::test(format!("{name} has a fixture"), move || {
                    if fixture.exists() {
                        Ok(())
                    } else {
                        Err(format!("orphaned expected file; no {}", fixture.display()).into())
                    }
                }));
            }
            _ => {}
        }
    }
    // every diagnostic code is expected by at least one fixture: these, or the YAML answer
    // fixtures of `tests/yaml/answers` (annotated `# error[CODE]: ...`, run by tad-yaml)
    // and the backends' fixtures (`tests/scenic/fixtures`, run by tad-scenic;
    // `tests/openscenario/fixtures`, run by tad-openscenario; `tests/runtime/fixtures`, the
    // runtime's notes, run by tad-eval)
    let mut yaml = Vec::new();
    fixtures(&repo().join("tests/yaml/answers"), &mut yaml);
    let mut scenic = Vec::new();
    fixtures(&repo().join("tests/scenic/fixtures"), &mut scenic);
    fixtures(&repo().join("tests/openscenario/fixtures"), &mut scenic);
    fixtures(&repo().join("tests/runtime/fixtures"), &mut scenic);
    let all: Vec<String> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "tad"))
        .chain(yaml.iter().filter(|p| p.extension().is_some_and(|e| e == "yaml")))
        .chain(scenic.iter().filter(|p| p.extension().is_some_and(|e| e == "tad")))
        .filter_map(|p| std::fs::read(p).ok())
        .map(|bytes| {
            String::from_utf8_lossy(&bytes)
                .replace("\n# error[", "\n// error[")
                .replace("\n# warning[", "\n// warning[")
                .replace("\n# hint[", "\n// hint[")
        })
        .flat_map(|t| expected(&t).into_iter().map(|(_, c, _)| c))
        .collect();
    trials.push(Trial::test("every code has a fixture", move || {
        let missing: Vec<&str> =
            tad_diagnostics::Code::ALL.iter().map(|c| c.as_str()).filter(|c| !all.iter().any(|a| a == c)).collect();
        if missing.is_empty() { Ok(()) } else { Err(format!("no UI fixture expects {}", missing.join(", ")).into()) }
    }));
    libtest_mimic::run(&args, trials).exit();
}
