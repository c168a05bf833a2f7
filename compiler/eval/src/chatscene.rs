//! The ChatScene-style generator (`--generators chatscene`): ChatScene's eight
//! safety-critical categories (SafeBench's scenario types) as parameterised TAD templates,
//! whose adversaries carry ChatScene's `OPT_*` ranges as TAD ranges, so the search narrows
//! them as ChatScene's does (`spec/eval.md` §2). Region-agnostic, like ChatScene's
//! snippet database: every region draws its own sample from the same templates.
//!
//! Scenario `i` of a region takes category `i mod 8`; its adversary (one of five per
//! category, as ChatScene writes five behaviours per category), weather and time of day are
//! drawn by SplitMix64 seeded with the region's seed and `i`.
//!
//! Facts carried over (`../shared/notes/runtime-and-metrics.md` §5): the categories and
//! their standard adversaries (SafeBench's `scenario_definition/standard`); ChatScene's
//! ranges: category 1 the adversary at 0–5 m/s, 15–50 m ahead, starting within 0–15 m of
//! the ego; category 3 a leading vehicle 0–30 m ahead at 1–5 m/s and the adversary at
//! 5–10 m/s; categories 5–8 the adversary at 5–15 m/s. Categories 2 and 4 have no published
//! ranges: they take 5–15 m/s, around SafeBench's 10 and 8 m/s. ChatScene's
//! `OPT_STOP_DISTANCE` (a walker stopping after it crossed) and `OPT_THROTTLE` have no TAD
//! field and are left out.

use tad_base::SplitMix64;
use tad_db::{Database, Language, RealFs};
use tad_ir::Rng;

use crate::corpus::counts;

/// One category: its name, road, ego, and the groups around it; `{adv}` and `{how}` stand
/// for the drawn adversary's type and behaviour.
struct Category {
    name: &'static str,
    road: &'static str,
    ego: &'static str,
    actors: &'static str,
    /// The five adversaries: (actor type, behaviour).
    adversaries: [(&'static str, &'static str); 5],
}

/// The vehicles that come at the ego straight on or across, where a category's adversary
/// is any of them.
const ONCOMING_OR_CROSSING: [(&str, &str); 5] = [
    ("car", "move_forward"),
    ("suv", "move_forward"),
    ("van", "move_forward"),
    ("truck", "move_forward"),
    ("motorcycle", "move_forward"),
];

/// SafeBench's eight categories, in its order.
const CATEGORIES: [Category; 8] = [
    Category {
        name: "straight_obstacle",
        road: "type: straight_road\n    lanes: 2\n    direction: two_way\n    light: none\n    roadside: [sidewalk, parked_cars]",
        ego: "behavior: move_forward\n    speed: 8..12 m/s\n    lane: 1",
        actors: "actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 0..5 m/s\n    position: front of ego\n    lane: 1\n    distance: 15..50 m\n    trigger: 0..15 m\n  }",
        adversaries: [
            ("pedestrian", "cross"),
            ("pedestrian", "run"),
            ("bicycle", "cross"),
            ("construction_worker", "cross"),
            ("pedestrian", "walk"),
        ],
    },
    Category {
        name: "turning_obstacle",
        road: "type: intersection\n    lanes: 2\n    direction: two_way\n    light: green",
        ego: "behavior: turn_left\n    speed: 4..8 m/s\n    lane: 1",
        actors: "actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..15 m/s\n    position: left_front of ego\n    lane: 1\n  }",
        adversaries: [
            ("bicycle", "cross"),
            ("motorcycle", "cross"),
            ("bicycle", "move_forward"),
            ("motorcycle", "move_forward"),
            ("car", "move_forward"),
        ],
    },
    Category {
        name: "lane_changing",
        road: "type: straight_road\n    lanes: 3\n    direction: one_way\n    light: none",
        ego: "behavior: move_forward\n    speed: 10..14 m/s\n    lane: 2",
        actors: "actor leading: 1 car {\n    behavior: move_forward\n    speed: 1..5 m/s\n    position: front of ego\n    lane: 2\n    distance: 0..30 m\n  }\n  actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..10 m/s\n    position: left_front of ego\n    lane: 1\n  }",
        adversaries: [
            ("car", "change_lane_right"),
            ("suv", "change_lane_right"),
            ("van", "change_lane_right"),
            ("truck", "merge_right"),
            ("motorcycle", "change_lane_right"),
        ],
    },
    Category {
        name: "vehicle_passing",
        road: "type: straight_road\n    lanes: 1\n    direction: two_way\n    light: none",
        ego: "behavior: overtake\n    speed: 8..12 m/s\n    lane: 1",
        actors: "actor obstacle: 1 truck {\n    behavior: parked\n    speed: 0 m/s\n    position: front of ego\n    lane: 1\n    distance: 50 m\n  }\n  actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..15 m/s\n    position: front of ego\n    lane: -1\n    distance: 80 m\n  }",
        adversaries: ONCOMING_OR_CROSSING,
    },
    Category {
        name: "red_light_running",
        road: "type: intersection\n    lanes: 2\n    direction: two_way\n    light: green",
        ego: "behavior: move_forward\n    speed: 8..12 m/s\n    lane: 1",
        actors: "actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..15 m/s\n    position: right_front of ego\n    lane: 1\n  }",
        adversaries: [
            ("sedan", "move_forward"),
            ("suv", "move_forward"),
            ("truck", "move_forward"),
            ("taxi", "move_forward"),
            ("motorcycle", "move_forward"),
        ],
    },
    Category {
        name: "unprotected_left_turn",
        road: "type: intersection\n    lanes: 1\n    direction: two_way\n    light: green",
        ego: "behavior: turn_left\n    speed: 4..8 m/s\n    lane: 1",
        actors: "actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..15 m/s\n    position: front of ego\n    lane: -1\n  }",
        adversaries: ONCOMING_OR_CROSSING,
    },
    Category {
        name: "right_turn",
        road: "type: intersection\n    lanes: 1\n    direction: two_way\n    light: green",
        ego: "behavior: turn_right\n    speed: 4..8 m/s\n    lane: 1",
        actors: "actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..15 m/s\n    position: left_front of ego\n    lane: 1\n  }",
        adversaries: [
            ("car", "move_forward"),
            ("suv", "move_forward"),
            ("van", "move_forward"),
            ("bus", "move_forward"),
            ("motorcycle", "move_forward"),
        ],
    },
    Category {
        name: "crossing_negotiation",
        road: "type: intersection\n    lanes: 1\n    direction: two_way\n    signs: [stop_sign]\n    light: none",
        ego: "behavior: move_forward\n    speed: 6..10 m/s\n    lane: 1",
        actors: "actor adversary: 1 {adv} {\n    behavior: {how}\n    speed: 5..15 m/s\n    position: right_front of ego\n    lane: 1\n  }",
        adversaries: ONCOMING_OR_CROSSING,
    },
];

/// How many categories there are (scenario `i` takes category `i mod CATEGORY_COUNT`).
pub const CATEGORY_COUNT: usize = CATEGORIES.len();

/// The categories' names, in SafeBench's order.
pub fn category_names() -> [&'static str; CATEGORY_COUNT] {
    CATEGORIES.map(|c| c.name)
}

const WEATHER: [&str; 3] = ["clear", "cloudy", "rainy"];
const TIME: [&str; 3] = ["daytime", "dusk", "nighttime"];

/// Scenario `index` of `region` named `name`, drawn with `seed` (the module's header).
pub fn scenario(name: &str, region: &str, index: usize, seed: u64) -> String {
    let category = &CATEGORIES[index % CATEGORY_COUNT];
    let mut rng = SplitMix64::new(seed);
    let mut pick = |n: usize| ((rng.unit() * n as f64) as usize).min(n - 1);
    let adversary = category.adversaries[pick(5)];
    let weather = WEATHER[pick(WEATHER.len())];
    let time = TIME[pick(TIME.len())];
    render(category, adversary, [weather, time], [name, region])
}

/// A category's template filled in.
fn render(
    category: &Category,
    (adv, how): (&str, &str),
    [weather, time]: [&str; 2],
    [name, region]: [&str; 2],
) -> String {
    let actors = category.actors.replace("{adv}", adv).replace("{how}", how);
    format!(
        "// ChatScene-style {category}: {adv} ({how})\nscenario {name} {{\n  source {{\n    region: {region}\n  }}\n  environment {{\n    weather: {weather}\n    time: {time}\n  }}\n  road {{\n    {road}\n  }}\n  ego {{\n    {ego}\n  }}\n  {actors}\n}}\n",
        category = category.name,
        road = category.road,
        ego = category.ego,
    )
}

/// `n` ChatScene-style scenarios for `region` (name, TAD), scenario `i` named
/// `REGION_chatscene_00i` and drawn with `region_seed + i`; one that does not count (it
/// should not happen: the tests check every category and adversary) is left out.
pub fn sample(db: &mut Database, region: &str, n: usize, region_seed: u64) -> Vec<(String, String)> {
    (0..n)
        .filter_map(|i| {
            let name = format!("{region}_chatscene_{:03}", i + 1);
            let text = scenario(&name, region, i, region_seed.wrapping_add(i as u64));
            let file = db.set_source(format!("{name}.tad").into(), text.clone(), Language::Tad, &RealFs);
            counts(tad_db::check(db, file).class).then_some((name, text))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_category_and_adversary_checks_clean() {
        let mut db = Database::new(tad_check::Options::default());
        for (k, category) in CATEGORIES.iter().enumerate() {
            for (j, &(adv, how)) in category.adversaries.iter().enumerate() {
                let text = render(category, (adv, how), ["clear", "daytime"], ["probe", "los_angeles"]);
                let file = db.set_source(format!("c{k}_{j}.tad").into(), text.clone(), Language::Tad, &RealFs);
                let checked = tad_db::check(&db, file);
                let errors: Vec<String> = checked
                    .diagnostics
                    .iter()
                    .filter(|d| d.severity == tad_diagnostics::Severity::Error)
                    .map(|d| d.message.clone())
                    .collect();
                assert!(errors.is_empty(), "{} with {adv} ({how}): {errors:?}\n{text}", category.name);
                assert!(counts(checked.class), "{} with {adv} ({how}) does not count", category.name);
            }
        }
    }

    #[test]
    fn the_categories_reach_their_conflicts() {
        // the naive ego, blind to everything, collides in at least 6 of the 8 categories
        // within 4 seeds of one draw each (measured: all but the straight obstacle, where
        // the walker's trigger range is wide; the search narrows it)
        let mut db = Database::new(tad_check::Options::default());
        let mut colliding = Vec::new();
        for (k, category) in CATEGORIES.iter().enumerate() {
            let text = scenario("probe", "los_angeles", k, 3);
            let input = tad_db::host::Input {
                name: format!("{}.tad", category.name),
                path: Some(format!("{}.tad", category.name).into()),
                text,
                invalid_utf8: None,
            };
            let program = crate::pipeline::compile(&mut db, &input).expect("a template compiles");
            let scene = tad_runtime::Scene::new(&program).expect("a template sets up");
            let collided = (0..4).any(|seed| {
                let params = tad_runtime::sample::sample(&scene.program.params, Some(seed));
                let mut naive = tad_policy::parse_policy("naive").unwrap();
                let e = tad_runtime::run(&scene, Some(seed), params, naive.as_mut(), &tad_runtime::Options::default());
                e.stop_reason == tad_metrics::StopReason::Collision
            });
            if collided {
                colliding.push(category.name);
            }
        }
        assert!(colliding.len() >= 6, "the naive ego collides only in {colliding:?}");
    }

    #[test]
    fn a_sample_covers_the_categories_and_repeats() {
        let mut db = Database::new(tad_check::Options::default());
        let a = sample(&mut db, "los_angeles", 16, 7);
        assert_eq!(a.len(), 16, "every draw counts");
        for (i, (name, text)) in a.iter().enumerate() {
            assert_eq!(name, &format!("los_angeles_chatscene_{:03}", i + 1));
            assert!(text.starts_with(&format!("// ChatScene-style {}:", CATEGORIES[i % 8].name)), "{text}");
        }
        assert_eq!(a, sample(&mut db, "los_angeles", 16, 7));
        assert_ne!(a, sample(&mut db, "los_angeles", 16, 8));
    }
}
