//! A program set up for running: the world, the ego's route, every actor's start and script.
//! Checks what a hand-built [`Program`] could get wrong (the loader already checks files),
//! so running never indexes out of bounds.

use crate::world::World;
use tad_bytecode::{ActorId, Instr, Program, Size};
use tad_road::geom::{Path, Pose, Vec2};
use tad_road::{Arm, Body, Facing, Place, Turn};

/// Why a program cannot run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SetupError(pub String);

impl std::fmt::Display for SetupError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SetupError {}

#[derive(Clone, Debug)]
pub struct EgoSetup {
    pub class: String,
    pub size: Size,
    pub lane: i64,
    pub turn: Turn,
    pub route: Path,
    pub start: f64,
    pub route_length: f64,
    pub speed: tad_bytecode::Value,
}

#[derive(Clone, Debug)]
pub struct ActorSetup {
    pub label: String,
    pub class: String,
    pub body: Body,
    pub size: Size,
    pub arm: Arm,
    pub lane: i64,
    pub place: Place,
    pub along: tad_bytecode::Value,
    pub lateral: f64,
    pub facing: Facing,
    pub yaw: f64,
    pub speed: f64,
    /// Its behaviour instructions, in program order.
    pub script: Vec<Instr>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    pub dt: f64,
    pub max_steps: u32,
    pub max_distance: f64,
    pub timeout: f64,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits { dt: 0.1, max_steps: 300, max_distance: 200.0, timeout: 60.0 }
    }
}

/// A program ready to run any number of episodes.
pub struct Scene {
    pub name: String,
    pub source: String,
    pub program: Program,
    pub world: World,
    pub limits: Limits,
    pub ego: EgoSetup,
    pub actors: Vec<ActorSetup>,
    pub paths: Vec<Path>,
    /// SafeBench's route points for the observation (`tad_policy`'s header): every metre
    /// of the route, then 12 more at 5 m past its end; positions and headings.
    pub preview: Vec<[f64; 2]>,
    pub preview_yaw: Vec<f64>,
}

impl Scene {
    pub fn new(program: &Program) -> Result<Scene, SetupError> {
        let err = |m: String| Err(SetupError(m));
        let paths: Vec<Path> =
            program.paths.iter().map(|p| Path::new(p.0.iter().map(|&[x, y]| Vec2::new(x, y)))).collect();
        let mut road = None;
        let mut limits = Limits::default();
        let mut signals = Vec::new();
        let mut ego = None;
        let mut actors: Vec<ActorSetup> = Vec::new();
        let mut ids: Vec<ActorId> = Vec::new();
        for instr in &program.code {
            match instr {
                Instr::Road(r) => road = Some(r.clone()),
                Instr::Limits { dt, max_steps, max_distance, timeout } => {
                    if !(*dt > 0.0 && dt.is_finite()) {
                        return err(format!("the step length must be positive, not {dt}"));
                    }
                    limits = Limits { dt: *dt, max_steps: *max_steps, max_distance: *max_distance, timeout: *timeout };
                }
                Instr::Signal { arm, phases } => signals.push((*arm, phases.clone())),
                Instr::Ego { class, size, lane, turn, path, start, route_length, speed } => {
                    let Some(route) = paths.get(usize::from(*path)) else {
                        return err(format!("the ego's route is path {path}, but the program has {}", paths.len()));
                    };
                    ego = Some(EgoSetup {
                        class: class.clone(),
                        size: *size,
                        lane: *lane,
                        turn: *turn,
                        route: route.clone(),
                        start: *start,
                        route_length: *route_length,
                        speed: *speed,
                    });
                }
                Instr::Spawn {
                    actor,
                    group,
                    index,
                    body,
                    class,
                    size,
                    arm,
                    lane,
                    place,
                    along,
                    lateral,
                    facing,
                    yaw,
                    speed,
                } => {
                    if ids.contains(actor) {
                        return err(format!("actor a{actor} is spawned twice"));
                    }
                    ids.push(*actor);
                    actors.push(ActorSetup {
                        label: format!("{group}[{index}]"),
                        class: class.clone(),
                        body: *body,
                        size: *size,
                        arm: *arm,
                        lane: *lane,
                        place: *place,
                        along: *along,
                        lateral: *lateral,
                        facing: *facing,
                        yaw: *yaw,
                        speed: *speed,
                        script: Vec::new(),
                    });
                }
                behaviour => {
                    let Some(actor) = actor_of(behaviour) else { continue };
                    let Some(k) = ids.iter().position(|a| *a == actor) else {
                        return err(format!("a behaviour names actor a{actor} before it is spawned"));
                    };
                    if let Instr::Follow { path, .. } = behaviour
                        && usize::from(*path) >= paths.len()
                    {
                        return err(format!("actor a{actor} follows path {path}, but the program has {}", paths.len()));
                    }
                    actors[k].script.push(behaviour.clone());
                }
            }
        }
        let Some(road) = road else { return err("the program sets up no road".into()) };
        let Some(ego) = ego else { return err("the program has no ego".into()) };
        let mut arcs: Vec<f64> =
            (0..=ego.route_length.max(0.0).floor() as usize).map(|k| ego.start + k as f64).collect();
        let end = ego.start + ego.route_length.max(0.0);
        arcs.extend((1..=12).map(|k| end + 5.0 * f64::from(k)));
        let poses: Vec<Pose> = arcs.iter().map(|&a| ego.route.pose(a)).collect();
        Ok(Scene {
            preview: poses.iter().map(|p| [p.position.x, p.position.y]).collect(),
            preview_yaw: poses.iter().map(|p| p.yaw).collect(),
            name: program.name.clone(),
            source: program.source.clone(),
            program: program.clone(),
            world: World::new(road, signals),
            limits,
            ego,
            actors,
            paths,
        })
    }

    /// The ego's start on its route.
    pub fn ego_pose(&self) -> Pose {
        self.ego.route.pose(self.ego.start)
    }
}

/// The actor a behaviour instruction is about.
pub fn actor_of(instr: &Instr) -> Option<ActorId> {
    match instr {
        Instr::Wait { actor, .. }
        | Instr::WaitNear { actor, .. }
        | Instr::Meet { actor, .. }
        | Instr::Drive { actor, .. }
        | Instr::Follow { actor, .. }
        | Instr::Cross { actor, .. }
        | Instr::ChangeLane { actor, .. }
        | Instr::Speed { actor, .. }
        | Instr::Stop { actor }
        | Instr::Signals { actor, .. }
        | Instr::Mobil { actor, .. } => Some(*actor),
        _ => None,
    }
}
