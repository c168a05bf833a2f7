//! The layout: where everything of a scenario is, target-neutral, for every backend (the
//! Scenic printer, the runtime). Specified in `spec/layout.md`.
//!
//! ```text
//! ir::Scenario ──facts──▶ bodies, counts, motions, speeds (+ the values chosen)
//!              ──road───▶ Road: shape, lanes, arms, stop lines, crosswalks, the ego's approach
//!              ──place──▶ every actor on an arm, a lane and a station, facing along or across
//!              ──paths──▶ the path each one drives or walks (through the junction, a lane change)
//!              ──timing─▶ each adversary started so it meets the ego at their conflict point
//! ```
//!
//! Modules: `facts`, `place` (the steps above), `predict` (a kinematic roll-out of the
//! layout: constant speeds, IDM following), and `fidelity` (what a simulated run must show:
//! relations at the start, no overlap, adversaries reaching the ego; the same checks for the
//! roll-out and for a simulator's trace). The road it decides is `tad-road`'s contract,
//! re-exported here: `geom` (points, paths, footprints), `road`, [`Body`], [`Place`],
//! [`Facing`].

pub mod facts;
pub mod fidelity;
pub mod idm;
mod place;
pub mod predict;

pub use facts::{Body, Chosen, Facts, MAX_GROUP};
pub use place::{MEET_MARGIN, lay_out, lay_out_within};
pub use road::{Arm, Road, Shape, Side, Station, Turn};
/// What a traffic light shows: the schema's closed set, the one light state of the workspace.
pub use tad_ir::{ClosedSet, Signal};
/// The road contract the layout decides (`tad-road`), under the paths it always had here.
pub use tad_road::{Facing, Place, geom, road};

use geom::{Footprint, Path, Pose};
use tad_ir::{GroupId, Motion, Span};

/// When an actor starts doing its behavior.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Start {
    /// Seconds it waits first (a written `delay`).
    pub delay: f64,
    /// It waits until the ego is within this distance, m (a written `trigger`).
    pub trigger: Option<f64>,
    /// It waits until the ego is as near its conflict point as it is itself (the layout's
    /// timing of an adversary that would arrive early).
    pub meet: Option<Meet>,
}

/// An adversary's start, measured while the scenario runs: it waits until the ego's time to
/// `point`, at the ego's speed along its route, falls to `travel`, its own time to the
/// point at its speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Meet {
    pub point: geom::Vec2,
    /// s.
    pub travel: f64,
}

/// One actor: the ego or one member of a group.
#[derive(Clone, Debug, PartialEq)]
pub struct Agent {
    /// `None` for the ego.
    pub group: Option<GroupId>,
    /// Its place in its group, from 0.
    pub index: usize,
    pub body: Body,
    pub length: f64,
    pub width: f64,
    pub station: Station,
    /// TAD lane index on its arm.
    pub lane: i64,
    pub place: Place,
    /// Left of its arm's centre line (as the arm's incoming traffic sees it), m.
    pub lateral: f64,
    pub facing: Facing,
    pub motion: Option<Motion>,
    /// What it does at the junction ahead.
    pub turn: Turn,
    /// m/s: the speed it keeps once it moves.
    pub speed: f64,
    /// It is moving at the start (at `speed`).
    pub moving: bool,
    pub start: Start,
    /// Its pose at the start.
    pub pose: Pose,
    /// What it drives or walks along, and the arc length of its start on it.
    pub path: Path,
    pub path_start: f64,
}

impl Agent {
    pub fn footprint(&self) -> Footprint {
        Footprint { pose: self.pose, length: self.length, width: self.width }
    }

    /// Whether it never moves by itself.
    pub fn is_static(&self) -> bool {
        self.speed <= 0.0 || self.body == Body::Object
    }
}

/// A group's actors and the room the layout left around them.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupLayout {
    pub group: GroupId,
    pub facts: Facts,
    pub agents: Vec<Agent>,
    /// How far the whole group may be sampled nearer its reference (m, along its lane
    /// towards it) without touching anything: the free room the layout keeps.
    pub slack: f64,
}

impl GroupLayout {
    /// How far the whole group may be sampled nearer its reference: its [`slack`], but never
    /// so far that an actor on another arm would reach into the junction (0.5 m kept).
    ///
    /// [`slack`]: GroupLayout::slack
    pub fn shift_room(&self) -> f64 {
        self.agents
            .iter()
            .filter(|a| a.station.arm != Arm::Ego && a.facing == Facing::Along)
            .map(|a| a.station.along - a.length / 2.0 - 0.5)
            .fold(self.slack, f64::min)
    }
}

/// A group timed to meet the ego.
#[derive(Clone, Debug, PartialEq)]
pub struct Conflict {
    pub group: GroupId,
    /// Where the first actor's path meets the ego's.
    pub point: geom::Vec2,
    /// When the ego reaches it at its stated speed, s.
    pub time: f64,
    /// How long the first actor takes to reach it from its start, at its speed, s (no more
    /// than `time`; less when it waits for the ego: [`Start::meet`]).
    pub travel: f64,
    /// How far (m, along its path) the adversary's start may vary either way and still meet
    /// the ego within about a second.
    pub spread: f64,
}

/// Half a conflict's spread, the most an agent's start is sampled either way: at least
/// 0.5 m, at most 5 m.
pub(crate) fn half_spread(spread: f64) -> f64 {
    (spread * 0.5).clamp(0.5, 5.0)
}

/// What the layout could not do as the scenario says.
#[derive(Clone, Debug, PartialEq)]
pub enum Finding {
    /// A value not stated, chosen.
    Chosen(Chosen),
    /// The group belongs on a junction arm the road does not have: it is on the ego's road.
    NoArm { group: GroupId, arm: Arm, span: Span },
    /// More actors than [`MAX_GROUP`].
    Capped { group: GroupId, wanted: usize, placed: usize, span: Span },
    /// A written lane of the ego's road that the target's road lacks ([`Limits`]): moved to
    /// the nearest lane it has. `group` is `None` for the ego.
    Moved { group: Option<GroupId>, from: i64, to: i64, span: Span },
}

/// The lanes a target's road has (a map's), when a layout must fit on it: `same` in the
/// ego's direction, `other` in the opposite one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    pub same: u32,
    pub other: u32,
}

impl Limits {
    /// The nearest lane to `lane` that the road has: a lane past the last one in its
    /// direction is the last one; an opposite lane on a road without any is lane 1.
    pub fn fit(self, lane: i64) -> i64 {
        if lane > 0 {
            lane.min(i64::from(self.same.max(1)))
        } else if self.other > 0 {
            lane.max(-i64::from(self.other))
        } else {
            1
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub road: Road,
    pub ego: Agent,
    pub ego_facts: Facts,
    /// In the scenario's source order.
    pub groups: Vec<GroupLayout>,
    pub conflicts: Vec<Conflict>,
    pub findings: Vec<Finding>,
}

impl Layout {
    /// The ego and every actor, the ego first.
    pub fn agents(&self) -> impl Iterator<Item = &Agent> {
        std::iter::once(&self.ego).chain(self.groups.iter().flat_map(|g| &g.agents))
    }

    pub fn group(&self, id: GroupId) -> Option<&GroupLayout> {
        self.groups.iter().find(|g| g.group == id)
    }

    pub fn conflict(&self, id: GroupId) -> Option<&Conflict> {
        self.conflicts.iter().find(|c| c.group == id)
    }

    /// How far an agent's start may be sampled either way: half its group's conflict
    /// spread (at most 5 m), never into the junction; 0 for an agent not timed.
    pub fn conflict_spread(&self, agent: &Agent) -> f64 {
        let Some(c) = agent.group.and_then(|g| self.conflict(g)) else { return 0.0 };
        let half = half_spread(c.spread);
        match agent.station.arm {
            Arm::Ego => half,
            _ => half.min(agent.station.along - agent.length / 2.0 - 0.5).max(0.0),
        }
    }
}
