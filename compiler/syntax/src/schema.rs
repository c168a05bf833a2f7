//! The shape of a scenario: which sections exist, which fields each has, and what kind of
//! value each field takes.
//!
//! This table is the single source for lowering (unknown field, wrong kind of value,
//! "did you mean"), for the formatter's knowledge of lists, and for the field reference in
//! `spec/language.md` (a test checks they agree). Vocabularies (which names are valid
//! weather, behaviors, ...) are not here: they are declared in TAD in `stdlib/`.
//!
//! The few sets of words the compiler itself gives meaning to (a relation's [`Lateral`]
//! and [`Longitudinal`] parts, a behavior's [`Motion`], an actor type's [`SimulatedAs`], a
//! light state's [`Signal`], a road type's [`RoadShape`]) are closed sets: each is one Rust
//! enum declared here with its words, a field takes it as [`ValueType::Choice`], lowering
//! rejects any other word, and later stages (the IR) use the enum.

/// The kind of value a field takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ValueType {
    /// One name from a vocabulary: `clear`, `move_forward`.
    Symbol,
    /// A list of names: `[stop_sign, school_zone]`; `[]` for none.
    SymbolList,
    /// A whole number: `3`, `-1`.
    Integer,
    /// A number with a speed unit: `38 km/h`, `20 mph`, `5 m/s`.
    Speed,
    /// A number with a time unit: `195 s`.
    Duration,
    /// A number with a length unit: `4.5 m`.
    Length,
    /// A string or text block.
    Text,
    /// `RELATION of REFERENCE`: `left_front of ego`.
    Position,
    /// `yes` or `no`.
    Flag,
    /// One word of a closed set ([`ClosedSet::NAMES`]): `left`, `turn_left`.
    Choice(&'static [&'static str]),
}

impl ValueType {
    /// "a speed", "a list of names", ... for messages.
    pub fn describe(self) -> &'static str {
        match self {
            ValueType::Symbol => "a name",
            ValueType::SymbolList => "a list of names",
            ValueType::Integer => "a whole number",
            ValueType::Speed => "a speed",
            ValueType::Duration => "a duration",
            ValueType::Length => "a length",
            ValueType::Text => "a string",
            ValueType::Position => "a position",
            ValueType::Flag => "`yes` or `no`",
            ValueType::Choice(_) => "a name",
        }
    }
}

/// A closed set of words the compiler gives meaning to, as an enum.
pub trait ClosedSet: Sized + Copy + 'static {
    /// The words of the set, as written in TAD.
    const NAMES: &'static [&'static str];
    fn parse(word: &str) -> Option<Self>;
    fn as_str(self) -> &'static str;
}

/// Declares an enum and its [`ClosedSet`] words.
macro_rules! closed_set {
    ($(#[$meta:meta])* $set:ident { $($(#[$vmeta:meta])* $variant:ident = $word:literal),+ $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum $set {
            $($(#[$vmeta])* $variant),+
        }

        impl $set {
            /// Every member, in the order of [`ClosedSet::NAMES`].
            pub const ALL: &'static [$set] = &[$($set::$variant),+];
        }

        impl ClosedSet for $set {
            const NAMES: &'static [&'static str] = &[$($word),+];

            fn parse(word: &str) -> Option<$set> {
                match word {
                    $($word => Some($set::$variant),)+
                    _ => None,
                }
            }

            fn as_str(self) -> &'static str {
                match self {
                    $($set::$variant => $word),+
                }
            }
        }
    };
}

closed_set! {
    /// The words a `lane` field takes besides its number, in the ego's direction.
    LaneWord {
        /// Lane 1.
        Leftmost = "leftmost",
        /// The road's last lane, `lanes`.
        Rightmost = "rightmost",
    }
}

closed_set! {
    /// Where a relation is across the road from its reference.
    Lateral {
        Left = "left",
        Right = "right",
        /// In the reference's lane.
        Same = "same",
        /// In the opposite direction's lanes.
        Opposite = "opposite",
    }
}

closed_set! {
    /// Where a relation is along the road from its reference.
    Longitudinal {
        Front = "front",
        Behind = "behind",
        /// Beside it.
        Same = "same",
    }
}

closed_set! {
    /// What a behavior does as motion, independent of who performs it: the class a
    /// simulator backend maps to a driving or walking behavior.
    Motion {
        /// Keep moving along the lane.
        Follow = "follow",
        /// Halted for the moment in traffic.
        Stop = "stop",
        /// Standing at the curb or in a parking space.
        Parked = "parked",
        /// Standing still (a pedestrian or an animal).
        Stand = "stand",
        /// Walking along the road.
        Walk = "walk",
        /// Crossing the road.
        Cross = "cross",
        /// Grazing, barely moving.
        Graze = "graze",
        TurnLeft = "turn_left",
        TurnRight = "turn_right",
        UTurn = "u_turn",
        ChangeLaneLeft = "change_lane_left",
        ChangeLaneRight = "change_lane_right",
        Overtake = "overtake",
        Yield = "yield",
        Reverse = "reverse",
    }
}

closed_set! {
    /// How an actor type is simulated: the body a simulator gives it.
    SimulatedAs {
        /// A vehicle driven along lanes (cars, trucks, two-wheelers).
        Car = "car",
        /// A walker (people; animals where the simulator has none).
        Pedestrian = "pedestrian",
        /// A static object that does not move by itself.
        Object = "object",
    }
}

closed_set! {
    /// What a traffic light shows.
    Signal {
        Green = "green",
        Red = "red",
        Yellow = "yellow",
        /// Dark or flashing: out of order.
        Off = "off",
    }
}

closed_set! {
    /// The shape of a road type.
    RoadShape {
        /// Turning less than 10° over the stretch a scenario needs.
        Straight = "straight",
        /// Turning more than 20° over it.
        Curved = "curved",
        /// A circular junction.
        Roundabout = "roundabout",
    }
}

#[derive(Debug, PartialEq, Eq, Hash)]
pub struct FieldDef {
    pub name: &'static str,
    pub ty: ValueType,
    /// The vocabulary (declaration kind) its names come from, for name fields.
    pub vocabulary: Option<&'static str>,
    /// A valid value, used in help messages.
    pub example: &'static str,
    pub doc: &'static str,
    /// Whether a complete scenario states it (TrafficAlign's semantic validation).
    pub essential: bool,
    /// Whether it takes a parameter: a range (`30..40 km/h`) for a quantity, a choice
    /// (`a | b`) for a name. Other fields take single values only (E0205).
    pub param: bool,
    /// Whether a length or duration below 0 means something (else E0216).
    pub signed: bool,
}

#[derive(Debug, PartialEq, Eq, Hash)]
pub struct SectionDef {
    pub name: &'static str,
    pub doc: &'static str,
    pub fields: &'static [FieldDef],
}

impl SectionDef {
    pub fn field(&self, name: &str) -> Option<&'static FieldDef> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The fields a complete scenario states, in order.
    pub fn essential(&self) -> impl Iterator<Item = &'static FieldDef> + '_ {
        self.fields.iter().filter(|f| f.essential)
    }
}

macro_rules! field {
    ($name:literal, $ty:ident, $example:literal, $doc:literal) => {
        FieldDef {
            name: $name,
            ty: ValueType::$ty,
            vocabulary: None,
            example: $example,
            doc: $doc,
            essential: false,
            param: false,
            signed: false,
        }
    };
    ($name:literal, $ty:ident in $vocabulary:literal, $example:literal, $doc:literal) => {
        FieldDef {
            name: $name,
            ty: ValueType::$ty,
            vocabulary: Some($vocabulary),
            example: $example,
            doc: $doc,
            essential: false,
            param: false,
            signed: false,
        }
    };
    (essential $($rest:tt)*) => {
        FieldDef { essential: true, ..field!($($rest)*) }
    };
    (param $($rest:tt)*) => {
        FieldDef { param: true, ..field!($($rest)*) }
    };
    (signed $($rest:tt)*) => {
        FieldDef { signed: true, ..field!($($rest)*) }
    };
    ($name:literal, one of $set:ident, $example:literal, $doc:literal) => {
        FieldDef {
            name: $name,
            ty: ValueType::Choice(<$set as ClosedSet>::NAMES),
            vocabulary: None,
            example: $example,
            doc: $doc,
            essential: false,
            param: false,
            signed: false,
        }
    };
}

/// The most actors one group becomes in a scene (the layout caps a larger count; the
/// checker warns, W0512).
pub const MAX_GROUP: usize = 20;

/// How far a scene's road runs on either side of the ego's start and past a junction, m:
/// what is farther is not in the scene (the checker warns of a `distance` beyond it, W0513).
pub const SCENE_REACH: f64 = 200.0;

pub const SOURCE: SectionDef = SectionDef {
    name: "source",
    doc: "where the scenario comes from",
    fields: &[
        field!("video", Text, "\"la_014.mp4\"", "the source video file"),
        field!("time", Duration, "195 s", "the timestamp of the frame in the video"),
        field!("frame", Integer, "4680", "the frame number in the video, when no timestamp is known"),
        field!("region", Symbol in "region", "los_angeles", "the region the video was recorded in"),
        field!("description", Text, "\"\"\" ... \"\"\"", "the natural-language description the scenario was made from"),
    ],
};

pub const ENVIRONMENT: SectionDef = SectionDef {
    name: "environment",
    doc: "weather and time of day",
    fields: &[
        field!(essential param "weather", Symbol in "weather", "clear", "the weather"),
        field!(essential param "time", Symbol in "time_of_day", "daytime", "the time of day"),
    ],
};

pub const ROAD: SectionDef = SectionDef {
    name: "road",
    doc: "the road network around the ego vehicle",
    fields: &[
        field!(essential "type", Symbol in "road_type", "straight_road", "the road type"),
        field!("context", Symbol in "road_context", "urban", "the road context"),
        field!(essential "lanes", Integer, "2", "lanes per direction"),
        field!(essential "direction", Symbol in "direction", "two_way", "`one_way` or `two_way`"),
        field!("special_lanes", SymbolList in "special_lane", "[bike_lane]", "special lanes; `[]` for none"),
        field!("signs", SymbolList in "traffic_sign", "[stop_sign]", "traffic signs; `[]` for none"),
        field!("light", Symbol in "light_state", "green", "the traffic light state facing the ego vehicle; `none` for no light"),
        field!("traffic", Symbol in "traffic_density", "light", "traffic density"),
        field!("hazards", SymbolList in "hazard", "[accident]", "accidents and other hazards; `[]` for none"),
        field!("roadworks", SymbolList in "roadwork", "[lane_closure]", "roadworks and lane closures; `[]` for none"),
        field!("emergency_vehicles", SymbolList in "emergency_vehicle", "[ambulance]", "emergency vehicles present; `[]` for none"),
        field!("roadside", SymbolList in "roadside", "[sidewalk, trees]", "what lines the road"),
    ],
};

pub const EGO: SectionDef = SectionDef {
    name: "ego",
    doc: "the ego vehicle",
    fields: &[
        field!(essential param "behavior", Symbol in "behavior", "move_forward", "what the ego vehicle does"),
        field!(essential param "speed", Speed, "30 km/h", "its speed"),
        field!(essential "lane", Integer, "1", "its lane index: 1 is the leftmost lane in its direction"),
    ],
};

/// The fields of an `actor` block (count and type are in its header).
pub const ACTOR: SectionDef = SectionDef {
    name: "actor",
    doc: "a group of actors of one type that move together",
    fields: &[
        field!(essential param "behavior", Symbol in "behavior", "move_forward", "what every actor of the group does"),
        field!(param "speed", Speed, "30 km/h", "their speed"),
        field!(essential "position", Position, "front of ego", "where the group is, relative to a reference"),
        field!(essential "lane", Integer, "1", "their lane index; negative for the opposite direction"),
        field!(
            param "distance",
            Length,
            "15 m",
            "the gap along the road from the position's reference to the group's nearest actor"
        ),
        field!(param "delay", Duration, "2 s", "the time before the group starts its behavior"),
        field!(param "trigger", Length, "30 m", "the group starts its behavior when the ego vehicle is this close"),
        field!(
            signed param "offset",
            Length,
            "1.5 m",
            "how far the group is moved along its lane from where the layout puts it; a range is searched"
        ),
    ],
};

/// Fields every declaration may have.
const ALIASES: FieldDef =
    field!("aliases", SymbolList, "[sunny]", "other names for the same thing; using one is a warning with a fix");
const DOC: FieldDef = field!("description", Text, "\"...\"", "what the name means");

macro_rules! declaration {
    ($name:literal, $doc:literal $(, $field:expr)* $(,)?) => {
        SectionDef { name: $name, doc: $doc, fields: &[ALIASES, DOC $(, $field)*] }
    };
}

/// The kinds of vocabulary declaration (`KIND NAME { ... }`) and their fields. A scenario
/// field with a `vocabulary` takes the names declared with that kind.
pub const DECLARATIONS: &[&SectionDef] = &[
    &declaration!(
        "weather",
        "a weather condition",
        field!("cloudiness", Integer, "80", "cloud cover, 0 (none) to 100 (overcast)"),
        field!("precipitation", Integer, "70", "rain intensity, 0 to 100"),
        field!("precipitation_deposits", Integer, "60", "puddles on the road, 0 to 100"),
        field!("wetness", Integer, "80", "how wet the road surface is, 0 to 100"),
        field!("wind_intensity", Integer, "30", "wind, 0 to 100"),
        field!("fog_density", Integer, "60", "fog thickness, 0 to 100"),
        field!("fog_distance", Length, "10 m", "where the fog begins"),
    ),
    &declaration!(
        "time_of_day",
        "a time of day",
        field!("sun_altitude", Integer, "60", "the sun's altitude above the horizon, in degrees (negative below)"),
        field!("sun_azimuth", Integer, "135", "the sun's azimuth, in degrees"),
    ),
    &declaration!(
        "road_type",
        "a kind of road layout",
        field!("signalised", Flag, "no", "whether traffic lights can control it (default `yes`)"),
        field!("junction", Flag, "yes", "whether roads meet or cross in it (default `no`)"),
        field!("arms", Integer, "4", "for a junction: how many road arms meet in it"),
        field!("shape", one of RoadShape, "straight", "its shape: `straight`, `curved` or `roundabout`"),
    ),
    &declaration!(
        "road_context",
        "the kind of area a road runs through",
        field!("max_speed", Speed, "60 km/h", "the highest plausible speed there"),
        field!("signalised", Flag, "no", "whether traffic lights occur there (default `yes`)"),
        field!("carla_towns", SymbolList, "[Town10HD, Town01]", "the CARLA towns that look most like it, best first"),
        field!("carla_note", Text, "\"...\"", "what the CARLA towns cannot show of it"),
    ),
    &declaration!(
        "direction",
        "one-way or two-way traffic",
        field!("opposite_lanes", Flag, "yes", "whether the road has lanes for the opposite direction"),
    ),
    &declaration!("special_lane", "a lane with a special purpose"),
    &declaration!(
        "traffic_sign",
        "a traffic sign",
        field!("conflicts_with", SymbolList in "light_state", "[green]", "light states that contradict it"),
        field!("opendrive_type", Integer, "206", "its OpenDRIVE signal type (a map's signals of that type are it)"),
    ),
    &declaration!(
        "light_state",
        "the state of the traffic light facing the ego vehicle",
        field!("present", Flag, "no", "whether there is a light at all (default `yes`)"),
        field!("signal", one of Signal, "red", "what the light shows: `green`, `red`, `yellow` or `off`"),
    ),
    &declaration!("traffic_density", "how dense the traffic is"),
    &declaration!("hazard", "an accident or other hazard on the road"),
    &declaration!("roadwork", "roadworks or a lane closure"),
    &declaration!("emergency_vehicle", "a kind of emergency vehicle"),
    &declaration!(
        "roadside",
        "something that lines the road",
        field!("walkway", Flag, "yes", "whether it is a path for pedestrians along the road (default `no`)"),
    ),
    &declaration!(
        "region",
        "a region scenarios come from",
        field!("style", Symbol, "metropolitan", "its kind of region"),
        field!(
            "module",
            Symbol,
            "national_park",
            "the standard module with the region's own vocabulary, in scope for its scenarios"
        ),
    ),
    &declaration!(
        "actor_kind",
        "a broad class of actors that share behaviors",
        field!("max_speed", Speed, "45 km/h", "the physical limit: no actor of the kind is faster"),
        field!("simulated_as", one of SimulatedAs, "car", "how a type of this kind without its own is simulated"),
        field!(
            "carla_blueprint",
            Text,
            "\"vehicle.toyota.prius\"",
            "the CARLA blueprint of a type of this kind without its own"
        ),
        field!("carla_note", Text, "\"...\"", "why that blueprint only approximates such a type"),
    ),
    &declaration!(
        "actor_type",
        "a type of actor with its physical attributes",
        field!("kind", Symbol in "actor_kind", "vehicle", "its class"),
        field!("length", Length, "4.6 m", "its length"),
        field!("width", Length, "1.8 m", "its width"),
        field!("height", Length, "1.5 m", "its height"),
        field!("typical_speed", Speed, "40 km/h", "its usual speed"),
        field!("max_speed", Speed, "180 km/h", "the highest plausible speed"),
        field!("simulated_as", one of SimulatedAs, "car", "how it is simulated: `car`, `pedestrian` or `object`"),
        field!("carla_blueprint", Text, "\"vehicle.tesla.model3\"", "the CARLA 0.9.15 blueprint of its actor"),
        field!("carla_note", Text, "\"...\"", "why the CARLA actor only approximates it"),
    ),
    &declaration!(
        "behavior",
        "something an actor does",
        field!("performers", SymbolList in "actor_kind", "[vehicle]", "the actor kinds that can do it"),
        field!("max_speed", Speed, "0 km/h", "the highest speed compatible with it"),
        field!("motion", one of Motion, "follow", "its class of motion, for simulators"),
    ),
    &declaration!(
        "relation",
        "where something is relative to a reference",
        field!("lateral", one of Lateral, "left", "across the road: `left`, `right`, `same` or `opposite`"),
        field!("longitudinal", one of Longitudinal, "front", "along the road: `front`, `behind` or `same`"),
    ),
    &declaration!(
        "road_element",
        "a point of the road a position can refer to",
        field!("at_junction", Flag, "yes", "whether it is at the junction ahead (default `no`)"),
    ),
    &declaration!(
        "reference",
        "a built-in reference point (`ego`)",
        field!("actor_type", Symbol in "actor_type", "car", "the actor type it is, for its size and speed"),
    ),
];

pub fn declaration(kind: &str) -> Option<&'static SectionDef> {
    DECLARATIONS.iter().copied().find(|d| d.name == kind)
}

/// Field names other notations use (TrafficAlign's YAML, TrafficComposer's IR) and the
/// TAD field each means, for suggestions.
pub const FIELD_ALIASES: &[(&str, &str)] = &[
    ("lane_number", "lanes"),
    ("lane_num", "lanes"),
    ("num_lanes", "lanes"),
    ("road_type", "type"),
    ("road_context", "context"),
    ("traffic_sign", "signs"),
    ("traffic_signs", "signs"),
    ("traffic_light", "light"),
    ("special_lane", "special_lanes"),
    ("one_way_or_two_way", "direction"),
    ("lane_index", "lane"),
    ("lane_idx", "lane"),
    ("position_relation", "position"),
    ("position_target", "position"),
    ("relation", "position"),
    ("time_of_day", "time"),
    ("current_behavior", "behavior"),
    ("behaviour", "behavior"),
    ("velocity", "speed"),
    ("density", "traffic"),
];

/// The sections a scenario may contain, in canonical order.
pub const SECTIONS: &[&SectionDef] = &[&SOURCE, &ENVIRONMENT, &ROAD, &EGO];

pub fn section(name: &str) -> Option<&'static SectionDef> {
    SECTIONS.iter().copied().find(|s| s.name == name)
}

/// Physical units, by the quantity they measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Unit {
    KilometresPerHour,
    MilesPerHour,
    MetresPerSecond,
    Metres,
    Seconds,
}

impl Unit {
    pub fn parse(text: &str) -> Option<Unit> {
        Some(match text {
            "km/h" => Unit::KilometresPerHour,
            "mph" => Unit::MilesPerHour,
            "m/s" => Unit::MetresPerSecond,
            "m" => Unit::Metres,
            "s" => Unit::Seconds,
            _ => return None,
        })
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Unit::KilometresPerHour => "km/h",
            Unit::MilesPerHour => "mph",
            Unit::MetresPerSecond => "m/s",
            Unit::Metres => "m",
            Unit::Seconds => "s",
        }
    }

    /// The value type this unit measures.
    pub fn measures(self) -> ValueType {
        match self {
            Unit::KilometresPerHour | Unit::MilesPerHour | Unit::MetresPerSecond => ValueType::Speed,
            Unit::Metres => ValueType::Length,
            Unit::Seconds => ValueType::Duration,
        }
    }

    /// Multiply by this to get SI units (m/s, m, s).
    pub fn to_si(self) -> f64 {
        match self {
            Unit::KilometresPerHour => 1000.0 / 3600.0,
            Unit::MilesPerHour => 1609.344 / 3600.0,
            Unit::MetresPerSecond | Unit::Metres | Unit::Seconds => 1.0,
        }
    }
}
