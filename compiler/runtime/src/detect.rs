//! SafeBench's criteria on the ego, on the road's geometry (CARLA computes these client-side
//! from OpenDRIVE, so geometry is faithful; only collisions need the physics engine):
//! lane invasion (a bounding-box corner changes lane), off-road (the centre on no driving
//! lane), distance to the route and route completion, red lights and stop signs.

use crate::world::{Spot, World};
use tad_bytecode::Light;
use tad_road::geom::{Footprint, Path};

/// Route completion counts as complete past this share within [`END_DISTANCE`] of the end.
const COMPLETE_SHARE: f64 = 0.99;
const END_DISTANCE: f64 = 10.0;
/// A stop sign's trigger box: this far before the stop line, m.
const STOP_BOX: f64 = 6.0;
/// Below this the ego has stopped, m/s.
const STOPPED: f64 = 0.1;

pub struct Detectors {
    /// The spot of each bounding-box corner at the previous step.
    corners: Option<[Spot; 4]>,
    pub lane_invasions: u32,
    pub red_lights: u32,
    pub stop_signs: u32,
    /// Route: the arc of the start, the route's length; progress so far (m along it).
    start: f64,
    length: f64,
    progress: f64,
    /// The ego's stop line on the route (arc), if its lane has one.
    stop_line: Option<f64>,
    red_counted: bool,
    sign: SignState,
}

#[derive(Clone, Copy, PartialEq)]
enum SignState {
    Before,
    /// In the box; whether it has stopped.
    Inside(bool),
    Done,
}

/// The ego as the criteria read it after a step.
#[derive(Clone, Copy, Debug)]
pub struct EgoState {
    pub footprint: Footprint,
    /// Its arc on the route, and its (signed) distance from it, m.
    pub s: f64,
    pub off_route: f64,
    /// m/s.
    pub speed: f64,
}

/// What the criteria say after a step.
pub struct Reading {
    pub off_road: bool,
    pub distance_to_route: f64,
    /// Percent, exactly 100 when complete.
    pub route_complete: f64,
    /// New events this step.
    pub lane_invasion: bool,
    pub red_light: bool,
    pub stop_sign: bool,
}

impl Detectors {
    pub fn new(start: f64, length: f64, stop_line: Option<f64>) -> Detectors {
        Detectors {
            corners: None,
            lane_invasions: 0,
            red_lights: 0,
            stop_signs: 0,
            start,
            length: length.max(1.0),
            progress: 0.0,
            stop_line,
            red_counted: false,
            sign: SignState::Before,
        }
    }

    /// Read the criteria with the ego as `ego` says, on `route`, at time `t`.
    pub fn read(&mut self, world: &World, route: &Path, ego: &EgoState, t: f64) -> Reading {
        let EgoState { footprint: ego, s, off_route, speed } = *ego;
        // lane invasion: any corner now in another lane of the same road than before
        let corners = ego.corners().map(|c| world.spot(c));
        let mut invasion = false;
        if let Some(before) = self.corners {
            invasion = before.iter().zip(&corners).any(|(a, b)| match (a, b) {
                (Spot::Lane(arm1, l1), Spot::Lane(arm2, l2)) => arm1 == arm2 && l1 != l2,
                (Spot::Lane(..), Spot::Off) | (Spot::Off, Spot::Lane(..)) => true,
                _ => false,
            });
        }
        self.corners = Some(corners);
        self.lane_invasions += u32::from(invasion);
        let off_road = !world.on_road(ego.pose.position);

        // route: progress only forward, never past its end
        self.progress = self.progress.max((s - self.start).clamp(0.0, self.length));
        let end = route.pose(self.start + self.length).position;
        let mut complete = 100.0 * self.progress / self.length;
        if complete > 100.0 * COMPLETE_SHARE && ego.pose.position.distance(end) <= END_DISTANCE {
            complete = 100.0;
        }

        // red light: the rear part of the ego crosses the stop line while its light is red
        let mut red = false;
        let mut sign = false;
        if let Some(line) = self.stop_line {
            let rear = s - 0.4 * ego.length;
            if !self.red_counted
                && rear >= line
                && rear - speed * 0.1 - 1.0 < line
                && world.light(tad_road::Arm::Ego, t) == Light::Red
            {
                red = true;
                self.red_counted = true;
                self.red_lights += 1;
            }
            if world.stop_signs() {
                let inside = s >= line - STOP_BOX && s < line;
                self.sign = match self.sign {
                    SignState::Before if inside => SignState::Inside(speed < STOPPED),
                    SignState::Inside(stopped) if inside => SignState::Inside(stopped || speed < STOPPED),
                    SignState::Inside(stopped) if s >= line => {
                        if !stopped {
                            sign = true;
                            self.stop_signs += 1;
                        }
                        SignState::Done
                    }
                    other => other,
                };
            }
        }
        Reading {
            off_road,
            distance_to_route: off_route.abs(),
            route_complete: complete,
            lane_invasion: invasion,
            red_light: red,
            stop_sign: sign,
        }
    }

    /// Whether the ego has stopped at its stop sign (or has none to stop at).
    pub fn stopped_at_sign(&self) -> bool {
        matches!(self.sign, SignState::Inside(true) | SignState::Done)
    }
}
