//! The scenario as OpenSCENARIO XML 1.2 (`spec/backends/openscenario.md` §3), read from the
//! lowered program (`tad_bytecode::lower`): its parameter slots become
//! `ParameterDeclarations`, its spawns entities placed by `LanePosition` on the generated
//! road (a `WorldPosition` off every road), its phase programs traffic signal controllers,
//! and each actor's script one maneuver whose events follow the script: a start (the time,
//! the ego's distance, the ego's time to the conflict point), then the motion it starts.

use std::f64::consts::PI;

use tad_bytecode::{Instr, Program, Value};
use tad_diagnostics::{Code, Diagnostic, Payload};
use tad_ir::{ClosedSet, Scenario};
use tad_layout::Layout;
use tad_road::geom::{Pose, Vec2, wrap};
use tad_road::road::Station;
use tad_road::{Arm, Body, Turn};

use crate::attrs;
use crate::mapping::{self, Category};
use crate::network::{Network, arm_road};
use crate::site::{self, Site};
use crate::xml::{Xml, num};

/// The OpenSCENARIO version written.
pub const REV_MINOR: u32 = 2;
/// How far into its exit road a route's last waypoint is, m.
const ROUTE_BEYOND: f64 = 20.0;
/// A lane change's duration, s, and a stop's deceleration, m/s².
const LANE_CHANGE_TIME: f64 = 3.0;
const STOP_RATE: f64 = 6.0;

pub struct Context<'a> {
    pub scenario: &'a Scenario,
    pub layout: &'a Layout,
    pub program: &'a Program,
    pub ground: Ground<'a>,
    /// The road's file: the generated road's name, or the town's path.
    pub xodr_file: &'a str,
}

/// What the scenario stands on: the road generated from the layout, or (`--map`) the
/// layout's place on a town.
#[derive(Clone, Copy)]
pub enum Ground<'a> {
    Generated(&'a Network),
    Town(&'a Site<'a>),
}

/// A parameter's name: the slot's `group.what` as `group_what`.
pub fn parameter(name: &str) -> String {
    let mut out: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
    if out.chars().next().is_none_or(|c| c.is_ascii_digit()) {
        out.insert(0, 'p');
    }
    out
}

/// A value: a number, a parameter, or an expression of both.
fn value(program: &Program, v: Value, scale: f64, add: f64) -> String {
    let base = v.base * scale + add;
    let Some(slot) = v.slot.and_then(|s| program.params.get(usize::from(s))) else { return num(base) };
    let p = format!("${}", parameter(&slot.name));
    let p = if scale == 1.0 { p } else { format!("{p} * {}", num(scale)) };
    if base.abs() < 1e-9 && scale == 1.0 {
        return p;
    }
    if base < 0.0 { format!("${{{p} - {}}}", num(-base)) } else { format!("${{{p} + {}}}", num(base)) }
}

/// An actor's entity name.
pub fn entity(group: &str, index: u16) -> String {
    format!("{group}_{}", u32::from(index) + 1)
}

/// A position: on a lane of the generated road when it lies on one, else in the world.
#[derive(Clone, Debug, PartialEq)]
pub enum Position {
    Lane { road: u32, lane: i32, s: String, offset: f64, heading: f64 },
    World(Pose),
}

impl Position {
    fn write(&self, x: &mut Xml) {
        x.open("Position", &[]);
        match self {
            Position::Lane { road, lane, s, offset, heading } => {
                x.open(
                    "LanePosition",
                    attrs!("roadId" => road, "laneId" => lane, "offset" => num(*offset), "s" => s),
                );
                x.empty("Orientation", attrs!("type" => "relative", "h" => num(*heading), "p" => 0, "r" => 0));
                x.close();
            }
            Position::World(p) => x.empty(
                "WorldPosition",
                attrs!("x" => num(p.position.x), "y" => num(p.position.y), "z" => 0, "h" => num(wrap(p.yaw)), "p" => 0, "r" => 0),
            ),
        }
        x.close();
    }
}

/// Where a pose of an arm is, on the generated road; `along` (the slot of the station's
/// `along`) moves `s` with it.
fn locate(c: &Context, arm: Arm, pose: Pose, along: Option<Value>) -> Position {
    let net = match c.ground {
        Ground::Generated(net) => net,
        Ground::Town(site) => return locate_on_town(c, site, arm, pose, along),
    };
    let Some((road_id, s, t)) = net.locate(arm, pose.position) else { return Position::World(pose) };
    let Some(road) = net.road(road_id) else { return Position::World(pose) };
    let Some((lane, offset)) = road.lane_at(t) else { return Position::World(pose) };
    let heading = wrap(pose.yaw - road.pose(s).yaw);
    let s_text = match along {
        // s grows with `along` on every arm's road (the ego's from its start, the others outwards)
        Some(v @ Value { slot: Some(_), .. }) => value(c.program, Value { base: 0.0, ..v }, 1.0, s),
        _ => num(s),
    };
    Position::Lane { road: road_id, lane, s: s_text, offset, heading }
}

/// [`locate`] on a town: the same distance from the arm's origin, the same lane from the
/// centre (`site::Site::place`).
fn locate_on_town(c: &Context, site: &Site, arm: Arm, pose: Pose, along: Option<Value>) -> Position {
    let road = &c.layout.road;
    let (out, lateral, traffic) = site::frame(road, arm, pose.position);
    let lane = site.place(road, arm, out, lateral, wrap(pose.yaw - traffic)).and_then(|place| {
        let (lane, offset) = site.town.road(place.road)?.lane_at(place.s, place.t)?;
        Some((place, lane, offset))
    });
    let Some((place, lane, offset)) = lane else {
        let yaw = site.direction(Vec2::from_yaw(pose.yaw)).yaw();
        return Position::World(Pose { position: site.world(road, pose.position), yaw });
    };
    // s moves with `along`: with it on the ego's arm, against it on the others, as the road runs
    let dir = site.arm(arm).map_or(1.0, |a| a.dir);
    let rate = if arm == Arm::Ego { dir } else { -dir };
    let s_text = match along {
        Some(v @ Value { slot: Some(_), .. }) => value(c.program, Value { base: 0.0, ..v }, rate, place.s),
        _ => num(place.s),
    };
    Position::Lane { road: place.road, lane, s: s_text, offset, heading: place.heading }
}

/// A layout point in the road file's world.
fn world(c: &Context, p: Vec2) -> Vec2 {
    match c.ground {
        Ground::Generated(_) => p,
        Ground::Town(site) => site.world(&c.layout.road, p),
    }
}

/// One start condition of an event.
enum Start {
    /// Simulation time past a value (a parameter or a number).
    Time(String),
    /// Some seconds after the actor's previous event started.
    After { event: String, seconds: String },
    /// The ego within a distance of the actor.
    Near(String),
    /// The ego's time to a point at most a travel time (the layout's conflict start).
    Meet { point: Vec2, travel: String },
}

struct Event {
    name: String,
    actor: String,
    starts: Vec<Start>,
    actions: Vec<(String, Action)>,
}

enum Action {
    Speed(String),
    Stop,
    Route(Vec<Position>),
    Trajectory(Vec<Vec2>),
    /// Straight across, from wherever the actor stands when it starts (its sampled place).
    Across(Vec2),
    LaneChange(i64),
}

pub struct Output {
    pub text: String,
    pub distribution: Option<String>,
    pub diagnostics: Vec<Diagnostic>,
}

/// The `.xosc` text, the parameter value distribution (when the program has slots) and what
/// could not be said. `file` is the scenario file's name, for the distribution to name.
pub fn print(c: &Context, file: &str) -> Output {
    let mut diagnostics = Vec::new();
    let mut x = Xml::new();
    let name = &c.program.name;
    x.open("OpenSCENARIO", &[]);
    x.empty(
        "FileHeader",
        attrs!("revMajor" => 1, "revMinor" => REV_MINOR, "date" => crate::DATE,
               "description" => format!("{name} (TADSL, from {})", c.program.source), "author" => "tadslc"),
    );
    parameters(&mut x, c.program);
    x.empty("CatalogLocations", &[]);
    road_network(&mut x, c, &mut diagnostics);
    let actors = entities(&mut x, c, &mut diagnostics);
    storyboard(&mut x, c, &actors, &mut diagnostics);
    let distribution = (!c.program.params.is_empty()).then(|| print_distribution(c.program, file));
    Output { text: x.finish(), distribution, diagnostics }
}

fn parameters(x: &mut Xml, program: &Program) {
    if program.params.is_empty() {
        return;
    }
    x.open("ParameterDeclarations", &[]);
    for p in &program.params {
        x.empty(
            "ParameterDeclaration",
            attrs!("name" => parameter(&p.name), "parameterType" => "double", "value" => num(p.default)),
        );
    }
    x.close();
}

fn road_network(x: &mut Xml, c: &Context, diagnostics: &mut Vec<Diagnostic>) {
    x.open("RoadNetwork", &[]);
    x.empty("LogicFile", attrs!("filepath" => c.xodr_file));
    let controllers: Vec<(Arm, &[tad_bytecode::Phase])> = c
        .program
        .code
        .iter()
        .filter_map(|i| match i {
            Instr::Signal { arm, phases } => Some((*arm, phases.as_slice())),
            _ => None,
        })
        .collect();
    if !controllers.is_empty() {
        x.open("TrafficSignals", &[]);
        for (arm, phases) in controllers {
            let signals = signals_facing(c, arm);
            if signals.is_empty() {
                if let Ground::Town(site) = c.ground {
                    let what = format!("the town's junction has no traffic lights for the {} road", arm.as_str());
                    diagnostics.push(misfit(c, site, &what, false, "its lights keep the town's own phases"));
                }
                continue;
            }
            x.open("TrafficSignalController", attrs!("name" => format!("{}_lights", arm.as_str())));
            for (k, phase) in phases.iter().enumerate() {
                let light = phase.light.as_str();
                x.open("Phase", attrs!("name" => format!("{light}{}", k + 1), "duration" => num(phase.seconds)));
                for signal in &signals {
                    x.empty("TrafficSignalState", attrs!("trafficSignalId" => signal, "state" => light));
                }
                x.close();
            }
            x.close();
        }
        x.close();
    }
    x.close();
}

/// The traffic lights facing an arm's incoming traffic: the generated road's first one, or
/// the town's (`Site::signals`).
fn signals_facing(c: &Context, arm: Arm) -> Vec<u32> {
    match c.ground {
        Ground::Town(site) => site.signals(arm),
        Ground::Generated(net) => {
            net.controllers.iter().find(|k| k.arm == arm).and_then(|k| k.signals.first()).into_iter().copied().collect()
        }
    }
}

/// W0712: what of the scenario the town does not have, and what is done instead; on the
/// road's `lanes` when it is about lanes, else on its `type`.
pub fn misfit(c: &Context, site: &Site, what: &str, lanes: bool, instead: &str) -> Diagnostic {
    let message = format!("{what} on `{}`", site.town.name);
    let payload = Payload::Unsupported {
        backend: "openscenario".into(),
        construct: what.to_string(),
        instead: Some(instead.to_string()),
    };
    let road = &c.scenario.road;
    let field = if lanes { road.lanes.span() } else { road.road_type.span() };
    let span = field.or(road.span).unwrap_or(c.scenario.span);
    Diagnostic::new(Code::W0712, message, span, format!("placed on `{}`", site.town.name)).with_payload(payload)
}

/// An actor of the program: its entity's name and how it starts.
struct Actor {
    id: u16,
    name: String,
    group: String,
    position: Position,
    speed: f64,
    arm: Arm,
    lane: i64,
    pose: Pose,
    body: Body,
}

fn bounding_box(x: &mut Xml, size: tad_bytecode::Size, centre_x: f64) {
    x.open("BoundingBox", &[]);
    x.empty("Center", attrs!("x" => num(centre_x), "y" => 0, "z" => num(size.height / 2.0)));
    x.empty(
        "Dimensions",
        attrs!("width" => num(size.width), "length" => num(size.length), "height" => num(size.height)),
    );
    x.close();
}

fn vehicle(x: &mut Xml, name: &str, category: &str, size: tad_bytecode::Size, max_speed: f64) {
    x.open("Vehicle", attrs!("name" => name, "vehicleCategory" => category));
    // the reference point is the rear axle's centre, as OpenSCENARIO's vehicles have it
    let rear = size.length * 0.2;
    bounding_box(x, size, size.length / 2.0 - rear);
    x.empty("Performance", attrs!("maxSpeed" => num(max_speed), "maxAcceleration" => 5, "maxDeceleration" => 8));
    x.open("Axles", &[]);
    let wheel = 0.6_f64.min(size.height / 2.0).max(0.3);
    for (axle, position) in [("FrontAxle", (size.length * 0.6).max(0.5)), ("RearAxle", 0.0)] {
        x.empty(
            axle,
            attrs!("maxSteering" => if position > 0.0 { "0.5" } else { "0" }, "wheelDiameter" => num(wheel),
                   "trackWidth" => num(size.width * 0.85), "positionX" => num(position), "positionZ" => num(wheel / 2.0)),
        );
    }
    x.close();
    x.empty("Properties", &[]);
    x.close();
}

fn entities(x: &mut Xml, c: &Context, diagnostics: &mut Vec<Diagnostic>) -> Vec<Actor> {
    x.open("Entities", &[]);
    let mut actors = Vec::new();
    for instr in &c.program.code {
        match instr {
            Instr::Ego { class, size, speed, .. } => {
                x.open("ScenarioObject", attrs!("name" => "ego"));
                let category = mapping::listed(class).unwrap_or(Category::Vehicle("car"));
                vehicle(x, class, category.as_str(), *size, (speed.base * 2.0).max(40.0));
                x.close();
            }
            Instr::Spawn { actor, group, index, body, class, size, arm, lane, along, lateral, yaw, speed, .. } => {
                let name = entity(group, *index);
                x.open("ScenarioObject", attrs!("name" => name));
                let category = mapping::listed(class).unwrap_or_else(|| {
                    let category = mapping::of_body(*body);
                    approximated(diagnostics, c, group, class, category);
                    category
                });
                match category {
                    Category::Vehicle(cat) => vehicle(x, class, cat, *size, 70.0),
                    Category::Pedestrian(cat) => {
                        x.open(
                            "Pedestrian",
                            attrs!("name" => class, "mass" => if cat == "animal" { 200 } else { 75 },
                                   "model3d" => class, "pedestrianCategory" => cat),
                        );
                        bounding_box(x, *size, 0.0);
                        x.empty("Properties", &[]);
                        x.close();
                    }
                    Category::Misc(cat) => {
                        x.open("MiscObject", attrs!("name" => class, "mass" => 10, "miscObjectCategory" => cat));
                        bounding_box(x, *size, 0.0);
                        x.empty("Properties", &[]);
                        x.close();
                    }
                }
                x.close();
                let station = Station { arm: *arm, along: along.base };
                let mut pose = c.layout.road.pose_at(station, *lane, *lateral);
                pose.yaw = *yaw;
                let position = locate(c, *arm, pose, Some(*along));
                actors.push(Actor {
                    id: *actor,
                    name,
                    group: group.clone(),
                    position,
                    speed: *speed,
                    arm: *arm,
                    lane: *lane,
                    pose,
                    body: *body,
                });
            }
            _ => {}
        }
    }
    x.close();
    actors
}

fn approximated(diagnostics: &mut Vec<Diagnostic>, c: &Context, group: &str, class: &str, category: Category) {
    let group = c.scenario.group_named(group).and_then(|g| c.scenario.group(g));
    let span = group.map_or(c.scenario.span, |g| g.actor_type.span().unwrap_or(g.name_span));
    let message = format!("actor type `{class}` has no OpenSCENARIO category");
    let payload = Payload::Unsupported {
        backend: "openscenario".into(),
        construct: format!("actor type `{class}`"),
        instead: Some(format!("the `{category}` category", category = category.as_str())),
    };
    let label = format!("written as `{}`", category.as_str());
    diagnostics.push(Diagnostic::new(Code::W0711, message, span, label).with_payload(payload));
}

/// The span of the group an actor belongs to (the scenario's without one).
fn group_span(c: &Context, group: &str) -> tad_diagnostics::Span {
    c.scenario.group_named(group).and_then(|g| c.scenario.group(g)).map_or(c.scenario.span, |g| g.name_span)
}

/// The route of a vehicle in `lane` of `arm` taking `turn`: its start, then a point on its
/// exit road's lane; `None` without a junction.
fn route(c: &Context, start: &Position, arm: Arm, lane: i64, turn: Turn) -> Option<Vec<Position>> {
    let net = match c.ground {
        Ground::Generated(net) => net,
        Ground::Town(site) => return route_on_town(site, start, arm, lane, turn),
    };
    let connecting = net.connecting(arm, lane, turn)?;
    let (_, out) = connecting.turn.map(|(a, _, t)| (a, t.exit(a)))?;
    let exit_lane = connecting.right.first()?.successor?;
    let exit_road = net.road(arm_road(out))?;
    let s = if out == Arm::Ego { (exit_road.length() - ROUTE_BEYOND).max(0.0) } else { ROUTE_BEYOND };
    let heading = if exit_lane > 0 { PI } else { 0.0 };
    let end = Position::Lane { road: exit_road.id, lane: exit_lane, s: num(s), offset: 0.0, heading };
    Some(vec![start.clone(), end])
}

/// [`route`] on a town: its start, the middle of the town's connecting road for the lane and
/// turn (which pins the way through the junction), and a point on the exit road's lane.
fn route_on_town(site: &Site, start: &Position, arm: Arm, lane: i64, turn: Turn) -> Option<Vec<Position>> {
    let (connecting, via, exit) = site.route(arm, lane, turn)?;
    let length = site.town.road(connecting)?.length;
    let along_via = if via > 0 { PI } else { 0.0 };
    let middle = Position::Lane { road: connecting, lane: via, s: num(length / 2.0), offset: 0.0, heading: along_via };
    let exit_lane = site.exit_lane(exit, lane, turn)?;
    let exit_road = site.town.road(exit.road)?;
    let s = (exit.s0 - exit.dir * ROUTE_BEYOND).clamp(0.0, exit_road.length);
    let heading = if exit.dir > 0.0 { PI } else { 0.0 };
    let end = Position::Lane { road: exit.road, lane: exit_lane, s: num(s), offset: 0.0, heading };
    Some(vec![start.clone(), middle, end])
}

/// Each actor's events, in its script's order.
fn events(c: &Context, actor: &Actor, diagnostics: &mut Vec<Diagnostic>) -> Vec<Event> {
    let mut events: Vec<Event> = Vec::new();
    let new = |k: usize| Event {
        name: format!("{}_event{k}", actor.name),
        actor: actor.name.clone(),
        starts: Vec::new(),
        actions: Vec::new(),
    };
    let mut current = new(1);
    let flush = |events: &mut Vec<Event>, current: &mut Event| {
        let done = std::mem::replace(current, new(events.len() + 2));
        events.push(done);
    };
    let p = c.program;
    for instr in &p.code {
        let mine = |a: &u16| *a == actor.id;
        match instr {
            Instr::Wait { actor: a, seconds } if mine(a) => {
                if !current.actions.is_empty() {
                    flush(&mut events, &mut current);
                }
                let seconds = value(p, *seconds, 1.0, 0.0);
                match events.last() {
                    Some(prev) => current.starts.push(Start::After { event: prev.name.clone(), seconds }),
                    None => current.starts.push(Start::Time(seconds)),
                }
            }
            Instr::Meet { actor: a, point, travel } if mine(a) => {
                if !current.actions.is_empty() {
                    flush(&mut events, &mut current);
                }
                let laid = Vec2::new(point[0], point[1]);
                let point = match c.ground {
                    Ground::Generated(_) => laid,
                    Ground::Town(site) => site.conflict(&c.layout.road, laid),
                };
                // on a town, its own way to the point is as much longer as the straight line
                let ratio = match actor.pose.position.distance(laid) {
                    d if d > 1.0 => world(c, actor.pose.position).distance(point) / d,
                    _ => 1.0,
                };
                current.starts.push(Start::Meet { point, travel: value(p, *travel, ratio, 0.0) });
            }
            Instr::WaitNear { actor: a, distance } if mine(a) => {
                if !current.actions.is_empty() {
                    flush(&mut events, &mut current);
                }
                current.starts.push(Start::Near(value(p, *distance, 1.0, 0.0)));
            }
            Instr::Drive { actor: a, speed, turn } if mine(a) => {
                current.actions.push(("speed".into(), Action::Speed(value(p, *speed, 1.0, 0.0))));
                if actor.lane > 0
                    && let Some(waypoints) = route(c, &actor.position, actor.arm, actor.lane, *turn)
                {
                    current.actions.push(("route".into(), Action::Route(waypoints)));
                }
            }
            Instr::Follow { actor: a, path, speed } if mine(a) => {
                current.actions.push(("speed".into(), Action::Speed(value(p, *speed, 1.0, 0.0))));
                if let Some(line) = p.paths.get(usize::from(*path)) {
                    let points: Vec<Vec2> = line.0.iter().map(|q| world(c, Vec2::new(q[0], q[1]))).collect();
                    let from = world(c, actor.pose.position);
                    current.actions.push(("path".into(), Action::Trajectory(ahead_of(&points, from))));
                }
            }
            Instr::Cross { actor: a, speed } if mine(a) => {
                current.actions.push(("speed".into(), Action::Speed(value(p, *speed, 1.0, 0.0))));
                let (road, arm, at) = (&c.layout.road, actor.arm, actor.pose.position);
                let d = match c.ground {
                    Ground::Generated(_) => Vec2::from_yaw(actor.pose.yaw),
                    Ground::Town(site) => site.direction_on(road, arm, at, actor.pose.yaw),
                };
                current.actions.push(("cross".into(), Action::Across(d * crossing_length(c, actor))));
            }
            Instr::ChangeLane { actor: a, lanes } if mine(a) => {
                current.actions.push(("lane_change".into(), Action::LaneChange(*lanes)));
            }
            Instr::Speed { actor: a, speed } if mine(a) => {
                current.actions.push(("speed".into(), Action::Speed(value(p, *speed, 1.0, 0.0))));
            }
            Instr::Stop { actor: a } if mine(a) => current.actions.push(("stop".into(), Action::Stop)),
            Instr::Mobil { actor: a, on: true } if mine(a) => {
                let message = format!("`{}` changes lanes to pass what blocks it only in the runtime", actor.group);
                let label = "OpenSCENARIO has no action for a driver's own lane changes (MOBIL)";
                let payload = Payload::Unsupported {
                    backend: "openscenario".into(),
                    construct: format!("lane changes to pass (MOBIL) of `{}`", actor.group),
                    instead: Some("it keeps its lane".into()),
                };
                diagnostics.push(
                    Diagnostic::new(Code::W0710, message, group_span(c, &actor.group), label).with_payload(payload),
                );
            }
            _ => {}
        }
    }
    if !current.actions.is_empty() || !current.starts.is_empty() {
        events.push(current);
    }
    events.retain(|e| !e.actions.is_empty());
    events
}

/// The part of a polyline from the point nearest `from` on.
fn ahead_of(points: &[Vec2], from: Vec2) -> Vec<Vec2> {
    let nearest = points
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.distance(from).total_cmp(&b.1.distance(from)))
        .map_or(0, |(k, _)| k);
    let mut out = vec![from];
    out.extend(points[nearest..].iter().copied().filter(|p| p.distance(from) > 0.05));
    out
}

/// How far a crossing walker walks: to the far side of its road, plus a sidewalk's width.
fn crossing_length(c: &Context, actor: &Actor) -> f64 {
    let road = &c.layout.road;
    let (incoming, outgoing) = road.arm_lanes(actor.arm);
    let total = f64::from(incoming + outgoing) * road.lane_width;
    (total + tad_road::road::SIDEWALK_WIDTH * 1.5).max(road.lane_width)
}

fn storyboard(x: &mut Xml, c: &Context, actors: &[Actor], diagnostics: &mut Vec<Diagnostic>) {
    x.open("Storyboard", &[]);
    x.open("Init", &[]);
    x.open("Actions", &[]);
    crate::environment::write(x, c.scenario, diagnostics);
    ego_init(x, c);
    for a in actors {
        x.open("Private", attrs!("entityRef" => a.name));
        x.open("PrivateAction", &[]);
        x.open("TeleportAction", &[]);
        a.position.write(x);
        x.close();
        x.close();
        if a.speed > 0.0 && a.body != Body::Object {
            speed_action(x, &num(a.speed), None);
        }
        x.close();
    }
    x.close();
    x.close();
    x.open("Story", attrs!("name" => "tad"));
    x.open("Act", attrs!("name" => "act"));
    let mut any = false;
    for a in actors {
        let events = events(c, a, diagnostics);
        if events.is_empty() {
            continue;
        }
        any = true;
        x.open("ManeuverGroup", attrs!("name" => format!("{}_group", a.name), "maximumExecutionCount" => 1));
        x.open("Actors", attrs!("selectTriggeringEntities" => "false"));
        x.empty("EntityRef", attrs!("entityRef" => a.name));
        x.close();
        x.open("Maneuver", attrs!("name" => format!("{}_script", a.name)));
        for e in &events {
            event(x, e);
        }
        x.close();
        x.close();
    }
    if !any {
        // an act needs a maneuver group: the ego's, empty
        x.open("ManeuverGroup", attrs!("name" => "ego_group", "maximumExecutionCount" => 1));
        x.open("Actors", attrs!("selectTriggeringEntities" => "false"));
        x.empty("EntityRef", attrs!("entityRef" => "ego"));
        x.close();
        x.close();
    }
    x.open("StartTrigger", &[]);
    x.open("ConditionGroup", &[]);
    time_condition(x, "act_start", "0");
    x.close();
    x.close();
    x.close();
    x.close();
    let timeout = c.program.code.iter().find_map(|i| match i {
        Instr::Limits { timeout, .. } => Some(*timeout),
        _ => None,
    });
    x.open("StopTrigger", &[]);
    x.open("ConditionGroup", &[]);
    time_condition(x, "timeout", &num(timeout.unwrap_or(30.0)));
    x.close();
    x.close();
    x.close();
}

fn ego_init(x: &mut Xml, c: &Context) {
    let Some((lane, turn, speed)) = c.program.code.iter().find_map(|i| match i {
        Instr::Ego { lane, turn, speed, .. } => Some((*lane, *turn, *speed)),
        _ => None,
    }) else {
        return;
    };
    let ego = &c.layout.ego;
    let position = locate(c, Arm::Ego, ego.pose, None);
    x.open("Private", attrs!("entityRef" => "ego"));
    x.open("PrivateAction", &[]);
    x.open("TeleportAction", &[]);
    position.write(x);
    x.close();
    x.close();
    if ego.moving {
        speed_action(x, &value(c.program, speed, 1.0, 0.0), None);
    }
    if let Some(waypoints) = route(c, &position, Arm::Ego, lane, turn) {
        x.open("PrivateAction", &[]);
        route_action(x, "ego_route", &waypoints);
        x.close();
    }
    x.close();
}

fn time_condition(x: &mut Xml, name: &str, value: &str) {
    x.open("Condition", attrs!("name" => name, "delay" => 0, "conditionEdge" => "none"));
    x.open("ByValueCondition", &[]);
    x.empty("SimulationTimeCondition", attrs!("value" => value, "rule" => "greaterThan"));
    x.close();
    x.close();
}

/// `<Condition>` on the ego (`<ByEntityCondition>`, the ego its triggering entity), its
/// `<EntityCondition>` written by `condition`.
fn ego_condition(x: &mut Xml, name: &str, edge: &str, condition: impl FnOnce(&mut Xml)) {
    x.open("Condition", attrs!("name" => name, "delay" => 0, "conditionEdge" => edge));
    x.open("ByEntityCondition", &[]);
    x.open("TriggeringEntities", attrs!("triggeringEntitiesRule" => "any"));
    x.empty("EntityRef", attrs!("entityRef" => "ego"));
    x.close();
    x.open("EntityCondition", &[]);
    condition(x);
    x.close();
    x.close();
    x.close();
}

/// `<PrivateAction>` with a speed action (or, with a name, inside an `<Action>`).
fn speed_action(x: &mut Xml, target: &str, dynamics: Option<(&str, f64, &str)>) {
    x.open("PrivateAction", &[]);
    x.open("LongitudinalAction", &[]);
    x.open("SpeedAction", &[]);
    let (shape, v, dimension) = dynamics.unwrap_or(("step", 0.0, "time"));
    x.empty(
        "SpeedActionDynamics",
        attrs!("dynamicsShape" => shape, "value" => num(v), "dynamicsDimension" => dimension),
    );
    x.open("SpeedActionTarget", &[]);
    x.empty("AbsoluteTargetSpeed", attrs!("value" => target));
    x.close();
    x.close();
    x.close();
    x.close();
}

fn route_action(x: &mut Xml, name: &str, waypoints: &[Position]) {
    x.open("RoutingAction", &[]);
    x.open("AssignRouteAction", &[]);
    x.open("Route", attrs!("name" => name, "closed" => "false"));
    for w in waypoints {
        x.open("Waypoint", attrs!("routeStrategy" => "shortest"));
        w.write(x);
        x.close();
    }
    x.close();
    x.close();
    x.close();
}

fn event(x: &mut Xml, e: &Event) {
    x.open("Event", attrs!("name" => e.name, "priority" => "parallel", "maximumExecutionCount" => 1));
    for (k, (what, action)) in e.actions.iter().enumerate() {
        x.open("Action", attrs!("name" => format!("{}_{}_{what}", e.name, k + 1)));
        match action {
            Action::Speed(target) => speed_action(x, target, None),
            Action::Stop => speed_action(x, "0", Some(("linear", STOP_RATE, "rate"))),
            Action::Route(waypoints) => {
                x.open("PrivateAction", &[]);
                route_action(x, &format!("{}_route", e.name), waypoints);
                x.close();
            }
            Action::Trajectory(_) | Action::Across(_) => {
                x.open("PrivateAction", &[]);
                x.open("RoutingAction", &[]);
                x.open("FollowTrajectoryAction", &[]);
                x.open("TrajectoryRef", &[]);
                x.open("Trajectory", attrs!("name" => format!("{}_path", e.name), "closed" => "false"));
                x.open("Shape", &[]);
                x.open("Polyline", &[]);
                match action {
                    Action::Across(d) => {
                        for (dx, dy) in [(0.0, 0.0), (d.x, d.y)] {
                            x.open("Vertex", &[]);
                            x.open("Position", &[]);
                            x.empty(
                                "RelativeWorldPosition",
                                attrs!("entityRef" => e.actor, "dx" => num(dx), "dy" => num(dy), "dz" => 0),
                            );
                            x.close();
                            x.close();
                        }
                    }
                    Action::Trajectory(points) => {
                        for p in points {
                            x.open("Vertex", &[]);
                            Position::World(Pose { position: *p, yaw: 0.0 }).write(x);
                            x.close();
                        }
                    }
                    _ => {}
                }
                x.close();
                x.close();
                x.close();
                x.close();
                x.open("TimeReference", &[]);
                x.empty("None", &[]);
                x.close();
                x.empty("TrajectoryFollowingMode", attrs!("followingMode" => "position"));
                x.close();
                x.close();
                x.close();
            }
            Action::LaneChange(lanes) => {
                x.open("PrivateAction", &[]);
                x.open("LateralAction", &[]);
                x.open("LaneChangeAction", &[]);
                x.empty(
                    "LaneChangeActionDynamics",
                    attrs!("dynamicsShape" => "sinusoidal", "value" => num(LANE_CHANGE_TIME), "dynamicsDimension" => "time"),
                );
                x.open("LaneChangeTarget", &[]);
                // OpenSCENARIO counts lanes to the left, TAD to the right
                x.empty("RelativeTargetLane", attrs!("entityRef" => e.actor, "value" => -lanes));
                x.close();
                x.close();
                x.close();
                x.close();
            }
        }
        x.close();
    }
    x.open("StartTrigger", &[]);
    x.open("ConditionGroup", &[]);
    if e.starts.is_empty() {
        time_condition(x, &format!("{}_at_start", e.name), "0");
    }
    for (k, start) in e.starts.iter().enumerate() {
        let name = format!("{}_when{}", e.name, k + 1);
        match start {
            Start::Time(seconds) => time_condition(x, &name, seconds),
            Start::After { event, seconds } => {
                x.open("Condition", attrs!("name" => name, "delay" => seconds, "conditionEdge" => "none"));
                x.open("ByValueCondition", &[]);
                x.empty(
                    "StoryboardElementStateCondition",
                    attrs!("storyboardElementType" => "event", "storyboardElementRef" => event, "state" => "startTransition"),
                );
                x.close();
                x.close();
            }
            Start::Meet { point, travel } => ego_condition(x, &name, "none", |x| {
                x.open(
                    "TimeToCollisionCondition",
                    attrs!("value" => travel, "freespace" => "false", "rule" => "lessOrEqual",
                           "relativeDistanceType" => "euclidianDistance", "coordinateSystem" => "entity"),
                );
                x.open("TimeToCollisionConditionTarget", &[]);
                Position::World(Pose { position: *point, yaw: 0.0 }).write(x);
                x.close();
                x.close();
            }),
            Start::Near(distance) => ego_condition(x, &name, "rising", |x| {
                x.empty(
                    "RelativeDistanceCondition",
                    attrs!("entityRef" => e.actor, "relativeDistanceType" => "euclidianDistance", "freespace" => "false",
                           "rule" => "lessThan", "value" => distance),
                );
            }),
        }
    }
    x.close();
    x.close();
    x.close();
}

/// The parameter value distribution: every slot uniform over its range.
fn print_distribution(program: &Program, file: &str) -> String {
    let mut x = Xml::new();
    x.open("OpenSCENARIO", &[]);
    x.empty(
        "FileHeader",
        attrs!("revMajor" => 1, "revMinor" => REV_MINOR, "date" => crate::DATE,
               "description" => format!("{}: the parameter ranges", program.name), "author" => "tadslc"),
    );
    x.open("ParameterValueDistribution", &[]);
    x.empty("ScenarioFile", attrs!("filepath" => file));
    x.open("Stochastic", attrs!("numberOfTestRuns" => 100, "randomSeed" => 0));
    for p in &program.params {
        x.open("StochasticDistribution", attrs!("parameterName" => parameter(&p.name)));
        x.open("UniformDistribution", &[]);
        x.empty("Range", attrs!("lowerLimit" => num(p.min), "upperLimit" => num(p.max)));
        x.close();
        x.close();
    }
    x.close();
    x.close();
    x.finish()
}
