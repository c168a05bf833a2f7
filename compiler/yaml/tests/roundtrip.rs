//! export → lower is the identity on models, and `to_tad` prints canonical TAD:
//! for every example, `to_tad(lower(export(m)))` equals `to_tad(m)`, `to_tad(m)` parses
//! without errors, and equals the example without its comments.

mod common;
use common::*;

fn without_comments(src: &str) -> String {
    let kept: Vec<&str> = src.lines().filter(|l| !l.trim_start().starts_with("//")).collect();
    let text = kept.join("\n");
    format!("{}\n", text.trim_matches('\n'))
}

fn round_trip(name: &str, src: &str) {
    let (model, diagnostics) = tad_syntax::analyze(src);
    assert!(errors(&diagnostics).is_empty(), "{name}: {diagnostics:?}");
    let tad = tad_yaml::to_tad(&model);
    let (_, again) = tad_syntax::analyze(&tad);
    assert!(errors(&again).is_empty(), "{name}: to_tad output does not check: {again:?}\n{tad}");
    assert_eq!(tad_syntax::format::format(&tad).as_deref(), Ok(tad.as_str()), "{name}: to_tad is not canonical");

    let yaml = tad_yaml::export(&model, src);
    assert!(serde_norway::from_str::<serde_norway::Value>(&yaml).is_ok(), "{name}: export is not YAML\n{yaml}");
    let (imported, diagnostics) = tad_yaml::lower(&yaml);
    assert!(diagnostics.is_empty(), "{name}: importing the export gives {diagnostics:?}\n{yaml}");
    assert_spans_valid(&yaml, &diagnostics);
    assert_eq!(tad_yaml::to_tad(&imported), tad, "{name}: export → lower changed the scenario\n{yaml}");
}

#[test]
fn every_example_survives_export_and_import() {
    let examples = files(&repo().join("examples"), "tad");
    assert!(examples.len() >= 18, "{examples:?}");
    for path in examples {
        let src = read(&path);
        let name = path.display().to_string();
        round_trip(&name, &src);
        let (model, _) = tad_syntax::analyze(&src);
        assert_eq!(tad_yaml::to_tad(&model), without_comments(&src), "{name}: to_tad differs from the example");
    }
}

#[test]
fn everything_tad_can_say_survives() {
    let src = r#"use national_park
use regions.usa

scenario everything {
  source {
    video: "clip \"7\": a\\b.mp4"
    time: 195.5 s
    frame: 4680
    region: los_angeles
    description: """
      Line one: with a colon, # a hash, and "quotes".
        An indented line.

      After a blank line, unicode é ü 🚗.
    """
  }
  environment {
    weather: partially_cloudy
    time: unspecified
  }
  road {
    type: t_intersection
    context: unspecified
    lanes: 3
    direction: one_way
    special_lanes: [bike_lane, tram_track]
    signs: [stop_sign, yield_sign, none]
    light: none
    traffic: unspecified
    hazards: []
    roadworks: unspecified
    emergency_vehicles: [ambulance]
    roadside: [sidewalk]
  }
  ego {
    behavior: turn_left
    speed: 12.5 m/s
    lane: unspecified
  }
  actor yes: unspecified unspecified {
    behavior: unspecified
    speed: unspecified
    position: unspecified
    lane: -2
  }
  actor on: 3 pedestrian {
    position: left_front of yes
    speed: 3 mph
    distance: 12..20 m
    delay: 1.5 s
  }
  actor late: 1 car {
    position: behind of ego
    lane: 1
    trigger: 30 m
    offset: -2.5..4 m
  }
  actor x_9: bus {
    position: behind of traffic_light
  }
  actor null: 2 null {
    behavior: null
  }
  actor one_way_street_user: car {
  }
}
"#;
    round_trip("everything", src);
}

#[test]
fn awkward_names_and_texts_survive() {
    for (field, value) in [
        ("weather", "clear_night"),
        ("weather", "night"),
        ("time", "true"),
        ("time", "_x"),
        ("time", "a__b"),
        ("weather", "none"),
    ] {
        let src = format!("scenario demo {{\n  environment {{\n    {field}: {value}\n  }}\n}}\n");
        round_trip(&format!("{field}: {value}"), &src);
    }
    for road_type in
        ["one_way_street", "two_way_road_with_bike_lane", "road", "straight_road_and_more", "y_intersection"]
    {
        let src = format!("scenario demo {{\n  road {{\n    type: {road_type}\n  }}\n}}\n");
        round_trip(road_type, &src);
    }
    for text in [
        "\\\"\\\"\\\"",
        "a\\nb\\\"\\\"\\\"c",
        "a\\u{0}b",
        "x\\ty",
        "trailing \\n",
        "\\u{2028}\\u{feff}\\u{85}",
        "\\r\\n",
        " lead",
    ] {
        let src = format!("scenario demo {{\n  source {{\n    description: \"{text}\"\n  }}\n}}\n");
        round_trip(text, &src);
    }
    round_trip("no scenario name", "scenario demo {\n  ego {\n  }\n}\n");
}

#[test]
fn speed_and_count_ranges_survive() {
    let src = "scenario ranged {\n  ego {\n    behavior: go_forward\n    speed: 25..30 km/h\n    lane: 1\n  }\n  actor walkers: 3..5 pedestrian {\n    behavior: cross\n    speed: 3.5..5 km/h\n    position: front of ego\n    lane: 1\n  }\n}\n";
    round_trip("ranges", src);
    let (model, _) = tad_syntax::analyze(src);
    let yaml = tad_yaml::export(&model, src);
    assert!(yaml.contains("speed: 25-30 km/h") && yaml.contains("number: 3-5"), "{yaml}");
}
