//! Scenario text cannot inject code into the generated program: names that are Python or
//! Scenic keywords, builtins or model names, and strings with quotes, triple quotes,
//! backslashes, line breaks, control characters and Unicode all come out inert. The
//! structure of every program is checked here; with the Scenic venv, the real Scenic also
//! compiles, samples and simulates them.

mod common;

use std::path::{Path, PathBuf};

use tad_scenic::{EmitOptions, Simulator};

/// Adversarial scenarios, as (name, text). Every one checks without errors.
fn scenarios() -> Vec<(&'static str, String)> {
    let names = [
        "class",
        "ego2",
        "new",
        "require",
        "import",
        "def",
        "lambda",
        "print",
        "exec",
        "Car",
        "network",
        "ego_",
        "tadAnchor",
        "TadWalk",
        "simulation",
        "param",
        "model",
        "behavior",
        "monitor",
        "interrupt",
        "True",
        "None",
        "match",
        "type",
        "workspace",
        "road",
        "Uniform",
        "localPath",
        "g_class",
        "class_2",
        "os",
    ];
    let mut out = Vec::new();
    // every name as a group, each referencing the previous one
    let mut groups = String::new();
    for (i, name) in names.iter().enumerate() {
        let reference = if i == 0 { "ego" } else { names[i - 1] };
        groups.push_str(&format!(
            "  actor {name}: {} car {{\n    behavior: move_forward\n    speed: 20 km/h\n    position: front of {reference}\n    lane: {}\n  }}\n",
            1 + i % 2,
            1 + i % 2,
        ));
    }
    out.push((
        "keywords_as_names",
        format!(
            "scenario import {{\n  road {{\n    type: straight_road\n    lanes: 2\n    direction: one_way\n  }}\n  ego {{\n    behavior: move_forward\n    speed: 20 km/h\n    lane: 1\n  }}\n{groups}}}\n"
        ),
    ));
    let strings = [
        r#"'); import os; os.system('echo pwned'); ('"#,
        r#"\"\"\"; import os; \"\"\""#,
        r#"\"\"\" ''' \\ \\\\ \" ' # not a comment"#,
        r#"line one\nimport os\r\nos.system('x')\rexec('y')"#,
        r#"\u{2028}import os\u{2029}os.exit()\u{85}\u{b}\u{c}\u{1c}"#,
        r#"\u{202e}gnirts desrever\u{202c} \u{200b}zero width \u{feff}bom"#,
        r#"Zürich — 東京 — עברית — 😀 — \u{0} nul"#,
        r#"\\"#,
        r#"ends with a backslash \\"#,
        r#"{braces} %s %(x)s {0} $HOME `backticks`"#,
    ];
    for (i, s) in strings.iter().enumerate() {
        out.push((
            ["s0", "s1", "s2", "s3", "s4", "s5", "s6", "s7", "s8", "s9"][i],
            format!(
                "scenario injection_{i} {{\n  source {{\n    video: \"{s}\"\n    description: \"{s}\"\n  }}\n  environment {{\n    weather: clear\n    time: daytime\n  }}\n  road {{\n    type: straight_road\n    lanes: 1\n    direction: two_way\n  }}\n  ego {{\n    behavior: move_forward\n    speed: 30 km/h\n    lane: 1\n  }}\n  actor x: 1 pedestrian {{\n    behavior: cross\n    speed: 5 km/h\n    position: front of ego\n    lane: 1\n  }}\n}}\n"
            ),
        ));
    }
    out.push((
        "text_block",
        "// a multi-line description with every kind of quote\nscenario text_block {\n  source {\n    description: \"\"\"\n      first line ' \" \\ \\\\\n      import os\n      '''\n      # hash\n      \\\"\\\"\\\"\n    \"\"\"\n  }\n  environment {\n    weather: rainy\n    time: nighttime\n  }\n  road {\n    type: intersection\n    lanes: 1\n    direction: two_way\n    light: red\n  }\n  ego {\n    behavior: turn_left\n    speed: 10 km/h\n    lane: 1\n  }\n}\n".to_string(),
    ));
    out.push((
        "declared_names",
        "behavior exec {\n  description: \"'); import os #\"\n  performers: [vehicle]\n}\nactor_type print {\n  kind: vehicle\n  length: 4 m\n  width: 2 m\n}\nscenario declared_names {\n  road {\n    type: straight_road\n    lanes: 1\n    direction: one_way\n  }\n  ego {\n    behavior: exec\n    speed: 20 km/h\n    lane: 1\n  }\n  actor lambda: 2 print {\n    behavior: exec\n    speed: 20 km/h\n    position: front of ego\n    lane: 1\n  }\n}\n".to_string(),
    ));
    out
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The structure of a generated program: comments, the statements the backend writes, and
/// nothing else.
fn check_structure(name: &str, text: &str) {
    let prelude: Vec<&str> = tad_scenic::PRELUDE_PLACEMENT
        .lines()
        .chain(tad_scenic::PRELUDE_BEHAVIORS.lines())
        .chain(tad_scenic::PRELUDE_PARAMS.lines())
        .chain(["# Parameters: a choice of behaviors, a delay, a trigger."])
        .collect();
    for c in text.chars() {
        assert!(
            c == '\n'
                || !(c.is_control()
                    || matches!(c as u32, 0x2028 | 0x2029 | 0x202A..=0x202E | 0x200B..=0x200F | 0xFEFF)),
            "{name}: raw {c:?} in the program"
        );
    }
    let mut in_prelude = false;
    let mut continuation = false;
    for line in text.lines() {
        if line.starts_with("# ---- TADSL prelude") {
            in_prelude = true;
            continue;
        }
        if line.starts_with("# ---- end of the prelude") {
            in_prelude = false;
            continue;
        }
        if in_prelude {
            assert!(line.is_empty() || prelude.contains(&line), "{name}: prelude line changed: {line}");
            continue;
        }
        if line.starts_with('#') || line.is_empty() {
            continue;
        }
        assert!(line.is_ascii(), "{name}: non-ASCII code: {line}");
        // strings close on their line
        let mut quote = None;
        let mut escaped = false;
        for c in line.chars() {
            match (quote, c) {
                (Some(_), '\\') if !escaped => escaped = true,
                (Some(q), c) if c == q && !escaped => quote = None,
                (Some(_), _) => escaped = false,
                (None, '\'' | '"') => quote = Some(c),
                (None, '#') => panic!("{name}: a comment after code: {line}"),
                _ => {}
            }
        }
        assert!(quote.is_none(), "{name}: unterminated string: {line}");
        if line.starts_with(' ') {
            assert!(continuation, "{name}: unexpected indented line: {line}");
            continue;
        }
        continuation = line.ends_with(',') || line.starts_with("tadRoad") || line.starts_with("monitor");
        let allowed = ["param map = ", "param carla_map = '", "param weather = {", "model scenic.simulators."];
        if allowed.iter().any(|p| line.starts_with(p))
            || line.starts_with("tadRoad = dict(")
            || line.starts_with("tadAnchor = Uniform(")
            || line.starts_with("require monitor TadTrafficLight('")
            || line.starts_with("monitor TadTrafficLight(state):")
        {
            continue;
        }
        let (target, value) = line.split_once(" = ").unwrap_or_else(|| panic!("{name}: unexpected statement: {line}"));
        if target.starts_with("tadAt") || target == "tadEgoAt" {
            let spots =
                ["tadSpot(tadAnchor, ", "tadArmSpot(tadAnchor, '", "tadCross(tadAnchor, '", "tadCrossAt(tadAnchor, "];
            assert!(spots.iter().any(|s| value.starts_with(s)), "{name}: {line}");
            continue;
        }
        // the sampled variables of the layout's room and spread
        let numbered = |prefix: &str| {
            target.strip_prefix(prefix).is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()))
        };
        if ["tadShift", "tadJitter", "tadSpeed", "tadPick", "tadDelay", "tadTrigger"].iter().any(|p| numbered(p)) {
            let number = value.parse::<f64>().is_ok();
            assert!(number || value.starts_with("Range(") || value.starts_with("DiscreteRange("), "{name}: {line}");
            continue;
        }
        assert!(is_identifier(target), "{name}: bad identifier `{target}`");
        assert!(target == "ego" || !tad_scenic::python::is_reserved(target), "{name}: reserved identifier `{target}`");
        assert!(
            value.starts_with("new Car at tadAt")
                || value.starts_with("new Pedestrian at tadAt")
                || value.starts_with("new Debris at tadAt")
                || value.starts_with("new Car at tadEgoAt"),
            "{name}: {line}"
        );
    }
}

fn emit_all(dir: &Path, options: &EmitOptions) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    let mut files = Vec::new();
    for (name, text) in scenarios() {
        let source = dir.join(format!("{name}.tad"));
        std::fs::write(&source, &text).unwrap();
        let emitted = common::build_text(&source, &text, options);
        check_structure(name, &emitted.text);
        let path = dir.join(format!("{name}.scenic"));
        std::fs::write(&path, &emitted.text).unwrap();
        files.push(path);
    }
    files
}

#[test]
fn scenario_text_cannot_break_out_of_the_program() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-injection-structure");
    for simulator in [Simulator::Carla, Simulator::Newtonian] {
        emit_all(&dir, &EmitOptions { simulator, ..EmitOptions::default() });
    }
    // hostile options are escaped too
    let options = EmitOptions {
        simulator: Simulator::Carla,
        map: Some("Town10HD'); import os #\n".into()),
        map_dir: Some("maps\"\n'''\\".into()),
        source: Some("file\nimport os.tad".into()),
    };
    emit_all(&dir, &options);
}

#[test]
fn descriptions_survive_as_comments() {
    let (_, text) = scenarios().into_iter().find(|(n, _)| *n == "s6").unwrap();
    let emitted = common::build_text(Path::new("/nonexistent/s6.tad"), &text, &EmitOptions::default());
    assert!(emitted.text.contains("# Video: Zürich — 東京 — עברית — 😀 — \\u{0} nul\n"), "{}", emitted.text);
    let (_, text) = scenarios().into_iter().find(|(n, _)| *n == "s4").unwrap();
    let emitted = common::build_text(Path::new("/nonexistent/s4.tad"), &text, &EmitOptions::default());
    assert!(emitted.text.contains("#   \\u{2028}import os\\u{2029}os.exit()\\u{85}\\u{b}\\u{c}\\u{1c}\n"));
    let (_, text) = scenarios().into_iter().find(|(n, _)| *n == "s3").unwrap();
    let emitted = common::build_text(Path::new("/nonexistent/s3.tad"), &text, &EmitOptions::default());
    assert!(emitted.text.contains("# Video: line one\\u{a}import os\\u{d}\\u{a}os.system('x')\\u{d}exec('y')\n"));
    assert!(emitted.text.contains("#   line one\n#   import os\n#   os.system('x')\\u{d}exec('y')\n"));
}

#[test]
fn adversarial_programs_run_in_scenic() {
    let Some((python, check, maps)) = common::oracle() else { return };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenic-injection");
    let options = EmitOptions {
        simulator: Simulator::Newtonian,
        map_dir: Some(maps.to_string_lossy().into_owned()),
        ..EmitOptions::default()
    };
    let files = emit_all(&dir, &options);
    let records = common::run_oracle(&python, &check, &["--sim", "100", "--max-iters", "500"], &files);
    let failures = common::failures(&records, 100);
    assert!(failures.is_empty(), "{} of {} failed:\n{}", failures.len(), records.len(), failures.join("\n"));
}
