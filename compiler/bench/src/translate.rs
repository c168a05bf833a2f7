//! `bench --translate`: how faithfully a model turns descriptions into scenarios, scored
//! attribute by attribute against hand-written ground truth.
//!
//! Each description `NN_name.txt` has a truth `NN_name.tad` (`tests/llm/truth/`). Both
//! programs are resolved to the IR, so aliases and units compare as the compiler reads
//! them. The scene's attributes (weather, time, road type, lanes, direction, light, signs)
//! and the ego's (behaviour, speed, lane) count where the truth states them. Groups are
//! matched one to one so that the most attributes agree (the assignment problem, solved
//! exactly); a truth group without a partner counts every attribute it states as wrong,
//! and an answer group without one counts as one wrong value of each group attribute. An
//! answer without a program gets every attribute wrong. Speeds agree within 10 % or
//! 1 m/s, whichever is wider; everything else agrees when equal, a relation as the layout
//! places it ([`relation`]: `opposite` in an oncoming lane is `front`). Each case's line is
//! followed by its misses, the answer's value beside the truth's.
//!
//! The translation itself is the host's (the CLI builds the session): this module pairs
//! the files, runs the loop over them through a callback, and scores.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use tad_eval::interval::{Interval, RESAMPLES};
use tad_ir::{Entries, Field, Group, Kind, Lateral, Named, Param, Reference, Rng, Scenario, SplitMix64};

use crate::{BenchError, Report};

/// One description and its ground truth.
#[derive(Clone, Debug)]
pub struct Case {
    pub name: String,
    pub description: PathBuf,
    pub truth: PathBuf,
}

/// The cases of `descriptions` (`*.txt`) with their truths in `truth` (same stem, `.tad`).
/// A description without a truth is an error: the benchmark scores all or nothing.
pub fn cases(descriptions: &Path, truth: &Path) -> Result<Vec<Case>, BenchError> {
    let files = tad_db::host::with_extension(descriptions, "txt");
    if files.is_empty() {
        return Err(BenchError(format!("no descriptions (*.txt) in `{}`", descriptions.display())));
    }
    let mut cases = Vec::new();
    let mut missing = Vec::new();
    for description in files {
        let name = description.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let truth = truth.join(format!("{name}.tad"));
        if truth.is_file() {
            cases.push(Case { name, description, truth });
        } else {
            missing.push(truth.display().to_string());
        }
    }
    if !missing.is_empty() {
        return Err(BenchError(format!("descriptions without a ground truth: {}", missing.join(", "))));
    }
    Ok(cases)
}

/// The scored attributes, in report order: the scene's, the ego's, then each group's.
pub const SCENE: [&str; 7] = ["weather", "time", "road type", "lanes", "direction", "light", "signs"];
pub const EGO: [&str; 3] = ["ego behaviour", "ego speed", "ego lane"];
pub const GROUP: [&str; 5] = ["type", "count", "behaviour", "relation", "lane"];

/// Each attribute's field as a program writes it, in the order of [`SCENE`], [`EGO`] and
/// [`GROUP`]; a group's is written after its name (`bus_ahead.lane`).
const SCENE_FIELDS: [&str; 7] = [
    "environment.weather",
    "environment.time",
    "road.type",
    "road.lanes",
    "road.direction",
    "road.light",
    "road.signs",
];
const EGO_FIELDS: [&str; 3] = ["ego.behavior", "ego.speed", "ego.lane"];
const GROUP_FIELDS: [&str; 5] = ["type", "count", "behavior", "position", "lane"];

/// The comment line of a ground truth that lists the fields its description does not
/// state, whose values are plausible defaults: `// not stated: road.type, bus_ahead.lane`.
/// They are not scored.
pub const NOT_STATED: &str = "// not stated:";

/// An attribute's value as the comparison sees it.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Text(String),
    /// m/s
    Speed(f64),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Text(t) => f.write_str(t),
            Value::Speed(v) => write!(f, "{:.1} km/h", v * 3.6),
        }
    }
}

impl Value {
    fn agrees(&self, other: &Value) -> bool {
        match (self, other) {
            (Value::Speed(t), Value::Speed(a)) => (t - a).abs() <= (0.1 * t.abs()).max(1.0),
            (a, b) => a == b,
        }
    }
}

/// A scenario's scored attributes: `None` where it does not state one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Attributes {
    pub scene: Vec<Option<Value>>,
    pub ego: Vec<Option<Value>>,
    pub groups: Vec<Vec<Option<Value>>>,
    /// The groups' names, in the order of `groups`.
    pub names: Vec<String>,
}

/// A ground truth's attributes: those of [`attributes`] but the ones its [`NOT_STATED`]
/// lines list. `Ok(None)` when it holds no scenario; an error names a listed field that is
/// no scored attribute of it.
pub fn ground_truth(program: &str) -> Result<Option<Attributes>, String> {
    let Some(mut attributes) = attributes(program) else { return Ok(None) };
    let listed = program.lines().filter_map(|l| l.strip_prefix(NOT_STATED));
    for field in listed.flat_map(|l| l.split(',')).map(str::trim).filter(|f| !f.is_empty()) {
        let slot = if let Some(i) = SCENE_FIELDS.iter().position(|f| *f == field) {
            attributes.scene.get_mut(i)
        } else if let Some(i) = EGO_FIELDS.iter().position(|f| *f == field) {
            attributes.ego.get_mut(i)
        } else {
            let (group, name) = field.rsplit_once('.').unwrap_or(("", field));
            let g = attributes.names.iter().position(|n| n == group);
            let i = GROUP_FIELDS.iter().position(|f| *f == name);
            g.zip(i).and_then(|(g, i)| attributes.groups[g].get_mut(i))
        };
        match slot {
            Some(value @ Some(_)) => *value = None,
            _ => return Err(format!("`{field}` in `{NOT_STATED}` is no field the program states")),
        }
    }
    Ok(Some(attributes))
}

/// The attributes of `program` resolved as the compiler reads it (its `use` lines
/// included); `None` when it holds no scenario.
pub fn attributes(program: &str) -> Option<Attributes> {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(PathBuf::from("answer.tad"), program.to_string());
    let s = tad_db::resolve(&db, file).as_ref()?;
    let e = &s.entries;
    let text = |v: Option<String>| v.map(Value::Text);
    let scene = vec![
        text(param_name(e, &s.environment.weather)),
        text(param_name(e, &s.environment.time)),
        text(name(e, &s.road.road_type)),
        text(s.road.lanes.get().map(|n| n.to_string())),
        text(name(e, &s.road.direction)),
        text(name(e, &s.road.light)),
        text(s.road.signs.given().map(|signs| {
            let mut names: Vec<&str> = signs.iter().map(|n| e.name(&n.value)).collect();
            names.sort_unstable();
            names.join(", ")
        })),
    ];
    let ego = vec![
        text(param_name(e, &s.ego.behavior)),
        speed(&s.ego.speed),
        text(s.ego.lane.get().map(|l| l.index().to_string())),
    ];
    let groups = s.groups.iter().map(|g| group(s, g)).collect();
    let names = s.groups.iter().map(|g| g.name.clone()).collect();
    Some(Attributes { scene, ego, groups, names })
}

fn group(s: &Scenario, g: &Group) -> Vec<Option<Value>> {
    let e = &s.entries;
    let count = g.count_param().map(|p| match p {
        Param::Fixed(n) => n.to_string(),
        Param::Range { min, max } => format!("{min}..{max}"),
        Param::Choice(options) => options.iter().map(i64::to_string).collect::<Vec<_>>().join(" | "),
    });
    let lane = g.lane.get().map(|l| l.index());
    let relation = g.position.given().map(|p| {
        let of = match &p.reference.value {
            Reference::Ego => "ego".to_string(),
            Reference::Group(id) => s.group(*id).and_then(|r| name(e, &r.actor_type)).unwrap_or_default(),
            Reference::RoadElement(id) => e.get(*id).map(|r| r.name.clone()).unwrap_or_default(),
            Reference::Unknown(written) => written.clone(),
        };
        format!("{} of {of}", relation(e, &p.relation.value, lane))
    });
    [name(e, &g.actor_type), count, param_name(e, &g.behavior), relation, lane.map(|l| l.to_string())]
        .into_iter()
        .map(|v| v.map(Value::Text))
        .collect()
}

/// A relation's name as the scene places it. A relation `opposite` the reference (ahead,
/// coming towards it) in a negative lane is where its `same`-side relation puts it: the
/// layout gives `opposite of ego` and `front of ego` in lane -2 one place and one heading,
/// and the truths write oncoming traffic the second way.
fn relation(e: &Entries, relation: &Named<tad_ir::Relation>, lane: Option<i64>) -> String {
    let written = e.name(relation).to_string();
    let Some(attrs) = e.resolved(relation).map(|r| r.attrs) else { return written };
    if attrs.lateral != Some(Lateral::Opposite) || lane.is_none_or(|l| l >= 0) {
        return written;
    }
    let same_side = |r: &tad_ir::Relation| r.lateral == Some(Lateral::Same) && r.longitudinal == attrs.longitudinal;
    let table = e.table::<tad_ir::Relation>();
    table.iter().find(|(_, r)| same_side(&r.attrs)).map_or(written, |(_, r)| r.name.clone())
}

fn name<K: Kind>(e: &Entries, f: &Field<Named<K>>) -> Option<String> {
    f.given().map(|n| e.name(n).to_string())
}

fn param_name<K: Kind>(e: &Entries, f: &Field<Param<Named<K>>>) -> Option<String> {
    match f.given()? {
        Param::Fixed(n) => Some(e.name(n).to_string()),
        Param::Range { min, max } => Some(format!("{}..{}", e.name(min), e.name(max))),
        Param::Choice(options) => {
            let mut names: Vec<&str> = options.iter().map(|n| e.name(n)).collect();
            names.sort_unstable();
            Some(names.join(" | "))
        }
    }
}

fn speed(f: &Field<Param<tad_ir::MetresPerSecond>>) -> Option<Value> {
    let mid = match f.given()? {
        Param::Fixed(v) => v.0,
        Param::Range { min, max } => (min.0 + max.0) / 2.0,
        Param::Choice(options) => options.iter().map(|v| v.0).sum::<f64>() / options.len().max(1) as f64,
    };
    Some(Value::Speed(mid))
}

/// Right and total per attribute, in report order, and what each miss was.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tally {
    pub per: BTreeMap<&'static str, (u32, u32)>,
    /// `weather: clear, truth rainy`, a group's attributes after its truth's type and
    /// place (`group 2 (truck) relation: …`), in report order.
    pub misses: Vec<String>,
}

impl Tally {
    fn add(&mut self, key: &'static str, right: bool) {
        let entry = self.per.entry(key).or_default();
        entry.0 += u32::from(right);
        entry.1 += 1;
    }

    /// Right and total over every attribute.
    pub fn overall(&self) -> (u32, u32) {
        self.per.values().fold((0, 0), |(r, t), (a, b)| (r + a, t + b))
    }

    /// Adds `other`'s counts (its misses stay its own).
    pub fn merge(&mut self, other: &Tally) {
        for (key, (r, t)) in &other.per {
            let entry = self.per.entry(key).or_default();
            entry.0 += r;
            entry.1 += t;
        }
    }
}

/// The answer's attributes scored against the truth's.
pub fn score(truth: &Attributes, answer: Option<&Attributes>) -> Tally {
    let mut tally = Tally::default();
    let empty = Attributes::default();
    let a = answer.unwrap_or(&empty);
    let mut fields = |keys: &[&'static str], t: &[Option<Value>], a: &[Option<Value>], whose: &str| {
        for (k, key) in keys.iter().enumerate() {
            if let Some(t) = t.get(k).and_then(Option::as_ref) {
                let answered = a.get(k).and_then(Option::as_ref);
                let right = answered.is_some_and(|a| t.agrees(a));
                tally.add(key, right);
                if !right {
                    let answered = answered.map_or("none".to_string(), Value::to_string);
                    tally.misses.push(format!("{whose}{key}: {answered}, truth {t}"));
                }
            }
        }
    };
    fields(&SCENE, &truth.scene, &a.scene, "");
    fields(&EGO, &truth.ego, &a.ego, "");
    let agreeing = |t: &[Option<Value>], a: &[Option<Value>]| {
        t.iter().zip(a).filter(|(t, a)| matches!((t, a), (Some(t), Some(a)) if t.agrees(a))).count() as i64
    };
    let weights: Vec<Vec<i64>> =
        truth.groups.iter().map(|t| a.groups.iter().map(|g| agreeing(t, g)).collect()).collect();
    let partner = best_assignment(&weights, a.groups.len());
    let none = vec![None; GROUP.len()];
    for (i, t) in truth.groups.iter().enumerate() {
        let answered = partner[i].map_or(&none, |j| &a.groups[j]);
        fields(&GROUP, t, answered, &format!("group {}{} ", i + 1, kind(t)));
    }
    for (j, g) in a.groups.iter().enumerate() {
        if !partner.contains(&Some(j)) {
            for key in GROUP {
                tally.add(key, false);
            }
            tally.misses.push(format!("an answer group without a truth{}", kind(g)));
        }
    }
    tally
}

/// A group's type for a miss's line: ` (truck)`, or nothing when it states none.
fn kind(group: &[Option<Value>]) -> String {
    group.first().and_then(Option::as_ref).map_or(String::new(), |v| format!(" ({v})"))
}

/// For each row, the column it is assigned to (at most one row per column) so that the
/// sum of `weights` is the largest: the Hungarian method on the padded square matrix.
fn best_assignment(weights: &[Vec<i64>], columns: usize) -> Vec<Option<usize>> {
    let n = weights.len().max(columns);
    if n == 0 {
        return Vec::new();
    }
    let cost = |i: usize, j: usize| -weights.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0);
    // potentials u (rows), v (columns); p[j] = the row assigned to column j (1-based; 0 = none)
    let (mut u, mut v, mut p, mut way) =
        (vec![0i64; n + 1], vec![0i64; n + 1], vec![0usize; n + 1], vec![0usize; n + 1]);
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0;
        let mut min = vec![i64::MAX; n + 1];
        let mut used = vec![false; n + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let (mut delta, mut j1) = (i64::MAX, 0);
            for j in 1..=n {
                if !used[j] {
                    let reduced = cost(i0 - 1, j - 1) - u[i0] - v[j];
                    if reduced < min[j] {
                        min[j] = reduced;
                        way[j] = j0;
                    }
                    if min[j] < delta {
                        delta = min[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=n {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    min[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut partner = vec![None; weights.len()];
    for j in 1..=n {
        if p[j] >= 1 && p[j] <= weights.len() && j <= columns {
            partner[p[j] - 1] = Some(j - 1);
        }
    }
    partner
}

/// What the host's translation of one description gave.
#[derive(Clone, Debug, Default)]
pub struct Answer {
    /// The best program of the rounds.
    pub program: Option<String>,
    /// The round whose program first had no errors.
    pub valid_round: Option<u32>,
    /// The checker's suggestions that made the program valid after the last round.
    pub suggested: usize,
    pub rounds: u32,
    pub tokens: u64,
    pub seconds: f64,
}

/// One scored case.
#[derive(Clone, Debug)]
pub struct Scored {
    pub name: String,
    pub answer: Answer,
    pub tally: Tally,
}

/// Every case translated by `translate` (its text and path) and scored; `progress` gets a
/// line per case as it finishes.
pub fn run(
    cases: &[Case],
    translate: &mut dyn FnMut(&Case, &str) -> Answer,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Scored>, BenchError> {
    let mut scored = Vec::new();
    for case in cases {
        let read = |p: &Path| std::fs::read_to_string(p).map_err(|e| BenchError(format!("{}: {e}", p.display())));
        let (text, truth_text) = (read(&case.description)?, read(&case.truth)?);
        let truth = ground_truth(&truth_text)
            .map_err(|e| BenchError(format!("{}: {e}", case.truth.display())))?
            .ok_or_else(|| BenchError(format!("{}: the ground truth holds no scenario", case.truth.display())))?;
        let answer = translate(case, text.trim());
        let tally = score(&truth, answer.program.as_deref().and_then(attributes).as_ref());
        let (right, total) = tally.overall();
        progress(&format!(
            "{}: {right}/{total} attributes, {}, {} round{}, {:.0} s",
            case.name,
            match (answer.valid_round, answer.suggested) {
                (Some(r), _) => format!("valid at round {r}"),
                (None, 0) => "never valid".to_string(),
                (None, n) => format!("valid with {n} of the checker's suggestions"),
            },
            answer.rounds,
            if answer.rounds == 1 { "" } else { "s" },
            answer.seconds
        ));
        for miss in &tally.misses {
            progress(&format!("  {miss}"));
        }
        scored.push(Scored { name: case.name.clone(), answer, tally });
    }
    Ok(scored)
}

/// The overall accuracy of `scored`, in percent, with its 95 % interval: the descriptions
/// drawn with replacement ([`RESAMPLES`] draws from `seed`).
pub fn accuracy(scored: &[Scored], seed: u64) -> Interval {
    let tallies: Vec<(u32, u32)> = scored.iter().map(|s| s.tally.overall()).collect();
    bootstrap(tallies.len(), seed, |pick| percent(pick.iter().map(|&i| tallies[i])))
}

/// Two runs compared on the descriptions both scored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paired {
    /// The descriptions both scored.
    pub cases: usize,
    /// Each run's overall accuracy on them, in percent.
    pub before: f64,
    pub after: f64,
    /// How many points `after` is above `before`, with its 95 % interval.
    pub points: Interval,
}

/// `after` against `before` on the descriptions both scored: each draw of the interval the
/// same descriptions for both, so it keeps their pairing. `None` when they share none.
pub fn difference(before: &[Scored], after: &[Scored], seed: u64) -> Option<Paired> {
    let pairs: Vec<[(u32, u32); 2]> = before
        .iter()
        .filter_map(|b| after.iter().find(|a| a.name == b.name).map(|a| [b.tally.overall(), a.tally.overall()]))
        .collect();
    if pairs.is_empty() {
        return None;
    }
    let side = |pick: &[usize], k: usize| percent(pick.iter().map(|&i| pairs[i][k]));
    let all: Vec<usize> = (0..pairs.len()).collect();
    Some(Paired {
        cases: pairs.len(),
        before: side(&all, 0),
        after: side(&all, 1),
        points: bootstrap(pairs.len(), seed, |pick| side(pick, 1) - side(pick, 0)),
    })
}

/// Right over total, in percent, of some tallies.
fn percent(tallies: impl Iterator<Item = (u32, u32)>) -> f64 {
    let (r, t) = tallies.fold((0, 0), |(r, t), (a, b)| (r + a, t + b));
    100.0 * f64::from(r) / f64::from(t.max(1))
}

/// `measure` of all `n` cases, with the percentiles of its value over [`RESAMPLES`] draws
/// of `n` cases with replacement.
fn bootstrap(n: usize, seed: u64, measure: impl Fn(&[usize]) -> f64) -> Interval {
    let all: Vec<usize> = (0..n).collect();
    let mut rng = SplitMix64::new(seed);
    let mut draw = || measure(&(0..n).map(|_| rng.below(n)).collect::<Vec<_>>());
    let draws = if n == 0 { Vec::new() } else { (0..RESAMPLES).map(|_| draw()).collect() };
    Interval::of(measure(&all), draws)
}

/// The report: per-attribute and overall accuracy, the overall accuracy's interval
/// ([`accuracy`]), valid@1, valid after repair, mean rounds, tokens and seconds per scenario
/// (unless not `recorded`: answers read back without the run's manifest).
pub fn report(model: &str, scored: &[Scored], recorded: bool, seed: u64) -> Report {
    let mut all = Tally::default();
    for s in scored {
        all.merge(&s.tally);
    }
    let n = scored.len().max(1) as f64;
    let pct =
        |(r, t): (u32, u32)| if t == 0 { "–".to_string() } else { format!("{:.1} %", 100.0 * r as f64 / t as f64) };
    let mut lines = vec![
        format!("faithfulness of {model} on {} descriptions with ground truth", scored.len()),
        String::new(),
        "| attribute | right | of | accuracy |".to_string(),
        "|---|---:|---:|---:|".to_string(),
    ];
    for key in SCENE.iter().chain(&EGO).chain(&GROUP) {
        if let Some(&(r, t)) = all.per.get(key) {
            lines.push(format!("| {key} | {r} | {t} | {} |", pct((r, t))));
        }
    }
    let (r, t) = all.overall();
    lines.push(format!("| **overall** | {r} | {t} | **{}** |", pct((r, t))));
    lines.push(String::new());
    let overall = accuracy(scored, seed);
    lines.push(format!(
        "overall {:.1} % [{:.1}, {:.1}]: the 95 % interval of {RESAMPLES} draws of the descriptions (seed {seed})",
        overall.value, overall.low, overall.high
    ));
    let count = |f: &dyn Fn(&Answer) -> bool| scored.iter().filter(|s| f(&s.answer)).count();
    let mean = |f: &dyn Fn(&Answer) -> f64| scored.iter().map(|s| f(&s.answer)).sum::<f64>() / n;
    lines.push(String::new());
    lines.push(if recorded {
        format!(
            "valid@1 {:.1} %, valid after repair {:.1} % (and {:.1} % with the checker's suggestions), {:.2} rounds, {:.0} tokens and {:.1} s per scenario",
            100.0 * count(&|a| a.valid_round == Some(1)) as f64 / n,
            100.0 * count(&|a| a.valid_round.is_some()) as f64 / n,
            100.0 * count(&|a| a.valid_round.is_none() && a.suggested > 0) as f64 / n,
            mean(&|a| a.rounds as f64),
            mean(&|a| a.tokens as f64),
            mean(&|a| a.seconds),
        )
    } else {
        "valid@1, rounds, tokens and seconds: not recorded (no `faithfulness.jsonl` with the answers)".into()
    });
    Report { lines, ..Report::default() }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRUTH: &str = r#"scenario t {
  environment {
    weather: rainy
    time: night
  }
  road {
    type: straight_road
    context: urban
    lanes: 2
    direction: two_way
    light: red
  }
  ego {
    behavior: stopped
    lane: 1
  }
  actor queue: 3 car {
    behavior: stopped
    position: front of ego
    lane: 1
  }
  actor walkers: 2 pedestrian {
    behavior: cross
    position: front of queue
  }
}"#;

    #[test]
    fn the_truth_scores_itself_perfectly_and_the_group_order_does_not_matter() {
        let truth = attributes(TRUTH).expect("a scenario");
        let tally = score(&truth, Some(&truth));
        let (r, t) = tally.overall();
        assert_eq!(r, t);
        assert!(t >= 15, "{t} attributes");
        let mut swapped = truth.clone();
        swapped.groups.reverse();
        assert_eq!(score(&truth, Some(&swapped)), tally);
    }

    /// A scenario with one oncoming car, its position and lane as written.
    fn oncoming(road: &str, position: &str, lane: i64) -> String {
        format!(
            "scenario t {{\n  road {{\n    type: {road}\n    lanes: 2\n    direction: two_way\n  }}\n  ego {{\n    \
             behavior: move_forward\n    lane: 1\n  }}\n  actor car: 1 car {{\n    behavior: move_forward\n    \
             position: {position} of ego\n    lane: {lane}\n  }}\n}}\n"
        )
    }

    #[test]
    fn opposite_in_an_oncoming_lane_scores_as_front_because_the_layout_places_them_alike() {
        let agents = |program: &str| {
            let mut db = tad_db::Database::new(tad_check::Options::default());
            let file = db.set_file(PathBuf::from("t.tad"), program.to_string());
            let scenario = tad_db::resolve(&db, file).clone().expect("a scenario");
            tad_layout::lay_out(&scenario).agents().cloned().collect::<Vec<_>>()
        };
        for road in ["straight_road", "intersection"] {
            assert_eq!(agents(&oncoming(road, "opposite", -2)), agents(&oncoming(road, "front", -2)), "{road}");
        }
        let truth = attributes(&oncoming("straight_road", "front", -2)).expect("a scenario");
        let answer = |position, lane| score(&truth, attributes(&oncoming("straight_road", position, lane)).as_ref());
        assert_eq!(answer("opposite", -2).per["relation"], (1, 1));
        assert_eq!(answer("oncoming", -1).per["relation"], (1, 1), "the alias too, in another oncoming lane");
        // in the ego's direction `opposite` says something else than `front`
        assert_eq!(answer("opposite", 2).per["relation"], (0, 1));
        assert_eq!(answer("opposite", 2).misses[0], "group 1 (car) relation: opposite of ego, truth front of ego");
    }

    #[test]
    fn what_a_truth_lists_as_not_stated_is_not_scored() {
        let listed = format!("{NOT_STATED} road.type, ego.lane, queue.lane\n{TRUTH}");
        let truth = ground_truth(&listed).expect("known fields").expect("a scenario");
        let answer = TRUTH.replace("straight_road", "curved_road").replace("lane: 1", "lane: 2");
        let tally = score(&truth, attributes(&answer).as_ref());
        let scored = |key| tally.per.get(key).copied().unwrap_or_default();
        assert_eq!(scored("road type"), (0, 0));
        assert_eq!(scored("ego lane"), (0, 0));
        assert_eq!(scored("lane"), (0, 0), "the walkers state no lane, the queue's is not stated");
        assert_eq!(tally.misses, Vec::<String>::new());
        let all = score(&attributes(TRUTH).expect("a scenario"), attributes(&answer).as_ref());
        assert_eq!(all.overall().1, tally.overall().1 + 3);
        assert_eq!(all.overall().0, tally.overall().0);
        for unknown in ["road.colour", "walkers.lane", "bus.lane", "ego.speed"] {
            let err = ground_truth(&format!("{NOT_STATED} {unknown}\n{TRUTH}")).expect_err(unknown);
            assert!(err.contains(&format!("`{unknown}`")), "{err}");
        }
    }

    #[test]
    fn accuracy_has_a_bootstrap_interval_and_a_difference_keeps_the_pairing() {
        let case = |name: &str, right: u32, total: u32| {
            let mut tally = Tally::default();
            (0..total).for_each(|i| tally.add("type", i < right));
            let answer = Answer { program: None, valid_round: None, suggested: 0, rounds: 1, tokens: 0, seconds: 0.0 };
            Scored { name: name.to_string(), answer, tally }
        };
        let before: Vec<Scored> = (0..20).map(|i| case(&format!("c{i}"), 10 + i % 10, 20)).collect();
        let overall = accuracy(&before, 1);
        assert!((overall.value - 72.5).abs() < 1e-9, "{overall}");
        assert!(overall.low < 70.0 && overall.high > 75.0 && overall.high < 80.0, "{overall}");
        assert_eq!(accuracy(&before, 1), overall, "seeded");
        // one more right in each case: +5 points, and every draw agrees, however spread the cases are
        let after: Vec<Scored> = (0..20).map(|i| case(&format!("c{i}"), 11 + i % 10, 20)).collect();
        let paired = difference(&before, &after, 1).expect("shared cases");
        let d = paired.points;
        assert_eq!(paired.cases, 20);
        assert!((paired.before - 72.5).abs() < 1e-9 && (paired.after - 77.5).abs() < 1e-9, "{paired:?}");
        assert!((d.value - 5.0).abs() < 1e-9 && (d.low - 5.0).abs() < 1e-9 && (d.high - 5.0).abs() < 1e-9, "{d}");
        // only the cases both scored are compared
        let paired = difference(&before[..5], &after, 1).expect("shared cases");
        assert_eq!(paired.cases, 5);
        assert!(paired.points.value > 0.0, "{paired:?}");
        assert!(difference(&before, &[case("other", 1, 1)], 1).is_none());
    }

    #[test]
    fn misses_extra_groups_and_no_answer_count_as_wrong() {
        let truth = attributes(TRUTH).expect("a scenario");
        let wrong = TRUTH.replace("rainy", "clear").replace("3 car", "2 car");
        let tally = score(&truth, attributes(&wrong).as_ref());
        assert_eq!(tally.per["weather"], (0, 1));
        assert_eq!(tally.per["count"], (1, 2));
        assert_eq!(tally.per["type"], (2, 2));
        assert_eq!(tally.misses, ["weather: clear, truth rainy", "group 1 (car) count: 2, truth 3"]);
        let extra =
            format!("{}  actor stray: 1 bicycle {{\n    behavior: cross\n  }}\n}}", TRUTH.trim_end_matches('}'));
        let tally = score(&truth, attributes(&extra).as_ref());
        assert_eq!(tally.per["type"], (2, 3), "an invented group is a wrong value of each attribute");
        assert_eq!(tally.misses, ["an answer group without a truth (bicycle)"]);
        let nothing = score(&truth, None);
        assert_eq!(nothing.overall().0, 0);
        assert_eq!(nothing.overall().1, score(&truth, Some(&truth)).overall().1);
    }

    #[test]
    fn speeds_agree_within_a_tenth_or_one_metre_per_second() {
        let at = |kmh: f64| Value::Speed(kmh / 3.6);
        assert!(at(50.0).agrees(&at(54.0)));
        assert!(!at(50.0).agrees(&at(57.0)));
        assert!(at(5.0).agrees(&at(8.0)));
    }

    #[test]
    fn the_assignment_is_the_best_one() {
        // greedy would take (0,0) = 3 and leave 0; the best is 2 + 2
        let weights = vec![vec![3, 2], vec![2, 0]];
        assert_eq!(best_assignment(&weights, 2), vec![Some(1), Some(0)]);
        assert_eq!(best_assignment(&[vec![1]], 3), vec![Some(0)]);
        assert_eq!(best_assignment(&[vec![], vec![]], 0), vec![None, None]);
    }
}
