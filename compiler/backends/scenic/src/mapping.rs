//! Scenic's and CARLA's side of the mapping: the classes an actor can become, the words of
//! CARLA's weather parameters and light states, the maneuver names, and the defaults for
//! what a declaration leaves unsaid.
//!
//! No vocabulary name appears here. What a name of the vocabulary maps to is declared with
//! the name, in TAD (`stdlib/core.tad`, `stdlib/national_park.tad`, or the scenario's own
//! declarations): an actor type's `simulated_as` and `carla_blueprint`, a weather's
//! `cloudiness` ..., a time of day's `sun_altitude`, a light state's `signal`, a road
//! type's `arms` and `shape`, a road context's `carla_towns`, a sign's `opendrive_type`, a
//! road element's `at_junction` (`spec/vocabulary.md` §2, `spec/backends/scenic.md`). The
//! planner reads them from the resolved IR; this module only names their Scenic and CARLA
//! counterparts.

use tad_ir::{Signal, SimulatedAs, TimeOfDay, Weather};

/// The Scenic class an actor becomes. The Newtonian driving model has only `Car`,
/// `Pedestrian`, `Vehicle` and `Debris`; the CARLA model has them too, and the `blueprint`
/// property picks the CARLA actor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    Car,
    Pedestrian,
    Debris,
}

impl Class {
    pub fn as_str(self) -> &'static str {
        match self {
            Class::Car => "Car",
            Class::Pedestrian => "Pedestrian",
            Class::Debris => "Debris",
        }
    }

    /// The class of an actor simulated as `body`.
    pub fn of(body: SimulatedAs) -> Class {
        match body {
            SimulatedAs::Car => Class::Car,
            SimulatedAs::Pedestrian => Class::Pedestrian,
            SimulatedAs::Object => Class::Debris,
        }
    }

    /// The layout's body of an actor of this class.
    pub fn body(self) -> tad_layout::Body {
        match self {
            Class::Car => tad_layout::Body::Vehicle,
            Class::Pedestrian => tad_layout::Body::Walker,
            Class::Debris => tad_layout::Body::Object,
        }
    }

    /// The length and width of an actor of this class whose type states none (the layout's).
    pub fn default_size(self) -> (f64, f64) {
        self.body().default_size()
    }

    /// The CARLA blueprint of an actor of this class when neither its type nor its kind
    /// declares one.
    pub fn default_blueprint(self) -> &'static str {
        match self {
            Class::Car => "vehicle.toyota.prius",
            Class::Pedestrian => "walker.pedestrian.0001",
            Class::Debris => "static.prop.streetbarrier",
        }
    }
}

/// The ego vehicle's blueprint (the usual CARLA ego car).
pub const EGO_BLUEPRINT: &str = "vehicle.lincoln.mkz_2017";

/// Why an actor whose type and kind declare no blueprint is only approximated.
pub const FALLBACK_NOTE: &str = "an unknown vehicle type becomes a car";

/// The Scenic maneuver type of a maneuver letter of the map table (`L`, `R`, `U`, `S`).
pub fn maneuver(letter: char) -> &'static str {
    match letter {
        'L' => "LEFT_TURN",
        'R' => "RIGHT_TURN",
        'U' => "U_TURN",
        _ => "STRAIGHT",
    }
}

/// `carla.WeatherParameters` for a weather's declared sky and road, in CARLA's order; empty
/// when it declares none.
pub fn weather_parameters(weather: &Weather) -> Vec<(&'static str, f64)> {
    let scales = [
        ("cloudiness", weather.cloudiness),
        ("precipitation", weather.precipitation),
        ("precipitation_deposits", weather.precipitation_deposits),
        ("wetness", weather.wetness),
        ("wind_intensity", weather.wind_intensity),
        ("fog_density", weather.fog_density),
    ];
    let mut out: Vec<(&'static str, f64)> =
        scales.into_iter().filter_map(|(name, value)| Some((name, value? as f64))).collect();
    if let Some(distance) = weather.fog_distance {
        out.push(("fog_distance", distance.0));
    }
    out
}

/// `carla.WeatherParameters` for the sun of a time of day: angles in degrees; empty when
/// it declares no altitude. An azimuth not declared is 0.
pub fn sun_parameters(time: &TimeOfDay) -> Vec<(&'static str, f64)> {
    match time.sun_altitude {
        Some(altitude) => {
            vec![("sun_altitude_angle", altitude as f64), ("sun_azimuth_angle", time.sun_azimuth.unwrap_or(0) as f64)]
        }
        None => Vec::new(),
    }
}

/// The CARLA traffic-light state that shows `signal` (`setClosestTrafficLightStatus`).
pub fn light_state(signal: Signal) -> &'static str {
    match signal {
        Signal::Green => "green",
        Signal::Red => "red",
        Signal::Yellow => "yellow",
        Signal::Off => "off",
    }
}
