//! The normative spec agrees with the implementation: every code's erroneous example
//! produces it and its corrected example checks; the field tables list the schema.

mod common;
use tad_diagnostics::{Code, Severity};

/// Fenced blocks as `(language, text)`.
fn blocks(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut current: Option<(String, String)> = None;
    for line in text.lines() {
        match (&mut current, line.trim_end()) {
            (None, fence) if fence.starts_with("```") => current = Some((fence[3..].to_string(), String::new())),
            (Some(_), "```") => out.extend(current.take()),
            (Some((_, block)), line) => {
                block.push_str(line);
                block.push('\n');
            }
            _ => {}
        }
    }
    out
}

fn tad_blocks(text: &str) -> Vec<String> {
    blocks(text).into_iter().filter(|(lang, _)| lang == "tad").map(|(_, b)| b).collect()
}

/// Check `text` as a file of its own, with the standard library.
fn check(text: &str, options: tad_check::Options) -> Vec<tad_diagnostics::Diagnostic> {
    let input = tad_db::host::Input {
        name: "example.tad".into(),
        path: Some(std::env::temp_dir().join("tadsl-spec-example.tad")),
        text: text.to_string(),
        invalid_utf8: None,
    };
    tad_db::host::diagnose_in(&mut tad_db::Database::new(options), &input).diagnostics
}

#[test]
fn every_code_has_an_erroneous_and_a_corrected_example() {
    for code in Code::ALL {
        let options = tad_check::Options {
            profile: if *code == Code::E0510 { tad_check::Profile::Dashcam } else { tad_check::Profile::Default },
            ..Default::default()
        };
        let examples: Vec<(String, String)> =
            blocks(code.explanation()).into_iter().filter(|(l, _)| l != "json").collect();
        assert_eq!(examples.len(), 2, "{code}: an erroneous and a corrected example");
        let (language, erroneous) = &examples[0];
        if language == "tad" {
            let diagnostics = check(erroneous, options.clone());
            assert!(
                diagnostics.iter().any(|d| d.code == *code),
                "{code}: the erroneous example gives {diagnostics:#?}"
            );
        }
        let (language, corrected) = &examples[1];
        if language == "tad" {
            let diagnostics = check(corrected, options.clone());
            assert!(
                diagnostics.iter().all(|d| d.severity != Severity::Error && d.code != *code),
                "{code}: the corrected example gives {diagnostics:#?}"
            );
            assert_eq!(
                tad_syntax::format::format(corrected).as_deref(),
                Ok(corrected.as_str()),
                "{code}: not formatted"
            );
        }
    }
}

#[test]
fn language_examples_check_clean_and_are_formatted() {
    let text = std::fs::read_to_string(common::repo().join("spec/language.md")).unwrap();
    let blocks = tad_blocks(&text);
    assert!(!blocks.is_empty());
    for block in blocks {
        let (_, diagnostics) = tad_syntax::analyze(&block);
        assert!(diagnostics.is_empty(), "{diagnostics:?}\n{block}");
        assert_eq!(tad_syntax::format::format(&block).as_deref(), Ok(block.as_str()));
    }
}

#[test]
fn field_tables_match_the_schema() {
    let text = std::fs::read_to_string(common::repo().join("spec/language.md")).unwrap();
    let sections = tad_syntax::schema::SECTIONS.iter().copied().chain([&tad_syntax::schema::ACTOR]);
    for section in sections {
        let lines: Vec<&str> = text.lines().collect();
        let heading = lines
            .iter()
            .position(|l| l.starts_with("### 5.") && l.contains(&format!("`{}", section.name)))
            .unwrap_or_else(|| panic!("spec/language.md has no §5 heading for `{}`", section.name));
        let listed: Vec<&str> = lines[heading + 1..]
            .iter()
            .take_while(|l| !l.starts_with('#'))
            .filter_map(|l| l.strip_prefix("| `"))
            .filter_map(|l| l.split('`').next())
            .collect();
        let fields: Vec<&str> = section.fields.iter().map(|f| f.name).collect();
        assert_eq!(listed, fields, "spec/language.md table for `{}`", section.name);
    }
}

#[test]
fn vocabulary_spec_lists_every_declaration_kind_and_field() {
    let text = std::fs::read_to_string(common::repo().join("spec/vocabulary.md")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let kinds: Vec<&str> =
        lines.iter().filter_map(|l| l.strip_prefix("### `")).filter_map(|l| l.split('`').next()).collect();
    let declared: Vec<&str> = tad_syntax::schema::DECLARATIONS.iter().map(|d| d.name).collect();
    assert_eq!(kinds, declared);
    for kind in tad_syntax::schema::DECLARATIONS {
        let heading = lines.iter().position(|l| *l == format!("### `{}`", kind.name)).unwrap();
        let listed: Vec<&str> = lines[heading + 1..]
            .iter()
            .take_while(|l| !l.starts_with('#'))
            .filter_map(|l| l.strip_prefix("| `"))
            .filter_map(|l| l.split('`').next())
            .collect();
        let fields: Vec<&str> =
            kind.fields.iter().map(|f| f.name).filter(|f| !matches!(*f, "aliases" | "description")).collect();
        assert_eq!(listed, fields, "spec/vocabulary.md for `{}`", kind.name);
    }
}

#[test]
fn exit_statuses_are_said_the_same_everywhere() {
    let root = tad_test_support::repo();
    for doc in ["README.md", "spec/output.md"] {
        let text = std::fs::read_to_string(root.join(doc)).unwrap();
        assert!(text.contains(tadslc::EXIT_STATUSES), "{doc} does not say `{}`", tadslc::EXIT_STATUSES);
    }
    let help = common::tadslc(&["--help"], "");
    assert!(common::stdout(&help).contains(tadslc::EXIT_STATUSES), "{}", common::stdout(&help));
    // the spec's table has one row per status, in order
    let spec = std::fs::read_to_string(root.join("spec/output.md")).unwrap();
    let table: Vec<u8> = spec
        .split("## Exit status")
        .nth(1)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("| ")?.split(' ').next()?.parse().ok())
        .collect();
    use tadslc::Status;
    let statuses =
        [Status::Ok, Status::Failed, Status::Usage, Status::Incomplete, Status::NonScenario, Status::Unreachable];
    assert_eq!(table, statuses.iter().map(|&s| s as u8).collect::<Vec<_>>());
}

/// `option`'s default as `tadslc COMMAND --help` shows it (`[default: X]`).
fn help_default(command: &str, option: &str) -> Option<String> {
    let help = common::stdout(&common::tadslc(&[command, "--help"], ""));
    let start = help.find(&format!("{option} ")).or_else(|| help.find(&format!("{option}\n")))?;
    let rest = &help[start..];
    let end = [rest[1..].find("\n  -"), rest[1..].find("\n      --")]
        .into_iter()
        .flatten()
        .min()
        .map_or(rest.len(), |e| e + 1);
    let block = &rest[..end];
    let value = block.split("[default: ").nth(1)?.split(']').next()?;
    Some(value.to_string())
}

/// Two defaults agree: as numbers when both are numbers, else as text.
fn same_default(a: &str, b: &str) -> bool {
    match (a.trim().parse::<f64>(), b.trim().parse::<f64>()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a.trim().trim_matches('`') == b.trim().trim_matches('`'),
    }
}

#[test]
fn the_specs_defaults_are_the_commands() {
    let root = tad_test_support::repo();
    let mut checked = 0;
    let mut wrong = Vec::new();
    // spec/llm.md's `finetune` table: | `--rank R` | 16 | …
    let llm = std::fs::read_to_string(root.join("spec/llm.md")).unwrap();
    let table = llm.split("| `-o, --out DIR` |").nth(1).unwrap().split("\n\n").next().unwrap();
    for row in table.lines().filter(|l| l.starts_with("| `--")) {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let option = cells[1].trim_matches('`').split(' ').next().unwrap();
        let spec = cells[2].split(' ').next().unwrap();
        // a default in words (`off`, `the default`) is not a value to compare
        let value = spec.parse::<f64>().is_ok() || spec.starts_with('`');
        if let Some(help) = help_default("finetune", option).filter(|_| value) {
            checked += 1;
            if !same_default(spec, &help) {
                wrong.push(format!("finetune {option}: spec/llm.md {spec}, --help {help}"));
            }
        }
    }
    // spec/eval.md's search options: `--samples N` (50), …
    let eval = std::fs::read_to_string(root.join("spec/eval.md")).unwrap();
    let options = eval.split("## 4. `tadslc search").nth(1).unwrap().split("Inputs as").next().unwrap();
    for part in options.split("`--").skip(1) {
        let option = format!("--{}", part.split([' ', '`']).next().unwrap());
        let Some(spec) = part.split_once("` (").map(|(_, rest)| rest.split(')').next().unwrap()) else { continue };
        checked += 1;
        match help_default("search", &option) {
            Some(help) if same_default(spec, &help) => {}
            help => wrong.push(format!("search {option}: spec/eval.md {spec}, --help {help:?}")),
        }
    }
    assert!(checked >= 9, "only {checked} defaults found in the specs");
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn the_language_model_table_is_tad_models() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let llm = std::fs::read_to_string(root.join("spec/llm.md")).unwrap();
    let rows: Vec<Vec<&str>> = llm
        .lines()
        .skip_while(|l| !l.starts_with("| model | packages | joined file |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    let languages: Vec<_> = tad_models::MODELS.iter().filter(|m| m.kind == tad_models::Kind::Language).collect();
    assert_eq!(rows.len(), languages.len(), "one row per language model: {rows:?}");
    for row in rows {
        let name = row[0].trim_matches('`');
        let model = tad_models::model(name).unwrap_or_else(|| panic!("spec/llm.md lists `{name}`"));
        let file = &model.files[0];
        let bytes = file.bytes.to_string();
        let grouped: Vec<String> =
            bytes.as_bytes().rchunks(3).rev().map(|c| String::from_utf8(c.to_vec()).unwrap()).collect();
        assert_eq!(row[3], grouped.join(","), "{name}'s bytes");
        assert!(file.sha256.starts_with(row[4].trim_matches(['`', '…'])), "{name}'s sha256 {}", row[4]);
        assert!(row[1].contains(&format!("=={}`", model.version)), "{name}'s version in {}", row[1]);
    }
}

/// spec/gym.md's observation table (`| `name` | length | … |`) and the kinematics layout
/// are `tad_policy`'s observations.
#[test]
fn the_observation_tables_are_tad_policys() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let gym = std::fs::read_to_string(root.join("spec/gym.md")).unwrap();
    let rows: Vec<(String, usize)> = gym
        .lines()
        .skip_while(|l| !l.starts_with("| `observation=` | length |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<&str> = l.trim_matches('|').split('|').map(str::trim).collect();
            (cells[0].trim_matches('`').to_string(), cells[1].parse().expect("a length"))
        })
        .collect();
    let code: Vec<(String, usize)> =
        tad_policy::Observation::ALL.iter().map(|(name, o)| (name.to_string(), o.width())).collect();
    assert_eq!(rows, code);
    // the kinematics table's offsets: one row per value an actor adds
    let offsets: usize = gym
        .lines()
        .skip_while(|l| !l.starts_with("The `kinematics` observation"))
        .skip_while(|l| !l.starts_with("| offset | value |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').next().unwrap().split(',').count())
        .sum();
    assert_eq!(offsets, tad_policy::NEAR_FEATURES);
}
