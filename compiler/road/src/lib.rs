//! The road contract: the geometry and vocabulary of a laid-out road, shared by the layout
//! (which decides it), the bytecode (which serialises it) and the runtime (which drives on
//! it). What changes here changes the `.tadc` format (`spec/bytecode.md`).
//!
//! Modules: `geom` (points, poses, polyline paths, footprints) and `road` (the road's shape,
//! arms, lanes, stations, junction paths); here, how a placed actor is described: its
//! [`Body`], where across its lane it stands ([`Place`]) and which way it faces
//! ([`Facing`]); and how long an actor takes to cover the rest of its way ([`time_to`]), by
//! which an adversary's start is measured (`meet`).

pub mod geom;
pub mod road;

pub use road::{Arm, Junction, Road, Shape, Side, Station, Turn};

/// The slowest an actor counts as moving when its time to a point is measured, m/s.
pub const CREEP: f64 = 0.1;

/// How long an actor at `speed` takes to cover `distance` more metres of its way (negative
/// once past the point); a standing actor counts as creeping ([`CREEP`]).
pub fn time_to(distance: f64, speed: f64) -> f64 {
    distance / speed.max(CREEP)
}
use tad_ir::{Motion, SimulatedAs};

/// The body an actor is simulated as (its type's `simulated_as`, else its kind's).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Body {
    Vehicle,
    Walker,
    Object,
}

impl Body {
    pub fn of(simulated: SimulatedAs) -> Body {
        match simulated {
            SimulatedAs::Car => Body::Vehicle,
            SimulatedAs::Pedestrian => Body::Walker,
            SimulatedAs::Object => Body::Object,
        }
    }

    /// Length and width of a body whose type states none, m.
    pub fn default_size(self) -> (f64, f64) {
        match self {
            Body::Vehicle => (4.5, 1.8),
            Body::Walker => (0.5, 0.6),
            Body::Object => (0.5, 0.5),
        }
    }

    /// The motion of a body whose behavior is not given.
    pub fn default_motion(self) -> Motion {
        match self {
            Body::Vehicle => Motion::Follow,
            Body::Walker => Motion::Stand,
            Body::Object => Motion::Parked,
        }
    }
}

/// Where across its lane an actor stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Place {
    /// The lane's centre.
    Lane,
    /// The curb side of an outermost lane.
    Curb,
    /// Just outside the outermost lane: on the shoulder or in a parking strip.
    Shoulder,
    /// The sidewalk beside the road.
    Sidewalk,
}

/// Which way an actor faces at the start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Facing {
    /// Along its lane's traffic.
    Along,
    /// Across the road, from the sidewalk of `from` towards the other side.
    Across { from: Side },
}
