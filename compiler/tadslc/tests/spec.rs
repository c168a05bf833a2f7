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
    let input = tadslc::files::Input {
        name: "example.tad".into(),
        path: Some(std::env::temp_dir().join("tadsl-spec-example.tad")),
        text: text.to_string(),
        invalid_utf8: None,
    };
    tadslc::check::diagnose_in(&mut tad_db::Database::new(options), &input).diagnostics
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
