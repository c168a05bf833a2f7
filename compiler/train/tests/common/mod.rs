//! The hand-built straight-road scenes and helpers the training tests share.
#![allow(dead_code)]

use std::path::PathBuf;

use tad_bytecode::{Instr, ParamSlot, Polyline, Program, Size, Value};
use tad_layout::road::LANE_WIDTH;
use tad_layout::{Arm, Body, Facing, Place, Road, Shape, Turn};
use tad_runtime::Scene;
use tad_train::{Config, Trainer};

const CAR: Size = Size { length: 4.5, width: 1.8, height: 1.5 };

/// A straight two-lane road, the ego in lane 1 at 8 m/s (a slot shifts it by up to
/// ±1 m/s), alone or with a car ahead at 4 m/s (40 m ahead: within the observation's 15 m
/// only near the end of a long episode).
pub fn scene(max_steps: u32, lead: bool) -> Scene {
    on_road(max_steps, lead.then_some((40.0, 4.0)))
}

/// The same road with a car stopped 12 m ahead of the ego: an exploring actor hits it.
pub fn blocked(max_steps: u32) -> Scene {
    on_road(max_steps, Some((12.0, 0.0)))
}

/// The straight road, with a car in the ego's lane `(along, speed)`.
fn on_road(max_steps: u32, lead: Option<(f64, f64)>) -> Scene {
    let road = Road {
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
    };
    let (path, start) = road.vehicle_path(tad_layout::Station { arm: Arm::Ego, along: 0.0 }, 1, Turn::Straight);
    let mut code = vec![
        Instr::Road(road),
        Instr::Limits { dt: 0.1, max_steps, max_distance: 200.0, timeout: 60.0 },
        Instr::Ego {
            class: "car".into(),
            size: CAR,
            lane: 1,
            turn: Turn::Straight,
            path: 0,
            start,
            route_length: 150.0,
            speed: Value { base: 8.0, slot: Some(0) },
        },
    ];
    if let Some((along, speed)) = lead {
        code.push(Instr::Spawn {
            actor: 0,
            group: "lead".into(),
            index: 0,
            body: Body::Vehicle,
            class: "sedan".into(),
            size: CAR,
            arm: Arm::Ego,
            lane: 1,
            place: Place::Lane,
            along: Value::lit(along),
            lateral: -0.5 * LANE_WIDTH,
            facing: Facing::Along,
            yaw: 0.0,
            speed,
        });
        code.push(Instr::Drive { actor: 0, speed: Value::lit(speed), turn: Turn::Straight });
    }
    let program = Program {
        name: match lead {
            None => "alone".into(),
            Some((_, speed)) if speed > 0.0 => "lead".into(),
            Some(_) => "blocked".into(),
        },
        source: "hand.tad".into(),
        params: vec![ParamSlot { name: "ego.speed".into(), min: -1.0, max: 1.0, default: 0.0 }],
        paths: vec![Polyline(path.points().iter().map(|p| [p.x, p.y]).collect())],
        code,
    };
    Scene::new(&program).expect("the hand-built program sets up")
}

pub fn small(seed: u64) -> Config {
    Config {
        hidden: vec![32, 32],
        actor_lr: 3e-3,
        critic_lr: 3e-3,
        batch: 64,
        buffer: 5000,
        start_training: 200,
        updates_per_episode: 25,
        seed,
        ..Config::default()
    }
}

pub fn params(scene: &Scene, seed: u64) -> Vec<f64> {
    tad_runtime::sample::sample(&scene.program.params, Some(seed))
}

/// `n` training episodes on `scenes`, each chosen by the trainer.
pub fn train(trainer: &mut Trainer, scenes: &[Scene], until: u64) {
    while trainer.episodes() < until {
        let task = trainer.task(scenes.len());
        let scene = &scenes[task.scenario];
        trainer.step(scene, params(scene, task.seed), task.seed).expect("a learning step");
    }
}

/// The deterministic actor's mean return over a few seeds of each scene.
pub fn mean_return(trainer: &Trainer, scenes: &[Scene]) -> f64 {
    let mut total = 0.0;
    let mut n = 0.0;
    for scene in scenes {
        for seed in 100..103 {
            total += trainer.evaluate(scene, params(scene, seed), seed).episode_return;
            n += 1.0;
        }
    }
    total / n
}

pub fn temp(name: &str) -> PathBuf {
    tad_test_support::scratch(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")), name)
}
