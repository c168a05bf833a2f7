//! Traces of emitted programs in the real Scenic 3.1.1: every object's pose at every step
//! of Scenic's Newtonian simulator, for several seeds, as plain Rust values. The measuring
//! is done by `compiler/backends/scenic/tools/scenic_trace.py` (found through
//! `TADSL_SCENIC_TRACE`, else in the repository), run by the Scenic oracle's Python; see
//! that script for the JSON it prints and its conventions (Scenic's: headings in radians,
//! counter-clockwise from +y; step 0 is the sampled scene).
//!
//! ```ignore
//! let Some(tracer) = tad_test_support::trace::tracer(Path::new(env!("CARGO_TARGET_TMPDIR"))) else { return };
//! // (the test suites' tracer: a skip or, with TAD_REQUIRE_SCENIC=1, a failure without Scenic)
//! // build the programs with `map_dir: Some(tracer.maps ...)` so the map cache is reused
//! let traces = tracer.run(&files, &TraceOptions { seeds: vec![0, 1, 2], steps: 60, ..TraceOptions::default() });
//! ```

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::{repo, turn};

/// One object's state at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Metres, in the map's frame.
    pub x: f64,
    pub y: f64,
    /// Radians, counter-clockwise from north (+y): Scenic's convention.
    pub heading: f64,
    /// Metres per second, never negative.
    pub speed: f64,
}

/// An object of the sampled scene.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceObject {
    /// Its `tadName` property, if the program gives one.
    pub name: Option<String>,
    /// Its `tadGroup` property, if the program gives one.
    pub group: Option<String>,
    /// Its `tadIndex` property (its place in its group), if the program gives one.
    pub index: Option<usize>,
    /// Scenic's class: `Car`, `Pedestrian`, ...
    pub class: String,
    pub length: f64,
    pub width: f64,
    pub is_ego: bool,
}

/// One simulation of one program with one seed.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The program, as given to the script.
    pub file: PathBuf,
    pub seed: u64,
    /// Whether it compiled, sampled and simulated every step asked for.
    pub ok: bool,
    /// Why not, prefixed by the stage: `[compile]`, `[sample]`, `[simulate]`.
    pub error: Option<String>,
    /// Seconds per step (NaN when nothing was simulated).
    pub dt: f64,
    /// Why the simulation ended (e.g. `timeLimit: ...`), when it ended without an error.
    pub termination: Option<String>,
    /// Seconds Scenic spent simulating (the script's `sim_s`: the steps, not compiling or
    /// sampling), when it simulated.
    pub sim_s: Option<f64>,
    /// The scene's objects, in `scene.objects` order (the ego first in TADSL's programs).
    pub objects: Vec<TraceObject>,
    /// `states[step][object]`; step 0 is the sampled scene, before any step. Empty when
    /// the scene could not be sampled; shorter than asked when a simulation stopped early.
    pub states: Vec<Vec<Pose>>,
}

fn text(v: &Value) -> Option<String> {
    v.as_str().map(str::to_string)
}

fn float(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

impl Trace {
    /// A record printed by the script.
    pub fn from_json(v: &Value) -> Result<Trace, String> {
        let file = v["file"].as_str().ok_or("no `file`")?;
        let seed = v["seed"].as_u64().ok_or("no `seed`")?;
        let mut objects = Vec::new();
        for (i, o) in v["objects"].as_array().ok_or("no `objects`")?.iter().enumerate() {
            if o["index"].as_u64() != Some(i as u64) {
                return Err(format!("object {i} has index {}", o["index"]));
            }
            objects.push(TraceObject {
                name: text(&o["name"]),
                group: text(&o["group"]),
                index: o["group_index"].as_u64().map(|k| k as usize),
                class: text(&o["class"]).unwrap_or_default(),
                length: float(&o["length"]),
                width: float(&o["width"]),
                is_ego: o["is_ego"] == true,
            });
        }
        let mut states = Vec::new();
        for (step, s) in v["states"].as_array().ok_or("no `states`")?.iter().enumerate() {
            let poses = s.as_array().ok_or_else(|| format!("step {step} is not a list"))?;
            if poses.len() != objects.len() {
                return Err(format!("step {step} has {} poses for {} objects", poses.len(), objects.len()));
            }
            states.push(
                poses
                    .iter()
                    .map(|p| Pose { x: float(&p[0]), y: float(&p[1]), heading: float(&p[2]), speed: float(&p[3]) })
                    .collect(),
            );
        }
        Ok(Trace {
            file: PathBuf::from(file),
            seed,
            ok: v["ok"] == true,
            error: text(&v["error"]),
            dt: float(&v["dt"]),
            termination: text(&v["termination"]),
            sim_s: v["sim_s"].as_f64(),
            objects,
            states,
        })
    }

    /// A line printed by the script.
    pub fn parse(line: &str) -> Result<Trace, String> {
        let v: Value = serde_json::from_str(line).map_err(|e| e.to_string())?;
        Trace::from_json(&v)
    }

    /// The number of steps simulated (the states less the sampled scene).
    pub fn steps(&self) -> usize {
        self.states.len().saturating_sub(1)
    }

    /// The time of `step`, in seconds.
    pub fn time(&self, step: usize) -> f64 {
        step as f64 * self.dt
    }

    /// The index of the ego in `objects`.
    pub fn ego(&self) -> Option<usize> {
        self.objects.iter().position(|o| o.is_ego)
    }
}

/// An actor group as an emitted program announces it: `# group `NAME`: COUNT TYPE ...`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Group {
    pub name: String,
    pub count: usize,
}

/// The groups of an emitted program, in the order it creates them (after the ego).
pub fn program_groups(program: &str) -> Vec<Group> {
    program
        .lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("# group `")?;
            let (name, rest) = rest.split_once('`')?;
            let count = rest.strip_prefix(": ")?.split_whitespace().next()?.parse().ok()?;
            Some(Group { name: name.to_string(), count })
        })
        .collect()
}

/// Who an object is in TAD terms: `ego`, or a member (from 1) of an actor group.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Label {
    pub group: String,
    pub member: usize,
    /// The size of its group.
    pub count: usize,
}

impl std::fmt::Display for Label {
    /// As the program names it: `ego`, `bus`, `parked_sedans_3`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.count > 1 { write!(f, "{}_{}", self.group, self.member) } else { f.write_str(&self.group) }
    }
}

/// The label of each object of `trace`: from its `tadName`/`tadGroup` and `tadIndex` where
/// the program gives them, else by creation order (the ego, then `count` objects per group
/// of `groups`). `None` where neither tells (more objects than the groups hold).
pub fn labels(trace: &Trace, groups: &[Group]) -> Vec<Option<Label>> {
    let mut by_order = Vec::new();
    for g in groups {
        for member in 1..=g.count {
            by_order.push(Label { group: g.name.clone(), member, count: g.count });
        }
    }
    let mut by_order = by_order.into_iter();
    trace
        .objects
        .iter()
        .map(|o| {
            if o.is_ego {
                return Some(Label { group: "ego".to_string(), member: 1, count: 1 });
            }
            let ordered = by_order.next();
            match (o.group.as_ref().or(o.name.as_ref()), o.index) {
                (Some(group), index) => {
                    let count = groups.iter().find(|g| &g.name == group).map_or(1, |g| g.count);
                    Some(Label { group: group.clone(), member: index.unwrap_or(1), count })
                }
                (None, _) => ordered,
            }
        })
        .collect()
}

/// The trace script: `TADSL_SCENIC_TRACE`, else the repository's, else the copy embedded in
/// this crate, written once under the system's temporary directory.
pub fn script() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("TADSL_SCENIC_TRACE").map(PathBuf::from),
        Some(repo().join("compiler/backends/scenic/tools/scenic_trace.py")),
    ];
    if let Some(found) = candidates.into_iter().flatten().find(|p| p.is_file()) {
        return Some(found);
    }
    const SCRIPT: &str = include_str!("../../scenic/tools/scenic_trace.py");
    let path = std::env::temp_dir().join(format!("tadsl-scenic-trace-{}.py", std::process::id()));
    std::fs::write(&path, SCRIPT).ok()?;
    Some(path)
}

/// What tracing needs: the Python with Scenic, the script, and a directory of links to the
/// maps for the programs to name (so Scenic's map cache lands there and is reused).
#[derive(Debug, Clone)]
pub struct Tracer {
    pub python: PathBuf,
    pub script: PathBuf,
    pub maps: PathBuf,
}

/// How to trace.
#[derive(Debug, Clone)]
pub struct TraceOptions {
    pub seeds: Vec<u64>,
    /// Steps per simulation (0.1 s each).
    pub steps: u32,
    /// Scenic processes run at once (files that name the same map share one, so that two
    /// never write the same map cache).
    pub jobs: usize,
    /// More arguments for the script (e.g. `--max-iters 500`).
    pub args: Vec<String>,
}

impl Default for TraceOptions {
    fn default() -> Self {
        TraceOptions { seeds: vec![0], steps: 60, jobs: 1, args: Vec::new() }
    }
}

/// The map a program names (`param map = '...'`), to keep programs of one map together.
fn map_of(file: &Path) -> String {
    std::fs::read_to_string(file)
        .ok()
        .and_then(|t| t.lines().find_map(|l| l.strip_prefix("param map = ").map(str::to_string)))
        .unwrap_or_default()
}

/// `files` in at most `jobs` batches, the files of one map in one batch, the batches about
/// equally long.
fn batches(files: &[PathBuf], jobs: usize) -> Vec<Vec<PathBuf>> {
    let mut by_map: Vec<(String, Vec<PathBuf>)> = Vec::new();
    for file in files {
        let map = map_of(file);
        match by_map.iter_mut().find(|(m, _)| *m == map) {
            Some((_, group)) => group.push(file.clone()),
            None => by_map.push((map, vec![file.clone()])),
        }
    }
    by_map.sort_by_key(|(_, group)| std::cmp::Reverse(group.len()));
    let mut out: Vec<Vec<PathBuf>> = vec![Vec::new(); jobs.clamp(1, by_map.len().max(1))];
    for (_, group) in by_map {
        out.iter_mut().min_by_key(|b| b.len()).expect("a batch").extend(group);
    }
    out.retain(|b| !b.is_empty());
    out
}

impl Tracer {
    /// Trace `files` (Scenic programs for the Newtonian simulator): one [`Trace`] per file
    /// and seed, in the order of `files`, then of `options.seeds`. Panics (with Scenic's
    /// standard error) when the script does not give every record.
    pub fn run(&self, files: &[PathBuf], options: &TraceOptions) -> Vec<Trace> {
        run(&self.python, &self.script, files, options)
    }
}

/// [`Tracer::run`] with a given python and script.
pub fn run(python: &Path, script: &Path, files: &[PathBuf], options: &TraceOptions) -> Vec<Trace> {
    try_run(python, script, files, options).unwrap_or_else(|e| panic!("{e}"))
}

/// [`run`], saying why instead of panicking when the script cannot be started or does not
/// give every record (with Scenic's standard error).
pub fn try_run(python: &Path, script: &Path, files: &[PathBuf], options: &TraceOptions) -> Result<Vec<Trace>, String> {
    if files.is_empty() || options.seeds.is_empty() {
        return Ok(Vec::new());
    }
    let _turn = turn();
    let seeds = options.seeds.iter().map(u64::to_string).collect::<Vec<_>>().join(",");
    let steps = options.steps.to_string();
    let run_batch = |batch: &[PathBuf]| -> Result<Vec<Trace>, String> {
        let output = Command::new(python)
            .arg(script)
            .args(["--seeds", &seeds, "--steps", &steps])
            .args(&options.args)
            .args(batch)
            .output()
            .map_err(|e| format!("{} {}: {e}", python.display(), script.display()))?;
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        let traces: Vec<Trace> = stdout
            .lines()
            .filter(|l| l.starts_with('{'))
            .map(Trace::parse)
            .collect::<Result<_, _>>()
            .map_err(|e| format!("the trace script printed a bad record: {e}\n{stderr}"))?;
        if traces.len() != batch.len() * options.seeds.len() {
            return Err(format!(
                "the trace script printed {} records for {} files and {} seeds\n--- stderr\n{stderr}",
                traces.len(),
                batch.len(),
                options.seeds.len()
            ));
        }
        Ok(traces)
    };
    let batches = batches(files, options.jobs);
    let mut traces: Vec<Trace> = if batches.len() == 1 {
        run_batch(&batches[0])?
    } else {
        let results: Vec<Result<Vec<Trace>, String>> = std::thread::scope(|s| {
            let handles: Vec<_> = batches.iter().map(|b| s.spawn(|| run_batch(b))).collect();
            handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
        });
        let mut all = Vec::new();
        for r in results {
            all.extend(r?);
        }
        all
    };
    let order = |t: &Trace| {
        let file = files.iter().position(|f| *f == t.file).unwrap_or(usize::MAX);
        let seed = options.seeds.iter().position(|&s| s == t.seed).unwrap_or(usize::MAX);
        (file, seed)
    };
    traces.sort_by_key(order);
    Ok(traces)
}

#[cfg(test)]
mod tests {
    use super::*;

    const RECORD: &str = r#"{"file":"a.scenic","seed":3,"ok":false,"error":"[simulate] rejected at step 1: x",
        "dt":0.1,"steps":1,"termination":null,"objects":[
        {"index":0,"name":null,"group":null,"group_index":null,"class":"Car","length":4.5,"width":1.8,"is_ego":true},
        {"index":1,"name":"bus","group":"bus","group_index":1,"class":"Car","length":12.0,"width":2.5,"is_ego":false}],
        "states":[[[0,0,0,10],[0,20,0.5,null]],[[0,1,0,10],[0,21,0.5,0]]]}"#;

    #[test]
    fn parses_a_record() {
        let t = Trace::parse(&RECORD.replace('\n', "")).unwrap();
        assert_eq!((t.file.to_str(), t.seed, t.ok, t.steps(), t.ego()), (Some("a.scenic"), 3, false, 1, Some(0)));
        assert_eq!(t.error.as_deref(), Some("[simulate] rejected at step 1: x"));
        assert_eq!(t.objects[1].name.as_deref(), Some("bus"));
        assert_eq!(t.objects[1].index, Some(1));
        assert_eq!(t.objects[0].name, None);
        assert!(t.states[0][1].speed.is_nan());
        assert_eq!(t.states[1][1], Pose { x: 0.0, y: 21.0, heading: 0.5, speed: 0.0 });
        assert!((t.time(1) - 0.1).abs() < 1e-12);
        assert_eq!((t.objects[1].length, t.objects[1].width), (12.0, 2.5));
        assert_eq!(t.sim_s, None);
        let timed =
            Trace::parse(&RECORD.replace('\n', "").replace(r#""steps":1,"#, r#""steps":1,"sim_s":0.25,"#)).unwrap();
        assert_eq!(timed.sim_s, Some(0.25));
    }

    #[test]
    fn rejects_a_step_of_the_wrong_size() {
        let bad = RECORD.replace('\n', "").replace("[[0,1,0,10],[0,21,0.5,0]]", "[[0,1,0,10]]");
        assert!(Trace::parse(&bad).unwrap_err().contains("step 1"));
    }

    #[test]
    fn groups_and_labels() {
        let program = "ego = new Car\n# group `parked_sedans`: 2 sedan, parked, 0 km/h, right_front of ego, lane 3\n\
                       x = new Car\n# group `bus`: 1 bus, move_forward, 35 km/h, front of ego\n# grouping\n";
        let groups = program_groups(program);
        assert_eq!(groups, [Group { name: "parked_sedans".into(), count: 2 }, Group { name: "bus".into(), count: 1 }]);
        let mut t = Trace::parse(&RECORD.replace('\n', "")).unwrap();
        let mut other = t.objects[1].clone();
        other.name = None;
        other.group = None;
        other.index = None;
        t.objects[1] = other.clone();
        t.objects.push(other.clone());
        t.objects.push(other);
        let names: Vec<String> = labels(&t, &groups).iter().map(|l| l.as_ref().unwrap().to_string()).collect();
        assert_eq!(names, ["ego", "parked_sedans_1", "parked_sedans_2", "bus"]);
        t.objects.push(t.objects[1].clone());
        assert_eq!(labels(&t, &groups)[4], None);
    }

    #[test]
    fn batches_keep_a_map_together() {
        let dir = std::env::temp_dir().join(format!("tad-trace-batches-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let files: Vec<PathBuf> = ["A", "B", "A", "C", "A"]
            .iter()
            .enumerate()
            .map(|(i, town)| {
                let f = dir.join(format!("{i}.scenic"));
                std::fs::write(&f, format!("# x\nparam map = '/m/{town}.xodr'\n")).unwrap();
                f
            })
            .collect();
        let b = batches(&files, 2);
        assert_eq!(b.len(), 2);
        assert_eq!(b[0], [files[0].clone(), files[2].clone(), files[4].clone()]);
        assert_eq!(b[1], [files[1].clone(), files[3].clone()]);
        assert_eq!(batches(&files, 1).len(), 1);
        assert_eq!(batches(&files, 8).len(), 3);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
