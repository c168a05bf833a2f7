//! The normative spec agrees with the implementation: every code's erroneous example
//! produces it and its corrected example checks; the field tables list the schema.

mod common;
use tad_diagnostics::{Code, Severity};

fn tad_blocks(text: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_end()) {
            (None, "```tad") => current = Some(String::new()),
            (Some(block), "```") => {
                blocks.push(std::mem::take(block));
                current = None;
            }
            (Some(block), line) => {
                block.push_str(line);
                block.push('\n');
            }
            _ => {}
        }
    }
    blocks
}

#[test]
fn every_code_has_an_erroneous_and_a_corrected_example() {
    for code in Code::ALL {
        let blocks = tad_blocks(code.explanation());
        assert_eq!(blocks.len(), if *code == Code::E0006 { 1 } else { 2 }, "{code}: examples");
        if *code != Code::E0006 {
            let (_, diagnostics) = tad_syntax::analyze(&blocks[0]);
            assert!(diagnostics.iter().any(|d| d.code == *code), "{code}: the erroneous example gives {diagnostics:?}");
        }
        let corrected = blocks.last().unwrap();
        let (_, diagnostics) = tad_syntax::analyze(corrected);
        assert!(
            diagnostics.iter().all(|d| d.severity != Severity::Error && d.code != *code),
            "{code}: the corrected example gives {diagnostics:?}"
        );
        assert_eq!(tad_syntax::format::format(corrected).as_deref(), Ok(corrected.as_str()), "{code}: not formatted");
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
