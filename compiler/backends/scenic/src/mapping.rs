//! The standard vocabulary's names and their Scenic counterparts.
//!
//! Every table here is keyed by canonical vocabulary names; `spec/backends/scenic.md` lists
//! the same rows for readers (a test checks that every standard name is in that document).
//! A name that is not in a table has no mapping: the caller reports it (W0700), or falls
//! back on what the name's declared attributes say (an actor type's kind, a road type's
//! `junction` flag) and reports the approximation (W0703).

use crate::maps::{JunctionKind, Shape};

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
}

/// A CARLA 0.9.15 blueprint for an actor type, and why it is only an approximation.
pub struct Blueprint {
    pub class: Class,
    pub blueprint: &'static str,
    pub approximation: Option<&'static str>,
}

const fn bp(class: Class, blueprint: &'static str) -> Blueprint {
    Blueprint { class, blueprint, approximation: None }
}

const fn approx(class: Class, blueprint: &'static str, why: &'static str) -> Blueprint {
    Blueprint { class, blueprint, approximation: Some(why) }
}

/// The ego vehicle's blueprint (the usual CARLA ego car).
pub const EGO_BLUEPRINT: &str = "vehicle.lincoln.mkz_2017";

const ANIMAL: &str = "CARLA has no animals: a pedestrian (walker) of the animal's size stands in for it";

/// The blueprint of a standard actor type.
pub fn actor_type(name: &str) -> Option<Blueprint> {
    use Class::*;
    Some(match name {
        "sedan" => bp(Car, "vehicle.tesla.model3"),
        "suv" => bp(Car, "vehicle.nissan.patrol"),
        "car" => bp(Car, "vehicle.toyota.prius"),
        "van" => bp(Car, "vehicle.mercedes.sprinter"),
        "truck" => bp(Car, "vehicle.carlamotors.carlacola"),
        "bus" => bp(Car, "vehicle.mitsubishi.fusorosa"),
        "taxi" => bp(Car, "vehicle.ford.crown"),
        "tram" => {
            approx(Car, "vehicle.mitsubishi.fusorosa", "CARLA has no trams: a bus of the tram's size stands in for it")
        }
        "ambulance" => bp(Car, "vehicle.ford.ambulance"),
        "fire_truck" => bp(Car, "vehicle.carlamotors.firetruck"),
        "police_car" => bp(Car, "vehicle.dodge.charger_police"),
        "emergency_vehicle" => bp(Car, "vehicle.ford.ambulance"),
        "construction_vehicle" => bp(Car, "vehicle.carlamotors.european_hgv"),
        "motorcycle" => bp(Car, "vehicle.yamaha.yzf"),
        "bicycle" => bp(Car, "vehicle.diamondback.century"),
        "pedestrian" => bp(Pedestrian, "walker.pedestrian.0001"),
        "construction_worker" => bp(Pedestrian, "walker.pedestrian.0030"),
        "traffic_cone" => bp(Debris, "static.prop.constructioncone"),
        "barrier" => bp(Debris, "static.prop.streetbarrier"),
        // national_park
        "deer" | "elk" | "bison" | "cow" | "bear" | "moose" => approx(Pedestrian, "walker.pedestrian.0001", ANIMAL),
        "tractor" => approx(
            Car,
            "vehicle.carlamotors.european_hgv",
            "CARLA has no tractors: a truck of the tractor's size stands in for it",
        ),
        "rv" => bp(Car, "vehicle.volkswagen.t2"),
        _ => return None,
    })
}

/// The blueprint for an actor type the tables do not know, by its actor kind.
pub fn actor_kind(kind: Option<&str>) -> Blueprint {
    use Class::*;
    match kind {
        Some("two_wheeler") => approx(Car, "vehicle.diamondback.century", "an unknown two-wheeler becomes a bicycle"),
        Some("pedestrian") => {
            approx(Pedestrian, "walker.pedestrian.0001", "an unknown pedestrian type becomes a walker")
        }
        Some("animal") => approx(Pedestrian, "walker.pedestrian.0001", ANIMAL),
        Some("static_object") => {
            approx(Debris, "static.prop.streetbarrier", "an unknown object becomes a street barrier")
        }
        _ => approx(Car, "vehicle.toyota.prius", "an unknown vehicle type becomes a car"),
    }
}

/// What an actor does, independent of its class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    Follow,
    Stop,
    Parked,
    Stand,
    Walk,
    Cross,
    Graze,
    /// The maneuver letter: `L`, `R`, `U`.
    Turn(char),
    ChangeLane {
        left: bool,
    },
    Overtake,
    Yield,
    Reverse,
}

/// The motion of a standard behavior.
pub fn behavior(name: &str) -> Option<Motion> {
    use Motion::*;
    Some(match name {
        "go_forward" => Follow,
        "stopped" => Stop,
        "parked" => Parked,
        "yield" => Yield,
        "turn_left" => Turn('L'),
        "turn_right" => Turn('R'),
        "u_turn" => Turn('U'),
        "change_lane_left" | "merge_left" => ChangeLane { left: true },
        "change_lane_right" | "merge_right" => ChangeLane { left: false },
        "overtake" => Overtake,
        "reverse" => Reverse,
        "cross" => Cross,
        "walk" => Walk,
        "stand" => Stand,
        "graze" => Graze,
        _ => return None,
    })
}

pub fn maneuver(letter: char) -> &'static str {
    match letter {
        'L' => "LEFT_TURN",
        'R' => "RIGHT_TURN",
        'U' => "U_TURN",
        _ => "STRAIGHT",
    }
}

/// `carla.WeatherParameters` for a weather.
pub fn weather(name: &str) -> Option<&'static [(&'static str, f64)]> {
    Some(match name {
        "clear" => &[
            ("cloudiness", 10.0),
            ("precipitation", 0.0),
            ("precipitation_deposits", 0.0),
            ("wetness", 0.0),
            ("wind_intensity", 10.0),
            ("fog_density", 0.0),
        ],
        "cloudy" => &[
            ("cloudiness", 80.0),
            ("precipitation", 0.0),
            ("precipitation_deposits", 0.0),
            ("wetness", 0.0),
            ("wind_intensity", 30.0),
            ("fog_density", 0.0),
        ],
        "foggy" => &[
            ("cloudiness", 50.0),
            ("precipitation", 0.0),
            ("precipitation_deposits", 0.0),
            ("wetness", 0.0),
            ("wind_intensity", 5.0),
            ("fog_density", 60.0),
            ("fog_distance", 10.0),
        ],
        "rainy" => &[
            ("cloudiness", 90.0),
            ("precipitation", 70.0),
            ("precipitation_deposits", 60.0),
            ("wetness", 80.0),
            ("wind_intensity", 40.0),
            ("fog_density", 10.0),
        ],
        "wet" => &[
            ("cloudiness", 40.0),
            ("precipitation", 0.0),
            ("precipitation_deposits", 50.0),
            ("wetness", 70.0),
            ("wind_intensity", 10.0),
            ("fog_density", 0.0),
        ],
        _ => return None,
    })
}

/// The sun for a time of day: `carla.WeatherParameters` angles in degrees.
pub fn time_of_day(name: &str) -> Option<&'static [(&'static str, f64)]> {
    Some(match name {
        "daytime" => &[("sun_altitude_angle", 60.0), ("sun_azimuth_angle", 135.0)],
        "nighttime" => &[("sun_altitude_angle", -40.0), ("sun_azimuth_angle", 0.0)],
        "dawn" => &[("sun_altitude_angle", 5.0), ("sun_azimuth_angle", 90.0)],
        "dusk" => &[("sun_altitude_angle", 5.0), ("sun_azimuth_angle", 270.0)],
        _ => return None,
    })
}

/// The CARLA traffic-light state for a light state (`setClosestTrafficLightStatus`).
pub fn light(name: &str) -> Option<&'static str> {
    Some(match name {
        "green" => "green",
        "red" => "red",
        "yellow" => "yellow",
        "broken" => "off",
        _ => return None,
    })
}

/// What a road type asks of the map.
pub enum RoadType {
    Shape(Shape),
    Junction(Option<JunctionKind>),
    /// A junction kind no map has (a roundabout): any junction instead.
    Missing(&'static str),
}

pub fn road_type(name: &str) -> Option<RoadType> {
    Some(match name {
        "straight_road" => RoadType::Shape(Shape::Straight),
        "curved_road" => RoadType::Shape(Shape::Curved),
        "intersection" => RoadType::Junction(Some(JunctionKind::Four)),
        "t_intersection" => RoadType::Junction(Some(JunctionKind::Three)),
        "roundabout" => RoadType::Missing("a roundabout"),
        _ => return None,
    })
}

/// The maps that suit a road context, best first (a preference among maps that have
/// everything else the scenario needs), and what the maps cannot show of it.
pub fn road_context(name: &str) -> Option<(&'static [&'static str], Option<&'static str>)> {
    Some(match name {
        "urban" => (&["Town10HD", "Town01", "Town02"], None),
        "residential" => (&["Town02", "Town01", "Town07", "Town10HD"], None),
        "highway" => (&["Town04", "Town06"], None),
        "country_road" | "hill_road" => (&["Town07"], None),
        "dirt_road" => (&["Town07"], Some("the maps have no unpaved roads")),
        _ => return None,
    })
}

/// The OpenDRIVE signal type of a junction sign (`206` stop, `205` yield), as the map
/// table names it and as the generated filter tests it.
pub fn sign(name: &str) -> Option<(&'static str, &'static str)> {
    Some(match name {
        "stop_sign" => ("stop", "206"),
        "yield_sign" => ("yield", "205"),
        _ => return None,
    })
}

/// Road elements a position can be relative to that the backend places at the junction
/// ahead of the ego vehicle.
pub fn junction_element(name: &str) -> bool {
    matches!(name, "intersection" | "traffic_light" | "stop_sign" | "crosswalk" | "roundabout")
}
