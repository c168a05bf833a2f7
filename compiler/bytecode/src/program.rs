//! The decoded program: set-up instructions (the road, signals, the ego, every actor),
//! then behaviour instructions run per actor, each actor with its own program counter.
//!
//! A behaviour instruction either returns at once (it sets what the actor does: `Drive`,
//! `Cross`, `Speed`, `ChangeLane`, `Stop`, `Signals`, `Mobil`) or blocks the actor's script
//! until it holds (`Wait`, `WaitNear`); the motion it set goes on meanwhile.

use tad_layout::{Arm, Body, Facing, Place, Turn};

/// A parameter slot's index in [`Program::params`].
pub type Slot = u16;
/// An actor's index in the spawn order (0 is the first `Spawn`; the ego has none).
pub type ActorId = u16;
/// A path's index in [`Program::paths`].
pub type PathId = u16;

/// A number: `base`, plus the slot's sampled value when there is one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Value {
    pub base: f64,
    pub slot: Option<Slot>,
}

impl Value {
    pub const fn lit(base: f64) -> Value {
        Value { base, slot: None }
    }

    /// With the slots' values for this run (a missing slot counts 0).
    pub fn eval(&self, params: &[f64]) -> f64 {
        self.base + self.slot.and_then(|s| params.get(usize::from(s))).copied().unwrap_or(0.0)
    }
}

/// A value sampled per run, uniformly in `min..=max`; `default` is the nominal run's.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSlot {
    /// `group.what`: `slow_truck.shift`, `runner.spread`, `runner.speed`.
    pub name: String,
    pub min: f64,
    pub max: f64,
    pub default: f64,
}

/// A polyline in the road's frame (m; the ego starts at the origin heading `+x`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Polyline(pub Vec<[f64; 2]>);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Light {
    Off,
    Red,
    Yellow,
    Green,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    pub light: Light,
    pub seconds: f64,
}

/// An actor's size, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Size {
    pub length: f64,
    pub width: f64,
    pub height: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Instr {
    // ── set-up, before step 0 ────────────────────────────────────────────────────────
    /// The road; exactly one, first. The runtime rebuilds `tad_layout::Road` from it.
    Road(tad_layout::Road),
    /// When a run ends: step length (s), steps, the ego's driven distance (m), time (s).
    Limits { dt: f64, max_steps: u32, max_distance: f64, timeout: f64 },
    /// The phase program of the lights facing an arm's incoming traffic; it repeats.
    Signal { arm: Arm, phases: Vec<Phase> },
    /// The ego: its vehicle, route (a path, the arc length of the start, the route's
    /// length from there) and the speed the scenario states (the policies' desired speed).
    Ego { class: String, size: Size, lane: i64, turn: Turn, path: PathId, start: f64, route_length: f64, speed: Value },
    /// One actor, standing (or moving at `speed` when `moving`) at a station on an arm.
    Spawn {
        actor: ActorId,
        /// The group's name and the actor's place in it.
        group: String,
        index: u16,
        body: Body,
        /// The vocabulary's name: `sedan`, `pedestrian`, `traffic_cone`.
        class: String,
        size: Size,
        arm: Arm,
        lane: i64,
        place: Place,
        /// The station's `along` (see `tad_layout::Station`), sampled shifts included.
        along: Value,
        /// Left of the arm's centre line, m.
        lateral: f64,
        facing: Facing,
        /// Heading in the road's frame, radians from `+x`, counter-clockwise.
        yaw: f64,
        /// m/s at step 0 (0 when standing).
        speed: f64,
    },
    // ── behaviour, per actor, in program order ───────────────────────────────────────
    /// Block this actor's script for a time.
    Wait { actor: ActorId, seconds: Value },
    /// Block until the ego is within a distance of the actor, m.
    WaitNear { actor: ActorId, distance: Value },
    /// Drive its lane from where it stands at `speed`, taking `turn` at the junction ahead
    /// (the path is `Road::vehicle_path`, kept `lateral` off the lane's centre).
    Drive { actor: ActorId, speed: Value, turn: Turn },
    /// Drive or walk an explicit path (an overtake, a walk along the sidewalk).
    Follow { actor: ActorId, path: PathId, speed: Value },
    /// Walk straight ahead across the road at `speed`.
    Cross { actor: ActorId, speed: Value },
    /// Move to the lane `lanes` to the right (negative: left) of the current one.
    ChangeLane { actor: ActorId, lanes: i64 },
    /// A new target speed, m/s.
    Speed { actor: ActorId, speed: Value },
    /// Brake to a stop and stay.
    Stop { actor: ActorId },
    /// Obey (the default) or run red lights and stop signs.
    Signals { actor: ActorId, obey: bool },
    /// Let the runtime change lanes when it pays (MOBIL); off by default.
    Mobil { actor: ActorId, on: bool },
}

/// A decoded `.tadc` program.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Program {
    /// The scenario's name and the file it was built from.
    pub name: String,
    pub source: String,
    pub params: Vec<ParamSlot>,
    pub paths: Vec<Polyline>,
    pub code: Vec<Instr>,
}
