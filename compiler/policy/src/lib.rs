//! Ego policies: what drives the ego in the runtime.
//!
//! Every policy sees an [`EgoView`] each step (SafeBench's four-feature observation and,
//! for rule-based drivers, the full state the runtime knows) and answers an [`Action`]:
//! an acceleration and a normalised steer the runtime applies to its kinematic bicycle.
//! Four drivers: [`Idm`] (lane keeping and IDM car following that obeys lights and stop
//! signs), [`Naive`] (constant speed along the route, blind to everything else),
//! [`Learned`] (SafeBench's SAC actor from a safetensors file) and [`External`] (any
//! process, over JSON lines). [`parse_policy`] names them.
//!
//! # Frames and signs
//!
//! Our frame is right-handed: `x` forward, `y` left, yaw counter-clockwise (seen from
//! above), radians. CARLA's is left-handed: `y` right, yaw clockwise, degrees; a CARLA pose
//! is ours with `y` and yaw negated. [`Action::steer`] keeps CARLA's sign (positive steers
//! right) because learned actors were trained with it: a wheel angle δ in our frame
//! (positive left) is `steer = −δ / MAX_WHEEL_ANGLE`.
//!
//! # The observation (`EgoView::obs`)
//!
//! SafeBench's `obs_type 0` state `[lateral_dis, −delta_yaw, speed, vehicle_front]`
//! (`gym_carla/envs/carla_env.py::_get_obs`), fed to the actor as is (no normalisation),
//! as `f32`. Definitions in our frame; [`observation`] computes the first three.
//!
//! **Route points.** `P_0, P_1, …` with headings `ψ_k`: the route densified at 1 m (SafeBench
//! interpolates the route with `interpolate_trajectory`'s default `hop_resolution` 1 m), then
//! continued past its end along the lane at 5 m (the route planner's `_sampling_radius`; a
//! runtime without the lane continues straight along the last heading). `ψ_k` is the lane's
//! heading at `P_k`.
//!
//! **Preview point** ([`Preview`]). A head index `h`, 0 at the episode's start. At each
//! observation: use `P_i` with `i = h + 2` (clamped to the last point); *then* advance: let
//! `j` be the largest offset in `0..12` (the planner's 12-point buffer) with
//! `|P_{h+j} − ego| < 4 m` (`_min_distance`); if there is one, `h += max(j − 1, 0)`. So on
//! the route the preview point lies 4–5 m ahead of where the ego was at the previous
//! observation, and the head never moves back.
//!
//! With ego position `p`, heading `ψ`, `w = (cos ψ_i, sin ψ_i)`, `u = (cos ψ, sin ψ)` and
//! `a × b = a.x·b.y − a.y·b.x`:
//! - `obs[0] = lateral_dis = w × (p − P_i)`, m: positive when the ego is **left** of the
//!   route line through `P_i`. (SafeBench computes `−|v|·(w × v/|v|)` with `v = p − P_i` in
//!   CARLA's frame; the frame flip cancels its minus sign.)
//! - `obs[1] = −delta_yaw = asin(w × u)`, rad in [−π/2, π/2]: positive when the ego heads
//!   **left** of the route's direction (SafeBench: `delta_yaw = asin(w × u)` in CARLA's
//!   frame, positive when heading right, and the observation negates it).
//! - `obs[2] = speed = ‖(v_x, v_y)‖`, m/s, the planar speed, never negative.
//! - `obs[3] = vehicle_front`, 1 or 0: 1 if some other *vehicle* (cars, trucks, bicycles and
//!   motorbikes: CARLA's `*vehicle*` actors; not walkers or props) has its centre on the
//!   same road and lane as the ego's centre (each projected to its nearest driving lane),
//!   at most 15 m from the ego's centre (`_proximity_threshold`), and strictly in front:
//!   `u · (c − p) > 0` for its centre `c` (less than 90° off the heading).
//!
//! SafeBench computes the observation after each tick, from the state the action led to;
//! the first one at reset.

pub mod external;
mod idm;
mod learned;
pub mod pretrained;

pub use external::External;
pub use idm::{Idm, IdmParams, Naive};
pub use learned::{Format, Learned};

use std::fmt;

/// The runtime's limits on [`Action::accel`], m/s².
pub const ACCEL_MIN: f64 = -8.0;
pub const ACCEL_MAX: f64 = 3.0;
/// The wheel angle of `steer = ±1`, rad (CARLA's cars: 70°).
pub const MAX_WHEEL_ANGLE: f64 = 70.0 * std::f64::consts::PI / 180.0;
pub use tad_layout::idm::STANDING;

/// What the ego's driver sees at a step. Frame: the ego's, `x` forward, `y` left.
#[derive(Clone, Debug, PartialEq)]
pub struct EgoView {
    /// SafeBench's observation `[lateral_dis, −delta_yaw, speed, vehicle_front]`, as the
    /// crate's header defines it (positive lateral: the ego is left of the route; positive
    /// angle: it heads left of the route).
    pub obs: [f64; OBS_DIM],
    /// m/s.
    pub speed: f64,
    /// The speed the scenario states for the ego, m/s.
    pub desired_speed: f64,
    /// The route's point [`EgoView::lookahead`] metres ahead, in the ego's frame, m.
    pub target: [f64; 2],
    pub lookahead: f64,
    /// Front-to-rear axle distance, m.
    pub wheelbase: f64,
    /// The nearest actor ahead in the ego's corridor: (bumper-to-bumper gap m, its speed
    /// along the route m/s).
    pub leader: Option<(f64, f64)>,
    /// Distance from the ego's front to where it must stop (a stop line whose light is red
    /// or yellow, a stop sign it has not stopped at yet), m.
    pub stop: Option<f64>,
    /// The highest speed at which the route ahead can be driven at a comfortable lateral
    /// acceleration, m/s (infinite where it is straight).
    pub curve_speed: f64,
    /// Step length, s.
    pub dt: f64,
    /// The other actors nearest the ego, nearest first: those within [`NEAR_RANGE`] of its
    /// centre, at most [`NEAR`].
    pub around: [Option<Near>; NEAR],
}

/// Another actor as the ego sees it, in the ego's frame (`x` forward, `y` left).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Near {
    /// Its centre, m.
    pub position: [f64; 2],
    /// Its velocity less the ego's, m/s.
    pub velocity: [f64; 2],
    /// Its heading less the ego's, rad.
    pub yaw: f64,
    /// Its length and width, m.
    pub size: [f64; 2],
}

/// How many other actors [`EgoView::around`] holds (highway-env's `Kinematics` shows five
/// besides the ego; a junction's adversary and the cars around it need one more).
pub const NEAR: usize = 6;
/// How far from the ego's centre an actor is seen in [`EgoView::around`], m; also the
/// `kinematics` observation's unit of position.
pub const NEAR_RANGE: f64 = 50.0;
/// The values each actor adds to the `kinematics` observation ([`EgoView::kinematics`]).
pub const NEAR_FEATURES: usize = 9;
/// The `kinematics` observation's length.
pub const KINEMATICS_DIM: usize = STATE_DIM + NEAR * NEAR_FEATURES;

/// What the driver does: `accel` in m/s² (the runtime clamps it to
/// [`ACCEL_MIN`]..=[`ACCEL_MAX`]), `steer` normalised to `[-1, 1]` of
/// [`MAX_WHEEL_ANGLE`], positive to the right (CARLA's sign). Given a finite view, every
/// policy here answers finite values within those ranges.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Action {
    pub accel: f64,
    pub steer: f64,
}

/// The `state` observation's length ([`EgoView::state`]).
pub const STATE_DIM: usize = 13;
/// What the `state` observation shows for "none" or "unbounded", m and m/s, and its unit
/// of distance: gaps are shown as fractions of it, so "none" is 1.
pub const STATE_FAR: f64 = 100.0;
/// The `state` observation's unit of speed (m/s) and of the route point's coordinates (m):
/// values near 1, where a network's first layer works best.
pub const STATE_UNIT: f64 = 10.0;

impl EgoView {
    /// The `state` observation: SafeBench's four features, then what the rule-based
    /// drivers see, as numbers a network takes (nothing infinite, presence as 0/1, the
    /// rest scaled to about 1 by [`STATE_UNIT`] and [`STATE_FAR`]):
    ///
    /// | index | value |
    /// |---|---|
    /// | 0–3 | [`EgoView::obs`] |
    /// | 4 | desired speed ÷ 10 m/s |
    /// | 5, 6 | the route's point [`EgoView::lookahead`] ahead, ego frame, ÷ 10 m |
    /// | 7, 8, 9 | a leader: 1/0, its gap ÷ 100 m (1 at most, 1 without), its speed ÷ 10 m/s (0 without) |
    /// | 10, 11 | a place to stop: 1/0, its distance ÷ 100 m (1 at most, 1 without) |
    /// | 12 | the route's curve speed ÷ 10 m/s, 10 at most |
    pub fn state(&self) -> [f64; STATE_DIM] {
        let far = |d: f64| d.min(STATE_FAR) / STATE_FAR;
        let (leader, gap, leader_speed) = match self.leader {
            Some((gap, speed)) => (1.0, far(gap), speed / STATE_UNIT),
            None => (0.0, 1.0, 0.0),
        };
        let (stop, stop_at) = self.stop.map_or((0.0, 1.0), |d| (1.0, far(d)));
        let [a, b, c, d] = self.obs;
        let [x, y] = self.target.map(|v| v / STATE_UNIT);
        let curve = self.curve_speed.min(STATE_FAR) / STATE_UNIT;
        [a, b, c, d, self.desired_speed / STATE_UNIT, x, y, leader, gap, leader_speed, stop, stop_at, curve]
    }

    /// The `kinematics` observation: the [`EgoView::state`], then each of the
    /// [`EgoView::around`] as highway-env's `Kinematics` shows a vehicle (presence, then
    /// where it is and how it moves relative to the ego, its heading as cosine and sine),
    /// with its size; an empty place is all zeros:
    ///
    /// | offset in the actor's 9 | value |
    /// |---|---|
    /// | 0 | 1 (present) |
    /// | 1, 2 | its centre, ego frame, ÷ [`NEAR_RANGE`] (within ±1) |
    /// | 3, 4 | its velocity less the ego's, ego frame, ÷ 10 m/s |
    /// | 5, 6 | cosine and sine of its heading less the ego's |
    /// | 7, 8 | its length and width ÷ 10 m |
    pub fn kinematics(&self) -> [f64; KINEMATICS_DIM] {
        let mut out = [0.0; KINEMATICS_DIM];
        out[..STATE_DIM].copy_from_slice(&self.state());
        for (near, slot) in self.around.iter().zip(out[STATE_DIM..].chunks_exact_mut(NEAR_FEATURES)) {
            let Some(n) = near else { continue };
            let [x, y] = n.position.map(|v| (v / NEAR_RANGE).clamp(-1.0, 1.0));
            let [vx, vy] = n.velocity.map(|v| v / STATE_UNIT);
            let [length, width] = n.size.map(|v| v / STATE_UNIT);
            slot.copy_from_slice(&[1.0, x, y, vx, vy, n.yaw.cos(), n.yaw.sin(), length, width]);
        }
        out
    }
}

/// What a learned driver sees: SafeBench's four values, the `state`, or the `kinematics`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Observation {
    /// SafeBench's `[lateral_dis, −delta_yaw, speed, vehicle_front]` ([`EgoView::obs`]).
    #[default]
    SafeBench,
    /// [`EgoView::state`].
    State,
    /// [`EgoView::kinematics`]: the `state` and the actors nearest the ego.
    Kinematics,
}

impl Observation {
    /// Every observation by its name.
    pub const ALL: [(&'static str, Observation); 3] =
        [("safebench", Observation::SafeBench), ("state", Observation::State), ("kinematics", Observation::Kinematics)];

    /// The observation a name means (`safebench`, `state`, `kinematics`).
    pub fn parse(name: &str) -> Option<Observation> {
        Observation::ALL.iter().find(|(n, _)| *n == name).map(|&(_, o)| o)
    }

    pub fn name(self) -> &'static str {
        Observation::ALL.iter().find(|(_, o)| *o == self).map_or("safebench", |&(n, _)| n)
    }

    /// How many values it holds.
    pub fn width(self) -> usize {
        match self {
            Observation::SafeBench => OBS_DIM,
            Observation::State => STATE_DIM,
            Observation::Kinematics => KINEMATICS_DIM,
        }
    }

    /// `f` of the observation of `view`, [`Observation::width`] values, without allocating.
    pub fn with<R>(self, view: &EgoView, f: impl FnOnce(&[f64]) -> R) -> R {
        match self {
            Observation::SafeBench => f(&view.obs),
            Observation::State => f(&view.state()),
            Observation::Kinematics => f(&view.kinematics()),
        }
    }

    /// The observation of `view`, [`Observation::width`] values.
    pub fn of(self, view: &EgoView) -> Vec<f64> {
        self.with(view, <[f64]>::to_vec)
    }

    /// The observation a learned actor with `inputs` inputs reads.
    pub fn of_inputs(inputs: usize) -> Option<Observation> {
        Observation::ALL.iter().map(|&(_, o)| o).find(|o| o.width() == inputs)
    }
}

/// SafeBench's observation's length ([`EgoView::obs`]).
pub const OBS_DIM: usize = 4;

/// How a learned actor's `[−1, 1]` outputs are applied: `accel = 3·a` m/s² forward
/// (SafeBench's `continuous_accel_range`), `accel = 8·a` m/s² braking (SafeBench's brake
/// normaliser, `brake = −acc/8`: −1 is the full brake), `steer = 0.3·s`
/// (`continuous_steer_range`, CARLA's sign).
///
/// SafeBench clips `acc` to ±3 before it maps the brake, so its agents never brake harder
/// than 3/8 of full. Measured on ordinary fitted scenes, the idm driver so clipped collides
/// in 27 % of its episodes against 6 % with its own braking: no driver can meet the idm
/// bar through that clip, so here the negative half reaches the full brake.
pub const ACCEL_RANGE: f64 = 3.0;
pub const BRAKE_RANGE: f64 = -ACCEL_MIN;
pub const STEER_RANGE: f64 = 0.3;

impl Action {
    /// An actor's `[acc, steer]` in `[−1, 1]` as applied ([`ACCEL_RANGE`],
    /// [`BRAKE_RANGE`], [`STEER_RANGE`]); values outside are clamped.
    pub fn from_unit([acc, steer]: [f32; 2]) -> Action {
        let acc = f64::from(acc).clamp(-1.0, 1.0);
        Action {
            accel: if acc >= 0.0 { acc * ACCEL_RANGE } else { acc * BRAKE_RANGE },
            steer: (f64::from(steer) * STEER_RANGE).clamp(-STEER_RANGE, STEER_RANGE),
        }
    }

    /// The `[−1, 1]²` action that [`Action::from_unit`] turns into this one, as near as
    /// its ranges allow (a stronger brake or steer is clamped): how a learned actor
    /// imitates a rule-based driver. Non-finite values become 0.
    pub fn to_unit(self) -> [f32; 2] {
        let unit = |v: f64, range: f64| if v.is_finite() { (v / range).clamp(-1.0, 1.0) as f32 } else { 0.0 };
        let range = if self.accel >= 0.0 { ACCEL_RANGE } else { BRAKE_RANGE };
        [unit(self.accel, range), unit(self.steer, STEER_RANGE)]
    }
}

pub trait EgoPolicy: Send {
    /// As the command line names it: `idm`, `naive`, `learned:PATH`.
    fn name(&self) -> &str;
    /// Called before each episode.
    fn reset(&mut self) {}
    fn act(&mut self, view: &EgoView) -> Action;
    /// Why the policy cannot drive any more (an external process that broke the protocol);
    /// the runtime ends the episode when it says.
    fn failure(&self) -> Option<&str> {
        None
    }
}

/// Pure pursuit towards `target` (ego frame, m) for a car of `wheelbase` m: the arc through
/// the target has curvature `κ = 2y / (x² + y²)`, the wheel angle `atan(wheelbase·κ)`;
/// the answer is that angle as a normalised steer with CARLA's sign (a target on the left
/// gives a negative steer), clamped to `[-1, 1]`. 0 for a target at the ego.
pub fn pure_pursuit(target: [f64; 2], wheelbase: f64) -> f64 {
    let [x, y] = target;
    let d2 = x * x + y * y;
    if d2.is_nan() || d2 <= 1e-9 || !wheelbase.is_finite() {
        return 0.0;
    }
    let wheel = (wheelbase * 2.0 * y / d2).atan();
    (-wheel / MAX_WHEEL_ANGLE).clamp(-1.0, 1.0)
}

/// `[lateral_dis, −delta_yaw, speed]` of the crate's header, in our frame: the ego at
/// `position` heading `yaw` (rad) at `speed`, the preview point at `point` heading
/// `point_yaw`.
pub fn observation(position: [f64; 2], yaw: f64, point: [f64; 2], point_yaw: f64, speed: f64) -> [f64; 3] {
    let w = [point_yaw.cos(), point_yaw.sin()];
    let v = [position[0] - point[0], position[1] - point[1]];
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    [cross(w, v), cross(w, [yaw.cos(), yaw.sin()]).clamp(-1.0, 1.0).asin(), speed.abs()]
}

/// SafeBench's preview point along the route (the crate's header): which route point the
/// observation measures against, step by step.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Preview {
    /// The planner buffer's first point.
    pub head: usize,
}

impl Preview {
    /// The planner's buffer length (`max_waypt`).
    pub const BUFFER: usize = 12;
    /// The buffer index the observation uses.
    pub const INDEX: usize = 2;
    /// Points closer than this to the ego are passed (`_min_distance`), m.
    pub const REACHED: f64 = 4.0;

    /// The index into `points` of this observation's preview point (`None`: no points),
    /// then the head advanced past the points the ego at `ego` has reached.
    pub fn step(&mut self, points: &[[f64; 2]], ego: [f64; 2]) -> Option<usize> {
        let last = points.len().checked_sub(1)?;
        let index = (self.head + Self::INDEX).min(last);
        let mut window = points.iter().enumerate().skip(self.head).take(Self::BUFFER);
        let reached = window.rfind(|(_, p)| (p[0] - ego[0]).hypot(p[1] - ego[1]) < Self::REACHED);
        if let Some((j, _)) = reached {
            self.head += (j - self.head).saturating_sub(1);
        }
        Some(index)
    }
}

/// Why a policy could not be made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PolicyError {
    /// Not one of the policies' names.
    UnknownPolicy { spec: String },
    /// `learned` without `:PATH`.
    MissingPath,
    /// `external` without `:CMD`.
    MissingCommand,
    /// The file could not be read or written.
    Io { path: String, message: String },
    /// The bytes are not a safetensors file (or hold a type candle cannot read).
    NotSafetensors { path: String, message: String },
    /// A tensor the actor needs is absent; `found` lists some that are there.
    MissingTensor { path: String, name: String, found: Vec<String> },
    /// A tensor has the wrong shape.
    WrongShape { path: String, name: String, expected: String, found: Vec<usize> },
    /// A tensor holds NaN or an infinity.
    NonFinite { path: String, name: String },
    /// [`Learned::random`] was given no hidden layer or an empty one.
    BadHidden { hidden: Vec<usize> },
    /// Anything else candle reports.
    Tensor { message: String },
}

impl fmt::Display for PolicyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PolicyError::UnknownPolicy { spec } => {
                write!(
                    f,
                    "unknown policy `{spec}` (expected `idm`, `naive`, `ppo`, `sac`, `td3`, `learned:PATH` or `external:CMD`)"
                )
            }
            PolicyError::MissingPath => {
                f.write_str("the learned policy needs a checkpoint: `learned:PATH` (a safetensors file)")
            }
            PolicyError::MissingCommand => {
                f.write_str("the external policy needs a command: `external:CMD` (it answers JSON lines)")
            }
            PolicyError::Io { path, message } => write!(f, "{path}: {message}"),
            PolicyError::NotSafetensors { path, message } => write!(f, "{path}: not a safetensors file: {message}"),
            PolicyError::MissingTensor { path, name, found } => {
                write!(
                    f,
                    "{path}: no tensor `{name}` (an actor needs SafeBench's `fc1` … `fcN` and `fc_mu`, or an SB3 policy's; found "
                )?;
                if found.is_empty() { f.write_str("none)") } else { write!(f, "{})", found.join(", ")) }
            }
            PolicyError::WrongShape { path, name, expected, found } => {
                write!(f, "{path}: tensor `{name}` has shape {found:?}, expected {expected}")
            }
            PolicyError::NonFinite { path, name } => write!(f, "{path}: tensor `{name}` holds a NaN or an infinity"),
            PolicyError::BadHidden { hidden } => {
                write!(f, "an actor needs at least one hidden layer, each of at least one unit (got {hidden:?})")
            }
            PolicyError::Tensor { message } => write!(f, "tensor error: {message}"),
        }
    }
}

impl std::error::Error for PolicyError {}

/// An ego by its command-line name (`idm`, `naive` or `learned:PATH`), read once and made
/// afresh for every episode: a learned actor is loaded when the spec is parsed and copied.
#[derive(Clone, Debug)]
pub enum EgoSpec {
    Idm,
    Naive,
    Learned(Learned),
    /// A command started for each episode ([`External`]).
    External(String),
}

impl EgoSpec {
    pub fn parse(spec: &str) -> Result<EgoSpec, PolicyError> {
        match spec.split_once(':') {
            None if spec == "idm" => Ok(EgoSpec::Idm),
            None if spec == "naive" => Ok(EgoSpec::Naive),
            None if let Some(model) = pretrained::find(spec) => Ok(EgoSpec::Learned(model.load()?)),
            None if spec == "learned" => Err(PolicyError::MissingPath),
            Some(("learned", "")) => Err(PolicyError::MissingPath),
            Some(("learned", path)) => Ok(EgoSpec::Learned(Learned::load(path)?)),
            Some(("external", command)) if !command.trim().is_empty() => Ok(EgoSpec::External(command.to_string())),
            Some(("external", _)) => Err(PolicyError::MissingCommand),
            _ => Err(PolicyError::UnknownPolicy { spec: spec.to_string() }),
        }
    }

    /// A fresh policy for one episode.
    pub fn make(&self) -> Box<dyn EgoPolicy> {
        match self {
            EgoSpec::Idm => Box::new(Idm::default()),
            EgoSpec::Naive => Box::new(Naive::default()),
            EgoSpec::Learned(actor) => Box::new(actor.clone()),
            EgoSpec::External(command) => Box::new(External::new(command, external::TIMEOUT)),
        }
    }
}

/// The egos named without a path or command, with what each is (for help and shell
/// completion); besides them, `learned:PATH` and `external:CMD` ([`EgoSpec::parse`]).
pub fn named_egos() -> Vec<(&'static str, &'static str)> {
    let mut named = vec![
        ("idm", "the Intelligent Driver Model, braking for what is ahead"),
        ("naive", "keeps its lane and speed, blind"),
    ];
    named.extend(pretrained::ALL.iter().map(|m| (m.name, "a shipped driving model")));
    named
}

/// The ego specs of a comma-separated list (`idm,naive,learned:a.safetensors`); an
/// `external:CMD` takes the rest of the list, commas and all, as its command.
pub fn split_specs(list: &str) -> Vec<String> {
    let mut specs = Vec::new();
    let mut rest = list;
    while !rest.is_empty() {
        if rest.starts_with("external:") {
            specs.push(rest.to_string());
            break;
        }
        let (spec, tail) = rest.split_once(',').unwrap_or((rest, ""));
        specs.push(spec.to_string());
        rest = tail;
    }
    specs
}

/// A policy by its command-line name: `idm`, `naive`, `learned:PATH` or `external:CMD`.
pub fn parse_policy(spec: &str) -> Result<Box<dyn EgoPolicy>, PolicyError> {
    EgoSpec::parse(spec).map(|ego| ego.make())
}

#[cfg(test)]
mod tests;
