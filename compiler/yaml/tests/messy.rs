//! Messy LLM answers: never a panic, always located diagnostics.

mod common;
use common::*;
use tad_diagnostics::Code;
use tad_syntax::model::*;

fn lower(text: &str) -> (Module, Vec<tad_diagnostics::Diagnostic>) {
    let (model, diagnostics) = tad_yaml::lower(text);
    assert_spans_valid(text, &diagnostics);
    if model.scenario.is_some() {
        let tad = tad_yaml::to_tad(&model);
        let (_, again) = tad_syntax::analyze(&tad);
        assert!(errors(&again).is_empty(), "{again:?}\n{tad}");
    }
    (model, diagnostics)
}

fn codes_at(text: &str) -> Vec<String> {
    let (_, d) = lower(text);
    located(text, &d)
}

fn tad(text: &str) -> String {
    tad_yaml::to_tad(&lower(text).0)
}

#[test]
fn empty_and_junk_inputs() {
    assert_eq!(codes_at(""), ["E0300@1"]);
    assert_eq!(codes_at("   \n\n"), ["E0300@1"]);
    assert_eq!(codes_at("<YAML>\n</YAML>"), ["E0300@1"]);
    assert_eq!(codes_at("prose\n<YAML>\n# only a comment\n</YAML>"), ["E0300@2"]);
    assert_eq!(codes_at("\n\nI cannot help with that."), ["E0300@3"]);
    let junk = String::from_utf8_lossy(&[0, 1, 2, 0xff, 0xfe, b'<', b'Y', b'A', b'M', b'L', b'>', 0x80, b':', 0x1b])
        .into_owned();
    let (model, d) = lower(&junk);
    assert!(model.scenario.is_none());
    assert!(d.iter().all(|d| d.code == Code::E0301 || d.code == Code::E0300), "{d:?}");
    assert!(!d.is_empty());
    for text in ["- a\n- b", "42", "\"just a string\"", "[environment]", "{", "}", ":", "---\n---", "<YAML>- x</YAML>"]
    {
        let (_, d) = lower(text);
        assert!(!errors(&d).is_empty(), "{text:?}: {d:?}");
    }
}

#[test]
fn trafficcomposer_none_is_unspecified() {
    let text = "participant:\n    ego_vehicle:\n        current_behavior: None\n        speed: None\n        lane_idx: None\n    other_actor_1:\n        type: car\n        current_behavior: go forward\n        position_relation: None\n        position_target: None\n        speed: \"30 mph\"\n";
    let (model, d) = lower(text);
    assert!(d.is_empty(), "{d:?}");
    let s = model.scenario.unwrap();
    assert_eq!(s.attr("ego", "speed").unwrap().value, Known::Unspecified);
    assert_eq!(s.attr("ego", "behavior").unwrap().value, Known::Unspecified);
    assert_eq!(s.attr("ego", "lane").unwrap().value, Known::Unspecified);
    let car = s.actor("other_actor_1").unwrap();
    assert_eq!(car.attr("position").unwrap().value, Known::Unspecified);
    let speed = car.attr("speed").unwrap().quantity().unwrap();
    assert_eq!((speed.value, speed.unit.as_str()), (30.0, "mph"));
    // a `None` light in TrafficComposer is "not mentioned"; in the paper's form `none` is no light
    assert!(tad("road_network:\n  - intersection\ntraffic_signal: None\n").contains("light: unspecified"));
    assert!(tad("road_network:\n  traffic_light: none\n").contains("light: none"));
    assert!(
        tad("participant:\n  a:\n    type: car\nroad_network:\n  traffic_sign: None\n").contains("signs: unspecified")
    );
    assert!(tad("road_network:\n  traffic_sign: none\n").contains("signs: []"));
}

#[test]
fn values_are_normalised_not_canonicalised() {
    let text = "environment:\n  weather: Sunny\n  time: NIGHT\nroad_network:\n  road_type: T-Intersection\n  road_context: Country Road\n  traffic_sign: stop sign\n  lane_number: \"2\"\n  one-way_or_two-way: One-Way\nactors:\n  Ego Vehicle:\n    behavior: Move Forward\n    speed: 30\n  2nd car:\n    type: SUV\n    behavior: turn-left\n    speed: 5 m/s\n    position_relation: front left\n    position_target: ego vehicle\n    lane_index: -1\n";
    let (_, d) = lower(text);
    assert!(d.is_empty(), "{d:?}");
    assert_eq!(
        tad(text),
        "scenario unnamed {\n  environment {\n    weather: sunny\n    time: night\n  }\n  road {\n    type: t_intersection\n    context: country_road\n    lanes: 2\n    direction: one_way\n    signs: [stop_sign]\n  }\n  ego {\n    behavior: move_forward\n    speed: 30 km/h\n  }\n  actor _2nd_car: suv {\n    behavior: turn_left\n    speed: 5 m/s\n    position: front_left of ego\n    lane: -1\n  }\n}\n"
    );
}

#[test]
fn road_type_text_sets_direction_and_special_lanes() {
    let out = tad("road_network:\n  road_type: two-way straight road with bike lane\n");
    assert!(out.contains("type: straight_road\n    direction: two_way\n    special_lanes: [bike_lane]"), "{out}");
    // the explicit key wins, silently when it agrees
    let text = "road_network:\n  road_type: one-way intersection\n  one-way_or_two-way: one-way\n";
    assert!(lower(text).1.is_empty());
    let text = "road_network:\n  road_type: one-way intersection\n  one-way_or_two-way: two-way\n";
    assert_eq!(codes_at(text), ["W0301@2"]);
    assert!(tad(text).contains("direction: two_way"));
}

#[test]
fn positions() {
    let text = "actors:\n  lead:\n    type: car\n    position_relation: front\n  follower:\n    type: car\n    position_relation: behind\n    position_target: lead\n  unknown:\n    type: car\n    position_relation: unspecified\n    position_target: ego_vehicle\n  at_light:\n    type: car\n    position_relation: behind\n    position_target: traffic light\n";
    let out = tad(text);
    assert!(out.contains("actor lead: car {\n    position: front of ego"), "{out}");
    assert!(out.contains("position: behind of lead"), "{out}");
    assert!(out.contains("actor unknown: car {\n    position: unspecified"), "{out}");
    assert!(out.contains("position: behind of traffic_light"), "{out}");
    assert_eq!(codes_at("actors:\n  a:\n    position_relation: left/front\n"), ["E0303@3"]);
}

#[test]
fn bad_values_point_at_their_line() {
    let text = "<YAML>\nenvironment:\n    weather: 42\nroad_network:\n    lane_number: many\n    lane_number2: 2\n    special_lane: [bike lane, {x: 1}]\nactors:\n    ego_vehicle:\n        speed: fast\n        lane_index: 1.5\n    bus:\n        number: 2.0\n        speed: 30-40 km/h\n        type: [bus]\n</YAML>\n";
    assert_eq!(
        codes_at(text),
        // `many` lanes and a `fast` speed give no number: warnings, read as unspecified; 30-40 km/h is a range
        ["E0303@3", "W0302@5", "E0302@6", "E0304@7", "W0302@10", "E0303@11", "E0303@13", "E0304@15"]
    );
    let (_, d) = lower(text);
    let unknown = d.iter().find(|d| d.code == Code::E0302).unwrap();
    assert_eq!(unknown.help.as_deref(), Some("did you mean `lane_number`?"));
    let fraction = d.iter().find(|d| d.message.contains("2.0")).unwrap();
    assert_eq!(fraction.fixes[0].replacement, "2");
}

#[test]
fn unknown_keys_get_suggestions() {
    let text = "environment:\n  wether: clear\n  time_of_day: day\nroad_network:\n  lanes: 2\nactors:\n  a:\n    postion_target: ego\n    count: 3\nenviroment: x\n";
    let (_, d) = lower(text);
    let helps: Vec<(String, Option<String>)> =
        d.iter().map(|d| (located(text, std::slice::from_ref(d))[0].clone(), d.help.clone())).collect();
    let expect = |at: &str, guess: &str| {
        assert!(
            helps.iter().any(|(l, h)| l == at && h.as_deref() == Some(&format!("did you mean `{guess}`?"))),
            "{at} {guess}: {helps:?}"
        )
    };
    expect("E0302@2", "weather");
    expect("E0302@3", "time");
    expect("E0302@5", "lane_number");
    expect("E0302@8", "position_target");
    expect("E0302@9", "number");
    expect("E0302@10", "environment");
}

#[test]
fn syntax_errors_are_located_and_the_rest_is_read() {
    let text = "Here is the YAML.\n```yaml\nenvironment:\n  weather: clear\n   time: day\nroad_network:\n  lane_number: 2\n  road_type: \"straight road\n  traffic_light: green\nactors:\n  ego_vehicle:\n    speed: 30 km/h\n  a:\n    type: car\n  a:\n    type: bus\n```\n";
    let located = codes_at(text);
    assert!(located.contains(&"E0301@5".to_string()), "{located:?}");
    assert!(located.contains(&"E0301@8".to_string()), "{located:?}");
    assert!(located.contains(&"E0301@15".to_string()), "{located:?}");
    let out = tad(text);
    assert!(out.contains("speed: 30 km/h"), "{out}");
    assert!(out.contains("lanes: 2"), "{out}");
}

#[test]
fn tags_and_fences_and_trailing_junk() {
    let yaml = "environment:\n  weather: clear\n";
    for answer in [
        format!("<YAML>\n{yaml}</YAML>\nsome: [junk"),
        format!("<yaml>{yaml}</yaml>"),
        format!("Reasoning...\n```yaml\n{yaml}```\nMore: {{junk"),
        format!("```\n{yaml}```"),
        format!("<YAML>\n```yml\n{yaml}```\n</YAML>"),
        format!("first try <YAML>\nenvironment:\n  weather: rainy\n</YAML> final <YAML>\n{yaml}</YAML>"),
        yaml.to_string(),
        format!("Answer:\n\n{yaml}\nDone."),
    ] {
        let (model, d) = lower(&answer);
        assert!(d.is_empty(), "{answer}: {d:?}");
        let weather = model.scenario.unwrap().attr("environment", "weather").unwrap().symbol().unwrap().clone();
        assert_eq!(weather.name, "clear", "{answer}");
        assert_eq!(&answer[weather.span.start..weather.span.end], "clear");
    }
}

#[test]
fn mph_and_other_units() {
    for (speed, value, unit) in [
        ("30 km/h", 30.0, "km/h"),
        ("\"30 mph\"", 30.0, "mph"),
        ("30", 30.0, "km/h"),
        ("12.5", 12.5, "km/h"),
        ("5 m/s", 5.0, "m/s"),
        ("40kph", 40.0, "km/h"),
        ("about 20 km/h", 20.0, "km/h"),
    ] {
        let text = format!("actors:\n  ego_vehicle:\n    speed: {speed}\n");
        let (model, d) = lower(&text);
        assert!(d.is_empty(), "{speed}: {d:?}");
        let q = model.scenario.unwrap().attr("ego", "speed").unwrap().quantity().unwrap();
        assert_eq!((q.value, q.unit.as_str()), (value, unit), "{speed}");
    }
    for speed in ["30 s", "30-40 s", "30 km/h-40 mph", "[30]", "true", ".nan", "1e999"] {
        let text = format!("actors:\n  ego_vehicle:\n    speed: {speed}\n");
        assert_eq!(errors(&lower(&text).1).len(), 1, "{speed}");
    }
    // words: `stopped` is 0 km/h (the paper's rule); `fast` gives no number, a warning
    let (model, d) = lower("actors:\n  ego_vehicle:\n    speed: stopped\n");
    assert!(d.is_empty(), "{d:?}");
    assert_eq!(model.scenario.unwrap().attr("ego", "speed").unwrap().quantity().map(|q| q.value), Some(0.0));
    let (model, d) = lower("actors:\n  ego_vehicle:\n    speed: fast\n");
    assert_eq!(d.iter().map(|d| d.code).collect::<Vec<_>>(), [Code::W0302]);
    assert!(matches!(model.scenario.unwrap().attr("ego", "speed").unwrap().value, Known::Unspecified));
}

#[test]
fn ranges_of_speeds_and_counts() {
    for speed in
        ["25-30 km/h", "25 - 30 km/h", "25 to 30 km/h", "between 25 and 30 km/h", "25 km/h - 30 km/h", "30-25 km/h"]
    {
        let text = format!("actors:\n  ego_vehicle:\n    speed: {speed}\n");
        let (model, d) = lower(&text);
        assert!(d.is_empty(), "{speed}: {d:?}");
        let attr = model.scenario.unwrap().attr("ego", "speed").cloned().unwrap();
        assert_eq!(
            attr.bounds().map(|(l, h)| (l * 3.6, h * 3.6)).map(|(l, h)| (l.round(), h.round())),
            Some((25.0, 30.0)),
            "{speed}"
        );
        assert!(tad(&text).contains("speed: 25..30 km/h"), "{speed}");
    }
    for count in ["3-5", "3 to 5", "between 3 and 5"] {
        let text = format!("actors:\n  walkers:\n    type: pedestrian\n    number: {count}\n");
        let (model, d) = lower(&text);
        assert!(d.is_empty(), "{count}: {d:?}");
        assert_eq!(model.scenario.unwrap().actors[0].count_bounds(), Some((3, 5)), "{count}");
        assert!(tad(&text).contains("actor walkers: 3..5 pedestrian"), "{count}");
    }
}

#[test]
fn lists_accept_the_paper_and_yaml_spellings() {
    assert!(tad("road_network:\n  traffic_sign: stop sign\n").contains("signs: [stop_sign]"));
    assert!(tad("road_network:\n  traffic_sign: stop sign, yield sign\n").contains("signs: [stop_sign, yield_sign]"));
    assert!(
        tad("road_network:\n  traffic_sign:\n    - stop sign\n    - school zone\n")
            .contains("signs: [stop_sign, school_zone]")
    );
    assert!(tad("road_network:\n  traffic_sign: [none]\n").contains("signs: []"));
    assert!(tad("road_network:\n  traffic_sign: unspecified\n").contains("signs: unspecified"));
    assert!(tad("road_network:\n  special_lane: none\n").contains("special_lanes: []"));
    assert_eq!(codes_at("road_network:\n  hazards: [a, b, a]\n"), ["W0201@2"]);
    // `signs` holds the full list, `traffic_sign` one of it: no conflict
    assert!(lower("road_network:\n  traffic_sign: stop sign\n  signs: [stop sign, yield sign]\n").1.is_empty());
}

#[test]
fn ego_extras_are_ignored_with_a_warning() {
    let text = "participant:\n  ego_vehicle:\n    type: car\n    position_target: intersection\n    position_relation: behind\n";
    assert_eq!(codes_at(text), ["W0302@3", "W0302@4"]);
    assert!(lower("actors:\n  ego_vehicle:\n    type: none\n    position_target: unspecified\n    position_relation: unspecified\n").1.is_empty());
}

#[test]
fn wrappers_and_names() {
    let text = "scenario:\n  environment:\n    weather: clear\n";
    assert!(tad(text).contains("weather: clear"));
    let text = "traffic_scenario:\n  environment:\n    weather: clear\n";
    assert!(tad(text).contains("weather: clear"));
    let text = "scenario: Left Turn At Night\nuse: [national_park]\nenvironment:\n  weather: clear\n";
    assert!(tad(text).starts_with("use national_park\n\nscenario left_turn_at_night {"));
}

#[test]
fn words_for_unknown_values_are_unspecified_and_none_is_lost_silently() {
    for word in ["unknown", "N/A", "n/a", "not visible", "Unclear", "\"?\""] {
        let text = format!("environment:\n  weather: {word}\nactors:\n  ego_vehicle:\n    lane_index: {word}\n");
        let (model, d) = lower(&text);
        assert!(d.is_empty(), "{word}: {d:?}");
        let scenario = model.scenario.unwrap();
        assert!(matches!(scenario.attr("environment", "weather").unwrap().value, Known::Unspecified), "{word}");
        assert!(matches!(scenario.attr("ego", "lane").unwrap().value, Known::Unspecified), "{word}");
    }
    // a count in words is its number; a count word that gives none is said, not taken as 1
    let (model, d) = lower("actors:\n  a:\n    type: car\n    number: two\n");
    assert!(d.is_empty(), "{d:?}");
    assert_eq!(model.scenario.unwrap().actors[0].count(), Some(2));
    let (model, d) = lower("actors:\n  a:\n    type: car\n    number: a few\n");
    assert_eq!(d.iter().map(|d| d.code).collect::<Vec<_>>(), [Code::W0302]);
    assert_eq!(model.scenario.unwrap().actors[0].count(), None, "not silently one");
    // TrafficComposer's `road_network: None` states no road
    let (model, d) = lower(
        "environment:\n  weather: clear\nroad_network: None\nparticipant:\n  ego_vehicle:\n    current_behavior: go forward\n",
    );
    assert!(errors(&d).is_empty(), "{d:?}");
    assert!(model.scenario.unwrap().section("road").is_none_or(|r| r.attrs.is_empty()));
}

#[test]
fn a_stray_closing_fence_does_not_hide_the_answer() {
    let text = "environment:\n  weather: clear\n  time: daytime\n```\n";
    let (model, d) = lower(text);
    assert!(errors(&d).is_empty(), "{d:?}");
    assert!(model.scenario.unwrap().attr("environment", "time").is_some());
}

#[test]
fn lanes_named_by_where_they_are() {
    let lane = |s: &Scenario, group: Option<&str>| match group {
        Some(g) => s.actor(g).unwrap().attr("lane").unwrap().value.clone(),
        None => s.attr("ego", "lane").unwrap().value.clone(),
    };
    let text = "road_network:\n  lane_number: 3\nactors:\n  ego_vehicle:\n    lane_index: Rightmost lane\n  Car 1:\n    type: car\n    lane_index: leftmost\n";
    let (model, d) = lower(text);
    assert!(errors(&d).is_empty(), "{d:?}");
    let s = model.scenario.unwrap();
    assert_eq!(lane(&s, None), Known::Given(Val::Integer(3)));
    assert_eq!(lane(&s, Some("car_1")), Known::Given(Val::Integer(1)));
    // without the road's lanes, rightmost has no number
    let text = "actors:\n  ego_vehicle:\n    lane_index: rightmost\n";
    assert_eq!(codes_at(text), ["E0217@3"]);
    // the same words in TAD
    let (model, d) = tad_syntax::analyze(
        "scenario lanes { road { lanes: 4 } ego { lane: rightmost } actor a: car { lane: leftmost } }",
    );
    assert!(d.is_empty(), "{d:?}");
    let s = model.scenario.unwrap();
    assert_eq!(lane(&s, None), Known::Given(Val::Integer(4)));
    assert_eq!(lane(&s, Some("a")), Known::Given(Val::Integer(1)));
}
