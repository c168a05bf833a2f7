//! The baseline generator: scenarios that know TAD's language but no region.
//!
//! It is the unaligned reference of both experiments: a row of `tadslc eval`'s table
//! (`--generators baseline`, each region drawing its own sample) and the "unaligned
//! baseline" of the recovery experiment (`tadslc bench --align`). Every choice is uniform
//! over the names the prelude (`stdlib/core.tad`) declares of its kind, within what the
//! prelude says fits together: an actor's behavior among those its type performs, its
//! speed below the behavior's `max_speed`, its relation one a dash-cam sees (the scenarios
//! come from a video). The same seed gives the same scenarios on every machine. Each scenario also comes as an equivalent JSON document, so `tadslc bench` can
//! compare the front end with a production JSON parser on the same content.

use tad_base::{Rng, SplitMix64};
use tad_db::Database;

/// The kinds the generator draws, each uniformly over the names the prelude declares of
/// it (`stdlib/core.tad`, in declaration order): its distribution is the vocabulary's,
/// never a list of its own.
pub const KINDS: &[&str] = &[
    "weather",
    "time_of_day",
    "road_type",
    "road_context",
    "traffic_sign",
    "light_state",
    "traffic_density",
    "roadside",
    "actor_type",
    "behavior",
    "relation",
    "region",
];

/// What the generator draws from, read once from the prelude.
struct Choices {
    /// Every kind's names, in declaration order.
    names: Vec<(&'static str, Vec<String>)>,
    /// The behaviors each actor type performs (its kind among the behavior's `performers`).
    performed: Vec<(String, Vec<String>)>,
    /// The relations a dash-cam sees (`longitudinal` not `behind`): the generator writes a
    /// video source, so the dash-cam rule (E0510) applies; and those of them a one-way road
    /// has room for (`lateral` not `opposite`).
    visible: Vec<String>,
    one_way: Vec<String>,
    /// The fastest each actor type moves, km/h (its `max_speed`).
    fastest: Vec<(String, u32)>,
}

fn choices() -> &'static Choices {
    static CHOICES: std::sync::OnceLock<Choices> = std::sync::OnceLock::new();
    CHOICES.get_or_init(|| {
        let vocabulary = tad_db::vocabulary_of(&[]);
        let names = KINDS.iter().map(|k| (*k, vocabulary.names(k).into_iter().map(String::from).collect())).collect();
        let performed = vocabulary
            .entries("actor_type")
            .into_iter()
            .map(|t| {
                let kind = t.symbol("kind").unwrap_or("");
                let behaviors = vocabulary.entries("behavior").into_iter().filter(|b| tad_check::performs(b, kind));
                (t.name.clone(), behaviors.map(|b| b.name.clone()).collect())
            })
            .collect();
        let seen: Vec<_> =
            vocabulary.entries("relation").into_iter().filter(|r| r.symbol("longitudinal") != Some("behind")).collect();
        let visible = seen.iter().map(|r| r.name.clone()).collect();
        let one_way = seen.iter().filter(|r| r.symbol("lateral") != Some("opposite")).map(|r| r.name.clone()).collect();
        let fastest = vocabulary
            .entries("actor_type")
            .into_iter()
            .filter_map(|t| Some((t.name.clone(), (t.speed("max_speed")? * 3.6).floor() as u32)))
            .collect();
        Choices { names, performed, visible, one_way, fastest }
    })
}

/// The prelude's names of `kind` (one of [`KINDS`]).
pub fn names(kind: &str) -> &'static [String] {
    choices().names.iter().find(|(k, _)| *k == kind).map_or(&[], |(_, names)| names.as_slice())
}

fn pick(rng: &mut SplitMix64, kind: &str) -> &'static str {
    rng.pick(names(kind)).as_str()
}

/// A behavior an actor of type `actor_type` performs.
fn behavior_of(rng: &mut SplitMix64, actor_type: &str) -> &'static str {
    let own = choices().performed.iter().find(|(t, _)| t == actor_type).map(|(_, b)| b.as_slice());
    match own.filter(|b| !b.is_empty()) {
        Some(behaviors) => rng.pick(behaviors).as_str(),
        None => pick(rng, "behavior"),
    }
}

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
    let weather = pick(rng, "weather");
    let time = pick(rng, "time_of_day");
    let road = pick(rng, "road_type");
    let context = pick(rng, "road_context");
    let light = pick(rng, "light_state");
    let traffic = pick(rng, "traffic_density");
    let signs: Vec<&str> = (0..rng.below(3))
        .map(|_| pick(rng, "traffic_sign"))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let roadside: Vec<&str> = (0..1 + rng.below(3))
        .map(|_| pick(rng, "roadside"))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let region = pick(rng, "region");
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
        let kind = pick(rng, "actor_type");
        let behavior = behavior_of(rng, kind);
        // below the behavior's and the type's `max_speed` (0 for a standing behavior), and 60 km/h
        let fastest = choices().fastest.iter().find(|(t, _)| t == kind).map_or(59, |(_, v)| *v);
        let limit = crate::synthetic::max_speed(behavior).unwrap_or(59).min(fastest).min(59) as usize;
        let speed = if limit == 0 { 0 } else { rng.below(limit + 1) };
        let relation = rng.pick(if two_way { &choices().visible } else { &choices().one_way }).as_str();
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
    fn what_the_prelude_says_fits_together_checks_without_errors() {
        // behaviors their types perform, speeds under both `max_speed`s, relations a
        // dash-cam sees and a one-way road has room for
        let mut db = Database::new(tad_check::Options::default());
        for (i, g) in generate(300, 5).into_iter().enumerate() {
            let file = db.set_source(format!("g{i}.tad").into(), g.tad.clone(), tad_db::Language::Tad, &tad_db::RealFs);
            let errors: Vec<String> = tad_db::check(&db, file)
                .diagnostics
                .iter()
                .filter(|d| d.is_error())
                .map(|d| d.message.clone())
                .collect();
            assert!(errors.is_empty(), "{errors:#?}\n{}", g.tad);
        }
    }

    #[test]
    fn every_kind_draws_from_the_prelude() {
        for kind in KINDS {
            assert!(names(kind).len() >= 4, "the prelude declares few {kind}: {:?}", names(kind));
        }
        assert!(names("behavior").iter().any(|b| b == "graze"), "the prelude's names, not a list of the generator's");
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
