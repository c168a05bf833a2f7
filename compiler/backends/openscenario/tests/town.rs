//! `--map TownNN` (`spec/backends/openscenario.md` §4): every example placed on each of
//! CARLA's six towns (`../shared/maps/CARLA`), the written `.xosc` read back as XML and resolved on the
//! town's `.xodr`:
//!
//! - every start is a lane of the town at an `s` within its road, a vehicle's a driving lane;
//! - on the ego's road, each actor's gap to the ego along the road is the layout's within
//!   10 cm, and its lane has the layout's rank from the centre line (where the town's road
//!   is long enough and has the lanes: else a W0712 says it is not);
//! - the ego's route enters the junction through a connection the town has from its road and
//!   lane, leaves it on that connection's road, and turns the way the layout's does.
//!
//! Skipped (loudly) without the maps, unless `TAD_REQUIRE_MAPS=1`.

mod common;

use std::collections::HashMap;
use std::f64::consts::PI;

use tad_bytecode::Instr;
use tad_openscenario::town::Town;
use tad_road::geom::{Vec2, wrap};
use tad_road::{Arm, Body, Turn};

/// Gaps within this of the layout's, m.
const GAP_TOLERANCE: f64 = 0.10;
/// Conflict points within this of the ego's way, m.
const WAY_TOLERANCE: f64 = 0.75;
/// A crossing within this of square to its road, rad.
const CROSS_TOLERANCE: f64 = 20.0 * PI / 180.0;
/// A turn's heading change within this of its nominal, rad.
const TURN_TOLERANCE: f64 = 35.0 * PI / 180.0;
/// The towns tried: CARLA's six of `../shared/maps/CARLA`.
const TOWNS: [&str; 6] = ["Town10HD", "Town04", "Town07", "Town06", "Town01", "Town02"];

fn towns() -> Vec<Town> {
    TOWNS.iter().map_while(|name| common::town(name).map(|(town, _)| town)).collect()
}

/// A `LanePosition` read back.
#[derive(Debug)]
struct Lane {
    road: u32,
    lane: i32,
    s: Option<f64>,
}

fn lane_position(node: roxmltree::Node) -> Option<Lane> {
    let p = node.descendants().find(|n| n.has_tag_name("LanePosition"))?;
    Some(Lane {
        road: p.attribute("roadId")?.parse().ok()?,
        lane: p.attribute("laneId")?.parse().ok()?,
        s: p.attribute("s")?.parse().ok(),
    })
}

/// Each entity's start (the `TeleportAction` of its `Private` in `Init`).
fn starts(doc: &roxmltree::Document) -> HashMap<String, Lane> {
    doc.descendants()
        .filter(|n| n.has_tag_name("Private") && n.ancestors().any(|a| a.has_tag_name("Init")))
        .filter_map(|n| {
            let teleport = n.descendants().find(|d| d.has_tag_name("TeleportAction"))?;
            Some((n.attribute("entityRef")?.to_string(), lane_position(teleport)?))
        })
        .collect()
}

/// The ego's route's waypoints.
fn ego_route(doc: &roxmltree::Document) -> Vec<Lane> {
    doc.descendants()
        .find(|n| n.has_tag_name("Route") && n.attribute("name") == Some("ego_route"))
        .map(|r| r.children().filter(|w| w.has_tag_name("Waypoint")).filter_map(lane_position).collect())
        .unwrap_or_default()
}

/// The rank of a lane among its side's driving lanes at `s`, from the centre (1 = innermost).
fn rank(town: &Town, road: u32, s: f64, lane: i32) -> Option<usize> {
    let r = town.road(road)?;
    r.driving(s, lane.signum()).iter().position(|id| *id == lane).map(|k| k + 1)
}

/// The direction traffic drives in a lane at `s`.
fn heading(town: &Town, road: u32, lane: i32, s: f64) -> f64 {
    let yaw = town.road(road).unwrap().pose(s).yaw;
    if lane > 0 { yaw + PI } else { yaw }
}

fn nominal(turn: Turn) -> f64 {
    match turn {
        Turn::Straight => 0.0,
        Turn::Left => PI / 2.0,
        Turn::Right => -PI / 2.0,
        Turn::UTurn => PI,
    }
}

#[derive(Default)]
struct Checked {
    gaps: usize,
    routes: usize,
    meets: usize,
    crossings: usize,
}

fn check(town: &Town, path: &std::path::Path, problems: &mut Vec<String>) -> Checked {
    let text = std::fs::read_to_string(path).unwrap();
    let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
    let (scenario, _) = common::emit(path, &text, &stem);
    let file = format!("{}.xodr", town.name);
    let emitted =
        common::on_town(&scenario, &stem, town, &file).unwrap_or_else(|e| panic!("{stem} on {}: {e}", town.name));
    assert!(emitted.xodr.is_none(), "no road of its own on a town");
    let warned = |what: &str| {
        emitted.diagnostics.iter().any(|d| d.code == tad_diagnostics::Code::W0712 && d.message.contains(what))
    };
    let (ego_short, ego_lanes) = (warned("the ego's road is"), warned("the ego's road has"));
    let layout = tad_layout::lay_out(&scenario);
    let program = tad_bytecode::lower(&scenario, &layout, &stem);
    let doc = roxmltree::Document::parse(&emitted.xosc).unwrap();
    assert!(
        doc.descendants().any(|n| n.has_tag_name("LogicFile") && n.attribute("filepath") == Some(file.as_str())),
        "{stem}: the town's file is the road network"
    );
    let starts = starts(&doc);
    let name = format!("{stem} on {}", town.name);
    let w0712 = emitted.diagnostics.iter().filter(|d| d.code == tad_diagnostics::Code::W0712).count();
    let ego_at = starts.get("ego").map_or("-".to_string(), |p| format!("road {} lane {}", p.road, p.lane));
    let route = ego_route(&doc);
    let via = route.get(1).map_or("-".to_string(), |p| format!("road {}", p.road));
    println!("| {stem} | {} | {ego_at} | {via} | {w0712} |", town.name);
    let mut checked = Checked::default();
    let Some(ego) = starts.get("ego") else {
        problems.push(format!("{name}: the ego has no lane position"));
        return checked;
    };
    for (entity, p) in &starts {
        let Some(road) = town.road(p.road) else {
            problems.push(format!("{name}: {entity} is on road {}, which the town lacks", p.road));
            continue;
        };
        let Some(s) = p.s else { continue };
        if !(-1e-6..=road.length + 1e-6).contains(&s) || road.lane_span(s, p.lane).is_none() {
            problems.push(format!("{name}: {entity} at s {s} lane {} is off road {}", p.lane, p.road));
        }
    }
    // the ego's road: lanes and gaps
    let ego_dir = if ego.lane > 0 { -1.0 } else { 1.0 };
    for instr in &program.code {
        let Instr::Spawn { group, index, body, arm: Arm::Ego, lane, along, lateral, .. } = instr else { continue };
        let entity = tad_openscenario::xosc::entity(group, *index);
        let Some(p) = starts.get(&entity) else { continue };
        let (Some(s), Some(ego_s)) = (p.s, ego.s) else { continue };
        let road = town.road(p.road).unwrap();
        let inside = s > 1e-6 && s < road.length - 1e-6;
        let on_lane = (lateral - layout.road.lateral(*lane)).abs() < 0.5 * layout.road.lane_width;
        if *body == Body::Vehicle && on_lane && !ego_lanes {
            let sides = (p.lane.signum() == ego.lane.signum()) == (*lane > 0);
            if rank(town, p.road, s, p.lane) != Some(lane.unsigned_abs() as usize) || !sides {
                problems.push(format!("{name}: {entity} in TAD lane {lane} is in town lane {}", p.lane));
            }
            if !road.lanes_at(s).iter().any(|l| l.id == p.lane && l.driving()) {
                problems.push(format!("{name}: {entity} is on a lane that is not for driving"));
            }
        }
        if p.road == ego.road && inside && !ego_short {
            let gap = (s - ego_s) * ego_dir;
            let want = along.base - layout.ego.station.along;
            if (gap - want).abs() > GAP_TOLERANCE {
                problems.push(format!(
                    "{name}: {entity} is {gap:.2} m from the ego along the road, the layout {want:.2} m"
                ));
            }
            checked.gaps += 1;
        }
    }
    // the ego's route through the junction
    let turn = program.code.iter().find_map(|i| match i {
        Instr::Ego { turn, .. } => Some(*turn),
        _ => None,
    });
    let route = ego_route(&doc);
    if let (Some(turn), [start, via, end], Some(_)) = (turn, route.as_slice(), layout.road.junction.as_ref()) {
        let junction = town.road(via.road).and_then(|r| r.junction).and_then(|j| town.junctions.get(&j));
        let connection = junction.and_then(|j| {
            j.connections.iter().find(|c| {
                c.incoming == start.road && c.connecting == via.road && c.lanes.contains(&(start.lane, via.lane))
            })
        });
        match connection {
            None => problems.push(format!(
                "{name}: the route's road {} is no connection from road {} lane {}",
                via.road, start.road, start.lane
            )),
            Some(c) => {
                let r = town.road(c.connecting).unwrap();
                let exit = if c.at_end { r.predecessor } else { r.successor };
                if exit.map(|l| l.id) != Some(end.road) {
                    problems.push(format!("{name}: the route leaves on road {}, its connection on {exit:?}", end.road));
                }
                let change = wrap(
                    heading(town, end.road, end.lane, end.s.unwrap())
                        - heading(town, start.road, start.lane, start.s.unwrap()),
                );
                if wrap(change - nominal(turn)).abs() > TURN_TOLERANCE {
                    problems
                        .push(format!("{name}: the route turns {:.0}°, the layout's {turn:?}", change.to_degrees()));
                }
                checked.routes += 1;
            }
        }
        // each conflict point the ego's time is measured to lies on its way
        let way: Vec<Vec2> = [start, via, end].iter().flat_map(|p| lane_points(town, p.road, p.lane)).collect();
        for point in meet_points(&doc) {
            let d = way.iter().map(|q| q.distance(point)).fold(f64::INFINITY, f64::min);
            if d > WAY_TOLERANCE {
                problems.push(format!("{name}: a conflict point is {d:.2} m off the ego's way"));
            }
            checked.meets += 1;
        }
    }
    // walkers cross their road
    for (walker, d) in crossings(&doc) {
        let Some(p) = starts.get(&walker) else { continue };
        let (Some(s), Some(road)) = (p.s, town.road(p.road)) else { continue };
        let along = Vec2::from_yaw(road.pose(s).yaw);
        if (d.dot(along) / d.length()).abs() > CROSS_TOLERANCE.sin() {
            problems.push(format!("{name}: {walker} crosses at {:.0}° to its road", d.dot(along).acos().to_degrees()));
        }
        checked.crossings += 1;
    }
    checked
}

/// A lane's centre line, every half metre.
fn lane_points(town: &Town, road: u32, lane: i32) -> Vec<Vec2> {
    let Some(r) = town.road(road) else { return Vec::new() };
    let n = (r.length * 2.0).ceil() as usize;
    (0..=n)
        .filter_map(|k| {
            let s = r.length * k as f64 / n.max(1) as f64;
            r.lane_centre(s, lane).map(|t| r.point(s, t))
        })
        .collect()
}

/// The points of the `TimeToCollisionCondition`s.
fn meet_points(doc: &roxmltree::Document) -> Vec<Vec2> {
    doc.descendants()
        .filter(|n| n.has_tag_name("TimeToCollisionConditionTarget"))
        .filter_map(|n| n.descendants().find(|d| d.has_tag_name("WorldPosition")))
        .filter_map(|w| Some(Vec2::new(w.attribute("x")?.parse().ok()?, w.attribute("y")?.parse().ok()?)))
        .collect()
}

/// Each walker's crossing: its entity and the vector it walks.
fn crossings(doc: &roxmltree::Document) -> Vec<(String, Vec2)> {
    doc.descendants()
        .filter(|n| n.has_tag_name("Action") && n.attribute("name").is_some_and(|a| a.ends_with("_cross")))
        .filter_map(|n| {
            let last = n.descendants().rfind(|d| d.has_tag_name("RelativeWorldPosition"))?;
            let d = Vec2::new(last.attribute("dx")?.parse().ok()?, last.attribute("dy")?.parse().ok()?);
            Some((last.attribute("entityRef")?.to_string(), d))
        })
        .collect()
}

#[test]
fn every_example_keeps_its_lanes_gaps_and_turns_on_each_town() {
    let towns = towns();
    let mut problems = Vec::new();
    let mut total = Checked::default();
    println!("| example | town | ego starts on | through | W0712 |\n|---|---|---|---|---|");
    for town in &towns {
        for path in common::scenarios() {
            let c = check(town, &path, &mut problems);
            total.gaps += c.gaps;
            total.routes += c.routes;
            total.meets += c.meets;
            total.crossings += c.crossings;
        }
    }
    let Checked { gaps, routes, meets, crossings } = total;
    println!("on {} towns: {gaps} gaps, {routes} routes, {meets} conflict points, {crossings} crossings", towns.len());
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
    if !towns.is_empty() {
        assert!(gaps >= 20 && routes >= 16 && meets >= 4 && crossings >= 4, "the checks ran on too few");
    }
}

/// A town is untrusted input: one whose roads have no lanes, whose junctions name roads that
/// do not exist, or whose lanes have no width places every example or refuses it in words.
#[test]
fn a_broken_town_places_or_refuses_never_panics() {
    let Some(dir) = common::maps() else { return };
    let text = std::fs::read_to_string(dir.join("Town10HD.xodr")).unwrap();
    let no_lanes = {
        let mut out = String::new();
        let mut rest = text.as_str();
        while let Some(k) = rest.find("<lanes>") {
            out.push_str(&rest[..k]);
            rest = rest[k..].find("</lanes>").map_or("", |e| &rest[k + e + "</lanes>".len()..]);
        }
        out + rest
    };
    let broken = [
        ("no lanes", no_lanes),
        ("dangling connections", text.replace("connectingRoad=\"", "connectingRoad=\"9")),
        ("no widths", text.replace("<width ", "<nowidth ")),
        ("no links", text.replace("<link>", "<nolink>").replace("</link>", "</nolink>")),
    ];
    for (what, text) in broken {
        let town = Town::parse("Broken", &text).unwrap_or_else(|e| panic!("{what}: {e}"));
        for path in common::scenarios() {
            let source = std::fs::read_to_string(&path).unwrap();
            let (scenario, _) = common::emit(&path, &source, "x");
            if let Err(e) = common::on_town(&scenario, "x", &town, "Broken.xodr") {
                assert!(e.contains("`Broken` has no"), "{what}: {e}");
            }
        }
    }
}
