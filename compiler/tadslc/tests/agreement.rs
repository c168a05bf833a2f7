//! The layout decides, every target renders: for every example, the layout
//! (`tad_layout::lay_out`), the Scenic plan (`tad_scenic::plan`) and the runtime's scene
//! (through the bytecode) agree on every fact of the ego and of every actor: size, speed,
//! motion, lane, place, arm, and how many actors each group has. Scenic renders the layout
//! itself, or, when no CARLA map has every lane the scenario uses, the layout laid out
//! within the closest map's lanes, with a W0701 for each lane that moved; when the map has
//! no junction, other arms' actors stand on the ego's road (W0701); where the map's road
//! cannot hold a whole group, a W0702 says how many were kept.

mod common;
use common::*;

use tad_diagnostics::Code;
use tad_scenic::EmitOptions;

/// Every fact of one scenario that the three disagree on, in words.
fn disagreements(scenario: &tad_ir::Scenario, name: &str) -> Vec<String> {
    let laid = tad_layout::lay_out(scenario);
    let (plan, diagnostics) = tad_scenic::plan::plan(scenario, &EmitOptions::default());
    let scene = tad_runtime::Scene::new(&tad_eval::pipeline::program(scenario, name)).expect("the scene sets up");
    let mut out = Vec::new();
    let mut differ = |what: &str, layout: String, other: String, target: &str| {
        if layout != other {
            out.push(format!("{what}: layout {layout}, {target} {other}"));
        }
    };
    let w0701 = diagnostics.iter().filter(|d| d.code == Code::W0701).count();

    // the layout Scenic renders is the layout, or (with W0701s saying why) the layout
    // within the lanes of a map that lacks some the scenario uses, a W0701 for every lane
    // it moved
    let moved = plan.layout.findings.iter().filter(|f| matches!(f, tad_layout::Finding::Moved { .. })).count();
    if plan.layout != laid && (w0701 == 0 || w0701 < moved) {
        differ(
            "the layout Scenic renders",
            "one".into(),
            format!("another, with {w0701} W0701 for {moved} lanes moved"),
            "Scenic",
        );
    }
    let rendered = &plan.layout;

    // the ego
    differ("ego length", format!("{:.3}", rendered.ego.length), format!("{:.3}", plan.ego.length), "Scenic");
    differ("ego width", format!("{:.3}", rendered.ego.width), format!("{:.3}", plan.ego.width), "Scenic");
    differ("ego speed", format!("{:.3}", rendered.ego.speed), format!("{:.3}", plan.ego.target_speed), "Scenic");
    differ("ego motion", format!("{:?}", rendered.ego.motion), format!("{:?}", plan.ego.motion), "Scenic");
    differ("ego lane", rendered.ego.lane.to_string(), plan.ego.lane.to_string(), "Scenic");
    differ("ego length", format!("{:.3}", laid.ego.length), format!("{:.3}", scene.ego.size.length), "runtime");
    differ("ego lane", laid.ego.lane.to_string(), scene.ego.lane.to_string(), "runtime");

    // every group, every actor
    let capped = diagnostics.iter().any(|d| d.code == Code::W0702);
    for (i, (group, drawn)) in rendered.groups.iter().zip(&plan.groups).enumerate() {
        if !(capped && drawn.actors.len() < group.agents.len()) {
            differ(
                &format!("group {i} count"),
                group.agents.len().to_string(),
                drawn.actors.len().to_string(),
                "Scenic",
            );
        }
        for (j, (agent, a)) in group.agents.iter().zip(&drawn.actors).enumerate() {
            let who = format!("group {i} actor {j}");
            differ(&format!("{who} length"), format!("{:.3}", agent.length), format!("{:.3}", a.length), "Scenic");
            differ(&format!("{who} motion"), format!("{:?}", agent.motion), format!("{:?}", a.motion), "Scenic");
            differ(&format!("{who} speed"), format!("{:.3}", agent.speed), format!("{:.3}", a.target_speed), "Scenic");
            differ(&format!("{who} lane"), agent.lane.to_string(), a.lane.to_string(), "Scenic");
            differ(&format!("{who} place"), format!("{:?}", agent.place), format!("{:?}", a.place), "Scenic");
            // a map without the junction has its other arms' actors on the ego's road
            if !(w0701 > 0 && a.arm == tad_layout::Arm::Ego) {
                differ(&format!("{who} arm"), format!("{:?}", agent.station.arm), format!("{:?}", a.arm), "Scenic");
            }
        }
    }
    differ("groups", rendered.groups.len().to_string(), plan.groups.len().to_string(), "Scenic");
    let mut spawned = scene.actors.iter();
    for (i, group) in laid.groups.iter().enumerate() {
        let runtime: Vec<_> = spawned.by_ref().take(group.agents.len()).collect();
        differ(&format!("group {i} count"), group.agents.len().to_string(), runtime.len().to_string(), "runtime");
        for (j, (agent, r)) in group.agents.iter().zip(&runtime).enumerate() {
            let who = format!("group {i} actor {j}");
            differ(
                &format!("{who} length"),
                format!("{:.3}", agent.length),
                format!("{:.3}", r.size.length),
                "runtime",
            );
            differ(&format!("{who} arm"), format!("{:?}", agent.station.arm), format!("{:?}", r.arm), "runtime");
            differ(&format!("{who} lane"), agent.lane.to_string(), r.lane.to_string(), "runtime");
            differ(&format!("{who} place"), format!("{:?}", agent.place), format!("{:?}", r.place), "runtime");
            // the speed at step 0: its speed when it starts moving, else standing
            let start = if agent.moving { agent.speed } else { 0.0 };
            differ(&format!("{who} start speed"), format!("{start:.3}"), format!("{:.3}", r.speed), "runtime");
        }
    }
    out
}

/// Scenarios at the edges of what the layout decides: a road wider than it lays out (the
/// ego in the middle of its 12 lanes, then moved by the map choice), a group larger than
/// it places, an ego written in an opposite lane, and nothing stated but the road.
const EDGES: &[(&str, &str)] = &[
    (
        "wide_road",
        "scenario wide_road {\n  environment {\n    weather: clear\n    time: daytime\n  }\n  road {\n    type: straight_road\n    lanes: 20\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    speed: 40 km/h\n  }\n  actor beside: 2 car {\n    behavior: move_forward\n    speed: 30 km/h\n    position: left_front of ego\n  }\n}\n",
    ),
    (
        "crowd",
        "scenario crowd {\n  environment {\n    weather: clear\n    time: daytime\n  }\n  road {\n    type: straight_road\n    lanes: 2\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    speed: 30 km/h\n    lane: 1\n  }\n  actor walkers: 100000 pedestrian {\n    behavior: walk\n    position: right_front of ego\n  }\n}\n",
    ),
    (
        "opposite_ego",
        "scenario opposite_ego {\n  environment {\n    weather: rain\n    time: night\n  }\n  road {\n    type: straight_road\n    lanes: 2\n    direction: two_way\n  }\n  ego {\n    behavior: move_forward\n    lane: -1\n  }\n  actor someone: pedestrian {\n  }\n}\n",
    ),
];

#[test]
fn the_layout_the_scenic_plan_and_the_runtime_agree_at_the_edges() {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let mut all = Vec::new();
    for (name, text) in EDGES {
        let file =
            db.set_source(format!("/edges/{name}.tad").into(), text.to_string(), tad_db::Language::Tad, &tad_db::NoFs);
        let errors: Vec<_> = tad_db::check(&db, file).diagnostics.iter().filter(|d| d.is_error()).cloned().collect();
        assert!(errors.is_empty(), "{name}: {errors:#?}");
        let scenario = tad_db::resolve(&db, file).as_ref().expect("a scenario");
        all.extend(disagreements(scenario, name).into_iter().map(|d| format!("{name}: {d}")));
    }
    assert!(all.is_empty(), "{} disagreements:\n{}", all.len(), all.join("\n"));
}

#[test]
fn the_layout_the_scenic_plan_and_the_runtime_agree_on_every_fact_of_every_example() {
    let root = repo().join("examples");
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let mut all = Vec::new();
    for path in tad_files(&root) {
        let input = tad_db::host::read(&path).unwrap();
        let file = tad_db::host::register(&mut db, &input);
        let Some(scenario) = tad_db::resolve(&db, file) else { continue };
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        for d in disagreements(scenario, &name) {
            all.push(format!("{}: {d}", path.strip_prefix(&root).unwrap().display()));
        }
    }
    assert!(all.is_empty(), "{} disagreements:\n{}", all.len(), all.join("\n"));
}
