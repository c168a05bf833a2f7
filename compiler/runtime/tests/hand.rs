//! Episodes on hand-built programs: each detector on a scenario built for it.

use tad_bytecode::{Instr, Polyline, Program, Size, Value};
use tad_policy::{Action, EgoPolicy, EgoView};
use tad_road::road::{LANE_WIDTH, RUN};
use tad_road::{Arm, Body, Facing, Place, Road, Shape, Turn};
use tad_runtime::{Options, Scene, StopReason, run};

const CAR: Size = Size { length: 4.5, width: 1.8, height: 1.5 };

fn straight() -> Road {
    Road {
        shape: Shape::Straight,
        lanes: 2,
        opposite: 1,
        cross_lanes: 0,
        lane_width: LANE_WIDTH,
        sidewalks: true,
        crosswalks: false,
        signal: None,
        junction: None,
        approach: 0.0,
    }
}

fn program(road: Road, speed: f64, extra: Vec<Instr>) -> Program {
    let (path, start) = road.vehicle_path(tad_road::Station { arm: Arm::Ego, along: 0.0 }, 1, Turn::Straight);
    let mut code = vec![
        Instr::Road(road),
        Instr::Limits { dt: 0.1, max_steps: 300, max_distance: 200.0, timeout: 60.0 },
        Instr::Ego {
            class: "car".into(),
            size: CAR,
            lane: 1,
            turn: Turn::Straight,
            path: 0,
            start,
            route_length: 100.0,
            speed: Value::lit(speed),
        },
    ];
    code.extend(extra);
    Program {
        name: "hand".into(),
        source: "hand.tad".into(),
        params: vec![],
        paths: vec![Polyline(path.points().iter().map(|p| [p.x, p.y]).collect())],
        code,
    }
}

fn parked(actor: u16, along: f64, lane: i64) -> Instr {
    Instr::Spawn {
        actor,
        group: "parked".into(),
        index: 0,
        body: Body::Vehicle,
        class: "sedan".into(),
        size: CAR,
        arm: Arm::Ego,
        lane,
        place: Place::Lane,
        along: Value::lit(along),
        lateral: -(lane as f64 - 0.5) * LANE_WIDTH,
        facing: Facing::Along,
        yaw: 0.0,
        speed: 0.0,
    }
}

/// Keeps its speed and its route, brakes for nothing.
struct Blind;
impl EgoPolicy for Blind {
    fn name(&self) -> &str {
        "blind"
    }
    fn act(&mut self, v: &EgoView) -> Action {
        let k = 2.0 * v.target[1] / (v.target[0].powi(2) + v.target[1].powi(2));
        Action { accel: 0.0, steer: -(v.wheelbase * k).atan() / 1.2217 }
    }
}

/// Brakes hard for anything within 15 m.
struct Careful;
impl EgoPolicy for Careful {
    fn name(&self) -> &str {
        "careful"
    }
    fn act(&mut self, v: &EgoView) -> Action {
        let mut a = Blind.act(v);
        let gap = v.leader.map(|l| l.0).into_iter().chain(v.stop).fold(f64::INFINITY, f64::min);
        a.accel = if gap < 20.0 { -8.0 } else { 0.0 };
        a
    }
}

#[test]
fn a_blind_ego_rear_ends_a_parked_car_and_a_careful_one_stops() {
    let scene = Scene::new(&program(straight(), 10.0, vec![parked(0, 40.0, 1)])).unwrap();
    let e = run(&scene, None, vec![], &mut Blind, &Options::default());
    assert_eq!(e.stop_reason, StopReason::Collision);
    let hit = e.events.iter().find(|e| e.kind == tad_runtime::EventKind::Collision).unwrap();
    // the ego's front reaches the car's rear at 40 - 4.5 = 35.5 m: about 3.5 s
    assert!((34..=37).contains(&hit.step), "hit at step {}", hit.step);
    assert!(e.records.last().unwrap().collision);
    let e = run(&scene, None, vec![], &mut Careful, &Options::default());
    assert_ne!(e.stop_reason, StopReason::Collision);
    assert!(e.records.iter().all(|r| !r.collision));
}

#[test]
fn the_route_completes_on_a_free_road() {
    let scene = Scene::new(&program(straight(), 10.0, vec![])).unwrap();
    let e = run(&scene, None, vec![], &mut Blind, &Options::default());
    assert_eq!(e.stop_reason, StopReason::RouteComplete);
    let last = e.records.last().unwrap();
    assert_eq!(last.route_complete, 100.0);
    assert!((last.driven_distance - 99.5).abs() < 1.0, "{}", last.driven_distance);
    assert!(e.records.iter().all(|r| r.lane_invasion == 0 && !r.off_road && r.distance_to_route < 0.05));
    let _ = RUN;
}

fn with_route(mut p: Program, points: Vec<[f64; 2]>) -> Program {
    p.paths[0] = Polyline(points);
    for i in &mut p.code {
        if let Instr::Ego { start, .. } = i {
            *start = 0.0;
        }
    }
    p
}

#[test]
fn crossing_a_lane_marking_is_a_lane_invasion() {
    // from lane 1 (y = -1.75) to lane 2 (y = -5.25) between x = 20 and 40
    let route = vec![[0.0, -1.75], [20.0, -1.75], [40.0, -5.25], [150.0, -5.25]];
    let scene = Scene::new(&with_route(program(straight(), 10.0, vec![]), route)).unwrap();
    let e = run(&scene, None, vec![], &mut Blind, &Options::default());
    let last = e.records.last().unwrap();
    // each corner crosses the marking at its own step: one event per step with a crossing
    assert!(last.lane_invasion >= 1 && last.lane_invasion <= 4, "{} invasions", last.lane_invasion);
    assert!(e.records.iter().all(|r| !r.off_road));
}

#[test]
fn leaving_the_road_ends_the_episode_unless_compat() {
    // straight off the right edge (lanes end at y = -7)
    let route = vec![[0.0, -1.75], [20.0, -1.75], [40.0, -14.0], [150.0, -14.0]];
    let scene = Scene::new(&with_route(program(straight(), 10.0, vec![]), route)).unwrap();
    let e = run(&scene, None, vec![], &mut Blind, &Options::default());
    assert_eq!(e.stop_reason, StopReason::OffRoad);
    assert!(e.records.last().unwrap().off_road);
    let e = run(&scene, None, vec![], &mut Blind, &Options { mode: tad_runtime::Mode::Compat, ..Options::default() });
    assert_ne!(e.stop_reason, StopReason::OffRoad);
    let off = e.records.iter().filter(|r| r.off_road).count();
    assert!(off > 50, "off road for {off} steps");
}

#[test]
fn the_same_seed_gives_the_same_episode() {
    let mut p = program(straight(), 10.0, vec![parked(0, 40.0, 2)]);
    p.params.push(tad_bytecode::ParamSlot { name: "parked.shift".into(), min: -10.0, max: 10.0, default: 0.0 });
    if let Some(Instr::Spawn { along, .. }) = p.code.last_mut() {
        along.slot = Some(0);
    }
    let scene = Scene::new(&p).unwrap();
    let opts = Options { keep_frames: true, ..Options::default() };
    let one = run(&scene, Some(3), tad_runtime::sample::sample(&p.params, Some(3)), &mut Blind, &opts);
    let two = run(&scene, Some(3), tad_runtime::sample::sample(&p.params, Some(3)), &mut Blind, &opts);
    assert_eq!(one.records, two.records);
    assert_eq!(one.frames, two.frames);
    let other = run(&scene, Some(4), tad_runtime::sample::sample(&p.params, Some(4)), &mut Blind, &opts);
    assert_ne!(one.frames[0].poses[1], other.frames[0].poses[1], "the parked car's place is sampled");
}

fn junction(signalised: bool) -> Road {
    Road {
        shape: Shape::Junction { arms: 4, roundabout: false },
        cross_lanes: 1,
        junction: Some(tad_road::road::Junction {
            arms: Arm::ALL.to_vec(),
            roundabout: false,
            half: 8.0,
            signalised,
            stop_signs: !signalised,
        }),
        approach: 30.0,
        ..straight()
    }
}

fn policy(name: &str) -> Box<dyn EgoPolicy> {
    tad_policy::parse_policy(name).unwrap()
}

#[test]
fn naive_runs_the_red_light_and_idm_waits() {
    let red = vec![tad_bytecode::Phase { light: tad_bytecode::Light::Red, seconds: 60.0 }];
    let p = program(junction(true), 10.0, vec![Instr::Signal { arm: Arm::Ego, phases: red }]);
    let scene = Scene::new(&p).unwrap();
    let e = run(&scene, None, vec![], policy("naive").as_mut(), &Options::default());
    assert_eq!(e.records.last().unwrap().run_red_light, 1, "one light, counted once");
    assert!(e.events.iter().any(|ev| ev.kind == tad_runtime::EventKind::RedLight));
    let e = run(&scene, None, vec![], policy("idm").as_mut(), &Options::default());
    let last = e.records.last().unwrap();
    assert_eq!(last.run_red_light, 0);
    assert_eq!(e.stop_reason, StopReason::MaxSteps, "it waits at the line for the whole episode");
    // the ego's front stands before the stop line at x = 30
    assert!(last.position[0] + 2.25 < 30.0 && last.position[0] > 20.0, "stopped at {:.1}", last.position[0]);
}

#[test]
fn naive_runs_the_stop_sign_and_idm_stops_then_goes() {
    let scene = Scene::new(&program(junction(false), 10.0, vec![])).unwrap();
    let e = run(&scene, None, vec![], policy("naive").as_mut(), &Options::default());
    assert_eq!(e.records.last().unwrap().run_stop, 1);
    let e = run(&scene, None, vec![], policy("idm").as_mut(), &Options::default());
    let last = e.records.last().unwrap();
    assert_eq!(last.run_stop, 0);
    assert!(e.records.iter().any(|r| r.velocity < 0.1), "it stood");
    assert_eq!(e.stop_reason, StopReason::RouteComplete, "then drove on");
}

#[test]
fn naive_rear_ends_a_standing_car_and_idm_does_not() {
    let scene = Scene::new(&program(straight(), 12.0, vec![parked(0, 50.0, 1)])).unwrap();
    let e = run(&scene, None, vec![], policy("naive").as_mut(), &Options::default());
    assert_eq!(e.stop_reason, StopReason::Collision);
    let e = run(&scene, None, vec![], policy("idm").as_mut(), &Options::default());
    assert!(e.records.iter().all(|r| !r.collision));
    let last = e.records.last().unwrap();
    assert!(last.velocity < 0.1 && last.position[0] > 40.0, "waits behind it at {:.1}", last.position[0]);
}

#[test]
fn metrics_of_a_free_run_are_the_hand_computed_ones() {
    // 10 m/s on a straight road, 100 m of route: complete after 99.5 m, no acceleration,
    // no yaw change, on the route
    let scene = Scene::new(&program(straight(), 10.0, vec![])).unwrap();
    let e = run(&scene, None, vec![], policy("naive").as_mut(), &Options::default());
    let score = tad_metrics::score_episode(&e.records, tad_metrics::Mode::Fixed).unwrap();
    let m = score.metrics;
    assert_eq!((m.cr, m.rr, m.ss, m.or, m.li), (0.0, 0.0, 0.0, 0.0, 0.0));
    assert_eq!(m.comp, 1.0);
    assert!(m.acc.abs() < 1e-9 && m.yv.abs() < 1e-9 && (m.rf - 1.0).abs() < 1e-6);
    // first record at t = 0.1, the last when the route completes: 99.5 m at 10 m/s
    let ts = m.ts.unwrap();
    assert!((ts - (e.records.last().unwrap().time - 0.1)).abs() < 1e-9 && (ts - 9.9).abs() < 0.15, "TS {ts}");
}

fn driving(actor: u16, along: f64, lane: i64, speed: f64) -> Instr {
    Instr::Spawn {
        actor,
        group: format!("car{actor}"),
        index: 0,
        body: Body::Vehicle,
        class: "sedan".into(),
        size: CAR,
        arm: Arm::Ego,
        lane,
        place: Place::Lane,
        along: Value::lit(along),
        lateral: -(lane as f64 - 0.5) * LANE_WIDTH,
        facing: Facing::Along,
        yaw: 0.0,
        speed,
    }
}

#[test]
fn mobil_passes_a_slow_car_and_stays_put_without_it() {
    let slow = |mobil: bool| {
        let mut code = vec![
            driving(0, 40.0, 1, 4.0),
            driving(1, 20.0, 1, 12.0),
            Instr::Drive { actor: 0, speed: Value::lit(4.0), turn: Turn::Straight },
            Instr::Drive { actor: 1, speed: Value::lit(12.0), turn: Turn::Straight },
        ];
        if mobil {
            code.push(Instr::Mobil { actor: 1, on: true });
        }
        Scene::new(&program(straight(), 0.0, code)).unwrap()
    };
    let opts = Options { keep_frames: true, ..Options::default() };
    // the ego stands at the start, out of the way
    let e = run(&slow(true), None, vec![], policy("idm").as_mut(), &opts);
    let last = e.frames.last().unwrap();
    let (fast, slow_car) = (last.poses[2], last.poses[1]);
    assert!(fast.0 > slow_car.0 + 10.0, "the fast car got past: {fast:?} vs {slow_car:?}");
    assert!((fast.1 + 5.25).abs() < 0.5, "in lane 2: {fast:?}");
    let e = run(&slow(false), None, vec![], policy("idm").as_mut(), &opts);
    let last = e.frames.last().unwrap();
    assert!(last.poses[2].0 < last.poses[1].0, "without MOBIL it follows");
    assert!((last.poses[2].1 + 1.75).abs() < 0.2);
}

#[test]
fn mobil_does_not_cut_in_front_of_a_close_follower() {
    // the MOBIL car (actor 1) closes on a slow car in lane 1 while a faster one (actor 2)
    // comes up lane 2 close behind it: it changes lanes only once that one is past
    let code = vec![
        driving(0, 40.0, 1, 4.0),
        driving(1, 20.0, 1, 12.0),
        driving(2, 5.0, 2, 14.0),
        Instr::Drive { actor: 0, speed: Value::lit(4.0), turn: Turn::Straight },
        Instr::Drive { actor: 1, speed: Value::lit(12.0), turn: Turn::Straight },
        Instr::Drive { actor: 2, speed: Value::lit(14.0), turn: Turn::Straight },
        Instr::Mobil { actor: 1, on: true },
    ];
    let scene = Scene::new(&program(straight(), 0.0, code)).unwrap();
    let opts = Options { keep_frames: true, ..Options::default() };
    let e = run(&scene, None, vec![], policy("idm").as_mut(), &opts);
    let in_lane_2 = |y: f64| (y + 5.25).abs() < 1.75;
    let step = e.frames.iter().position(|f| in_lane_2(f.poses[2].1)).expect("it changes lanes once it may");
    let (car, follower) = (e.frames[step].poses[2], e.frames[step].poses[3]);
    assert!(follower.0 > car.0, "it cut in {:.1} m ahead of the follower at step {step}", car.0 - follower.0);
}

/// The view's nearby actors: nearest first, in the ego's frame, relative to it, within
/// reach only.
#[test]
fn the_ego_sees_the_nearest_actors_in_its_frame() {
    // two parked cars ahead in lane 1 and one in lane 2, one beyond reach
    let cars = vec![parked(0, 30.0, 1), parked(1, 12.0, 2), parked(2, 20.0, 1), parked(3, 90.0, 1)];
    let scene = Scene::new(&program(straight(), 10.0, cars)).unwrap();
    let mut sim = tad_runtime::Sim::start(&scene, None, vec![], Options::default());
    let view = sim.view().expect("a first view").clone();
    let seen: Vec<_> = view.around.iter().flatten().collect();
    assert_eq!(seen.len(), 3, "the car 90 m on is out of reach: {seen:?}");
    let ahead: Vec<f64> = seen.iter().map(|n| n.position[0]).collect();
    assert!(ahead.windows(2).all(|w| w[0] <= w[1]), "nearest first: {ahead:?}");
    for n in &seen {
        // standing cars come at the ego at its own speed; they face its way
        assert!((n.velocity[0] + view.speed).abs() < 1e-9 && n.velocity[1].abs() < 1e-9, "{n:?}");
        assert!(n.yaw.abs() < 1e-9 && n.size == [CAR.length, CAR.width], "{n:?}");
    }
    // lane 2 is a lane's width to the ego's right (y is left); lane 1 is its own
    assert!((seen[0].position[1] + LANE_WIDTH).abs() < 0.2, "{:?}", seen[0]);
    assert!(seen[1].position[1].abs() < 0.2 && seen[2].position[1].abs() < 0.2);
    assert!((seen[1].position[0] - seen[0].position[0] - 8.0).abs() < 1e-6);
    assert!(view.around[3].is_none());
}
