//! The fitted generator: a probabilistic model of a corpus's choices that samples new
//! scenarios with a seed, with no language model and no GPU.
//!
//! ```text
//! checked scenarios ──Example::of──▶ field → value as written ──Fitted::fit──▶ count tables
//! Fitted ──sample(rng)──▶ TAD text (formatted) ──the caller checks it, and draws again if invalid
//! ```
//!
//! A scenario is a set of fields (`road.context`, `ego.speed`, …) and a list of actor
//! groups, each with its type, count and fields. Each field is drawn from a categorical
//! distribution conditioned on the fields named in [`PARENTS`] (road and environment
//! first, then the ego, then the groups, each group conditioned on its type), smoothed
//! towards the same field with fewer parents and finally its marginal, so a combination
//! the corpus never shows still gets values the corpus uses, and only those. A field a
//! scenario leaves out is the value `~`, so presence rates are kept too. Positions keep
//! their relation and whether they refer to the ego, an earlier group (`@group`, the one
//! before when sampled) or a road element. Values are the corpus's own text, so
//! units and spellings carry over.
//!
//! The model file is JSON ([`Fitted`]); it is untrusted input: loading checks its format
//! tag, and sampling from any table, empty or odd, returns text (the checker judges it).

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};
use tad_ir::{Rng, SplitMix64};
use tad_syntax::model::{Known, Module, Val};

pub const FORMAT: &str = "tadsl-fitted/1";

/// A value a scenario leaves out.
pub const ABSENT: &str = "~";
/// A position's reference that is another group of the scenario.
pub const GROUP: &str = "@group";

/// Field → the fields it is conditioned on, most informative first. A scenario field not
/// listed is conditioned on its section's first field here (`road.*` on `road.context`),
/// a group field not listed on the group's type.
pub const PARENTS: &[(&str, &[&str])] = &[
    ("road.context", &[]),
    ("road.type", &["road.context"]),
    ("road.lanes", &["road.type", "road.context"]),
    ("road.direction", &["road.context", "road.lanes"]),
    ("road.light", &["road.type", "road.context"]),
    ("road.traffic", &["road.context"]),
    ("environment.weather", &[]),
    ("environment.time", &["environment.weather"]),
    ("ego.behavior", &["road.type"]),
    ("ego.speed", &["ego.behavior", "road.context"]),
    ("ego.lane", &["road.lanes", "road.direction"]),
    ("source.region", &[]),
    ("groups", &["road.context", "road.traffic"]),
    ("group.type", &["road.context"]),
    ("group.count", &["group.type"]),
    ("group.behavior", &["group.type", "road.type"]),
    ("group.speed", &["group.type", "group.behavior"]),
    ("group.position", &["group.type", "group.behavior"]),
    ("group.lane", &["group.position", "road.lanes"]),
];

/// The sections whose fields are modelled (the `source` only for its region).
const SECTIONS: &[&str] = &["road", "environment", "ego"];

/// One scenario as field values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Example {
    pub uses: Vec<String>,
    /// `section.field` → value as written (whitespace collapsed).
    pub fields: BTreeMap<String, String>,
    pub groups: Vec<BTreeMap<String, String>>,
}

fn written(text: &str, span: tad_diagnostics::Span) -> Option<String> {
    let raw = text.get(span.start..span.end)?;
    Some(raw.split_whitespace().collect::<Vec<_>>().join(" "))
}

impl Example {
    /// The fields of `module`'s scenario (`text` is the source its spans point into);
    /// `None` without a scenario.
    pub fn of(text: &str, module: &Module) -> Option<Example> {
        let scenario = module.scenario.as_ref()?;
        let mut ex = Example {
            uses: module
                .uses
                .iter()
                .map(|u| u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join("."))
                .collect(),
            ..Example::default()
        };
        for section in &scenario.sections {
            let name = section.def.name;
            for attr in &section.attrs {
                let keep = SECTIONS.contains(&name) || (name == "source" && attr.def.name == "region");
                if keep && let Some(v) = written(text, attr.value_span) {
                    ex.fields.insert(format!("{name}.{}", attr.def.name), v);
                }
            }
        }
        let names: BTreeSet<&str> = scenario.actors.iter().map(|a| a.name.text.as_str()).collect();
        for actor in &scenario.actors {
            let mut g = BTreeMap::new();
            let kind = match &actor.kind.value {
                Known::Given(s) => s.name.clone(),
                Known::Unspecified => "unspecified".into(),
            };
            g.insert("group.type".to_string(), kind);
            let count = actor.count.as_ref().and_then(|c| written(text, c.span)).unwrap_or_else(|| ABSENT.into());
            g.insert("group.count".to_string(), count);
            for attr in &actor.attrs {
                let value = match &attr.value {
                    Known::Given(Val::Position(p)) => {
                        let to =
                            if names.contains(p.reference.name.as_str()) { GROUP } else { p.reference.name.as_str() };
                        Some(format!("{} of {to}", p.relation.name))
                    }
                    _ => written(text, attr.value_span),
                };
                if let Some(v) = value {
                    g.insert(format!("group.{}", attr.def.name), v);
                }
            }
            ex.groups.push(g);
        }
        Some(ex)
    }
}

/// Counts of one field's values, by the values of its parents.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Table {
    pub parents: Vec<String>,
    /// Parent values joined by `|` (a prefix of `parents`, so every backoff level is
    /// here: `""` is the marginal) → value → count.
    pub counts: BTreeMap<String, BTreeMap<String, u32>>,
}

impl Table {
    fn add(&mut self, context: &BTreeMap<String, String>, value: &str) {
        for k in 0..=self.parents.len() {
            let key = self.key(context, k);
            *self.counts.entry(key).or_default().entry(value.to_string()).or_insert(0) += 1;
        }
    }

    fn key(&self, context: &BTreeMap<String, String>, k: usize) -> String {
        self.parents[..k].iter().map(|p| context.get(p).map_or(ABSENT, String::as_str)).collect::<Vec<_>>().join("|")
    }

    /// The smoothed distribution given `context`: from the marginal up to all parents,
    /// each level's counts plus `strength` × the level below.
    pub fn distribution(&self, context: &BTreeMap<String, String>, strength: f64) -> Vec<(String, f64)> {
        let mut p: BTreeMap<String, f64> = BTreeMap::new();
        for k in 0..=self.parents.len() {
            let Some(counts) = self.counts.get(&self.key(context, k)) else { break };
            let total: f64 = counts.values().map(|c| *c as f64).sum();
            if total <= 0.0 {
                break;
            }
            if p.is_empty() {
                p = counts.iter().map(|(v, c)| (v.clone(), *c as f64 / total)).collect();
                continue;
            }
            let prior = std::mem::take(&mut p);
            let keys: BTreeSet<&String> = prior.keys().chain(counts.keys()).collect();
            p = keys
                .into_iter()
                .map(|v| {
                    let c = counts.get(v).copied().unwrap_or(0) as f64;
                    (v.clone(), (c + strength * prior.get(v).copied().unwrap_or(0.0)) / (total + strength))
                })
                .collect();
        }
        p.into_iter().filter(|(_, q)| *q > 0.0 && q.is_finite()).collect()
    }

    fn draw(&self, context: &BTreeMap<String, String>, strength: f64, rng: &mut impl Rng) -> Option<String> {
        let dist = self.distribution(context, strength);
        let total: f64 = dist.iter().map(|(_, q)| q).sum();
        let mut u = rng.unit() * total;
        for (v, q) in &dist {
            if u < *q {
                return Some(v.clone());
            }
            u -= q;
        }
        dist.last().map(|(v, _)| v.clone())
    }
}

/// A fitted model, as saved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fitted {
    pub format: String,
    /// The corpus's most common region, if it names one.
    pub region: Option<String>,
    pub scenarios: usize,
    /// How strongly a level leans on the one below (pseudo-counts).
    pub smoothing: f64,
    /// Every module the corpus `use`s.
    pub uses: Vec<String>,
    /// Scenario fields in the order they are drawn (parents first).
    pub order: Vec<String>,
    pub group_order: Vec<String>,
    pub tables: BTreeMap<String, Table>,
}

fn parents_of(key: &str) -> Vec<String> {
    if let Some((_, p)) = PARENTS.iter().find(|(k, _)| *k == key) {
        return p.iter().map(|s| s.to_string()).collect();
    }
    if key.starts_with("group.") {
        return vec!["group.type".into()];
    }
    let section = key.split('.').next().unwrap_or("");
    PARENTS
        .iter()
        .find(|(k, _)| k.starts_with(&format!("{section}.")))
        .map(|(k, _)| vec![k.to_string()])
        .unwrap_or_default()
}

/// `keys` ordered so that every key comes after its parents among `keys` (ties by
/// [`PARENTS`] order, then name).
fn ordered(keys: &BTreeSet<String>) -> Vec<String> {
    let rank = |k: &str| PARENTS.iter().position(|(p, _)| *p == k).unwrap_or(PARENTS.len());
    let mut pending: Vec<&String> = keys.iter().collect();
    pending.sort_by_key(|k| (rank(k), (*k).clone()));
    let mut out: Vec<String> = Vec::new();
    while !pending.is_empty() {
        let ready = pending
            .iter()
            .position(|k| parents_of(k).iter().all(|p| !keys.contains(p) || out.contains(p)))
            .unwrap_or(0);
        out.push(pending.remove(ready).clone());
    }
    out
}

impl Fitted {
    pub fn fit(examples: &[Example]) -> Fitted {
        let mut scenario_keys: BTreeSet<String> = examples.iter().flat_map(|e| e.fields.keys().cloned()).collect();
        scenario_keys.insert("groups".into());
        let group_keys: BTreeSet<String> =
            examples.iter().flat_map(|e| e.groups.iter().flat_map(|g| g.keys().cloned())).collect();
        let mut tables: BTreeMap<String, Table> = BTreeMap::new();
        for key in scenario_keys.iter().chain(&group_keys) {
            tables.insert(key.clone(), Table { parents: parents_of(key), counts: BTreeMap::new() });
        }
        let mut regions: BTreeMap<String, usize> = BTreeMap::new();
        let mut uses = BTreeSet::new();
        for e in examples {
            let mut context = e.fields.clone();
            context.insert("groups".into(), e.groups.len().to_string());
            for key in &scenario_keys {
                let value = context.get(key).cloned().unwrap_or_else(|| ABSENT.into());
                tables.get_mut(key).expect("a table per key").add(&context, &value);
            }
            for g in &e.groups {
                let mut gc = context.clone();
                gc.extend(g.iter().map(|(k, v)| (k.clone(), v.clone())));
                for key in &group_keys {
                    let value = gc.get(key).cloned().unwrap_or_else(|| ABSENT.into());
                    tables.get_mut(key).expect("a table per key").add(&gc, &value);
                }
            }
            if let Some(r) = e.fields.get("source.region") {
                *regions.entry(r.clone()).or_insert(0) += 1;
            }
            uses.extend(e.uses.iter().cloned());
        }
        let region = regions.into_iter().max_by_key(|(r, n)| (*n, std::cmp::Reverse(r.clone()))).map(|(r, _)| r);
        Fitted {
            format: FORMAT.into(),
            region,
            scenarios: examples.len(),
            smoothing: 1.0,
            uses: uses.into_iter().collect(),
            order: ordered(&scenario_keys),
            group_order: ordered(&group_keys),
            tables,
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    pub fn from_json(text: &str) -> Result<Fitted, String> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("not a fitted model (JSON: {e})"))?;
        match value.get("format").and_then(|f| f.as_str()) {
            Some(FORMAT) => {}
            Some(other) => return Err(format!("a fitted model of format `{other}`; this tadslc reads `{FORMAT}`")),
            None => return Err(format!("not a fitted model: no `format` (expected `{FORMAT}`)")),
        }
        let fitted: Fitted = serde_json::from_value(value).map_err(|e| format!("a malformed fitted model: {e}"))?;
        if !(fitted.smoothing.is_finite() && fitted.smoothing >= 0.0) {
            return Err("a malformed fitted model: `smoothing` must be a non-negative number".into());
        }
        Ok(fitted)
    }

    /// One scenario named `name`, as formatted TAD text (or as drawn, if it does not
    /// parse: the checker then says why).
    pub fn sample(&self, name: &str, rng: &mut SplitMix64) -> String {
        let mut context: BTreeMap<String, String> = BTreeMap::new();
        for key in &self.order {
            if let Some(v) = self.tables.get(key).and_then(|t| t.draw(&context, self.smoothing, rng)) {
                context.insert(key.clone(), v);
            }
        }
        let n = context.get("groups").and_then(|g| g.parse::<usize>().ok()).unwrap_or(0).min(64);
        let mut groups: Vec<(String, BTreeMap<String, String>)> = Vec::new();
        for i in 0..n {
            let mut gc = context.clone();
            for key in &self.group_order {
                if let Some(v) = self.tables.get(key).and_then(|t| t.draw(&gc, self.smoothing, rng)) {
                    gc.insert(key.clone(), v);
                }
            }
            let kind = gc.get("group.type").cloned().unwrap_or_else(|| "unspecified".into());
            let name = format!("{}_{}", identifier(&kind), i + 1);
            let fields: BTreeMap<String, String> =
                gc.into_iter().filter(|(k, v)| k.starts_with("group.") && v != ABSENT).collect();
            groups.push((name, fields));
        }
        let text = self.print(name, &context, &groups);
        tad_syntax::format::format(&text).unwrap_or(text)
    }

    fn print(
        &self,
        name: &str,
        context: &BTreeMap<String, String>,
        groups: &[(String, BTreeMap<String, String>)],
    ) -> String {
        let mut out = String::new();
        for u in &self.uses {
            out.push_str(&format!("use {u}\n"));
        }
        if !self.uses.is_empty() {
            out.push('\n');
        }
        out.push_str(&format!("scenario {} {{\n", identifier(name)));
        for section in ["source", "environment", "road", "ego"] {
            let prefix = format!("{section}.");
            let mut fields: Vec<(&String, &String)> =
                context.iter().filter(|(k, v)| k.starts_with(&prefix) && *v != ABSENT).collect();
            let def = tad_syntax::schema::section(section);
            fields.sort_by_key(|(k, _)| schema_rank(def, &k[prefix.len()..]));
            if fields.is_empty() {
                continue;
            }
            out.push_str(&format!("  {section} {{\n"));
            for (k, v) in fields {
                out.push_str(&format!("    {}: {v}\n", &k[prefix.len()..]));
            }
            out.push_str("  }\n");
        }
        for (i, (name, fields)) in groups.iter().enumerate() {
            let count = fields.get("group.count").map(|c| format!("{c} ")).unwrap_or_default();
            let kind = fields.get("group.type").map_or("unspecified", String::as_str);
            out.push_str(&format!("  actor {name}: {count}{kind} {{\n"));
            let mut ordered: Vec<(&String, &String)> = fields.iter().collect();
            ordered.sort_by_key(|(k, _)| schema_rank(Some(&tad_syntax::schema::ACTOR), &k["group.".len()..]));
            for (k, v) in ordered {
                if k == "group.type" || k == "group.count" {
                    continue;
                }
                let v = if k == "group.position" && v.ends_with(GROUP) {
                    let to = if i > 0 { groups[i - 1].0.as_str() } else { "ego" };
                    format!("{}{to}", &v[..v.len() - GROUP.len()])
                } else {
                    v.clone()
                };
                out.push_str(&format!("    {}: {v}\n", &k["group.".len()..]));
            }
            out.push_str("  }\n");
        }
        out.push_str("}\n");
        out
    }
}

/// Where `field` comes in its section's canonical order (unknown fields last, by name).
fn schema_rank(def: Option<&tad_syntax::schema::SectionDef>, field: &str) -> (usize, String) {
    let at = def.and_then(|d| d.fields.iter().position(|f| f.name == field)).unwrap_or(usize::MAX);
    (at, field.to_string())
}

/// `s` as a TAD identifier: letters, digits and `_`, not starting with a digit.
fn identifier(s: &str) -> String {
    let mut out: String = s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 's');
    }
    out
}
