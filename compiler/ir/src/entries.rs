//! The vocabulary a scenario sees, as typed tables addressed by [`Id`]s.
//!
//! One [`Table`] per declaration kind of `schema::DECLARATIONS`, in the vocabulary's order
//! (the prelude, the modules used, the file itself), holding every entry, not only those
//! the scenario names, so consumers can search a kind (the relation with given parts, the
//! names to complete). A kind is a type ([`ActorType`], [`Behavior`], ...) holding the
//! attributes its declarations take, typed: quantities in SI, flags with their defaults
//! applied, closed sets as enums, and names of other kinds as ids. An `Id<K>` indexes only
//! the table of `K`. A name a declaration refers to that resolves to nothing is left out
//! (the checker reports it).

use crate::quantity::{Metres, MetresPerSecond};
use std::fmt;
use std::hash::{Hash, Hasher};
use std::marker::PhantomData;
use std::ops::Index;
use tad_diagnostics::Span;
use tad_syntax::schema::{Lateral, Longitudinal, Motion, RoadShape, Signal, SimulatedAs};

/// The index of an item of type `K` in its table (for a [`crate::Group`], in the
/// scenario's groups). Ids are made by [`crate::resolve`] and are valid for the scenario
/// they come from.
pub struct Id<K> {
    index: usize,
    kind: PhantomData<fn() -> K>,
}

impl<K> Id<K> {
    pub(crate) fn new(index: usize) -> Self {
        Id { index, kind: PhantomData }
    }

    pub fn index(self) -> usize {
        self.index
    }
}

impl<K> Clone for Id<K> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<K> Copy for Id<K> {}

impl<K> PartialEq for Id<K> {
    fn eq(&self, other: &Self) -> bool {
        self.index == other.index
    }
}

impl<K> Eq for Id<K> {}

impl<K> PartialOrd for Id<K> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl<K> Ord for Id<K> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.index.cmp(&other.index)
    }
}

impl<K> Hash for Id<K> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.index.hash(state);
    }
}

impl<K> fmt::Debug for Id<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = std::any::type_name::<K>().rsplit("::").next().unwrap_or("?");
        write!(f, "Id<{kind}>({})", self.index)
    }
}

/// One declared name.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry<K> {
    /// The canonical name (aliases resolve to it).
    pub name: String,
    /// The module that declares it: `core`, `national_park`, or the file's own name.
    pub module: String,
    /// The whole declaration, in the declaring module's file.
    pub span: Span,
    /// The declaring module's file.
    pub file: tad_diagnostics::FileId,
    pub attrs: K,
}

/// The entries of one kind, in vocabulary order.
#[derive(Clone, Debug, PartialEq)]
pub struct Table<K> {
    pub(crate) entries: Vec<Entry<K>>,
}

impl<K> Default for Table<K> {
    fn default() -> Self {
        Table { entries: Vec::new() }
    }
}

impl<K> Table<K> {
    pub fn get(&self, id: Id<K>) -> Option<&Entry<K>> {
        self.entries.get(id.index)
    }

    /// The entry with this canonical name.
    pub fn find(&self, name: &str) -> Option<Id<K>> {
        self.entries.iter().position(|e| e.name == name).map(Id::new)
    }

    pub fn iter(&self) -> impl Iterator<Item = (Id<K>, &Entry<K>)> {
        self.entries.iter().enumerate().map(|(i, e)| (Id::new(i), e))
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// Panics on an id of another scenario, like a slice index out of bounds; [`Table::get`]
/// does not.
impl<K> Index<Id<K>> for Table<K> {
    type Output = Entry<K>;

    fn index(&self, id: Id<K>) -> &Entry<K> {
        &self.entries[id.index]
    }
}

/// A declaration kind: the type of its attributes, and where its table is.
pub trait Kind: Sized {
    /// The kind's name in `schema::DECLARATIONS`.
    const KIND: &'static str;
    fn table(entries: &Entries) -> &Table<Self>;
}

/// A name written in the scenario: resolved to its entry (directly or through an alias),
/// or unknown as written (the checker reports it).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Named<K> {
    Known(Id<K>),
    Unknown(String),
}

impl<K> Named<K> {
    pub fn id(&self) -> Option<Id<K>> {
        match self {
            Named::Known(id) => Some(*id),
            Named::Unknown(_) => None,
        }
    }
}

macro_rules! kinds {
    ($($(#[$doc:meta])* $kind:ident = $name:literal in $table:ident;)+) => {
        /// Every declared name the scenario's file sees, one table per kind.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct Entries {
            $(pub $table: Table<$kind>,)+
        }

        impl Entries {
            /// The declaration kinds, in the order of the tables.
            pub const KINDS: &'static [&'static str] = &[$($name),+];
        }

        $(
            impl Kind for $kind {
                const KIND: &'static str = $name;
                fn table(entries: &Entries) -> &Table<Self> {
                    &entries.$table
                }
            }
        )+
    };
}

kinds! {
    Weather = "weather" in weather;
    TimeOfDay = "time_of_day" in times_of_day;
    RoadType = "road_type" in road_types;
    RoadContext = "road_context" in road_contexts;
    Direction = "direction" in directions;
    SpecialLane = "special_lane" in special_lanes;
    TrafficSign = "traffic_sign" in traffic_signs;
    LightState = "light_state" in light_states;
    TrafficDensity = "traffic_density" in traffic_densities;
    Hazard = "hazard" in hazards;
    Roadwork = "roadwork" in roadworks;
    EmergencyVehicle = "emergency_vehicle" in emergency_vehicles;
    Roadside = "roadside" in roadsides;
    Region = "region" in regions;
    ActorKind = "actor_kind" in actor_kinds;
    ActorType = "actor_type" in actor_types;
    Behavior = "behavior" in behaviors;
    Relation = "relation" in relations;
    RoadElement = "road_element" in road_elements;
    ReferencePoint = "reference" in reference_points;
}

impl Entries {
    pub fn table<K: Kind>(&self) -> &Table<K> {
        K::table(self)
    }

    pub fn get<K: Kind>(&self, id: Id<K>) -> Option<&Entry<K>> {
        K::table(self).get(id)
    }

    /// The entry a written name resolved to.
    pub fn resolved<K: Kind>(&self, named: &Named<K>) -> Option<&Entry<K>> {
        self.get(named.id()?)
    }

    /// The canonical name of a resolved name, or the unknown name as written.
    pub fn name<'a, K: Kind>(&'a self, named: &'a Named<K>) -> &'a str {
        match named {
            Named::Known(id) => self.get(*id).map_or("", |e| e.name.as_str()),
            Named::Unknown(name) => name,
        }
    }
}

impl<K: Kind> Index<Id<K>> for Entries {
    type Output = Entry<K>;

    fn index(&self, id: Id<K>) -> &Entry<K> {
        &K::table(self)[id]
    }
}

/// Kinds known by name only.
macro_rules! name_only {
    ($($(#[$doc:meta])* $kind:ident;)+) => {
        $(
            $(#[$doc])*
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
            pub struct $kind;
        )+
    };
}

name_only! {
    SpecialLane;
    TrafficDensity;
    Hazard;
    Roadwork;
    EmergencyVehicle;
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Roadside {
    /// It is a path for pedestrians along the road (default no).
    pub walkway: bool,
}

/// A weather's sky and road, on the 0 (none) to 100 (most) scales of CARLA's weather
/// parameters; `None` when not declared.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Weather {
    pub cloudiness: Option<i64>,
    pub precipitation: Option<i64>,
    pub precipitation_deposits: Option<i64>,
    pub wetness: Option<i64>,
    pub wind_intensity: Option<i64>,
    pub fog_density: Option<i64>,
    /// Where the fog begins.
    pub fog_distance: Option<Metres>,
}

impl Weather {
    /// Whether any parameter is declared.
    pub fn is_described(&self) -> bool {
        *self != Weather::default()
    }
}

/// Where the sun is, in degrees; `None` when not declared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct TimeOfDay {
    /// Above the horizon (negative: below).
    pub sun_altitude: Option<i64>,
    pub sun_azimuth: Option<i64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RoadType {
    /// Roads meet or cross in it (default no).
    pub junction: bool,
    /// Traffic lights can control it (default yes).
    pub signalised: bool,
    /// For a junction: how many road arms meet in it; `None` when not declared.
    pub arms: Option<i64>,
    /// `None` when not declared.
    pub shape: Option<RoadShape>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RoadContext {
    pub max_speed: Option<MetresPerSecond>,
    /// Traffic lights occur there (default yes).
    pub signalised: bool,
    /// The CARLA towns that look most like it, best first (none declared: empty).
    pub carla_towns: Vec<String>,
    /// What the CARLA towns cannot show of it.
    pub carla_note: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Direction {
    /// The road has lanes for the opposite direction; `None` when not declared.
    pub opposite_lanes: Option<bool>,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct TrafficSign {
    /// Light states that contradict it.
    pub conflicts_with: Vec<Id<LightState>>,
    /// Its OpenDRIVE signal type (`206` a stop sign); `None` when not declared.
    pub opendrive_type: Option<i64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LightState {
    /// There is a light at all (default yes; `none` has no).
    pub present: bool,
    /// What the light shows; `None` when not declared.
    pub signal: Option<Signal>,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Region {
    /// Its kind of region, a free name (`metropolitan`).
    pub style: Option<String>,
}

/// How a simulator shows an actor: its body and the CARLA actor standing for it. Every
/// field is `None` when not declared.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Simulation {
    pub simulated_as: Option<SimulatedAs>,
    /// A CARLA 0.9.15 blueprint name (`vehicle.tesla.model3`).
    pub carla_blueprint: Option<String>,
    /// Why the CARLA actor only approximates it.
    pub carla_note: Option<String>,
}

/// A broad class of actors; its [`Simulation`] is for types of the kind that declare none.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct ActorKind {
    pub simulation: Simulation,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ActorType {
    pub kind: Option<Id<ActorKind>>,
    pub length: Option<Metres>,
    pub width: Option<Metres>,
    pub height: Option<Metres>,
    pub typical_speed: Option<MetresPerSecond>,
    pub max_speed: Option<MetresPerSecond>,
    pub simulation: Simulation,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Behavior {
    /// The actor kinds that can do it; `None` when not declared (any kind can).
    pub performers: Option<Vec<Id<ActorKind>>>,
    pub max_speed: Option<MetresPerSecond>,
    /// Its class of motion; `None` when not declared.
    pub motion: Option<Motion>,
}

impl Behavior {
    /// Whether an actor of `kind` can do it.
    pub fn performed_by(&self, kind: Id<ActorKind>) -> bool {
        self.performers.as_ref().is_none_or(|p| p.contains(&kind))
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct RoadElement {
    /// It is at the junction ahead (default no).
    pub at_junction: bool,
}

/// A built-in reference point (`ego`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ReferencePoint {
    /// The actor type it is, for its size and speed.
    pub actor_type: Option<Id<ActorType>>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Relation {
    /// `None` when not declared.
    pub lateral: Option<Lateral>,
    /// `None` when not declared.
    pub longitudinal: Option<Longitudinal>,
}
