//! The layout keeps every example's meaning, checked on its own roll-out (no simulator):
//! relations hold at the start, no two actors other than the ego overlap in the first
//! seconds, and every adversary comes within a few metres of the ego. Prints the table.

use std::path::Path;

use tad_layout::fidelity::{ADVERSARY_REACH, Assessment, assess};
use tad_layout::{Layout, lay_out, predict};

fn resolved(path: &Path) -> tad_ir::Scenario {
    let text = std::fs::read_to_string(path).unwrap();
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(path.to_path_buf(), text);
    tad_db::resolve(&db, file).clone().expect("an example has a scenario")
}

fn name(scenario: &tad_ir::Scenario, layout: &Layout, trace: &tad_layout::fidelity::Trace, k: usize) -> String {
    let o = &trace.objects[k];
    match o.group {
        None => "ego".into(),
        Some(g) => {
            let n = layout.group(g).map_or(1, |g| g.agents.len());
            let base = scenario.group(g).map_or("?", |g| g.name.as_str());
            if n > 1 { format!("{base}[{}]", o.index + 1) } else { base.to_string() }
        }
    }
}

pub fn describe(
    scenario: &tad_ir::Scenario,
    layout: &Layout,
    trace: &tad_layout::fidelity::Trace,
    a: &Assessment,
) -> String {
    let relations = a.relations.iter().filter(|r| r.holds).count();
    let overlaps: Vec<String> = a
        .overlaps
        .iter()
        .map(|o| {
            format!("{}×{} at {:.1} s", name(scenario, layout, trace, o.a), name(scenario, layout, trace, o.b), o.time)
        })
        .collect();
    let adversaries: Vec<String> = a
        .adversaries
        .iter()
        .map(|x| {
            let who = scenario.group(x.group).map_or("?", |g| g.name.as_str());
            format!("{who} {:.1} m at {:.1} s", x.distance, x.time)
        })
        .collect();
    format!(
        "relations {relations}/{} | overlaps {} | adversaries {}",
        a.relations.len(),
        if overlaps.is_empty() { "none".into() } else { overlaps.join(", ") },
        if adversaries.is_empty() { "-".into() } else { adversaries.join(", ") }
    )
}

#[test]
fn every_example_keeps_its_meaning_in_the_layouts_roll_out() {
    let mut failures = Vec::new();
    for path in tad_test_support::examples() {
        let scenario = resolved(&path);
        let layout = lay_out(&scenario);
        let trace = predict::roll_out(&layout, 150, 0.1);
        let assessment = assess(&scenario, &layout, &trace);
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        println!("{stem:<40} {}", describe(&scenario, &layout, &trace, &assessment));
        for r in assessment.relations.iter().filter(|r| !r.holds) {
            let who = scenario.group(r.group).map_or("?", |g| g.name.as_str());
            failures.push(format!("{stem}: {who}: {} — {}", r.measured, r.failure.clone().unwrap_or_default()));
        }
        if !assessment.overlaps.is_empty() {
            failures.push(format!("{stem}: overlaps {:?}", assessment.overlaps));
        }
        for x in assessment.adversaries.iter().filter(|x| x.distance > ADVERSARY_REACH) {
            let who = scenario.group(x.group).map_or("?", |g| g.name.as_str());
            failures.push(format!("{stem}: adversary {who} only comes within {:.1} m", x.distance));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
#[ignore]
fn dump() {
    let name = std::env::var("TAD_DUMP").unwrap_or_default();
    for path in tad_test_support::examples() {
        if !path.to_string_lossy().contains(&name) {
            continue;
        }
        let scenario = resolved(&path);
        let layout = lay_out(&scenario);
        println!("road {:?} approach {:.1}", layout.road.shape, layout.road.approach);
        for a in layout.agents() {
            println!(
                "{:?}#{} {:?} lane {} along {:.1} lat {:.1} pose ({:.1},{:.1},{:.0}°) v {:.1} moving {} delay {:.1} start {:.1}/{:.1}",
                a.group,
                a.index,
                a.station.arm,
                a.lane,
                a.station.along,
                a.lateral,
                a.pose.position.x,
                a.pose.position.y,
                a.pose.yaw.to_degrees(),
                a.speed,
                a.moving,
                a.start.delay,
                a.path_start,
                a.path.length()
            );
        }
        println!("{:#?}", layout.conflicts);
    }
}
