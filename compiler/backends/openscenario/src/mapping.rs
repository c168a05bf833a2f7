//! OpenSCENARIO's categories for the vocabulary's actor types (`spec/backends/openscenario.md`
//! §3, whose table the tests hold against [`TABLE`]). A type not in the table takes its
//! body's category, with a W0711.

use tad_road::Body;

/// What an actor is in OpenSCENARIO.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    /// A `Vehicle` of this `vehicleCategory`.
    Vehicle(&'static str),
    /// A `Pedestrian` of this `pedestrianCategory`.
    Pedestrian(&'static str),
    /// A `MiscObject` of this `miscObjectCategory`.
    Misc(&'static str),
}

impl Category {
    pub fn as_str(self) -> &'static str {
        match self {
            Category::Vehicle(c) | Category::Pedestrian(c) | Category::Misc(c) => c,
        }
    }
}

use Category::*;

/// The standard library's actor types.
pub const TABLE: &[(&str, Category)] = &[
    ("sedan", Vehicle("car")),
    ("suv", Vehicle("car")),
    ("car", Vehicle("car")),
    ("taxi", Vehicle("car")),
    ("police_car", Vehicle("car")),
    ("emergency_vehicle", Vehicle("car")),
    ("horse_buggy", Vehicle("car")),
    ("van", Vehicle("van")),
    ("ambulance", Vehicle("van")),
    ("rv", Vehicle("van")),
    ("truck", Vehicle("truck")),
    ("fire_truck", Vehicle("truck")),
    ("snowplow", Vehicle("truck")),
    ("construction_vehicle", Vehicle("truck")),
    ("tractor", Vehicle("truck")),
    ("bus", Vehicle("bus")),
    ("school_bus", Vehicle("bus")),
    ("snowcoach", Vehicle("bus")),
    ("tram", Vehicle("tram")),
    ("motorcycle", Vehicle("motorbike")),
    ("snowmobile", Vehicle("motorbike")),
    ("bicycle", Vehicle("bicycle")),
    ("pedestrian", Pedestrian("pedestrian")),
    ("construction_worker", Pedestrian("pedestrian")),
    ("horse_rider", Pedestrian("animal")),
    ("dog", Pedestrian("animal")),
    ("deer", Pedestrian("animal")),
    ("elk", Pedestrian("animal")),
    ("moose", Pedestrian("animal")),
    ("bison", Pedestrian("animal")),
    ("bear", Pedestrian("animal")),
    ("cow", Pedestrian("animal")),
    ("traffic_cone", Misc("obstacle")),
    ("barrier", Misc("barrier")),
];

/// The category of a type: from the table, else `None`.
pub fn listed(class: &str) -> Option<Category> {
    TABLE.iter().find(|(name, _)| *name == class).map(|(_, c)| *c)
}

/// The category a body takes when its type is not in the table.
pub fn of_body(body: Body) -> Category {
    match body {
        Body::Vehicle => Vehicle("car"),
        Body::Walker => Pedestrian("pedestrian"),
        Body::Object => Misc("obstacle"),
    }
}
