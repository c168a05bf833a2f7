//! `spec/diagnostics.md` agrees with the importer: for every YAML import code (`E03xx`,
//! `W03xx`) the first ```yaml block of its section, read as an LLM answer, gives the
//! code, and the second gives neither the code nor any error.

mod common;
use common::*;
use tad_diagnostics::Code;

fn yaml_blocks(text: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_end()) {
            (None, "```yaml") => current = Some(String::new()),
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

fn yaml_codes() -> Vec<Code> {
    Code::ALL.iter().copied().filter(|c| c.as_str()[1..].starts_with("03")).collect()
}

#[test]
fn every_yaml_code_has_an_erroneous_and_a_corrected_answer() {
    let codes = yaml_codes();
    assert!(codes.len() >= 5, "{codes:?}");
    for code in codes {
        let blocks = yaml_blocks(code.explanation());
        assert_eq!(blocks.len(), 2, "{code}: a YAML code's section has two ```yaml blocks");
        let (_, diagnostics) = tad_yaml::lower(&blocks[0]);
        assert!(diagnostics.iter().any(|d| d.code == code), "{code}: the erroneous answer gives {diagnostics:?}");
        let (model, diagnostics) = tad_yaml::lower(&blocks[1]);
        assert!(
            diagnostics.iter().all(|d| d.code != code) && errors(&diagnostics).is_empty(),
            "{code}: the corrected answer gives {diagnostics:?}"
        );
        assert!(model.scenario.is_some(), "{code}: the corrected answer holds a scenario");
    }
}

#[test]
fn yaml_codes_are_documented_after_e0214() {
    let text = read(&repo().join("spec/diagnostics.md"));
    let e0214 = text.find("## E0214").unwrap();
    let mut last = e0214;
    for code in yaml_codes() {
        let at = text.find(&format!("## {code} ")).unwrap_or_else(|| panic!("{code} undocumented"));
        assert!(at > last, "{code} is out of order");
        last = at;
    }
    let next = text[e0214 + 4..].find("\n## ").map(|i| i + e0214 + 5).unwrap();
    assert!(text[next..].starts_with("## E0300"), "the YAML codes follow E0214 directly");
}
