//! Labelled synthetic regions: known distributions of every choice, so a generator fitted
//! to a sample of one can be checked for recovering it (the recovery experiment, `tadslc
//! bench --align`). Weights are relative; nothing here is real data, and every scenario
//! says so.

use tad_base::{Rng, SplitMix64};

/// A labelled synthetic region: known distributions of every choice, so a generator fitted
/// to a sample of it can be checked for recovering it (`tadslc bench --align`). Weights are
/// relative; nothing here is real data, and every scenario says so.
pub struct SyntheticRegion {
    pub label: &'static str,
    /// The declared region its scenarios name, and the module they use.
    pub region: &'static str,
    pub uses: Option<&'static str>,
    pub weather: &'static [(&'static str, u32)],
    pub time: &'static [(&'static str, u32)],
    pub road: &'static [(&'static str, u32)],
    pub context: &'static [(&'static str, u32)],
    pub lanes: &'static [(i64, u32)],
    pub one_way: u32,
    pub light: &'static [(&'static str, u32)],
    pub traffic: &'static [(&'static str, u32)],
    pub signs: &'static [(&'static str, u32)],
    pub hazards: &'static [(&'static str, u32)],
    pub roadside: &'static [(&'static str, u32)],
    /// Groups per scenario, from..=to.
    pub groups: (usize, usize),
    pub actors: &'static [SyntheticActor],
    pub relations: &'static [(&'static str, u32)],
    pub ego_speed: (u32, u32),
}

/// Actor type, weight, most actors in a group, behaviours with weights, speed range km/h.
pub type SyntheticActor = (&'static str, u32, usize, &'static [(&'static str, u32)], (u32, u32));

const DRIVE: &[(&str, u32)] =
    &[("move_forward", 45), ("stopped", 25), ("turn_left", 10), ("turn_right", 10), ("yield", 10)];
const PARKING: &[(&str, u32)] = &[("move_forward", 40), ("stopped", 20), ("parked", 30), ("turn_right", 10)];
const ANIMAL: &[(&str, u32)] = &[("cross", 45), ("graze", 25), ("stand", 20), ("walk", 10)];

pub const SYNTHETIC: &[SyntheticRegion] = &[
    SyntheticRegion {
        label: "metro",
        region: "new_york_city",
        uses: None,
        weather: &[("clear", 50), ("cloudy", 25), ("rainy", 20), ("wet", 5)],
        time: &[("daytime", 60), ("nighttime", 25), ("dusk", 15)],
        road: &[("intersection", 55), ("straight_road", 35), ("t_intersection", 10)],
        context: &[("urban", 85), ("residential", 15)],
        lanes: &[(2, 40), (3, 40), (4, 20)],
        one_way: 30,
        light: &[("green", 35), ("red", 35), ("yellow", 10), ("none", 20)],
        traffic: &[("heavy", 45), ("moderate", 35), ("jam", 20)],
        signs: &[("yield_to_pedestrian_sign", 20), ("speed_limit_sign", 30), ("no_entry_sign", 10)],
        hazards: &[],
        roadside: &[("sidewalk", 80), ("buildings", 60), ("shops", 40), ("parked_cars", 30)],
        groups: (3, 7),
        actors: &[
            ("pedestrian", 30, 8, &[("cross", 60), ("walk", 30), ("stand", 10)], (3, 6)),
            ("sedan", 20, 3, PARKING, (10, 45)),
            ("taxi", 15, 2, DRIVE, (10, 45)),
            ("bus", 10, 1, DRIVE, (10, 35)),
            ("bicycle", 10, 2, &[("move_forward", 70), ("stopped", 30)], (10, 20)),
            ("suv", 10, 2, DRIVE, (10, 45)),
            ("van", 5, 1, PARKING, (10, 40)),
        ],
        relations: &[
            ("front", 30),
            ("right_front", 20),
            ("left_front", 15),
            ("right", 15),
            ("behind", 10),
            ("left", 10),
        ],
        ego_speed: (10, 45),
    },
    SyntheticRegion {
        label: "park",
        region: "yellowstone",
        uses: Some("national_park"),
        weather: &[("clear", 40), ("cloudy", 35), ("foggy", 15), ("snowy", 10)],
        time: &[("daytime", 50), ("dawn", 25), ("dusk", 25)],
        road: &[("straight_road", 50), ("curved_road", 50)],
        context: &[("country_road", 80), ("hill_road", 20)],
        lanes: &[(1, 100)],
        one_way: 0,
        light: &[("none", 100)],
        traffic: &[("light", 70), ("free_flow", 30)],
        signs: &[("speed_limit_sign", 30)],
        hazards: &[("animal_crossing", 50)],
        roadside: &[("meadow", 50), ("forest", 60), ("river", 25), ("cliffs", 15)],
        groups: (1, 3),
        actors: &[
            ("bison", 35, 8, ANIMAL, (2, 5)),
            ("elk", 20, 5, ANIMAL, (2, 6)),
            ("rv", 20, 1, &[("move_forward", 60), ("stopped", 40)], (20, 60)),
            ("suv", 15, 2, &[("move_forward", 70), ("stopped", 30)], (30, 70)),
            ("bear", 5, 1, ANIMAL, (2, 6)),
            ("motorcycle", 5, 2, &[("move_forward", 100)], (40, 80)),
        ],
        relations: &[("front", 70), ("left_front", 20), ("behind", 10)],
        ego_speed: (20, 70),
    },
    SyntheticRegion {
        label: "alpine",
        region: "switzerland",
        uses: None,
        weather: &[("snowy", 35), ("foggy", 25), ("cloudy", 25), ("clear", 15)],
        time: &[("daytime", 70), ("dusk", 30)],
        road: &[("curved_road", 60), ("straight_road", 20), ("roundabout", 20)],
        context: &[("hill_road", 60), ("residential", 20), ("urban", 20)],
        lanes: &[(1, 60), (2, 40)],
        one_way: 0,
        light: &[("none", 80), ("green", 20)],
        traffic: &[("light", 50), ("moderate", 50)],
        signs: &[("speed_limit_sign", 50), ("yield_sign", 20)],
        hazards: &[],
        roadside: &[("rocky_slopes", 50), ("guardrail", 50), ("houses", 30), ("trees", 30)],
        groups: (1, 4),
        actors: &[
            ("truck", 25, 1, &[("move_forward", 60), ("stopped", 20), ("yield", 20)], (20, 50)),
            ("bicycle", 20, 3, &[("move_forward", 80), ("stopped", 20)], (8, 20)),
            ("sedan", 20, 2, &[("move_forward", 50), ("overtake", 20), ("turn_right", 15), ("stopped", 15)], (20, 60)),
            ("bus", 15, 1, &[("move_forward", 60), ("stopped", 40)], (20, 50)),
            ("motorcycle", 10, 2, &[("move_forward", 60), ("overtake", 40)], (30, 70)),
            ("snowplow", 10, 1, &[("move_forward", 100)], (15, 30)),
        ],
        relations: &[("front", 50), ("behind", 25), ("left_front", 25)],
        ego_speed: (20, 60),
    },
];

pub fn synthetic(label: &str) -> Option<&'static SyntheticRegion> {
    SYNTHETIC.iter().find(|r| r.label == label)
}

/// The fastest a behaviour's actor is drawn, in whole km/h, from the standard vocabulary
/// (not a list of names): 0 when its motion stands as the layout judges it (stop, parked,
/// stand), else its declared `max_speed` (1 for `graze`: grazing animals move, slowly).
pub(crate) fn max_speed(behavior: &str) -> Option<u32> {
    use tad_syntax::schema::{ClosedSet, Motion};
    static LIMITS: std::sync::OnceLock<Vec<(String, u32)>> = std::sync::OnceLock::new();
    let limits = LIMITS.get_or_init(|| {
        let vocabulary = tad_db::vocabulary_of(&tad_db::standard_modules());
        vocabulary
            .names("behavior")
            .into_iter()
            .filter_map(|name| {
                let entry = vocabulary.get("behavior", name)?;
                let motion = entry.symbol("motion").and_then(Motion::parse);
                if matches!(motion, Some(Motion::Stop | Motion::Parked | Motion::Stand)) {
                    return Some((name.to_string(), 0));
                }
                Some((name.to_string(), (entry.speed("max_speed")? * 3.6).round() as u32))
            })
            .collect()
    });
    limits.iter().find(|(name, _)| name == behavior).map(|&(_, limit)| limit)
}

fn weighted<'a, T>(rng: &mut SplitMix64, items: &'a [(T, u32)]) -> &'a T {
    let total: u32 = items.iter().map(|(_, w)| w).sum();
    let mut u = rng.below(total.max(1) as usize) as u32;
    for (item, w) in items {
        if u < *w {
            return item;
        }
        u -= w;
    }
    &items[items.len() - 1].0
}

/// Each name with its weight as a percentage chance, independently.
fn subset(rng: &mut SplitMix64, items: &[(&'static str, u32)]) -> Vec<&'static str> {
    items.iter().filter(|(_, w)| rng.chance(*w as usize)).map(|(n, _)| *n).collect()
}

impl SyntheticRegion {
    /// Scenario `index` of this region, drawn from `rng`.
    pub fn scenario(&self, rng: &mut SplitMix64, index: usize) -> String {
        let lanes = *weighted(rng, self.lanes);
        let one_way = rng.chance(self.one_way as usize);
        let road = weighted(rng, self.road);
        let ego_lane = 1 + rng.below(lanes as usize) as i64;
        let between = |rng: &mut SplitMix64, (lo, hi): (u32, u32)| lo + rng.below((hi - lo + 1) as usize) as u32;
        let mut out = format!("// synthetic: drawn from the labelled distribution `{}` (not real data)\n", self.label);
        if let Some(module) = self.uses {
            out.push_str(&format!("use {module}\n\n"));
        }
        let list = |v: Vec<&str>| format!("[{}]", v.join(", "));
        out.push_str(&format!(
            "scenario synthetic_{}_{index:03} {{\n  source {{\n    region: {}\n  }}\n  environment {{\n    weather: {}\n    time: {}\n  }}\n  \
             road {{\n    type: {road}\n    context: {}\n    lanes: {lanes}\n    direction: {}\n    signs: {}\n    light: {}\n    traffic: {}\n    \
             hazards: {}\n    roadside: {}\n  }}\n  ego {{\n    behavior: move_forward\n    speed: {} km/h\n    lane: {ego_lane}\n  }}\n",
            self.label,
            self.region,
            weighted(rng, self.weather),
            weighted(rng, self.time),
            weighted(rng, self.context),
            if one_way { "one_way" } else { "two_way" },
            list(subset(rng, self.signs)),
            weighted(rng, self.light),
            weighted(rng, self.traffic),
            list(subset(rng, self.hazards)),
            list(subset(rng, self.roadside)),
            between(rng, self.ego_speed),
        ));
        let groups = self.groups.0 + rng.below(self.groups.1 - self.groups.0 + 1);
        let weights: Vec<(usize, u32)> = self.actors.iter().enumerate().map(|(i, a)| (i, a.1)).collect();
        for g in 0..groups {
            let (kind, _, most, behaviors, speeds) = self.actors[*weighted(rng, &weights)];
            let count = 1 + rng.below(most);
            let behavior = weighted(rng, behaviors);
            let drawn = between(rng, speeds);
            let speed = max_speed(behavior).map_or(drawn, |limit| drawn.min(limit));
            let relation = weighted(rng, self.relations);
            let lane = match *relation {
                "left" | "left_front" | "left_behind" if ego_lane > 1 => ego_lane - 1,
                "left" | "left_front" | "left_behind" if !one_way => -1,
                "right" | "right_front" | "right_behind" if ego_lane < lanes => ego_lane + 1,
                _ => ego_lane,
            };
            out.push_str(&format!(
                "  actor {kind}_{}: {count} {kind} {{\n    behavior: {behavior}\n    speed: {speed} km/h\n    position: {relation} of ego\n    lane: {lane}\n  }}\n",
                g + 1
            ));
        }
        out.push_str("}\n");
        out
    }

    /// `n` scenarios from `seed`.
    pub fn sample(&self, n: usize, seed: u64) -> Vec<String> {
        let mut rng = SplitMix64::new(seed);
        (0..n).map(|i| self.scenario(&mut rng, i)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_limits_are_the_vocabularys() {
        assert_eq!((max_speed("stopped"), max_speed("parked"), max_speed("stand")), (Some(0), Some(0), Some(0)));
        assert_eq!(max_speed("graze"), Some(1), "grazing animals move, slowly, as the layout moves them");
        assert_eq!(max_speed("cross"), None);
    }

    #[test]
    fn synthetic_regions_are_valid_scenarios() {
        let mut db = tad_db::Database::new(tad_check::Options::default());
        for region in SYNTHETIC {
            for (i, text) in region.sample(40, 5).into_iter().enumerate() {
                let path = std::path::PathBuf::from(format!("{}_{i}.tad", region.label));
                let file = db.set_source(path, text.clone(), tad_db::Language::Tad, &tad_db::RealFs);
                let checked = tad_db::check(&db, file);
                let errors: Vec<_> =
                    checked.diagnostics.iter().filter(|d| d.is_error()).map(|d| d.message.clone()).collect();
                assert!(errors.is_empty(), "{errors:?}\n{text}");
                assert_eq!(tad_syntax::format::format(&text).as_deref(), Ok(text.as_str()));
            }
        }
    }
}
