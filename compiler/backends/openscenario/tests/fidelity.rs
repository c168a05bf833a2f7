//! Fidelity of the OpenSCENARIO backend (`spec/backends/openscenario.md` §5), on every
//! example: the written files are read back as XML and evaluated here, independently of the
//! backend's own road model (OpenDRIVE's formulas for lines, arcs and normalised
//! `paramPoly3`, constant lane widths and offsets):
//!
//! - the lane centre lines of the `.xodr`, sampled every 2 m, lie within 5 cm of the
//!   layout's lanes (every arm's road, every driving lane; every connecting road of the
//!   junction against the layout's path for its lane and turn);
//! - every `LanePosition` start of the `.xosc`, resolved on the `.xodr`, is within 10 cm of
//!   the layout's start;
//! - the ego's route ends on the arm its turn leads to, through a connecting road the
//!   junction links to its lane.

mod common;

use std::collections::HashMap;
use tad_layout::geom::Vec2;
use tad_layout::road::Station;
use tad_layout::{Arm, Layout};

/// Lane centres within this of the layout's, m.
const LANE_TOLERANCE: f64 = 0.05;
/// Starts within this of the layout's, m.
const START_TOLERANCE: f64 = 0.10;

struct Example {
    stem: String,
    layout: Layout,
    xosc: String,
    xodr: String,
}

fn examples() -> Vec<Example> {
    common::scenarios()
        .iter()
        .map(|path| {
            let (stem, scenario, emitted) = common::emit_file(path);
            Example {
                stem,
                layout: tad_layout::lay_out(&scenario),
                xosc: emitted.xosc,
                xodr: emitted.xodr.expect("a generated road"),
            }
        })
        .collect()
}

// ── an OpenDRIVE reader of what the backend writes ─────────────────────────────────────

enum Shape {
    Line,
    Arc(f64),
    Poly3([f64; 4], [f64; 4]),
}

struct Piece {
    s: f64,
    x: f64,
    y: f64,
    hdg: f64,
    length: f64,
    shape: Shape,
}

struct OdrRoad {
    length: f64,
    junction: i64,
    pieces: Vec<Piece>,
    offset: f64,
    /// OpenDRIVE lane id → (width, type).
    lanes: HashMap<i64, (f64, String)>,
    successor: Option<(String, i64)>,
}

fn attr(n: roxmltree::Node, name: &str) -> f64 {
    n.attribute(name).unwrap_or_else(|| panic!("<{}> lacks {name}", n.tag_name().name())).parse().unwrap()
}

fn child<'a>(n: roxmltree::Node<'a, 'a>, name: &str) -> Option<roxmltree::Node<'a, 'a>> {
    n.children().find(|c| c.tag_name().name() == name)
}

fn read_odr(text: &str) -> HashMap<i64, OdrRoad> {
    let doc = roxmltree::Document::parse(text).expect("the .xodr is XML");
    let mut roads = HashMap::new();
    for r in doc.descendants().filter(|n| n.has_tag_name("road")) {
        let pieces = child(r, "planView")
            .unwrap()
            .children()
            .filter(|g| g.has_tag_name("geometry"))
            .map(|g| {
                let kind = g.children().find(|c| c.is_element()).unwrap();
                let shape = match kind.tag_name().name() {
                    "line" => Shape::Line,
                    "arc" => Shape::Arc(attr(kind, "curvature")),
                    "paramPoly3" => {
                        assert_eq!(kind.attribute("pRange"), Some("normalized"));
                        let c = |k: &str| attr(kind, k);
                        Shape::Poly3([c("aU"), c("bU"), c("cU"), c("dU")], [c("aV"), c("bV"), c("cV"), c("dV")])
                    }
                    other => panic!("unexpected geometry {other}"),
                };
                Piece {
                    s: attr(g, "s"),
                    x: attr(g, "x"),
                    y: attr(g, "y"),
                    hdg: attr(g, "hdg"),
                    length: attr(g, "length"),
                    shape,
                }
            })
            .collect();
        let lanes_node = child(r, "lanes").unwrap();
        let offset = child(lanes_node, "laneOffset").map_or(0.0, |o| attr(o, "a"));
        let mut lanes = HashMap::new();
        for l in lanes_node.descendants().filter(|n| n.has_tag_name("lane")) {
            let id: i64 = l.attribute("id").unwrap().parse().unwrap();
            if id != 0 {
                let width = attr(child(l, "width").unwrap(), "a");
                lanes.insert(id, (width, l.attribute("type").unwrap().to_string()));
            }
        }
        let successor = child(r, "link").and_then(|l| child(l, "successor")).map(|s| {
            (s.attribute("elementType").unwrap().to_string(), s.attribute("elementId").unwrap().parse().unwrap())
        });
        let id: i64 = r.attribute("id").unwrap().parse().unwrap();
        let junction: i64 = r.attribute("junction").unwrap().parse().unwrap();
        roads.insert(id, OdrRoad { length: attr(r, "length"), junction, pieces, offset, lanes, successor });
    }
    roads
}

impl OdrRoad {
    /// The reference line at `s`: point and heading.
    fn at(&self, s: f64) -> (Vec2, f64) {
        let g = self.pieces.iter().rev().find(|g| g.s <= s + 1e-9).unwrap();
        let ds = s - g.s;
        let (u, v, h) = match g.shape {
            Shape::Line => (ds, 0.0, 0.0),
            Shape::Arc(k) => ((ds * k).sin() / k, (1.0 - (ds * k).cos()) / k, ds * k),
            Shape::Poly3(a, b) => {
                let p = ds / g.length;
                let f = |c: [f64; 4]| c[0] + c[1] * p + c[2] * p * p + c[3] * p * p * p;
                let d = |c: [f64; 4]| c[1] + 2.0 * c[2] * p + 3.0 * c[3] * p * p;
                (f(a), f(b), d(b).atan2(d(a)))
            }
        };
        let (sin, cos) = g.hdg.sin_cos();
        (Vec2::new(g.x + u * cos - v * sin, g.y + u * sin + v * cos), g.hdg + h)
    }

    /// A lane's centre, `t`.
    fn centre(&self, id: i64) -> f64 {
        let sign = id.signum() as f64;
        let inner: f64 = (1..id.abs()).map(|k| self.lanes[&(sign as i64 * k)].0).sum();
        self.offset + sign * (inner + self.lanes[&id].0 / 2.0)
    }

    fn point(&self, s: f64, t: f64) -> Vec2 {
        let (p, h) = self.at(s);
        p + Vec2::new(-h.sin(), h.cos()) * t
    }
}

fn arm_of(road: i64) -> Arm {
    match road {
        1 => Arm::Ego,
        2 => Arm::Left,
        3 => Arm::Right,
        _ => Arm::Opposite,
    }
}

/// TAD's lane of an OpenDRIVE lane of an arm's road.
fn tad_lane(arm: Arm, id: i64) -> i64 {
    if arm == Arm::Ego { -id } else { id }
}

#[test]
fn lane_centres_lie_on_the_layouts_lanes() {
    let mut worst: f64 = 0.0;
    let mut sampled = 0;
    for e in examples() {
        let roads = read_odr(&e.xodr);
        let road = &e.layout.road;
        let x0 = roads[&1].at(0.0).0.x;
        for (id, r) in roads.iter().filter(|(_, r)| r.junction < 0) {
            let arm = arm_of(*id);
            for (lane, _) in r.lanes.iter().filter(|(_, (_, kind))| kind == "driving") {
                let n = (r.length / 2.0).floor() as usize;
                for k in 0..=n {
                    let s = r.length * k as f64 / n.max(1) as f64;
                    let along = if arm == Arm::Ego { x0 + s } else { s };
                    let want = road.lane_pose(Station { arm, along }, tad_lane(arm, *lane)).position;
                    let got = r.point(s, r.centre(*lane));
                    let d = got.distance(want);
                    worst = worst.max(d);
                    sampled += 1;
                    assert!(d <= LANE_TOLERANCE, "{}: road {id} lane {lane} at s {s:.1}: {d:.3} m off", e.stem);
                }
            }
        }
        // connecting roads: on the layout's path of their lane and turn
        let doc = roxmltree::Document::parse(&e.xodr).unwrap();
        for r in doc.descendants().filter(|n| n.has_tag_name("road") && n.attribute("junction") != Some("-1")) {
            let id: i64 = r.attribute("id").unwrap().parse().unwrap();
            let name = r.attribute("name").unwrap();
            let (arm, lane, turn) = parse_turn(name);
            let (path, _) = road.vehicle_path(road.edge(arm), lane, turn);
            let cr = &roads[&id];
            let n = (cr.length / 1.0).ceil() as usize;
            for k in 0..=n {
                let p = cr.point(cr.length * k as f64 / n as f64, cr.centre(-1));
                let d = path.project(p).1;
                worst = worst.max(d);
                sampled += 1;
                assert!(d <= LANE_TOLERANCE, "{}: connecting road {name} at {k}/{n}: {d:.3} m off", e.stem);
            }
        }
    }
    println!("{sampled} lane points, the farthest {:.1} mm from the layout's", worst * 1000.0);
}

fn parse_turn(name: &str) -> (Arm, i64, tad_layout::Turn) {
    let parts: Vec<&str> = name.split('_').collect();
    let arm = match parts[0] {
        "ego" => Arm::Ego,
        "left" => Arm::Left,
        "right" => Arm::Right,
        _ => Arm::Opposite,
    };
    let turn = match parts[2] {
        "straight" => tad_layout::Turn::Straight,
        "left" => tad_layout::Turn::Left,
        "right" => tad_layout::Turn::Right,
        _ => tad_layout::Turn::UTurn,
    };
    (arm, parts[1].parse().unwrap(), turn)
}

/// A number or `$p`, `${$p + c}`, `${$p - c}` with the parameters' defaults.
fn evaluate(text: &str, params: &HashMap<String, f64>) -> f64 {
    if let Some(name) = text.strip_prefix('$').filter(|t| !t.starts_with('{')) {
        return params[name];
    }
    if let Some(inner) = text.strip_prefix("${").and_then(|t| t.strip_suffix('}')) {
        let parts: Vec<&str> = inner.split_whitespace().collect();
        let p = params[parts[0].trim_start_matches('$')];
        let c: f64 = parts[2].parse().unwrap();
        return if parts[1] == "+" { p + c } else { p - c };
    }
    text.parse().unwrap()
}

#[test]
fn starts_resolved_on_the_road_are_the_layouts() {
    let mut worst: f64 = 0.0;
    let mut lane_starts = 0;
    for e in examples() {
        let roads = read_odr(&e.xodr);
        let doc = roxmltree::Document::parse(&e.xosc).unwrap();
        let params: HashMap<String, f64> = doc
            .descendants()
            .filter(|n| n.has_tag_name("ParameterDeclaration"))
            .map(|n| (n.attribute("name").unwrap().to_string(), attr(n, "value")))
            .collect();
        // the layout's agents by entity name
        let mut want: HashMap<String, Vec2> = HashMap::new();
        let names: Vec<String> = doc
            .descendants()
            .filter(|n| n.has_tag_name("ScenarioObject"))
            .map(|n| n.attribute("name").unwrap().to_string())
            .collect();
        let agents: Vec<&tad_layout::Agent> = e.layout.agents().collect();
        assert_eq!(names.len(), agents.len(), "{}: one entity per agent", e.stem);
        // entities in the layout's order: the ego, then each group's members
        for (name, agent) in names.iter().zip(&agents) {
            want.insert(name.clone(), agent.pose.position);
        }
        for p in doc.descendants().filter(|n| n.has_tag_name("Private")) {
            let entity = p.attribute("entityRef").unwrap();
            let Some(lp) = p
                .descendants()
                .find(|n| n.has_tag_name("TeleportAction"))
                .and_then(|t| t.descendants().find(|n| n.has_tag_name("LanePosition")))
            else {
                continue;
            };
            let road = &roads[&lp.attribute("roadId").unwrap().parse::<i64>().unwrap()];
            let lane: i64 = lp.attribute("laneId").unwrap().parse().unwrap();
            let s = evaluate(lp.attribute("s").unwrap(), &params);
            let t = road.centre(lane) + attr(lp, "offset");
            let got = road.point(s, t);
            let d = got.distance(want[entity]);
            worst = worst.max(d);
            lane_starts += 1;
            assert!(d <= START_TOLERANCE, "{}: {entity} starts {d:.3} m from the layout's start", e.stem);
        }
    }
    assert!(lane_starts > 100, "{lane_starts} lane starts");
    println!("{lane_starts} lane starts, the farthest {:.1} mm from the layout's", worst * 1000.0);
}

#[test]
fn the_egos_route_leads_through_the_arm_the_layout_chose() {
    let mut routes = 0;
    for e in examples() {
        let Some(_) = e.layout.road.junction.as_ref() else { continue };
        let roads = read_odr(&e.xodr);
        let doc = roxmltree::Document::parse(&e.xosc).unwrap();
        let ego =
            doc.descendants().find(|n| n.has_tag_name("Private") && n.attribute("entityRef") == Some("ego")).unwrap();
        let waypoints: Vec<roxmltree::Node> = ego.descendants().filter(|n| n.has_tag_name("Waypoint")).collect();
        let last = waypoints.last().and_then(|w| w.descendants().find(|n| n.has_tag_name("LanePosition")));
        let Some(last) = last else { panic!("{}: the ego has no route through its junction", e.stem) };
        let exit = e.layout.ego.turn.exit(Arm::Ego);
        let road: i64 = last.attribute("roadId").unwrap().parse().unwrap();
        assert_eq!(arm_of(road), exit, "{}: the route ends on the {} arm", e.stem, exit.as_str());
        // the junction links the ego's lane to a connecting road that leads onto that road
        let lane = -e.layout.ego.lane;
        let linked = doc_connections(&e.xodr)
            .into_iter()
            .filter(|(incoming, from, _)| *incoming == 1 && *from == lane)
            .any(|(_, _, connecting)| roads[&connecting].successor == Some(("road".into(), road)));
        assert!(linked, "{}: no connection from ego lane {lane} to road {road}", e.stem);
        routes += 1;
    }
    assert!(routes >= 8, "{routes} routes checked");
}

/// The junction's connections: (incoming road, from lane, connecting road).
fn doc_connections(xodr: &str) -> Vec<(i64, i64, i64)> {
    let doc = roxmltree::Document::parse(xodr).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("connection"))
        .map(|c| {
            let link = child(c, "laneLink").unwrap();
            (
                c.attribute("incomingRoad").unwrap().parse().unwrap(),
                link.attribute("from").unwrap().parse().unwrap(),
                c.attribute("connectingRoad").unwrap().parse().unwrap(),
            )
        })
        .collect()
}
