//! One episode: the ego driven by a policy through a scene, every other actor run by its
//! script, scored each step as SafeBench records it.
//!
//! Each step: scripts advance (conditions read the previous step's state, then actions apply
//! in program order, as esmini does, so the order never depends on iteration); the ego's
//! policy sees the previous state and acts; every actor moves (vehicles on the kinematic
//! bicycle with pure pursuit and IDM, walkers along their track); rapier reports the ego's new
//! contacts; the criteria read the new state; the record is stored; the stop rules run.

use crate::detect::{Detectors, EgoState, Reading};
use crate::models::{self, Kinematics, WHEELBASE, pursue};
use crate::physics::{Physics, Shape};
use crate::scene::Scene;
use crate::world::Spot;
use tad_bytecode::{Instr, Light, Value};
use tad_metrics::{Mode, StepRecord, StopReason};
use tad_policy::{ACCEL_MAX, ACCEL_MIN, Action, EgoPolicy, EgoView, IdmParams, MAX_WHEEL_ANGLE, Preview};
use tad_road::geom::{Footprint, Path, Pose, Stretch, Strip, Vec2, wrap};
use tad_road::road::Station;
use tad_road::{Arm, Body, Turn};

use std::ops::Deref;

/// How an episode runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Scoring mode: with `Mode::Compat` (SafeBench's quirks) off-road never ends an episode.
    pub mode: Mode,
    /// Keep every actor's pose at every step (for traces and pictures).
    pub keep_frames: bool,
    /// Off-road this long (s) ends the episode (unless `compat`).
    pub off_road_limit: f64,
}

impl Default for Options {
    fn default() -> Options {
        Options { mode: Mode::Fixed, keep_frames: false, off_road_limit: 0.5 }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    Collision,
    RedLight,
    StopSign,
    LaneInvasion,
    OffRoad,
}

impl EventKind {
    /// Every kind, in the order above.
    pub const ALL: [EventKind; 5] =
        [EventKind::Collision, EventKind::RedLight, EventKind::StopSign, EventKind::LaneInvasion, EventKind::OffRoad];

    /// The kind named `name` ([`EventKind::as_str`]).
    pub fn parse(name: &str) -> Option<EventKind> {
        EventKind::ALL.into_iter().find(|k| k.as_str() == name)
    }

    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::Collision => "collision",
            EventKind::RedLight => "red_light",
            EventKind::StopSign => "stop_sign",
            EventKind::LaneInvasion => "lane_invasion",
            EventKind::OffRoad => "off_road",
        }
    }
}

/// Something the criteria noticed.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    pub step: u32,
    pub kind: EventKind,
    pub position: Vec2,
    /// The actor the ego hit (index into the scene's actors).
    pub other: Option<usize>,
}

/// Every actor's pose at a step (the ego first; `None` before it exists) and the lights.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub poses: Vec<(f64, f64, f64)>,
    pub speeds: Vec<f64>,
    pub lights: Vec<(Arm, Light)>,
}

#[derive(Clone, Debug)]
pub struct Episode {
    pub seed: Option<u64>,
    pub params: Vec<f64>,
    pub steps: u32,
    pub stop_reason: StopReason,
    pub records: Vec<StepRecord>,
    pub events: Vec<Event>,
    /// Step 0 (the start) then one per step, when asked for.
    pub frames: Vec<Frame>,
    /// Why the ego's driver failed, when the episode stopped for it (`ego_failed`).
    pub failure: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Motion {
    Stand,
    Drive,
    Walk { keep_yaw: bool },
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Block {
    None,
    Until(f64),
    Near(f64),
    /// The ego's arc to the conflict point on its route, and the actor's travel time, s.
    Meet {
        at: f64,
        travel: f64,
    },
}

/// What a script may wait on: the ego at the step's start.
#[derive(Clone, Copy)]
struct EgoNow {
    position: Vec2,
    /// Its arc on its route, m, and its speed, m/s.
    s: f64,
    speed: f64,
}

struct Actor {
    body: Body,
    length: f64,
    width: f64,
    wheelbase: f64,
    kin: Kinematics,
    target: f64,
    motion: Motion,
    track: Option<Path>,
    /// Its track's [`models::bend`].
    bend: f64,
    s: f64,
    /// Arc of its stop line on its track and the arm whose light it obeys.
    stop_line: Option<(f64, Arm)>,
    stopped_at_sign: bool,
    stopping: bool,
    obey: bool,
    mobil: bool,
    next_mobil: f64,
    arm: Arm,
    lane: i64,
    along: f64,
    lateral: f64,
    turn: Turn,
    pc: usize,
    block: Block,
    /// The tracks of lanes beside its own, by lane and turn ([`beside_track`]).
    beside: Vec<(i64, Turn, Path)>,
    /// The strip of its track its leader search looks in, kept while the stretch stays
    /// ([`own_strip`]).
    strip: Option<(Stretch, Strip)>,
}

/// An actor as the others see it during a step: its state at the end of the previous one,
/// its heading as a unit vector (computed once per step), its size.
#[derive(Clone, Copy, Debug)]
struct Seen {
    position: Vec2,
    yaw: f64,
    heading: Vec2,
    speed: f64,
    length: f64,
    width: f64,
}

impl Seen {
    fn new(kin: &Kinematics, length: f64, width: f64) -> Seen {
        Seen { position: kin.position, yaw: kin.yaw, heading: Vec2::from_yaw(kin.yaw), speed: kin.speed, length, width }
    }

    /// Seen from behind: turned round.
    fn reversed(self) -> Seen {
        Seen { yaw: self.yaw + std::f64::consts::PI, heading: -self.heading, ..self }
    }
}

/// The actors nearest the ego (within [`tad_policy::NEAR_RANGE`] of its centre, nearest
/// first, the earlier on a tie) as it sees them: in its frame, relative to it.
fn around(ego: &Kinematics, others: &[Seen]) -> [Option<tad_policy::Near>; tad_policy::NEAR] {
    // the nearest few by insertion, without allocating (this runs every step)
    let mut near = [(f64::INFINITY, usize::MAX); tad_policy::NEAR];
    for (i, o) in others.iter().enumerate() {
        let d = o.position.distance(ego.position);
        if d <= tad_policy::NEAR_RANGE && d < near[tad_policy::NEAR - 1].0 {
            let at = near.iter().position(|&(e, _)| d < e).unwrap_or(tad_policy::NEAR - 1);
            near.copy_within(at..tad_policy::NEAR - 1, at + 1);
            near[at] = (d, i);
        }
    }
    let near = near.iter().take_while(|(_, i)| *i != usize::MAX);
    let frame = Pose { position: ego.position, yaw: ego.yaw };
    let forward = Vec2::from_yaw(ego.yaw);
    let mut out = [None; tad_policy::NEAR];
    for (slot, &(_, i)) in out.iter_mut().zip(near) {
        let o = &others[i];
        let local = frame.local(o.position);
        let relative = o.heading * o.speed - forward * ego.speed;
        *slot = Some(tad_policy::Near {
            position: [local.x, local.y],
            velocity: [relative.dot(forward), relative.dot(forward.left())],
            yaw: wrap(o.yaw - ego.yaw),
            size: [o.length, o.width],
        });
    }
    out
}

/// Run one episode of `scene` with parameters `params` (see [`crate::sample`]), `policy`
/// driving the ego: [`Sim`]'s steps, the policy asked at each.
pub fn run(scene: &Scene, seed: Option<u64>, params: Vec<f64>, policy: &mut dyn EgoPolicy, opts: &Options) -> Episode {
    policy.reset();
    let mut sim = Sim::start(scene, seed, params, *opts);
    while let Some(view) = sim.view() {
        let action = policy.act(view);
        sim.act(action);
        // a driver that failed (an external process) ends the episode after its step
        if let Some(why) = policy.failure() {
            sim.fail(why.to_string());
        }
    }
    sim.finish()
}

/// An episode stepped from outside, as Gymnasium's `reset`/`step` do: [`Sim::start`] begins
/// the first step and shows the ego's view; each [`Sim::act`] ends the step under way with
/// the ego's action and begins the next. [`run`] is this loop with a policy, so an episode
/// stepped here with the same actions has the same records.
///
/// `S` is how the scene is held: `&Scene` for a run, `Arc<Scene>` for an environment that
/// keeps its scenes.
pub struct Sim<S: Deref<Target = Scene>> {
    runner: Runner<S>,
    seed: Option<u64>,
    /// What the ego sees at the step under way; `None` once the episode has stopped.
    view: Option<EgoView>,
    stop_reason: Option<StopReason>,
    failure: Option<String>,
}

impl<S: Deref<Target = Scene>> Sim<S> {
    /// The episode of `scene` with parameters `params`, at its start.
    pub fn start(scene: S, seed: Option<u64>, params: Vec<f64>, opts: Options) -> Sim<S> {
        let runner = Runner::start(scene, params, opts);
        Sim { runner, seed, view: None, stop_reason: None, failure: None }
    }

    /// What the ego sees at the step under way (beginning it: the scripts run); `None`
    /// once the episode has stopped.
    pub fn view(&mut self) -> Option<&EgoView> {
        if self.view.is_none() && self.stop_reason.is_none() {
            if self.runner.step >= self.runner.scene.limits.max_steps {
                self.stop_reason = Some(StopReason::MaxSteps);
            } else {
                self.view = Some(self.runner.begin());
            }
        }
        self.view.as_ref()
    }

    /// End the step under way with the ego's `action`: everyone moves, the criteria read
    /// the new state, the step is recorded. Why the episode stopped, if it did (the step
    /// limit included); after the stop nothing moves.
    pub fn act(&mut self, action: Action) -> Option<StopReason> {
        if self.view().is_none() {
            return self.stop_reason;
        }
        self.view = None;
        self.stop_reason = self.runner.end(action);
        if self.stop_reason.is_none() && self.runner.step >= self.runner.scene.limits.max_steps {
            self.stop_reason = Some(StopReason::MaxSteps);
        }
        self.stop_reason
    }

    /// The ego's driver failed (`why`): the episode stops here, `ego_failed`.
    pub fn fail(&mut self, why: String) {
        self.view = None;
        self.stop_reason = Some(StopReason::EgoFailed);
        self.failure = Some(why);
    }

    /// Why the episode stopped; `None` while it runs.
    pub fn stop_reason(&self) -> Option<StopReason> {
        self.stop_reason
    }

    /// The steps recorded so far.
    pub fn records(&self) -> &[StepRecord] {
        &self.runner.records
    }

    /// What the criteria noticed so far.
    pub fn events(&self) -> &[Event] {
        &self.runner.events
    }

    pub fn scene(&self) -> &Scene {
        &self.runner.scene
    }

    /// The speed the scenario states for the ego, m/s.
    pub fn desired_speed(&self) -> f64 {
        self.runner.desired
    }

    /// The episode as [`run`] returns it.
    pub fn finish(self) -> Episode {
        let stop_reason = self.stop_reason.unwrap_or(StopReason::MaxSteps);
        let mut episode = self.runner.finish(self.seed, stop_reason);
        episode.failure = self.failure;
        episode
    }
}

/// An episode under way: what its steps share.
struct Runner<S: Deref<Target = Scene>> {
    scene: S,
    opts: Options,
    params: Vec<f64>,
    /// The ego's desired speed, m/s.
    desired: f64,
    /// The ego's route's [`models::bend`].
    route_bend: f64,
    ego: Kinematics,
    /// The ego's arc on its route, and its stop line's.
    ego_s: f64,
    ego_stop: Option<f64>,
    detectors: Detectors,
    actors: Vec<Actor>,
    /// The actors as they were at the end of the previous step.
    before: Vec<Seen>,
    physics: Physics,
    /// Everyone's pose for physics, and the ego's new contacts it reports.
    poses: Vec<(f64, f64, f64)>,
    hits: Vec<usize>,
    /// Contacts at the start, counted at step 1.
    pending_hits: Vec<usize>,
    preview: Preview,
    step: u32,
    /// The ego's distance driven, m; its velocity at the end of the last step.
    driven: f64,
    velocity: Vec2,
    collided: bool,
    /// How long the ego has been off the road, s.
    off_road_for: f64,
    records: Vec<StepRecord>,
    events: Vec<Event>,
    frames: Vec<Frame>,
}

impl<S: Deref<Target = Scene>> Runner<S> {
    /// The ego and every actor at their start, physics seeing them there.
    fn start(held: S, params: Vec<f64>, opts: Options) -> Runner<S> {
        let scene = &*held;
        let route = &scene.ego.route;
        let ego_size = scene.ego.size;
        let desired = scene.ego.speed.eval(&params).max(0.0);
        let start = scene.ego_pose();
        let ego = Kinematics { position: start.position, yaw: start.yaw, speed: desired };
        let (ego_s, _) = route.locate(start.position, scene.ego.start, 10.0);
        let ego_stop = scene
            .world
            .stop_line(Arm::Ego, scene.ego.lane)
            .map(|p| route.locate(p, ego_s, 400.0))
            .and_then(|(s, d)| (d.abs() < scene.world.road.lane_width).then_some(s));
        let detectors = Detectors::new(scene.ego.start, scene.ego.route_length, ego_stop);
        let actors: Vec<Actor> = scene.actors.iter().map(|a| spawn(scene, a, &params)).collect();
        let mut shapes = vec![Shape { length: ego_size.length, width: ego_size.width, height: ego_size.height }];
        shapes.extend(scene.actors.iter().map(|a| Shape {
            length: a.size.length,
            width: a.size.width,
            height: a.size.height,
        }));
        let physics = Physics::new(&shapes);
        let route_bend = models::bend(route);
        let max_steps = scene.limits.max_steps as usize;
        let mut runner = Runner {
            scene: held,
            opts,
            desired,
            route_bend,
            ego,
            ego_s,
            ego_stop,
            detectors,
            before: Vec::with_capacity(actors.len()),
            actors,
            physics,
            poses: Vec::with_capacity(shapes.len()),
            hits: Vec::new(),
            pending_hits: Vec::new(),
            preview: Preview::default(),
            step: 0,
            driven: 0.0,
            velocity: Vec2::from_yaw(ego.yaw) * ego.speed,
            collided: false,
            off_road_for: 0.0,
            records: Vec::with_capacity(max_steps),
            events: Vec::new(),
            frames: Vec::new(),
            params,
        };
        if opts.keep_frames {
            let frame = runner.frame(0.0);
            runner.frames.push(frame);
        }
        // physics sees the start, so a spawn already touching the ego counts at step 1
        runner.touch();
        runner.pending_hits = runner.hits.clone();
        runner
    }

    /// Begin a step, as the module's header lists its parts: the scripts advance; what the
    /// ego sees.
    fn begin(&mut self) -> EgoView {
        self.step += 1;
        let t = self.time();
        self.before.clear();
        self.before.extend(self.actors.iter().map(|a| Seen::new(&a.kin, a.length, a.width)));
        self.scripts(t);
        self.ego_view(t)
    }

    /// End the step with the ego's action: everyone moves, contacts and criteria, the
    /// record; the reason the episode stops after it, if it does.
    fn end(&mut self, action: Action) -> Option<StopReason> {
        let t = self.time();
        self.drive_ego(action);
        self.move_others(t);
        self.contacts();
        let reading = self.criteria(t);
        self.record(t, &reading);
        self.stop_rule(t, &reading)
    }

    /// The step under way's time, s.
    fn time(&self) -> f64 {
        f64::from(self.step) * self.scene.limits.dt
    }

    /// Scripts advance, on the previous state.
    fn scripts(&mut self, t: f64) {
        for (setup, actor) in self.scene.actors.iter().zip(self.actors.iter_mut()) {
            let ego = EgoNow { position: self.ego.position, s: self.ego_s, speed: self.ego.speed };
            run_script(&self.scene, &setup.script, actor, &self.params, t, ego);
        }
    }

    /// The ego moves by its driver's action (what it saw was the step's view: its arc on
    /// the route is the last criteria's).
    fn drive_ego(&mut self, action: Action) {
        let accel = if action.accel.is_finite() { action.accel.clamp(ACCEL_MIN, ACCEL_MAX) } else { 0.0 };
        let steer = if action.steer.is_finite() { action.steer.clamp(-1.0, 1.0) } else { 0.0 };
        let old = self.ego.position;
        let scene = &*self.scene;
        self.ego.bicycle(WHEELBASE * scene.ego.size.length, -steer * MAX_WHEEL_ANGLE, accel, scene.limits.dt);
        self.driven += old.distance(self.ego.position);
    }

    /// Everyone else moves.
    fn move_others(&mut self, t: f64) {
        let scene = &*self.scene;
        let ego_seen = Seen::new(&self.ego, scene.ego.size.length, scene.ego.size.width);
        for k in 0..self.actors.len() {
            move_actor(scene, &mut self.actors, k, &self.before, ego_seen, t, scene.limits.dt);
        }
    }

    /// Physics sees everyone where they are now; its new contacts of the ego go in `hits`.
    fn touch(&mut self) {
        self.poses.clear();
        self.poses.push((self.ego.position.x, self.ego.position.y, self.ego.yaw));
        self.poses.extend(self.actors.iter().map(|a| (a.kin.position.x, a.kin.position.y, a.kin.yaw)));
        self.physics.step(&self.poses, &mut self.hits);
    }

    /// The ego's contacts: its first collision is an event.
    fn contacts(&mut self) {
        self.touch();
        self.hits.append(&mut self.pending_hits);
        if let Some(&other) = self.hits.first().filter(|_| !self.collided) {
            self.collided = true;
            self.events.push(Event {
                step: self.step,
                kind: EventKind::Collision,
                position: self.ego.position,
                other: Some(other - 1),
            });
        }
    }

    /// The criteria read the new state; what they notice is an event.
    fn criteria(&mut self, t: f64) -> Reading {
        let scene = &*self.scene;
        let route = &scene.ego.route;
        let (s_now, off_route) = route.locate(self.ego.position, self.ego_s, 10.0);
        self.ego_s = s_now;
        let footprint = Footprint { pose: self.ego.pose(), length: scene.ego.size.length, width: scene.ego.size.width };
        let ego = EgoState { footprint, s: self.ego_s, off_route, speed: self.ego.speed };
        let reading = self.detectors.read(&scene.world, route, &ego, t);
        for (happened, kind) in [
            (reading.lane_invasion, EventKind::LaneInvasion),
            (reading.red_light, EventKind::RedLight),
            (reading.stop_sign, EventKind::StopSign),
            (reading.off_road && self.off_road_for == 0.0, EventKind::OffRoad),
        ] {
            if happened {
                self.events.push(Event { step: self.step, kind, position: self.ego.position, other: None });
            }
        }
        self.off_road_for = if reading.off_road { self.off_road_for + self.scene.limits.dt } else { 0.0 };
        reading
    }

    /// The step's record is stored (and its frame, when asked for).
    fn record(&mut self, t: f64, reading: &Reading) {
        let ego = &self.ego;
        let new_velocity = Vec2::from_yaw(ego.yaw) * ego.speed;
        let acceleration = (new_velocity - self.velocity) * (1.0 / self.scene.limits.dt);
        self.velocity = new_velocity;
        self.records.push(StepRecord {
            time: t,
            velocity: ego.speed,
            acceleration: [acceleration.x, acceleration.y, 0.0],
            position: [ego.position.x, ego.position.y, 0.0],
            // CARLA's yaw turns clockwise, in degrees within [-180, 180]
            yaw_deg: (-ego.yaw).to_degrees().clamp(-180.0, 180.0),
            driven_distance: self.driven,
            lane_invasion: self.detectors.lane_invasions,
            off_road: reading.off_road,
            collision: self.collided,
            run_red_light: self.detectors.red_lights,
            run_stop: self.detectors.stop_signs,
            distance_to_route: reading.distance_to_route,
            route_complete: reading.route_complete,
        });
        if self.opts.keep_frames {
            let frame = self.frame(t);
            self.frames.push(frame);
        }
    }

    /// The stop rules: why the episode ends after this step, if it does.
    fn stop_rule(&self, t: f64, reading: &Reading) -> Option<StopReason> {
        let (opts, limits) = (&self.opts, &self.scene.limits);
        if self.collided {
            Some(StopReason::Collision)
        } else if reading.route_complete >= 100.0 {
            Some(StopReason::RouteComplete)
        } else if opts.mode.off_road_terminates() && self.off_road_for >= opts.off_road_limit - 1e-9 {
            Some(StopReason::OffRoad)
        } else if self.driven >= limits.max_distance {
            Some(StopReason::MaxDistance)
        } else if t >= limits.timeout - 1e-9 {
            Some(StopReason::Timeout)
        } else {
            None
        }
    }

    /// Every actor's pose and speed (the ego first) and the lights, at time `t`.
    fn frame(&self, t: f64) -> Frame {
        let ego = &self.ego;
        Frame {
            poses: std::iter::once((ego.position.x, ego.position.y, ego.yaw))
                .chain(self.actors.iter().map(|a| (a.kin.position.x, a.kin.position.y, a.kin.yaw)))
                .collect(),
            speeds: std::iter::once(ego.speed).chain(self.actors.iter().map(|a| a.kin.speed)).collect(),
            lights: self.scene.world.lights(t),
        }
    }

    /// What the ego's driver sees: SafeBench's observation and the full state.
    fn ego_view(&mut self, t: f64) -> EgoView {
        let scene = &*self.scene;
        let (ego, s, actors, before) = (&self.ego, self.ego_s, &self.actors, &self.before);
        let route = &scene.ego.route;
        let size = scene.ego.size;
        let heading = Vec2::from_yaw(ego.yaw);
        let i = self.preview.step(&scene.preview, [ego.position.x, ego.position.y]).unwrap_or(0);
        let point = scene.preview.get(i).copied().unwrap_or([ego.position.x, ego.position.y]);
        let [lateral_dis, minus_delta_yaw, _] = tad_policy::observation(
            [ego.position.x, ego.position.y],
            ego.yaw,
            point,
            scene.preview_yaw.get(i).copied().unwrap_or(ego.yaw),
            ego.speed,
        );
        let ego_lane = scene.world.spot(ego.position);
        let front = before.iter().zip(actors).any(|(o, a)| {
            let p = o.position;
            a.body == Body::Vehicle
                && p.distance(ego.position) <= 15.0
                && (p - ego.position).dot(heading) > 0.0
                && o.heading.dot(heading) > 0.0
                && matches!(ego_lane, Spot::Lane(..))
                && scene.world.spot(p) == ego_lane
        });
        let lookahead = models::lookahead(ego.speed);
        let target = Pose { position: ego.position, yaw: ego.yaw }.local(route.pose(s + lookahead).position);
        let corridor = Corridor::new(route, s, size.length, size.width, false);
        let leader = ahead_on(corridor, Seen::new(ego, size.length, size.width), true, before.iter().copied());
        let stop = self.ego_stop.and_then(|line| {
            let gap = line - (s + size.length / 2.0);
            (gap > -0.5 && must_stop(scene, Arm::Ego, gap, ego.speed, t, self.detectors.stopped_at_sign()))
                .then_some(gap.max(0.0))
        });
        EgoView {
            obs: [lateral_dis, minus_delta_yaw, ego.speed, if front { 1.0 } else { 0.0 }],
            speed: ego.speed,
            desired_speed: self.desired,
            target: [target.x, target.y],
            lookahead,
            wheelbase: WHEELBASE * size.length,
            leader,
            stop,
            curve_speed: models::curve_speed_knowing(route, self.route_bend, s, ego.speed),
            dt: scene.limits.dt,
            around: around(ego, before),
        }
    }

    /// The episode as run.
    fn finish(self, seed: Option<u64>, stop_reason: StopReason) -> Episode {
        Episode {
            seed,
            params: self.params,
            steps: self.step,
            stop_reason,
            records: self.records,
            events: self.events,
            frames: self.frames,
            failure: None,
        }
    }
}

fn spawn(scene: &Scene, a: &crate::scene::ActorSetup, params: &[f64]) -> Actor {
    let along = a.along.eval(params);
    let mut pose = scene.world.pose_at(a.arm, along, a.lane, a.lateral);
    pose.yaw = a.yaw;
    Actor {
        body: a.body,
        length: a.size.length,
        width: a.size.width,
        wheelbase: WHEELBASE * a.size.length,
        kin: Kinematics { position: pose.position, yaw: pose.yaw, speed: a.speed.max(0.0) },
        target: a.speed.max(0.0),
        motion: Motion::Stand,
        track: None,
        bend: 0.0,
        s: 0.0,
        stop_line: None,
        stopped_at_sign: false,
        stopping: false,
        obey: true,
        mobil: false,
        next_mobil: 1.0,
        arm: a.arm,
        lane: a.lane,
        along,
        lateral: a.lateral,
        turn: Turn::Straight,
        pc: 0,
        block: Block::None,
        beside: Vec::new(),
        strip: None,
    }
}

/// A vehicle's lane path from its spawn station, kept as far off the lane's centre as it
/// stands.
fn lane_track(scene: &Scene, a: &Actor, lane: i64) -> Path {
    let road = &scene.world.road;
    let (path, _) = road.vehicle_path(Station { arm: a.arm, along: a.along }, lane, a.turn);
    let offset = a.lateral - road.lateral(a.lane);
    if offset.abs() > 1e-6 && lane == a.lane { path.offset(if lane < 0 { -offset } else { offset }) } else { path }
}

/// The index in `a.beside` of the track of `lane`, another than its own: built once, as
/// [`lane_track`] of another lane depends only on the spawn station and the turn, and MOBIL
/// weighs the lanes beside every second.
fn beside_track(scene: &Scene, a: &mut Actor, lane: i64) -> usize {
    if let Some(i) = a.beside.iter().position(|&(l, turn, _)| l == lane && turn == a.turn) {
        return i;
    }
    let track = lane_track(scene, a, lane);
    a.beside.push((lane, a.turn, track));
    a.beside.len() - 1
}

fn set_track(scene: &Scene, a: &mut Actor, track: Path) {
    let (s, _) = track.project(a.kin.position);
    a.s = s;
    a.stop_line = if a.lane > 0 {
        scene.world.stop_line(a.arm, a.lane).and_then(|p| {
            let (s, d) = track.project(p);
            (d.abs() < scene.world.road.lane_width / 2.0 && s > a.s - a.length).then_some((s, a.arm))
        })
    } else {
        None
    };
    a.bend = models::bend(&track);
    a.track = Some(track);
    a.strip = None;
}

/// Advance an actor's script until it blocks or ends.
fn run_script(scene: &Scene, script: &[Instr], a: &mut Actor, params: &[f64], t: f64, ego: EgoNow) {
    let v = |value: &Value| value.eval(params);
    while let Some(instr) = script.get(a.pc) {
        match (instr, a.block) {
            (Instr::Wait { seconds, .. }, Block::None) => {
                a.block = Block::Until(t + v(seconds).max(0.0));
                continue;
            }
            (Instr::WaitNear { distance, .. }, Block::None) => {
                a.block = Block::Near(v(distance).max(0.0));
                continue;
            }
            (Instr::Meet { point, travel, .. }, Block::None) => {
                let (at, _) = scene.ego.route.project(Vec2::new(point[0], point[1]));
                a.block = Block::Meet { at, travel: v(travel).max(0.0) };
                continue;
            }
            (Instr::Wait { .. }, Block::Until(until)) if t + 1e-9 < until => return,
            (Instr::WaitNear { .. }, Block::Near(d)) if ego.position.distance(a.kin.position) > d => return,
            (Instr::Meet { .. }, Block::Meet { at, travel })
                if tad_road::time_to(at - ego.s, ego.speed) > travel + 1e-9 =>
            {
                return;
            }
            (Instr::Wait { .. } | Instr::WaitNear { .. } | Instr::Meet { .. }, _) => {}
            (Instr::Drive { speed, turn, .. }, _) => {
                a.turn = *turn;
                a.target = v(speed).max(0.0);
                a.motion = Motion::Drive;
                a.stopping = false;
                let track = lane_track(scene, a, a.lane);
                set_track(scene, a, track);
            }
            (Instr::Follow { path, speed, .. }, _) => {
                a.target = v(speed).max(0.0);
                a.stopping = false;
                a.motion = if a.body == Body::Vehicle { Motion::Drive } else { Motion::Walk { keep_yaw: false } };
                let track = scene.paths.get(usize::from(*path)).cloned().unwrap_or_default();
                set_track(scene, a, track);
            }
            (Instr::Cross { speed, .. }, _) => {
                a.target = v(speed).max(0.0);
                a.motion = Motion::Walk { keep_yaw: true };
                let road = &scene.world.road;
                let width = f64::from(road.lanes + road.opposite.max(road.cross_lanes)) * road.lane_width + 12.0;
                let heading = Vec2::from_yaw(a.kin.yaw);
                a.track = Some(Path::new([a.kin.position, a.kin.position + heading * width]));
                a.s = 0.0;
            }
            (Instr::ChangeLane { lanes, .. }, _) => change_lane(scene, a, *lanes),
            (Instr::Speed { speed, .. }, _) => {
                a.target = v(speed).max(0.0);
                a.stopping = false;
            }
            (Instr::Stop { .. }, _) => a.stopping = true,
            (Instr::Signals { obey, .. }, _) => a.obey = *obey,
            (Instr::Mobil { on, .. }, _) => a.mobil = *on,
            _ => {}
        }
        a.block = Block::None;
        a.pc += 1;
    }
}

/// Move a vehicle `lanes` lanes to its right (negative: left) when the arm has them.
fn change_lane(scene: &Scene, a: &mut Actor, lanes: i64) {
    let Some(lane) = neighbour(scene, a, lanes) else { return };
    let slot = beside_track(scene, a, lane);
    let track = a.beside[slot].2.clone();
    a.lane = lane;
    a.lateral = scene.world.road.lateral(lane);
    set_track(scene, a, track);
}

/// The lane `lanes` to an actor's right, if its arm has it (same direction).
fn neighbour(scene: &Scene, a: &Actor, lanes: i64) -> Option<i64> {
    let (incoming, outgoing) = scene.world.road.arm_lanes(a.arm);
    let lane = if a.lane > 0 { a.lane + lanes } else { a.lane - lanes };
    let ok =
        if a.lane > 0 { (1..=i64::from(incoming)).contains(&lane) } else { (1..=i64::from(outgoing)).contains(&-lane) };
    (ok && lane != a.lane).then_some(lane)
}

fn move_actor(scene: &Scene, actors: &mut [Actor], k: usize, before: &[Seen], ego: Seen, t: f64, dt: f64) {
    match actors[k].motion {
        Motion::Stand => {
            let a = &mut actors[k];
            a.kin.speed = 0.0;
        }
        Motion::Walk { keep_yaw } => {
            let a = &mut actors[k];
            let Some(track) = &a.track else { return };
            let speed = if a.stopping || a.s >= track.length() { 0.0 } else { a.target };
            a.s = (a.s + speed * dt).min(track.length());
            let pose = track.pose(a.s);
            a.kin = Kinematics { position: pose.position, yaw: if keep_yaw { a.kin.yaw } else { pose.yaw }, speed };
        }
        Motion::Drive => {
            let strip = own_strip(&mut actors[k]);
            let mut leader = leader_of(scene, actors, k, strip, before, ego, t);
            if actors[k].mobil && t >= actors[k].next_mobil {
                actors[k].next_mobil = t + 1.0;
                // a new lane has another leader
                if mobil(scene, actors, k, before, ego, leader) {
                    let strip = own_strip(&mut actors[k]);
                    leader = leader_of(scene, actors, k, strip, before, ego, t);
                }
            }
            let a = &mut actors[k];
            let Some(track) = &a.track else { return };
            let (s, _) = track.locate(a.kin.position, a.s, 8.0);
            a.s = s;
            let wheel = pursue(track, s, a.kin.pose(), a.kin.speed, a.wheelbase);
            let accel = if a.stopping {
                -(a.kin.speed / dt).min(4.0)
            } else {
                IdmParams::default().accel(
                    a.kin.speed,
                    a.target.min(models::curve_speed_knowing(track, a.bend, s, a.kin.speed)),
                    leader,
                )
            };
            a.kin.bicycle(a.wheelbase, wheel, accel, dt);
            // a stop sign is passed once it has stood at it
            if let Some((line, _)) = a.stop_line
                && a.kin.speed < 0.1
                && line - (a.s + a.length / 2.0) < IDM_STOP_REACH
            {
                a.stopped_at_sign = true;
            }
        }
    }
}

/// How near its stop line a vehicle standing still counts as having stopped at it, m.
const IDM_STOP_REACH: f64 = 6.0;
/// How far ahead vehicles look for a leader, m.
const LOOK: f64 = 60.0;

/// The strip of its track an actor's leader search looks in now: kept from an earlier step
/// while the stretch stays, as a vehicle takes many steps to leave a chunk.
fn own_strip(a: &mut Actor) -> Strip {
    let Some(track) = &a.track else { return Strip::UNKNOWN };
    let stretch = Corridor::stretch_of(track, a.s, false);
    match a.strip {
        Some((kept, strip)) if kept == stretch => strip,
        _ => {
            let strip = track.strip(stretch);
            a.strip = Some((stretch, strip));
            strip
        }
    }
}

/// The nearest thing ahead of actor `k` on its track (whose [`own_strip`] is `strip`):
/// (bumper gap, its speed along), the ego included unless `k` runs lights (an adversary),
/// and its stop line when it must stop.
fn leader_of(
    scene: &Scene,
    actors: &[Actor],
    k: usize,
    strip: Strip,
    before: &[Seen],
    ego: Seen,
    t: f64,
) -> Option<(f64, f64)> {
    let me = &actors[k];
    let track = me.track.as_ref()?;
    // it has not moved yet this step: it is as the step began
    debug_assert_eq!((before[k].position, before[k].yaw), (me.kin.position, me.kin.yaw));
    let others = before.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, &o)| o);
    let ego_entry = me.obey.then_some(ego);
    let corridor = Corridor { track, s: me.s, length: me.length, width: me.width, back: false, strip };
    let mut best = ahead_on(corridor, before[k], me.obey, others.chain(ego_entry));
    if me.obey
        && let Some((line, arm)) = me.stop_line
    {
        let gap = line - (me.s + me.length / 2.0);
        if gap > -0.5
            && must_stop(scene, arm, gap, me.kin.speed, t, me.stopped_at_sign)
            && best.is_none_or(|(g, _)| gap < g)
        {
            best = Some((gap.max(0.0), 0.0));
        }
    }
    best
}

/// Whether a vehicle `gap` metres before its stop line must stop there: its light is red,
/// or yellow and it can still stop comfortably, or a stop sign it has not stood at.
fn must_stop(scene: &Scene, arm: Arm, gap: f64, speed: f64, t: f64, stopped_at_sign: bool) -> bool {
    match scene.world.light(arm, t) {
        Light::Red => true,
        Light::Yellow => gap > speed * speed / (2.0 * IdmParams::default().comfort_decel),
        Light::Green => false,
        Light::Off => scene.world.stop_signs() && !stopped_at_sign,
    }
}

/// The strip a vehicle sweeps ahead along its track: from its arc `s` on `track`, as wide as
/// the vehicle, its front bumper `length / 2` ahead of `s`; or, `back`, the strip behind it
/// down its track, from its rear bumper. `strip` is the track's [`Strip`] of the stretch
/// its search may look in ([`Corridor::stretch_of`]).
#[derive(Clone, Copy)]
struct Corridor<'a> {
    track: &'a Path,
    s: f64,
    length: f64,
    width: f64,
    back: bool,
    strip: Strip,
}

impl<'a> Corridor<'a> {
    /// The corridor on `track` from `s`, its strip taken now.
    fn new(track: &'a Path, s: f64, length: f64, width: f64, back: bool) -> Corridor<'a> {
        let strip = track.strip(Corridor::stretch_of(track, s, back));
        Corridor { track, s, length, width, back, strip }
    }

    /// The stretch of `track` a search from `s` may look in: [`in_corridor`]'s window
    /// about anything up to [`LOOK`] ahead (or, `back`, behind).
    fn stretch_of(track: &Path, s: f64, back: bool) -> Stretch {
        if back { track.stretch(s - LOOK - WINDOW, s + WINDOW) } else { track.stretch(s - WINDOW, s + LOOK + WINDOW) }
    }

    /// The arc `ahead` metres on from `s`, the corridor's way.
    fn on(&self, ahead: f64) -> f64 {
        if self.back { self.s - ahead } else { self.s + ahead }
    }
}

/// The nearest of `others` ahead in a vehicle's `corridor`, the vehicle as `me` sees it:
/// `(gap, speed along)`. A corridor `back` looks behind: the vehicle and the others are
/// turned round, so that the follower is the leader of the turned-round vehicle, and its
/// speed along is its speed towards the vehicle. Something going its way (or against it)
/// counts where it is; something moving across counts only if,
/// going on straight at its speed, it will be in the corridor when this vehicle (at its
/// speed, at least 1 m/s) gets there, within [`CROSS_HORIZON`] s, and then as standing where
/// they meet: crossing traffic that will have gone is no obstacle, and one about to cross is
/// one before it arrives. One that does not `yield` (an adversary) only stops for crossing
/// traffic already in front of it.
fn ahead_on(corridor: Corridor, me: Seen, yields: bool, others: impl Iterator<Item = Seen>) -> Option<(f64, f64)> {
    let turn = |o: Seen| if corridor.back { o.reversed() } else { o };
    let Seen { position, heading, speed, .. } = turn(me);
    let others = others.map(turn);
    NEAR.with_borrow_mut(|(ahead, crossing)| {
        ahead.clear();
        crossing.clear();
        for (i, o) in others.enumerate() {
            let d = o.position - position;
            if beyond(d, LOOK) {
                continue;
            }
            if o.speed > 0.3 && o.heading.dot(heading).abs() < 0.7 {
                crossing.push((i, o));
            } else if d.dot(heading) > 0.0 && !off_strip(&corridor, &o) {
                ahead.push((d.dot(d), i, o));
            }
        }
        // the nearest first, so that most of the rest fall to the bound below; the best
        // is the least (gap, index), the one taking them in order would keep
        ahead.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // how far the vehicle stands from its own track at `s`
        let off_track = corridor.track.pose(corridor.s).position.distance(position);
        let mut best: Option<(f64, f64, usize)> = None;
        let keep = |best: &mut Option<(f64, f64, usize)>, gap: f64, along: f64, i: usize| {
            if best.is_none_or(|(g, _, j)| gap < g || (gap == g && i < j)) {
                *best = Some((gap, along, i));
            }
        };
        for &(squared, i, seen) in ahead.iter() {
            let Seen { position: p, yaw: other_yaw, heading: facing, speed: v, length: l, width: w } = seen;
            // A bound on what it could keep: the arc to it is at least the chord between
            // the two points on the track, which is at least the distance less both
            // offsets from the track (its offset is within `in_corridor`'s reach); an
            // oncoming one is kept scaled by at least `speed / (speed + v)`.
            if let Some((g, _, _)) = best {
                let reach = corridor.width / 2.0 + l / 2.0 + w / 2.0 + 0.3;
                let bound = squared.sqrt() - reach - off_track - corridor.length / 2.0 - (l / 2.0 + w / 2.0);
                let scale = speed.max(1.0) / (speed.max(1.0) + v.max(0.0));
                if bound > 0.0 && bound * scale > g + BOUND_MARGIN {
                    continue;
                }
            }
            let other = Footprint { pose: Pose { position: p, yaw: other_yaw }, length: l, width: w };
            if let Some((gap, rel)) = in_corridor(&corridor, &other, facing, (p - position).dot(heading)) {
                let along = v * rel.cos();
                if along >= 0.0 {
                    keep(&mut best, gap, along, i);
                } else {
                    // oncoming: a standing obstacle where the two would meet
                    keep(&mut best, gap * speed.max(1.0) / (speed.max(1.0) - along), 0.0, i);
                }
            }
        }
        for &(i, seen) in crossing.iter() {
            let Seen { position: p, yaw: other_yaw, heading: other_heading, speed: v, length: l, width: w } = seen;
            let velocity = other_heading * v;
            let samples = if yields { CROSS_SAMPLES } else { 0 };
            for k in 0..=samples {
                let tau = CROSS_HORIZON * k as f64 / CROSS_SAMPLES as f64;
                let q = p + velocity * tau;
                let ahead = (q - position).dot(heading);
                if ahead <= 0.0 {
                    continue;
                }
                let other = Footprint { pose: Pose { position: q, yaw: other_yaw }, length: l, width: w };
                if let Some((gap, _)) = in_corridor(&corridor, &other, other_heading, ahead) {
                    let arrive = gap.max(0.0) / speed.max(1.0);
                    if (arrive - tau).abs() <= CROSS_MARGIN || (k == 0 && gap < 3.0) {
                        keep(&mut best, gap, 0.0, i);
                        break;
                    }
                }
            }
        }
        best.map(|(gap, along, _)| (gap, along))
    })
}

/// Whether `seen` is surely out of `corridor` wherever [`in_corridor`] may look: farther
/// from the strip its track keeps near than the box could reach into it. Decided before
/// the candidates are sorted, as it does not depend on the best so far.
fn off_strip(corridor: &Corridor, seen: &Seen) -> bool {
    let Seen { position, yaw, heading: facing, length, width, .. } = *seen;
    let strip = &corridor.strip;
    let other = Footprint { pose: Pose { position, yaw }, length, width };
    strip.distance_from(position) > reach(corridor.width, &other, facing, strip.along, strip.turn)
}

/// [`ahead_on`]'s lists, kept between calls: what is ahead (squared distance, index,
/// what it is) and what moves across (index, what it is).
type Near = (Vec<(f64, usize, Seen)>, Vec<(usize, Seen)>);
thread_local! {
    static NEAR: std::cell::RefCell<Near> = const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

/// What the bound must exceed the best gap by before a candidate is passed over, m: the
/// rounding of the bound's sums, many times over.
const BOUND_MARGIN: f64 = 1e-6;

/// Whether `d` is longer than `limit`, its exact length taken only when the bounds
/// `max(|x|, |y|) ≤ length ≤ |x| + |y|` do not tell.
fn beyond(d: Vec2, limit: f64) -> bool {
    let (x, y) = (d.x.abs(), d.y.abs());
    if x > limit || y > limit {
        return true;
    }
    x + y > limit && d.length() > limit
}

/// How far ahead crossing traffic is predicted, s, in how many steps, and how near in time
/// its passage and this vehicle's arrival must be to count.
const CROSS_HORIZON: f64 = 4.0;
const CROSS_SAMPLES: usize = 8;
const CROSS_MARGIN: f64 = 1.5;

/// How far either side of its expected arc a box is looked for on a track, m.
const WINDOW: f64 = 8.0;

/// At most how far off a track the box `other` (heading `facing`) may be and still reach
/// into a corridor `width` wide, where the track heads within `turn` rad of `heading`:
/// [`in_corridor`]'s test, known before the box's nearest point on the track is. Its
/// half-extent across the track, `|sin| l/2 + |cos| w/2` of the angle between their
/// headings, changes by at most `l/2 + w/2` per radian.
fn reach(width: f64, other: &Footprint, facing: Vec2, heading: Vec2, turn: f64) -> f64 {
    let (l, w) = (other.length, other.width);
    let across = heading.cross(facing).abs() * l / 2.0 + heading.dot(facing).abs() * w / 2.0;
    width / 2.0 + across + (l / 2.0 + w / 2.0) * turn + 0.3 + 1e-6
}

/// Whether the box `other` (heading `facing`, its yaw's unit vector), `ahead` metres in
/// front of the vehicle along its heading, reaches into its `corridor`: the bumper gap and
/// the box's heading relative to the corridor's way there.
fn in_corridor(corridor: &Corridor, other: &Footprint, facing: Vec2, ahead: f64) -> Option<(f64, f64)> {
    let Corridor { track, s, length, width, back, .. } = *corridor;
    let Footprint { pose: Pose { position: p, yaw }, length: l, width: w } = *other;
    let window = track.window(corridor.on(ahead), WINDOW);
    // anything farther is out, so the search need not find where
    let reach = reach(width, other, facing, window.heading, track.turn_within(&window));
    let (sj, lat) = track.nearest_in(&window, p, reach)?;
    let (past, way) = if back { (s - sj, std::f64::consts::PI) } else { (sj - s, 0.0) };
    if past <= 0.0 || lat.abs() > reach {
        return None;
    }
    let rel = wrap(yaw - track.pose(sj).yaw - way);
    let (c, sn) = (rel.cos().abs(), rel.sin().abs());
    if lat.abs() > width / 2.0 + sn * l / 2.0 + c * w / 2.0 + 0.3 {
        return None;
    }
    Some((past - length / 2.0 - (c * l / 2.0 + sn * w / 2.0), rel))
}

/// MOBIL (Kesting, Treiber and Helbing 2007) with politeness 0: change to a neighbouring lane
/// when it gains more than 0.2 m/s² and its new follower need not brake harder than 4 m/s².
/// `leader` is the vehicle's leader in its lane ([`leader_of`]); whether it changed lanes.
fn mobil(
    scene: &Scene,
    actors: &mut [Actor],
    k: usize,
    before: &[Seen],
    ego: Seen,
    leader: Option<(f64, f64)>,
) -> bool {
    const GAIN: f64 = 0.2;
    const SAFE: f64 = 4.0;
    // with the road ahead free, no lane gains: a leader only ever lowers IDM's acceleration
    if leader.is_none() {
        return false;
    }
    let now = {
        let me = &actors[k];
        IdmParams::default().accel(me.kin.speed, me.target, leader)
    };
    let mut choice: Option<(i64, f64)> = None;
    for dir in [-1, 1] {
        let Some(lane) = neighbour(scene, &actors[k], dir) else { continue };
        let slot = beside_track(scene, &mut actors[k], lane);
        let me = &actors[k];
        let track = &me.beside[slot].2;
        // the lanes are sampled alike: its arc on its own is near its arc on this one
        let (s, _) = track.project_from(me.kin.position, me.s);
        let entries =
            || before.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, &o)| o).chain(std::iter::once(ego));
        let corridor = Corridor::new(track, s, me.length, me.width, false);
        let then =
            IdmParams::default().accel(me.kin.speed, me.target, ahead_on(corridor, before[k], me.obey, entries()));
        let gain = then - now;
        // (the follower is looked for only where the lane gains; NaN gains nothing)
        if !(gain > GAIN && choice.is_none_or(|(_, g)| gain > g)) {
            continue;
        }
        // the new follower: the nearest behind in the target lane, with this vehicle ahead of it
        let corridor = Corridor::new(track, s, me.length, me.width, true);
        let behind = ahead_on(corridor, before[k], me.obey, entries());
        let safe = behind.is_none_or(|(gap, speed_back)| {
            IdmParams::default().accel(speed_back, speed_back.max(me.target), Some((gap, me.kin.speed))) >= -SAFE
                && gap > 1.0
        });
        if safe {
            choice = Some((dir, gain));
        }
    }
    let Some((dir, _)) = choice else { return false };
    change_lane(scene, &mut actors[k], dir);
    true
}
