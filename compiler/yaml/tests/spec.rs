//! The specs agree with the importer: for every YAML import code (`E03xx`, `W03xx`) the
//! first ```yaml block of its section in `spec/diagnostics.md`, read as an LLM answer,
//! gives the code, and the second gives neither the code nor any error; and the key
//! tables of `spec/yaml.md` §3 list exactly the keys of the dialect table
//! (`tad_yaml::dialect::KEYS`): each key in its form's table, at its place, with its
//! other spellings, the TAD field it states and its position in `export`'s output.

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

// ---- spec/yaml.md's key tables and the dialect table ---------------------------------------

use tad_yaml::dialect::{self, Dialect, Identifies, Key, Origin, Place, Tad};

/// The backticked spans of `text`.
fn code(text: &str) -> Vec<&str> {
    text.split('`').skip(1).step_by(2).collect()
}

/// The table a heading of `spec/yaml.md` §3 starts, by the origin of its keys.
fn origin_of(heading: &str) -> Option<Origin> {
    match heading {
        h if h.starts_with("### 3.1 ") => Some(Origin::TrafficAlign),
        h if h.starts_with("### 3.2 ") => Some(Origin::TrafficComposer),
        "#### Extra keys" => Some(Origin::Extra),
        "#### Keys read at another place" => Some(Origin::Elsewhere),
        _ => None,
    }
}

/// A documented path (`actors.<key>.lane_index`) as its place and key.
fn place_of(path: &str) -> Option<(Place, &str)> {
    let Some((prefix, key)) = path.rsplit_once('.') else { return Some((Place::Top, path)) };
    let place = match prefix {
        "environment" => Place::Environment,
        "road_network" => Place::Road,
        "source" => Place::Source,
        "actors.ego_vehicle" | "participant.ego_vehicle" => Place::Ego,
        "actors.<key>" | "participant.<key>" => Place::Actor,
        _ => return None,
    };
    Some((place, key))
}

/// How the TAD column names what a key states: its first code span, `-` for none.
fn tad_cell(k: &Key) -> String {
    match k.tad {
        Tad::Field(section, field) => format!("{} {{ {field} }}", section.name),
        Tad::Block(place) => place.section().map_or("-", |s| s.name).to_string(),
        Tad::Actors => "ego".into(),
        Tad::Uses => "use".into(),
        Tad::Profile => "--profile".into(),
        Tad::Type | Tad::Count if k.place == Place::Actor => "actor <key>: <number> <type>".into(),
        Tad::Type | Tad::Count | Tad::ScenarioName | Tad::Nothing => "-".into(),
    }
}

fn line(origin: Origin, place: Place, key: &str, aliases: &[&str], tad: &str, written: Option<u8>) -> String {
    let written = written.map_or(String::new(), |n| n.to_string());
    format!("{origin:?} {place:?} `{key}` also {aliases:?} → `{tad}` written {written}")
}

#[test]
fn key_tables_match_the_dialect_table() {
    let text = read(&repo().join("spec/yaml.md"));
    let mut documented = Vec::new();
    let mut origin = None;
    for l in text.lines() {
        if l.starts_with('#') {
            origin = origin_of(l);
            continue;
        }
        let (Some(origin), Some(row)) = (origin, l.strip_prefix("| `")) else { continue };
        let row = format!("`{}", row.replace("\\|", "¦"));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert!(cells.len() >= 4, "spec/yaml.md: a key row has four cells: {l}");
        let (paths, aliases) = cells[0].split_once("(also").unwrap_or((cells[0], ""));
        let paths = code(paths);
        assert_eq!(paths.len(), 1, "spec/yaml.md: one key per row: {l}");
        let (place, key) = place_of(paths[0]).unwrap_or_else(|| panic!("spec/yaml.md: unknown place in {l}"));
        let tad = code(cells[1]).first().copied().unwrap_or("-");
        let written = cells[3].parse().ok();
        documented.push(line(origin, place, key, &code(aliases), tad, written));
    }
    let mut table: Vec<String> =
        dialect::KEYS.iter().map(|k| line(k.origin, k.place, k.key, k.aliases, &tad_cell(k), k.export)).collect();
    documented.sort();
    table.sort();
    let undocumented: Vec<&String> = table.iter().filter(|k| !documented.contains(k)).collect();
    let unknown: Vec<&String> = documented.iter().filter(|k| !table.contains(k)).collect();
    assert!(
        undocumented.is_empty() && unknown.is_empty() && documented.len() == table.len(),
        "spec/yaml.md §3's key tables and compiler/yaml/src/dialect.rs differ:\n\
         in the table, not documented: {undocumented:#?}\ndocumented, not in the table: {unknown:#?}"
    );
}

/// The code spans of the sentence of `spec/yaml.md` that starts with `start`.
fn sentence<'t>(text: &'t str, start: &str) -> Vec<&'t str> {
    let at = text.find(start).unwrap_or_else(|| panic!("spec/yaml.md: no sentence `{start}`"));
    let rest = &text[at..];
    code(&rest[..rest.find(". ").or_else(|| rest.find(".\n")).unwrap_or(rest.len())])
}

#[test]
fn top_level_and_detection_keys_match_the_dialect_table() {
    let text = read(&repo().join("spec/yaml.md"));
    let mut known = sentence(&text, "The known top-level keys are");
    let mut table: Vec<&str> = dialect::KEYS
        .iter()
        .filter(|k| k.place == Place::Top && dialect::is_top_level(k.key, false))
        .map(|k| k.key)
        .collect();
    known.sort_unstable();
    table.sort_unstable();
    assert_eq!(known, table, "spec/yaml.md §1");

    let mut detecting = sentence(&text, "The dialect is decided from the top-level keys");
    let mut table: Vec<&str> = dialect::KEYS
        .iter()
        .filter(|k| k.place == Place::Top)
        .filter(|k| {
            matches!(
                k.identifies,
                Identifies::Always(Dialect::TrafficComposer) | Identifies::AsList(Dialect::TrafficComposer)
            )
        })
        .map(|k| k.key)
        .collect();
    detecting.sort_unstable();
    table.sort_unstable();
    assert_eq!(detecting, table, "spec/yaml.md §3");
}
