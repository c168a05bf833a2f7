//! What `tadslc run` leaves of its episodes, as values a host writes: each episode's JSON
//! record and each ego's aggregate (`--format json`), the trace of every actor's pose per
//! step (`--trace`), the picture of an episode (`--render`, SVG or GIF through
//! `tad-render`), the table for people, the results file `merge` reads, and the CI gate:
//! which episodes met a `--fail-on` criterion, and the JUnit XML report (`--junit`) that
//! GitLab, Jenkins and GitHub display, one test case per scenario × ego × seed.
//!
//! An episode is a [`Played`]: which scenario and which ego, the episode and its score.

use std::io::Write;

use tad_base::Shard;
use tad_metrics::{EpisodeScore, Mode};
use tad_runtime::{Episode, Event, EventKind, Scene};

use crate::{Results, Row, Setup};

/// One finished episode: the indexes of its scenario and ego, the episode and its score.
pub struct Played {
    pub scenario: usize,
    pub ego: usize,
    pub episode: Episode,
    pub score: EpisodeScore,
}

/// An episode's JSON record.
pub fn episode_json(file: &str, ego: &str, e: &Episode, score: &EpisodeScore) -> serde_json::Value {
    serde_json::json!({
        "file": file,
        "seed": e.seed,
        "ego": ego,
        "steps": e.steps,
        "stop_reason": e.stop_reason.as_str(),
        "metrics": score.metrics,
    })
}

/// An ego's aggregate over its episodes as JSON (`None` when nothing can be aggregated).
pub fn aggregate_json(ego: &str, scores: &[EpisodeScore], mode: Mode) -> Option<serde_json::Value> {
    let agg = tad_metrics::aggregate(scores, mode).ok()?;
    Some(serde_json::json!({
        "aggregate": true,
        "ego": ego,
        "episodes": agg.episodes,
        "completed": agg.completed,
        "mode": mode.as_str(),
        "metrics": agg.raw,
        "normalised": agg.normalised,
        "safety": agg.safety,
        "task": agg.task,
        "comfort": agg.comfort,
    }))
}

/// One JSON line per step of `e`: every actor's pose and speed (to the millimetre) and the
/// lights.
pub fn write_trace(w: &mut impl Write, file: &str, ego: &str, scene: &Scene, e: &Episode) -> std::io::Result<()> {
    let labels: Vec<String> =
        std::iter::once("ego".to_string()).chain(scene.actors.iter().map(|a| a.label.clone())).collect();
    for (step, frame) in e.frames.iter().enumerate() {
        let actors: Vec<serde_json::Value> = frame
            .poses
            .iter()
            .zip(&frame.speeds)
            .zip(&labels)
            .map(|((&(x, y, yaw), &v), label)| {
                serde_json::json!({"id": label, "x": round(x), "y": round(y), "yaw": round(yaw), "v": round(v)})
            })
            .collect();
        let lights: serde_json::Map<String, serde_json::Value> = frame
            .lights
            .iter()
            .map(|(arm, l)| (arm.as_str().to_string(), format!("{l:?}").to_lowercase().into()))
            .collect();
        let line = serde_json::json!({
            "file": file, "seed": e.seed, "ego": ego, "step": step,
            "t": round(step as f64 * scene.limits.dt), "actors": actors, "lights": lights,
        });
        writeln!(w, "{line}")?;
    }
    Ok(())
}

fn round(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// The picture of an episode: an animated GIF, or an SVG figure.
pub fn picture(scene: &Scene, ego: &str, e: &Episode, format: tad_render::Format) -> Vec<u8> {
    use tad_render::{ActorInfo, Frame, Kind};
    let size = scene.ego.size;
    let actors =
        std::iter::once(ActorInfo { label: "ego".into(), kind: Kind::Ego, length: size.length, width: size.width })
            .chain(scene.actors.iter().map(|a| ActorInfo {
                label: a.label.clone(),
                kind: match a.body {
                    tad_layout::Body::Vehicle => Kind::Vehicle,
                    tad_layout::Body::Walker => Kind::Walker,
                    tad_layout::Body::Object => Kind::Object,
                },
                length: a.size.length,
                width: a.size.width,
            }))
            .collect();
    let frames = e
        .frames
        .iter()
        .map(|f| Frame {
            poses: f.poses.iter().map(|&(x, y, yaw)| Some([x, y, yaw])).collect(),
            lights: f.lights.clone(),
        })
        .collect();
    let (start, length) = (scene.ego.start, scene.ego.route_length);
    let route = (0..=(length / 2.0).ceil() as usize)
        .map(|k| scene.ego.route.pose(start + (2.0 * k as f64).min(length)).position)
        .map(|p| [p.x, p.y])
        .collect();
    let events = e
        .events
        .iter()
        .map(|ev| tad_render::Event {
            step: ev.step as usize,
            position: [ev.position.x, ev.position.y],
            label: match ev.other {
                Some(k) => {
                    format!("{} with {}", ev.kind.as_str(), scene.actors.get(k).map_or("?", |a| a.label.as_str()))
                }
                None => ev.kind.as_str().replace('_', " "),
            },
        })
        .collect();
    let picture = tad_render::Scene {
        road: &scene.world.road,
        title: format!("{} · seed {} · ego {ego}", scene.name, e.seed.unwrap_or(0)),
        actors,
        frames,
        dt: scene.limits.dt,
        route,
        events,
    };
    format.draw(&picture)
}

/// The table for people: one row per scenario and ego (aggregated over the seeds), then
/// one per ego over all scenarios, in the paper's normalised values (value / max) and OS.
pub fn table(scenarios: &[&str], egos: &[String], played: &[Played], mode: Mode) -> String {
    let counted: Vec<Counted> = played
        .iter()
        .map(|d| Counted { scenario: d.scenario, ego: d.ego, score: &d.score, stop: d.episode.stop_reason.as_str() })
        .collect();
    table_of(scenarios, egos, &counted, mode)
}

/// The table of `run`'s results files merged (the shards of `run --shard --out`, each
/// once): the table the unsharded run prints. `None` for another command's files.
pub fn merged_table(all: &[Results]) -> Option<String> {
    let setup = &all.first()?.setup;
    if !setup.is_run() {
        return None;
    }
    let mut rows: Vec<&Row> = all.iter().flat_map(|r| &r.rows).collect();
    // the inputs' order, then the seed's: as the unsharded run plays them
    rows.sort_by_key(|r| (r.index, r.seed));
    let mut scenarios: Vec<(Option<usize>, &str)> = Vec::new();
    for r in &rows {
        if !scenarios.contains(&(r.index, r.scenario.as_str())) {
            scenarios.push((r.index, r.scenario.as_str()));
        }
    }
    let counted: Vec<Counted> = rows
        .iter()
        .filter_map(|r| {
            Some(Counted {
                scenario: scenarios.iter().position(|(i, name)| *i == r.index && *name == r.scenario)?,
                ego: setup.egos.iter().position(|e| *e == r.ego)?,
                score: &r.score,
                stop: r.stop.as_deref().unwrap_or("-"),
            })
        })
        .collect();
    let names: Vec<&str> = scenarios.iter().map(|(_, name)| *name).collect();
    Some(table_of(&names, &setup.egos, &counted, setup.mode()))
}

/// One episode as the table counts it.
struct Counted<'a> {
    scenario: usize,
    ego: usize,
    score: &'a EpisodeScore,
    stop: &'a str,
}

fn table_of(scenarios: &[&str], egos: &[String], played: &[Counted], mode: Mode) -> String {
    use std::fmt::Write;
    let width = scenarios.iter().map(|s| s.len()).max().unwrap_or(8).clamp(8, 40);
    // an ego named by its file (`learned:PATH`) widens its column rather than the rows
    let ego_width = egos.iter().map(|e| e.chars().count()).max().unwrap_or(10).clamp(10, 60);
    let mut out = format!("{:<width$}  {:<ego_width$} {:>4}", "scenario", "ego", "runs");
    for m in tad_metrics::METRICS.iter() {
        let _ = write!(out, " {:>6}", m.key);
    }
    let _ = writeln!(out, " {:>6}  stops", "OS");
    let mut row = |label: &str, ego: &str, rows: &[&Counted]| {
        let scores: Vec<EpisodeScore> = rows.iter().map(|d| d.score.clone()).collect();
        let Ok(agg) = tad_metrics::aggregate(&scores, mode) else { return };
        let _ = write!(out, "{label:<width$}  {ego:<ego_width$} {:>4}", rows.len());
        for m in tad_metrics::METRICS.iter() {
            let _ = match agg.normalised.get(m.metric) {
                Some(v) => write!(out, " {v:>6.3}"),
                None => write!(out, " {:>6}", "-"),
            };
        }
        let mut stops: Vec<(&str, usize)> = Vec::new();
        for d in rows {
            let name = d.stop;
            match stops.iter_mut().find(|(n, _)| *n == name) {
                Some((_, k)) => *k += 1,
                None => stops.push((name, 1)),
            }
        }
        let stops: Vec<String> = stops.iter().map(|(n, k)| format!("{n} {k}")).collect();
        let _ = writeln!(out, " {:>6.3}  {}", agg.normalised.os, stops.join(", "));
    };
    for (f, name) in scenarios.iter().enumerate() {
        for (e, ego) in egos.iter().enumerate() {
            let rows: Vec<&Counted> = played.iter().filter(|d| d.scenario == f && d.ego == e).collect();
            let name: String = name.chars().take(width).collect();
            row(&name, ego, &rows);
        }
    }
    if scenarios.len() > 1 {
        for (e, ego) in egos.iter().enumerate() {
            let rows: Vec<&Counted> = played.iter().filter(|d| d.ego == e).collect();
            row("all", ego, &rows);
        }
    }
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "values normalised as in TrafficAlign's tables ({}; OS 1 is perfect); {} scoring",
        tad_metrics::normalisation(),
        mode.as_str()
    );
    out
}

/// The episodes as a results file of `eval`'s form (one region `all`, one generator
/// `files`), for `tadslc merge`: `scenarios` named in order, `egos` as the table names
/// them, `seeds` the seeds each ran with; each row keeps its episode's stop and its
/// scenario's place among all the command's inputs, so that the shards merge into the
/// unsharded run's table.
pub fn results(
    scenarios: &[&str],
    egos: &[String],
    seeds: std::ops::Range<u64>,
    shard: Shard,
    played: &[Played],
    mode: Mode,
) -> Results {
    let rows: Vec<Row> = played
        .iter()
        .map(|d| Row {
            region: "all".into(),
            generator: "files".into(),
            ego: egos[d.ego].clone(),
            scenario: scenarios[d.scenario].to_string(),
            trial: 0,
            seed: d.episode.seed.unwrap_or(0),
            score: d.score.clone(),
            stop: Some(d.episode.stop_reason.as_str().to_string()),
            // the shard takes every count-th input from its index
            index: Some(shard.index + d.scenario * shard.count),
        })
        .collect();
    let setup = Setup {
        regions: vec![crate::results::RUN_REGION.into()],
        generators: vec![crate::results::RUN_GENERATOR.into()],
        egos: egos.to_vec(),
        search_ego: String::new(),
        n: 0,
        samples: (seeds.end - seeds.start) as usize,
        keep: 0,
        seed: seeds.start,
        compat: mode == Mode::Compat,
    };
    Results::new(setup, shard, [("all/files".to_string(), scenarios.len())].into_iter().collect(), rows)
}

/// The first event of `episode` that is one of `criteria`: the criterion it failed.
pub fn failed<'e>(episode: &'e Episode, criteria: &[EventKind]) -> Option<&'e Event> {
    episode.events.iter().find(|e| criteria.contains(&e.kind))
}

/// The JUnit XML report: one `<testsuite>` per scenario (`scenarios`: its name and step
/// length, as `played` indexes them), one `<testcase>` per ego and seed, named `EGO seed N`,
/// with its simulated time; a `<failure>` for an episode that met one of `criteria` (its
/// type the criterion, its message the step and time); the stop reason and the ten metrics
/// in `<system-out>`.
pub fn junit(scenarios: &[(&str, f64)], egos: &[String], played: &[Played], criteria: &[EventKind]) -> String {
    use std::fmt::Write;
    let fails = |p: &Played| failed(&p.episode, criteria).is_some();
    let dt = |p: &Played| scenarios.get(p.scenario).map_or(0.0, |(_, dt)| *dt);
    let seconds = |p: &Played| p.episode.steps as f64 * dt(p);
    let mut xml = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let (all, failures) = (played.len(), played.iter().filter(|p| fails(p)).count());
    let total: f64 = played.iter().map(seconds).sum();
    let _ = writeln!(
        xml,
        "<testsuites name=\"tadslc run\" tests=\"{all}\" failures=\"{failures}\" errors=\"0\" time=\"{total:.3}\">"
    );
    for (k, (scenario, _)) in scenarios.iter().enumerate() {
        let cases: Vec<&Played> = played.iter().filter(|p| p.scenario == k).collect();
        let failing = cases.iter().filter(|p| fails(p)).count();
        let time: f64 = cases.iter().map(|p| seconds(p)).sum();
        let name = tad_base::xml_escape(scenario);
        let _ = writeln!(
            xml,
            "  <testsuite name=\"{name}\" tests=\"{}\" failures=\"{failing}\" errors=\"0\" skipped=\"0\" time=\"{time:.3}\">",
            cases.len()
        );
        for p in cases {
            let ego = tad_base::xml_escape(egos.get(p.ego).map_or("", String::as_str));
            let seed = p.episode.seed.unwrap_or(0);
            let _ = writeln!(
                xml,
                "    <testcase classname=\"{name}\" name=\"{ego} seed {seed}\" time=\"{:.3}\">",
                seconds(p)
            );
            if let Some(event) = failed(&p.episode, criteria) {
                let kind = event.kind.as_str();
                let at = event.step as f64 * dt(p);
                let _ = writeln!(
                    xml,
                    "      <failure type=\"{kind}\" message=\"{kind} at step {} ({at:.1} s)\">{kind} at step {} ({at:.1} s), at ({:.1}, {:.1}) m</failure>",
                    event.step, event.step, event.position.x, event.position.y
                );
            }
            let metrics: Vec<String> = tad_metrics::METRICS
                .iter()
                .filter_map(|m| Some(format!("{} {:.3}", m.key, p.score.metrics.get(m.metric)?)))
                .collect();
            let _ = writeln!(
                xml,
                "      <system-out>stop reason: {}; steps: {}; {}</system-out>",
                p.episode.stop_reason.as_str(),
                p.episode.steps,
                metrics.join(", ")
            );
            xml.push_str("    </testcase>\n");
        }
        xml.push_str("  </testsuite>\n");
    }
    xml.push_str("</testsuites>\n");
    xml
}
