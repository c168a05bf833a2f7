//! Every exported grammar accepts every example and rejects broken programs.
//!
//! The Lark grammar runs in llguidance with a byte-level tokenizer (one token per byte), as
//! a constrained decoder would run it; the GBNF is read back by a converter written here
//! (rules, literals, classes, repetitions) into Lark for the same engine, so it is judged
//! from its text, not from the printer's structure. The JSON Schema is checked by a
//! validator (`jsonschema`) against each example's YAML form, and compiled by llguidance.

use std::sync::Arc;

use llguidance::api::TopLevelGrammar;
use llguidance::{Matcher, ParserFactory};
use tad_grammar::Format;
use tad_test_support::examples;
use toktrie::{ApproximateTokEnv, TokEnv};

fn env() -> TokEnv {
    ApproximateTokEnv::single_byte_env()
}

fn factory() -> Arc<ParserFactory> {
    Arc::new(ParserFactory::new_simple(&env()).expect("a parser factory"))
}

/// Whether the grammar accepts `text` as a whole program.
fn accepts(factory: &ParserFactory, grammar: &TopLevelGrammar, text: &str) -> Result<(), String> {
    let tokens = factory.tok_env().tokenize_bytes(text.as_bytes());
    let mut matcher = Matcher::new(factory.create_parser(grammar.clone()));
    if let Some(e) = matcher.get_error() {
        return Err(format!("grammar: {e}"));
    }
    for (i, &t) in tokens.iter().enumerate() {
        if matcher.consume_token(t).is_err() || matcher.is_error() {
            let at = tokens[..i].len();
            return Err(format!(
                "rejected at byte {at}: {:?}",
                &text[at.saturating_sub(40)..(at + 10).min(text.len())]
            ));
        }
    }
    if matcher.is_accepting().unwrap_or(false) { Ok(()) } else { Err("the program ends too early".into()) }
}

fn lark(region: Option<&str>) -> String {
    let (vocabulary, modules) = tad_grammar::scope(region).unwrap();
    tad_grammar::export(Format::Lark, &vocabulary, &modules, "test")
}

fn gbnf(region: Option<&str>) -> String {
    let (vocabulary, modules) = tad_grammar::scope(region).unwrap();
    tad_grammar::export(Format::Gbnf, &vocabulary, &modules, "test")
}

/// GBNF read back as llguidance Lark: `a-b ::= ...` becomes `a_b: ...`, `root` `start`,
/// character classes regular-expression lexemes; literals and repetitions are the same.
fn gbnf_to_lark(gbnf: &str) -> String {
    let mut out = String::new();
    for line in gbnf.lines() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        let (name, body) = line.split_once(" ::= ").expect("a GBNF rule per line");
        let name = if name == "root" { "start".to_string() } else { name.replace('-', "_") };
        let mut converted = String::new();
        let mut chars = body.chars().peekable();
        while let Some(c) = chars.next() {
            match c {
                '"' => {
                    converted.push('"');
                    while let Some(c) = chars.next() {
                        converted.push(c);
                        if c == '\\' {
                            converted.push(chars.next().unwrap());
                        } else if c == '"' {
                            break;
                        }
                    }
                }
                '[' => {
                    converted.push_str("/[");
                    while let Some(c) = chars.next() {
                        converted.push(c);
                        if c == '\\' {
                            converted.push(chars.next().unwrap());
                        } else if c == ']' {
                            break;
                        }
                    }
                    converted.push('/');
                }
                '-' => converted.push('_'),
                c => converted.push(c),
            }
        }
        out.push_str(&format!("{name}: {converted}\n"));
    }
    out
}

fn programs() -> Vec<(String, String)> {
    examples().into_iter().map(|p| (p.display().to_string(), std::fs::read_to_string(&p).unwrap())).collect()
}

/// The answers a translation should give: the benchmark's ground truths, the fine-tuning
/// pairs' (`tests/llm/train`: a pair the grammar refuses would teach an answer the
/// constrained decoder cannot write) and the translate prompt's worked examples, without their comment lines (truths explain themselves at
/// length; answers need not) but for the examples' list of road users, which opens them.
fn answers() -> Vec<(String, String)> {
    let repo = tad_test_support::repo();
    let dirs = [
        repo.join("tests/llm/truth"),
        repo.join("tests/llm/train/truth"),
        repo.join("compiler/frontend/prompts/examples"),
    ];
    let files = dirs.iter().flat_map(|d| tad_test_support::files(d, "tad"));
    files
        .map(|p| {
            let text = tad_test_support::read(&p);
            let users = text.lines().filter(|l| l.starts_with("// road users:"));
            let program = text.lines().filter(|l| !l.starts_with("//")).skip_while(|l| l.is_empty());
            let code: String = users.chain(program).map(|l| format!("{l}\n")).collect();
            (p.display().to_string(), code.trim_start().to_string())
        })
        .collect()
}

#[test]
fn the_grammar_accepts_every_truth_and_worked_example() {
    let factory = factory();
    let grammar = TopLevelGrammar::from_lark(lark(None));
    let answers = answers();
    assert!(answers.len() >= 140, "{}", answers.len());
    for (path, text) in answers {
        accepts(&factory, &grammar, &text).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
}

#[test]
fn the_lark_grammar_accepts_every_example_and_the_region_grammar_its_own() {
    let factory = factory();
    let grammar = TopLevelGrammar::from_lark(lark(None));
    for (path, text) in programs() {
        accepts(&factory, &grammar, &text).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
    let yellowstone = TopLevelGrammar::from_lark(lark(Some("yellowstone")));
    let (_, text) = programs().into_iter().find(|(p, _)| p.contains("yellowstone")).unwrap();
    accepts(&factory, &yellowstone, &text).unwrap();
    // a region without the national-park module has no bison
    let los_angeles = TopLevelGrammar::from_lark(lark(Some("los_angeles")));
    assert!(accepts(&factory, &los_angeles, &text).is_err());
}

#[test]
fn the_gbnf_grammar_accepts_every_example() {
    let factory = factory();
    let grammar = TopLevelGrammar::from_lark(gbnf_to_lark(&gbnf(None)));
    for (path, text) in programs() {
        accepts(&factory, &grammar, &text).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
}

/// The Lark grammar and the GBNF read back, for every standard module.
fn both_grammars() -> [(&'static str, TopLevelGrammar); 2] {
    [("lark", TopLevelGrammar::from_lark(lark(None))), ("gbnf", TopLevelGrammar::from_lark(gbnf_to_lark(&gbnf(None))))]
}

/// Programs one edit away from an example that the language or the vocabulary rules out.
fn mutants(text: &str) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    let mut push = |what: &'static str, from: &str, to: &str| {
        if text.contains(from) {
            out.push((what, text.replacen(from, to, 1)));
        }
    };
    push("an undeclared weather", "weather: ", "weather: sunnyish_");
    push("an undeclared behavior", "behavior: ", "behavior: teleport_");
    if let Some(line) = text.lines().find(|l| l.starts_with("    speed: ") && l.ends_with(" km/h")) {
        push("a unit that does not exist", line, &line.replace("km/h", "kmh"));
    }
    push("an unknown field", "    lane: ", "    lane_no: ");
    push("a missing brace", "\n  }\n", "\n");
    push("a lane that is not a number", "lane: 1", "lane: one");
    push("a range in a single-valued field", "lanes: ", "lanes: 1..");
    if let Some(header) = text.lines().find(|l| l.starts_with("  actor ") && l.contains(": 1 ")) {
        push("a group of no actors", header, &header.replacen(": 1 ", ": 0 ", 1));
        push("a group of a negative count", header, &header.replacen(": 1 ", ": -1 ", 1));
    }
    push("prose before the program", "scenario ", "Here is the scenario:\nscenario ");
    out.push(("a comment line that runs on", format!("// {}\n{text}", "If you need more, ask. ".repeat(6))));
    out
}

#[test]
fn both_grammars_reject_broken_programs() {
    let factory = factory();
    let grammars = both_grammars();
    let mut checked = 0;
    for (path, text) in programs().into_iter().take(6) {
        for (what, mutant) in mutants(&text) {
            for (notation, grammar) in &grammars {
                assert!(accepts(&factory, grammar, &mutant).is_err(), "{notation} accepts {what} in {path}");
                checked += 1;
            }
        }
    }
    assert!(checked >= 60, "only {checked} mutants");
}

/// The answer `export` writes for `text`: without the host's `profile`, which answers
/// never state (the schema leaves it out).
fn json_form(text: &str) -> serde_json::Value {
    let module = tad_syntax::analyze(text).0;
    let yaml = tad_yaml::export(&module, text);
    let answer = yaml.replacen("profile: auto\n", "", 1);
    assert_ne!(answer, yaml, "export states the profile");
    serde_norway::from_str(&answer).expect("YAML that reads as JSON values")
}

#[test]
fn the_json_schema_validates_every_example_and_rejects_mutants() {
    let (vocabulary, _) = tad_grammar::scope(None).unwrap();
    let schema = tad_grammar::json_schema(&vocabulary, "test");
    let validator = jsonschema::validator_for(&schema).expect("a valid JSON Schema");
    let factory = factory();
    let grammar = TopLevelGrammar::from_json_schema(schema.clone());
    for (path, text) in programs() {
        let value = json_form(&text);
        let errors: Vec<String> =
            validator.iter_errors(&value).map(|e| format!("{e} at {}", e.instance_path())).collect();
        assert!(errors.is_empty(), "{path}: {errors:?}");
        accepts(&factory, &grammar, &serde_json::to_string(&value).unwrap()).unwrap_or_else(|e| panic!("{path}: {e}"));

        let mut bad = value.clone();
        bad["environment"]["weather"] = "sunnyish".into();
        assert!(!validator.is_valid(&bad), "{path}: an undeclared weather");
        let mut bad = value.clone();
        bad["actors"]["ego_vehicle"]["lane_index"] = "two".into();
        assert!(!validator.is_valid(&bad), "{path}: a lane in words");
        let mut bad = value.clone();
        bad["road_network"]["colour"] = "red".into();
        assert!(!validator.is_valid(&bad), "{path}: an unknown key");
        let mut bad = value;
        bad.as_object_mut().unwrap().remove("actors");
        assert!(!validator.is_valid(&bad), "{path}: no actors");
    }
}

/// A program of one group of `kind` that does `behavior`, and an ego that does `ego`.
fn one_group(kind: &str, behavior: &str, ego: &str) -> String {
    format!(
        "scenario performers {{\n  ego {{\n    behavior: {ego}\n  }}\n  actor group: 2 {kind} {{\n    behavior: {behavior}\n  }}\n}}\n"
    )
}

/// Whether the checker reports `code` on the program.
fn checker_reports(text: &str, code: &str) -> bool {
    let mut db = tad_db::Database::new(Default::default());
    let file = db.set_source("answer.tad".into(), text.to_string(), tad_db::Language::Tad, &tad_db::NoFs);
    tad_db::check(&db, file).diagnostics.iter().any(|d| d.code.as_str() == code)
}

#[test]
fn the_grammar_allows_a_behavior_exactly_when_the_checker_does() {
    let factory = factory();
    let grammar = TopLevelGrammar::from_lark(lark(None));
    let (vocabulary, _) = tad_grammar::scope(None).unwrap();
    // one type of each kind
    let kinds: Vec<String> = vocabulary
        .names("actor_kind")
        .into_iter()
        .filter_map(|k| vocabulary.entries("actor_type").into_iter().find(|t| t.symbol("kind") == Some(k)))
        .map(|t| t.name.clone())
        .collect();
    assert!(kinds.len() >= 4, "{kinds:?}");
    let (mut allowed, mut refused) = (0, 0);
    for kind in &kinds {
        for behavior in vocabulary.names("behavior") {
            let text = one_group(kind, behavior, "move_forward");
            let rejected = checker_reports(&text, "E0502");
            assert_eq!(accepts(&factory, &grammar, &text).is_err(), rejected, "{kind} that does {behavior}");
            if rejected { refused += 1 } else { allowed += 1 }
        }
    }
    for behavior in vocabulary.names("behavior") {
        let text = one_group("car", "move_forward", behavior);
        let rejected = checker_reports(&text, "E0502");
        assert_eq!(accepts(&factory, &grammar, &text).is_err(), rejected, "an ego that does {behavior}");
        refused += rejected as usize;
    }
    // both sides of the rule are exercised: a cyclist cannot `stand`, nor can the ego
    assert!(allowed > 40 && refused > 20, "{allowed} allowed, {refused} refused");
    assert!(accepts(&factory, &grammar, &one_group("bicycle", "stand", "move_forward")).is_err());
    assert!(accepts(&factory, &grammar, &one_group("bicycle", "stopped", "move_forward")).is_ok());
    assert!(accepts(&factory, &grammar, &one_group("car", "move_forward", "stand")).is_err());
    // a group names its type
    assert!(accepts(&factory, &grammar, &one_group("unspecified", "move_forward", "move_forward")).is_err());
}

#[test]
fn on_a_one_way_road_no_lane_is_negative() {
    let factory = factory();
    let grammars = both_grammars();
    let program = |direction: &str, ego: &str, group: &str| {
        format!(
            "scenario lanes {{\n  road {{\n    lanes: 2\n{direction}  }}\n  ego {{\n    lane: {ego}\n  }}\n  actor bus: 1 bus {{\n    lane: {group}\n  }}\n}}\n"
        )
    };
    for (notation, grammar) in &grammars {
        for (direction, ego, group, checker_accepts) in [
            ("    direction: two_way\n", "1", "-1", true),
            ("", "1", "-1", true),
            ("    direction: unspecified\n", "1", "-1", true),
            ("    direction: one_way\n", "1", "2", true),
            ("    direction: one_way\n", "1", "-1", false),
            ("    direction: one_way\n", "-2", "1", false),
        ] {
            let text = program(direction, ego, group);
            assert_eq!(!checker_reports(&text, "E0501"), checker_accepts, "the checker on {text}");
            assert_eq!(accepts(&factory, grammar, &text).is_ok(), checker_accepts, "{notation} on {text}");
        }
    }
}

#[test]
fn a_lane_is_within_the_roads_lanes() {
    let factory = factory();
    let grammars = both_grammars();
    let program = |lanes: &str, direction: &str, ego: &str, group: &str| {
        format!(
            "scenario lanes {{\n  road {{\n{lanes}{direction}  }}\n  ego {{\n    lane: {ego}\n  }}\n  actor bus: 1 bus {{\n    lane: {group}\n  }}\n}}\n"
        )
    };
    let two_way = "    direction: two_way\n";
    let one_way = "    direction: one_way\n";
    for (notation, grammar) in &grammars {
        for (lanes, direction, ego, group, checker_accepts) in [
            ("    lanes: 1\n", two_way, "1", "-1", true),
            ("    lanes: 1\n", two_way, "2", "1", false),
            ("    lanes: 1\n", "", "1", "-2", false),
            ("    lanes: 3\n", two_way, "3", "-3", true),
            ("    lanes: 3\n", two_way, "0", "3", false),
            ("    lanes: 3\n", one_way, "3", "4", false),
            ("    lanes: 6\n", one_way, "6", "5", true),
            ("    lanes: 8\n", two_way, "8", "-7", true),
            ("    lanes: 12\n", two_way, "12", "-12", true),
            ("    lanes: unspecified\n", two_way, "9", "-9", true),
            ("", two_way, "9", "-9", true),
        ] {
            let text = program(lanes, direction, ego, group);
            assert_eq!(!checker_reports(&text, "E0500"), checker_accepts, "the checker on {text}");
            assert_eq!(accepts(&factory, grammar, &text).is_ok(), checker_accepts, "{notation} on {text}");
        }
    }
}
