//! What a scenario contributes to a corpus's statistics.
//!
//! Each attribute of [`ATTRIBUTES`] maps a scenario to zero or more values: one for a
//! single-valued field (`weather`), one per listed name (`signs`), or one per actor
//! (`actor_type`, weighted by the group's count, as the paper counts actors). A missing
//! field counts as `(missing)`, so presence rates are compared too. Names are the
//! vocabulary's canonical ones (aliases resolved by the IR).

use std::collections::BTreeMap;

use serde::Serialize;
use tad_ir::{Entries, Field, Kind, Named, Param, Reference, Scenario};

/// A value that was not stated.
pub const MISSING: &str = "(missing)";

/// How an attribute's values are counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Per {
    /// One value per scenario.
    Scenario,
    /// One per name of a list field; an empty list counts as `(none)`.
    Item,
    /// One per actor of every group.
    Actor,
}

pub struct Attribute {
    pub key: &'static str,
    pub title: &'static str,
    pub per: Per,
    extract: fn(&Scenario, &mut Vec<String>),
}

impl std::fmt::Debug for Attribute {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Attribute").field("key", &self.key).field("per", &self.per).finish()
    }
}

/// The compared attributes, in table order.
pub const ATTRIBUTES: &[Attribute] = &[
    Attribute {
        key: "weather",
        title: "Weather",
        per: Per::Scenario,
        extract: |s, v| name(s, &s.environment.weather, v),
    },
    Attribute {
        key: "time",
        title: "Time of day",
        per: Per::Scenario,
        extract: |s, v| name(s, &s.environment.time, v),
    },
    Attribute {
        key: "road_type",
        title: "Road type",
        per: Per::Scenario,
        extract: |s, v| plain(s, &s.road.road_type, v),
    },
    Attribute {
        key: "road_context",
        title: "Road context",
        per: Per::Scenario,
        extract: |s, v| plain(s, &s.road.context, v),
    },
    Attribute {
        key: "lanes",
        title: "Lanes per direction",
        per: Per::Scenario,
        extract: |s, v| v.push(s.road.lanes.get().map_or(MISSING.into(), |n| n.to_string())),
    },
    Attribute {
        key: "direction",
        title: "Direction",
        per: Per::Scenario,
        extract: |s, v| plain(s, &s.road.direction, v),
    },
    Attribute { key: "light", title: "Traffic light", per: Per::Scenario, extract: |s, v| plain(s, &s.road.light, v) },
    Attribute {
        key: "traffic",
        title: "Traffic density",
        per: Per::Scenario,
        extract: |s, v| plain(s, &s.road.traffic, v),
    },
    Attribute { key: "signs", title: "Traffic signs", per: Per::Item, extract: |s, v| list(s, &s.road.signs, v) },
    Attribute {
        key: "special_lanes",
        title: "Special lanes",
        per: Per::Item,
        extract: |s, v| list(s, &s.road.special_lanes, v),
    },
    Attribute { key: "hazards", title: "Hazards", per: Per::Item, extract: |s, v| list(s, &s.road.hazards, v) },
    Attribute { key: "roadside", title: "Roadside", per: Per::Item, extract: |s, v| list(s, &s.road.roadside, v) },
    Attribute {
        key: "ego_behavior",
        title: "Ego behavior",
        per: Per::Scenario,
        extract: |s, v| name(s, &s.ego.behavior, v),
    },
    Attribute {
        key: "actor_type",
        title: "Actor types",
        per: Per::Actor,
        extract: |s, v| each_actor(s, v, |g| named(&s.entries, &g.actor_type)),
    },
    Attribute {
        key: "behavior",
        title: "Actor behaviors",
        per: Per::Actor,
        extract: |s, v| each_actor(s, v, |g| param_name(&s.entries, &g.behavior)),
    },
    Attribute {
        key: "type_behavior",
        title: "Actor type and behavior",
        per: Per::Actor,
        extract: |s, v| {
            each_actor(s, v, |g| {
                format!("{} {}", named(&s.entries, &g.actor_type), param_name(&s.entries, &g.behavior))
            })
        },
    },
    Attribute {
        key: "position",
        title: "Group positions",
        per: Per::Actor,
        extract: |s, v| {
            each_actor(s, v, |g| match g.position.given() {
                Some(p) => {
                    let to = match &p.reference.value {
                        Reference::Ego => "ego",
                        Reference::Group(_) => "group",
                        Reference::RoadElement(_) => "road",
                        Reference::Unknown(_) => "?",
                    };
                    format!("{} of {to}", s.entries.name(&p.relation.value))
                }
                None => MISSING.into(),
            })
        },
    },
];

/// One scenario, as the statistics see it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Features {
    pub name: String,
    /// Attribute key → its values in this scenario.
    pub values: BTreeMap<&'static str, Vec<String>>,
    /// Actors (groups' counts summed; a range counts its middle).
    pub actors: u32,
    pub groups: u32,
    /// The scenario in one paragraph of words, for sentence embeddings.
    pub sentence: String,
}

impl Features {
    pub fn of(name: &str, s: &Scenario) -> Features {
        let values = ATTRIBUTES
            .iter()
            .map(|a| {
                let mut v = Vec::new();
                (a.extract)(s, &mut v);
                if a.per == Per::Item && v.is_empty() {
                    v.push("(none)".into());
                }
                (a.key, v)
            })
            .collect();
        Features {
            name: name.to_string(),
            values,
            actors: s.groups.iter().map(actors).sum(),
            groups: s.groups.len() as u32,
            sentence: sentence(s),
        }
    }
}

/// `value(group)` once per actor of every group.
fn each_actor(s: &Scenario, v: &mut Vec<String>, value: impl Fn(&tad_ir::Group) -> String) {
    for g in &s.groups {
        v.extend(std::iter::repeat_n(value(g), actors(g) as usize));
    }
}

fn actors(g: &tad_ir::Group) -> u32 {
    g.count_param().map_or(1, |p| p.nominal()).clamp(0, 10_000) as u32
}

fn named<K: Kind>(entries: &Entries, f: &Field<Named<K>>) -> String {
    f.given().map_or(MISSING.into(), |n| entries.name(n).to_string())
}

fn param_name<K: Kind>(entries: &Entries, f: &Field<Param<Named<K>>>) -> String {
    match f.given() {
        Some(Param::Fixed(n)) => entries.name(n).to_string(),
        Some(Param::Choice(options)) if !options.is_empty() => entries.name(&options[0]).to_string(),
        _ => MISSING.into(),
    }
}

fn plain<K: Kind>(s: &Scenario, f: &Field<Named<K>>, v: &mut Vec<String>) {
    v.push(named(&s.entries, f));
}

fn name<K: Kind>(s: &Scenario, f: &Field<Param<Named<K>>>, v: &mut Vec<String>) {
    v.push(param_name(&s.entries, f));
}

fn list<K: Kind>(s: &Scenario, f: &Field<tad_ir::Names<K>>, v: &mut Vec<String>) {
    match f.given() {
        Some(names) => v.extend(names.iter().map(|n| s.entries.name(&n.value).to_string())),
        None => v.push(MISSING.into()),
    }
}

fn words(name: &str) -> String {
    name.replace('_', " ")
}

/// The scenario in words: the same rendering for every corpus, so embedding distances
/// compare scenarios, not writing styles.
pub fn sentence(s: &Scenario) -> String {
    let e = &s.entries;
    let mut out = String::new();
    let get = |v: String| if v == MISSING { "unknown".to_string() } else { words(&v) };
    let lanes = s.road.lanes.get().map_or("some".into(), |n| n.to_string());
    out.push_str(&format!(
        "A {} in a {} setting with {lanes} lanes, {}, {} weather at {}, {} traffic, traffic light {}.",
        get(named(e, &s.road.road_type)),
        get(named(e, &s.road.context)),
        get(named(e, &s.road.direction)),
        get(param_name(e, &s.environment.weather)),
        get(param_name(e, &s.environment.time)),
        get(named(e, &s.road.traffic)),
        get(named(e, &s.road.light)),
    ));
    let lists: [(&str, Vec<String>); 4] = [
        ("Signs", names_of(e, &s.road.signs)),
        ("Special lanes", names_of(e, &s.road.special_lanes)),
        ("Hazards", names_of(e, &s.road.hazards)),
        ("Roadside", names_of(e, &s.road.roadside)),
    ];
    for (label, names) in lists {
        if !names.is_empty() {
            out.push_str(&format!(" {label}: {}.", names.join(", ")));
        }
    }
    let speed = |f: &Field<Param<tad_ir::MetresPerSecond>>| {
        f.given().map(|p| format!(" at {:.0} km/h", p.nominal().0 * 3.6)).unwrap_or_default()
    };
    out.push_str(&format!(" The ego vehicle is {}{}.", get(param_name(e, &s.ego.behavior)), speed(&s.ego.speed)));
    for g in &s.groups {
        let count = actors(g);
        let position = g
            .position
            .given()
            .map(|p| {
                let to = match &p.reference.value {
                    Reference::Ego => "the ego vehicle".to_string(),
                    Reference::Group(id) => {
                        s.group(*id).map_or("another group".into(), |o| words(&named(e, &o.actor_type)))
                    }
                    Reference::RoadElement(id) => {
                        e.road_elements.get(*id).map_or("the road".into(), |r| words(&r.name))
                    }
                    Reference::Unknown(n) => words(n),
                };
                format!(" {} of {to}", words(e.name(&p.relation.value)))
            })
            .unwrap_or_default();
        out.push_str(&format!(
            " {count} {} {}{}{position}.",
            get(named(e, &g.actor_type)),
            get(param_name(e, &g.behavior)),
            speed(&g.speed)
        ));
    }
    out
}

fn names_of<K: Kind>(e: &Entries, f: &Field<tad_ir::Names<K>>) -> Vec<String> {
    f.given().map(|ns| ns.iter().map(|n| words(e.name(&n.value))).collect()).unwrap_or_default()
}

/// A model-free embedding: each attribute's value shares, one coordinate per (attribute,
/// value) of `vocabulary`, plus the actor count's logarithm; L2-normalised. MMD and
/// Fréchet over it compare joint attribute distributions without a language model.
pub fn one_hot(features: &Features, vocabulary: &[(&'static str, String)]) -> Vec<f32> {
    let mut v = vec![0f32; vocabulary.len() + 1];
    for (i, (key, value)) in vocabulary.iter().enumerate() {
        if let Some(values) = features.values.get(key) {
            let n = values.len().max(1) as f32;
            v[i] = values.iter().filter(|x| *x == value).count() as f32 / n;
        }
    }
    v[vocabulary.len()] = (1.0 + features.actors as f32).ln();
    let norm = v.iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-12);
    v.iter_mut().for_each(|x| *x /= norm);
    v
}

/// Every (attribute, value) seen in `corpora`, sorted: the coordinates of [`one_hot`].
pub fn vocabulary<'a>(corpora: impl IntoIterator<Item = &'a Features>) -> Vec<(&'static str, String)> {
    let mut seen = std::collections::BTreeSet::new();
    for f in corpora {
        for (key, values) in &f.values {
            for v in values {
                seen.insert((*key, v.clone()));
            }
        }
    }
    seen.into_iter().collect()
}
