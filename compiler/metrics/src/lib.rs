//! SafeBench/ChatScene's ten-metric scorer (`spec/runtime.md` §metrics).

/// What the runtime records about the ego at each step (one `record_dict` entry).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepRecord {
    /// Simulation time, s.
    pub time: f64,
    /// Speed, m/s.
    pub velocity: f64,
    /// Acceleration (kinematic, Δv/dt), m/s².
    pub acceleration: [f64; 3],
    pub position: [f64; 3],
    /// Heading in degrees within [−180, 180] (CARLA's `yaw`).
    pub yaw_deg: f64,
    /// Distance driven since the start, m.
    pub driven_distance: f64,
    /// Lane invasion events so far.
    pub lane_invasion: u32,
    /// The ego's centre is on no driving or parking lane.
    pub off_road: bool,
    /// The ego has collided (with a vehicle, a walker or a static prop).
    pub collision: bool,
    /// Red lights run so far.
    pub run_red_light: u32,
    /// Stop signs run so far.
    pub run_stop: u32,
    /// Distance from the ego to the nearest route point ahead, m.
    pub distance_to_route: f64,
    /// Route completion, percent (exactly 100 when complete).
    pub route_complete: f64,
}
