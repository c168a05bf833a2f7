//! The baseline generator: scenarios that know TAD's language but no region.
//!
//! It is the unaligned reference of both experiments: a row of `tadslc eval`'s table
//! (`--generators baseline`, each region drawing its own sample) and the "unaligned
//! baseline" of the recovery experiment (`tadslc bench --align`). Every choice is uniform
//! over a fixed list of common names; the same seed gives the same scenarios on every
//! machine. Each scenario also comes as an equivalent JSON document, so `tadslc bench` can
//! compare the front end with a production JSON parser on the same content.

use tad_base::{Rng, SplitMix64};
use tad_db::Database;

const WEATHER: &[&str] = &["clear", "cloudy", "foggy", "rainy", "snowy", "wet"];
const TIME: &[&str] = &["daytime", "nighttime", "dawn", "dusk"];
const ROAD: &[&str] = &["straight_road", "curved_road", "intersection", "t_intersection", "roundabout"];
const CONTEXT: &[&str] = &["urban", "residential", "highway", "country_road", "dirt_road", "hill_road"];
const SIGNS: &[&str] = &["stop_sign", "speed_limit_sign", "yield_sign", "yield_to_pedestrian_sign", "school_zone"];
const LIGHT: &[&str] = &["green", "red", "yellow", "broken", "none"];
const TRAFFIC: &[&str] = &["free_flow", "light", "moderate", "heavy", "jam"];
const ROADSIDE: &[&str] = &["sidewalk", "buildings", "trees", "shops", "parked_cars", "fields", "forest", "houses"];
const TYPES: &[&str] = &["sedan", "suv", "car", "truck", "bus", "van", "taxi", "motorcycle", "bicycle", "pedestrian"];
const BEHAVIORS: &[&str] =
    &["move_forward", "stopped", "parked", "turn_left", "turn_right", "change_lane_left", "yield"];
const RELATIONS: &[&str] =
    &["front", "behind", "left", "right", "left_front", "right_front", "left_behind", "right_behind"];
const REGIONS: &[&str] = &["los_angeles", "new_york_city", "yellowstone", "yosemite", "switzerland"];

/// The generator's choices by declaration kind: which common names it draws from (its
/// distribution); every name is declared in `stdlib/`, which a test holds.
pub const CHOICES: &[(&str, &[&str])] = &[
    ("weather", WEATHER),
    ("time_of_day", TIME),
    ("road_type", ROAD),
    ("road_context", CONTEXT),
    ("traffic_sign", SIGNS),
    ("light_state", LIGHT),
    ("traffic_density", TRAFFIC),
    ("roadside", ROADSIDE),
    ("actor_type", TYPES),
    ("behavior", BEHAVIORS),
    ("relation", RELATIONS),
    ("region", REGIONS),
];

/// One generated scenario in TAD and in JSON.
pub struct Generated {
    pub tad: String,
    pub json: String,
}

/// Scenario `index`, drawn from `rng`.
pub fn scenario(rng: &mut SplitMix64, index: usize) -> Generated {
    use std::fmt::Write;
    let lanes = 1 + rng.below(4) as i64;
    let two_way = rng.chance(70);
    let weather = rng.pick(WEATHER);
    let time = rng.pick(TIME);
    let road = rng.pick(ROAD);
    let context = rng.pick(CONTEXT);
    let light = rng.pick(LIGHT);
    let traffic = rng.pick(TRAFFIC);
    let signs: Vec<&str> =
        (0..rng.below(3)).map(|_| *rng.pick(SIGNS)).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
    let roadside: Vec<&str> = (0..1 + rng.below(3))
        .map(|_| *rng.pick(ROADSIDE))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let region = rng.pick(REGIONS);
    let ego_speed = rng.below(80);
    let ego_lane = 1 + rng.below(lanes as usize) as i64;
    let direction = if two_way { "two_way" } else { "one_way" };

    let mut tad = String::new();
    let mut json = String::new();
    let _ = write!(
        tad,
        "// generated scenario {index}\nscenario generated_{index} {{\n  source {{\n    video: \"video_{index}.mp4\"\n    time: {} s\n    region: {region}\n  }}\n  \
         environment {{\n    weather: {weather}\n    time: {time}\n  }}\n  road {{\n    type: {road}\n    context: {context}\n    lanes: {lanes}\n    \
         direction: {direction}\n    signs: [{}]\n    light: {light}\n    traffic: {traffic}\n    roadside: [{}]\n  }}\n  \
         ego {{\n    behavior: move_forward\n    speed: {ego_speed} km/h\n    lane: {ego_lane}\n  }}\n",
        15 * index,
        signs.join(", "),
        roadside.join(", "),
    );
    let quoted = |items: &[&str]| items.iter().map(|s| format!("\"{s}\"")).collect::<Vec<_>>().join(",");
    let _ = write!(
        json,
        "{{\"name\":\"generated_{index}\",\"source\":{{\"video\":\"video_{index}.mp4\",\"time\":{{\"value\":{},\"unit\":\"s\"}},\"region\":\"{region}\"}},\
         \"environment\":{{\"weather\":\"{weather}\",\"time\":\"{time}\"}},\"road\":{{\"type\":\"{road}\",\"context\":\"{context}\",\"lanes\":{lanes},\
         \"direction\":\"{direction}\",\"signs\":[{}],\"light\":\"{light}\",\"traffic\":\"{traffic}\",\"roadside\":[{}]}},\
         \"ego\":{{\"behavior\":\"move_forward\",\"speed\":{{\"value\":{ego_speed},\"unit\":\"km/h\"}},\"lane\":{ego_lane}}},\"actors\":[",
        15 * index,
        quoted(&signs),
        quoted(&roadside),
    );
    let groups = rng.below(8);
    for g in 0..groups {
        let count = 1 + rng.below(10);
        let kind = rng.pick(TYPES);
        let behavior = rng.pick(BEHAVIORS);
        let speed = if *behavior == "parked" { 0 } else { rng.below(60) };
        let relation = rng.pick(RELATIONS);
        let max = lanes as usize;
        let lane = if two_way && rng.chance(30) { -(1 + rng.below(max) as i64) } else { 1 + rng.below(max) as i64 };
        let _ = write!(
            tad,
            "  actor group_{g}: {count} {kind} {{\n    behavior: {behavior}\n    speed: {speed} km/h\n    position: {relation} of ego\n    lane: {lane}\n  }}\n"
        );
        let _ = write!(
            json,
            "{}{{\"name\":\"group_{g}\",\"count\":{count},\"type\":\"{kind}\",\"behavior\":\"{behavior}\",\"speed\":{{\"value\":{speed},\"unit\":\"km/h\"}},\
             \"position\":{{\"relation\":\"{relation}\",\"reference\":\"ego\"}},\"lane\":{lane}}}",
            if g == 0 { "" } else { "," }
        );
    }
    tad.push_str("}\n");
    json.push_str("]}");
    Generated { tad, json }
}

/// `n` scenarios from `seed`, whether they check or not (the benchmark's corpus).
pub fn generate(n: usize, seed: u64) -> Vec<Generated> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|i| scenario(&mut rng, i)).collect()
}

/// Up to `n` scenarios that count (no errors) from the first `4 n` drawn with `seed`:
/// (index from 0, TAD text). Each is registered in `db` under `NAME.tad` as `name(index)`
/// gives it.
pub fn sample(db: &mut Database, n: usize, seed: u64, name: impl Fn(usize) -> String) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (i, g) in generate(4 * n.max(1), seed).into_iter().enumerate() {
        if out.len() == n {
            break;
        }
        let name = name(i);
        let kept = crate::corpus::counting(db, "", vec![(name, g.tad)]);
        out.extend(kept);
    }
    out
}

/// The seed of region `region`'s sample: each region draws its own sample of the same
/// generator (FNV-1a of the name, mixed with the seed).
pub fn region_seed(seed: u64, region: &str) -> u64 {
    tad_base::fnv1a_seeded(seed, region.bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_choice_is_a_declared_name_of_its_kind() {
        let vocabulary = tad_db::vocabulary_of(&[]);
        for (kind, names) in CHOICES {
            for name in *names {
                assert!(
                    vocabulary.get(kind, name).is_some_and(|e| e.name == *name),
                    "`{name}` is not a {kind} declared in stdlib/ (under that name)"
                );
            }
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_corpus() {
        let a: Vec<String> = generate(20, 7).into_iter().map(|g| g.tad).collect();
        let b: Vec<String> = generate(20, 7).into_iter().map(|g| g.tad).collect();
        let c: Vec<String> = generate(20, 8).into_iter().map(|g| g.tad).collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn generated_scenarios_are_clean_formatted_and_valid_json() {
        for g in generate(200, 3) {
            let (module, diagnostics) = tad_syntax::analyze(&g.tad);
            assert!(diagnostics.is_empty(), "{diagnostics:?}\n{}", g.tad);
            assert!(module.scenario.is_some());
            assert_eq!(tad_syntax::format::format(&g.tad).as_deref(), Ok(g.tad.as_str()));
            let value: serde_json::Value = serde_json::from_str(&g.json).expect("valid JSON");
            let groups = module.scenario.map(|s| s.actors.len()).unwrap_or(0);
            assert_eq!(value["actors"].as_array().map(Vec::len), Some(groups));
        }
    }

    #[test]
    fn a_sample_counts_and_differs_by_region() {
        let mut db = Database::new(tad_check::Options::default());
        let a = sample(&mut db, 5, region_seed(0, "los_angeles"), |i| format!("a_{i}"));
        let b = sample(&mut db, 5, region_seed(0, "yellowstone"), |i| format!("b_{i}"));
        assert!(!a.is_empty() && a.len() <= 5, "{}", a.len());
        assert_ne!(a.iter().map(|(_, t)| t).collect::<Vec<_>>(), b.iter().map(|(_, t)| t).collect::<Vec<_>>());
        let mut fresh = Database::new(tad_check::Options::default());
        for (name, text) in a.iter().chain(&b) {
            let file =
                fresh.set_source(format!("{name}.tad").into(), text.clone(), tad_db::Language::Tad, &tad_db::RealFs);
            assert!(crate::counts(tad_db::check(&fresh, file).class), "{text}");
        }
    }
}
