//! `spec/backends/openscenario.md` and `spec/diagnostics.md` against the backend: the
//! category table is `mapping::TABLE` and names every actor type of the standard library;
//! the example of each W071x section, built, gives its code.

mod common;

use std::path::Path;

use tad_diagnostics::Code;
use tad_openscenario::mapping::{self, Category};

fn build(text: &str) -> tad_openscenario::Emitted {
    common::emit(Path::new("/nonexistent/example.tad"), text, "example").1
}

#[test]
fn every_openscenario_code_is_produced_by_its_example() {
    let codes: Vec<Code> = Code::ALL.iter().copied().filter(|c| c.as_str()[1..].starts_with("071")).collect();
    assert_eq!(codes, [Code::W0710, Code::W0711, Code::W0712]);
    for code in codes {
        let text = tad_test_support::fixtures::tad_block(code.explanation())
            .unwrap_or_else(|| panic!("{code}: no tad example"));
        let emitted = match code {
            Code::W0712 => {
                let Some((town, _)) = common::town("Town10HD") else { continue };
                let (scenario, _) = common::emit(Path::new("/nonexistent/example.tad"), &text, "example");
                common::on_town(&scenario, "example", &town, "Town10HD.xodr").expect("a site")
            }
            _ => build(&text),
        };
        assert!(
            emitted.diagnostics.iter().any(|d| d.code == code),
            "{code}: the example gives {:#?}",
            emitted.diagnostics
        );
    }
}

/// The rows of §3.2's table: (actor types, category cell).
fn table() -> Vec<(Vec<String>, String)> {
    let doc = std::fs::read_to_string(tad_test_support::repo().join("spec/backends/openscenario.md")).unwrap();
    let start = doc.find("| actor types | OpenSCENARIO |").expect("the category table");
    doc[start..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .filter(|l| !l.contains("any other type"))
        .map(|l| {
            let cells: Vec<&str> = l.trim_matches('|').split('|').map(str::trim).collect();
            (cells[0].split(", ").map(String::from).collect(), cells[1].to_string())
        })
        .collect()
}

#[test]
fn the_category_table_is_the_mappings_and_lists_every_standard_type() {
    let rows = table();
    let mut listed = Vec::new();
    for (names, cell) in &rows {
        for name in names {
            let category = mapping::listed(name).unwrap_or_else(|| panic!("`{name}` is in the spec, not the code"));
            let want = match category {
                Category::Vehicle(c) => format!("`Vehicle` `{c}`"),
                Category::Pedestrian(c) => format!("`Pedestrian` `{c}`"),
                Category::Misc(c) => format!("`MiscObject` `{c}`"),
            };
            assert_eq!(&want, cell, "{name}");
            listed.push(name.clone());
        }
    }
    for (name, _) in mapping::TABLE {
        assert!(listed.iter().any(|l| l == name), "`{name}` is in the code, not the spec");
    }
    // every actor type the standard library declares
    let stdlib = tad_test_support::repo().join("stdlib");
    for entry in std::fs::read_dir(stdlib).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "tad") {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        for line in text.lines().filter(|l| l.starts_with("actor_type ")) {
            let name = line["actor_type ".len()..].trim_end_matches(" {").trim();
            assert!(mapping::listed(name).is_some(), "the standard type `{name}` has no category");
        }
    }
}

#[test]
fn a_rainy_night_is_written_from_the_vocabularys_parameters() {
    let text = "scenario wet_night {\n  environment {\n    weather: rainy\n    time: nighttime\n  }\n  road {\n    type: straight_road\n    lanes: 1\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    speed: 30 km/h\n    lane: 1\n  }\n}\n";
    let xosc = build(text).xosc;
    // rainy: cloudiness 90, precipitation 70, deposits 60, wetness 80, wind 40, fog 10
    for part in [
        "<Weather fractionalCloudCover=\"sevenOktas\">",
        "precipitationType=\"rain\" precipitationIntensity=\"7\"",
        "<Wind direction=\"0\" speed=\"8\"/>",
        "<Fog visualRange=\"900\"/>",
        "<RoadCondition frictionScaleFactor=\"0.68\" wetness=\"wetWithPuddles\"/>",
        "illuminance=\"0.001\"",
        "dateTime=\"2026-06-21T23:00:00\"",
    ] {
        assert!(xosc.contains(part), "{part} not in\n{xosc}");
    }
}
