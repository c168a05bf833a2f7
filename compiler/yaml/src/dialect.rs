//! The YAML dialects' keys, in one declarative table.
//!
//! [`KEYS`] has one row per key of each place of the YAML form (the top level,
//! `environment`, `road_network`, the ego vehicle, an actor group, `source`): how it is
//! spelt, which other spellings are read as it, which spellings only suggest it, which
//! form it comes from, which TAD section and field it states (a name of
//! [`tad_syntax::schema`], whose `FieldDef` gives the TAD kind of the value), the YAML
//! value form where that is not just TAD's kind, whether and where `export` writes it,
//! and whether it identifies TrafficComposer's dialect.
//!
//! Everything else reads this table: import looks keys up in it ([`find`]), offers its
//! keys in "did you mean" and in the notes of E0302 ([`offered`], [`hint`]), detects the
//! dialect ([`identifies`]) and finds the YAML in an answer ([`is_top_level`]); export
//! writes a place's keys in the table's export order ([`written`]). `spec/yaml.md` §3's
//! tables list the same keys, and a test holds them to this table.
//!
//! Rows are in the order keys are offered in suggestions and notes; a key that several
//! places have (`time`) has one row in each. Keys match after [`normalize`] (`One-Way` is
//! `one_way`).

use crate::norm::normalize;
use tad_syntax::schema::{self, FieldDef, SectionDef};

/// Which notation a YAML answer is written in, detected from its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dialect {
    /// TrafficAlign's translation prompt: `environment`, `road_network` (a mapping),
    /// `actors`. Also what [`crate::export`] writes.
    TrafficAlign,
    /// TrafficComposer's IR: `participant`, and in its older form a top-level `weather`,
    /// `lane_num`, `traffic_signal` and `road_network` as a list of strings.
    TrafficComposer,
}

/// Where a key is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Place {
    /// The top-level mapping.
    Top,
    /// `environment`.
    Environment,
    /// `road_network` (a mapping).
    Road,
    /// The ego vehicle's mapping in `actors` (`ego_vehicle`, `ego vehicle`, `ego`).
    Ego,
    /// An actor group's mapping in `actors` (any other key).
    Actor,
    /// `source`.
    Source,
}

impl Place {
    /// The TAD section whose fields the place's keys state (`actor` for an actor group).
    pub fn section(self) -> Option<&'static SectionDef> {
        match self {
            Place::Top => None,
            Place::Environment => Some(&schema::ENVIRONMENT),
            Place::Road => Some(&schema::ROAD),
            Place::Ego => Some(&schema::EGO),
            Place::Actor => Some(&schema::ACTOR),
            Place::Source => Some(&schema::SOURCE),
        }
    }
}

/// Which form a key belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Origin {
    /// TrafficAlign's translation prompt (the paper's form).
    TrafficAlign,
    /// TrafficComposer's IR.
    TrafficComposer,
    /// The extra keys `export` adds for what TrafficAlign's form lacks; TAD-named, so
    /// they win over a paper key that states the same field.
    Extra,
    /// Keys of another place that answers also write here (`traffic_light` at the top).
    Elsewhere,
}

/// What a key means in TAD.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tad {
    /// A field of a TAD section (`actor` for an actor group's fields).
    Field(&'static SectionDef, &'static str),
    /// A mapping of the keys of another place.
    Block(Place),
    /// The actor groups: a mapping from actor keys (the ego vehicle's among them) to
    /// their mappings.
    Actors,
    /// The scenario's name.
    ScenarioName,
    /// The `use` declarations.
    Uses,
    /// The camera rules to check the file with ([`crate::PROFILES`]): what `export` writes
    /// so that its YAML is checked as its TAD source, not as a dash-cam answer.
    Profile,
    /// An actor group's type (in the TAD header); the ego vehicle has none.
    Type,
    /// An actor group's count (in the TAD header); there is one ego vehicle.
    Count,
    /// Nothing: the ego vehicle's position (other actors are placed relative to it).
    Nothing,
}

/// The YAML form of a key's value, where it is not just the TAD kind of its field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// The TAD field's kind (`schema::FieldDef::ty`), TAD's names in the paper's spelling
    /// (`straight road`); a bare number is km/h for a speed and seconds for a duration.
    Value,
    /// A mapping of keys (or, for `road_network` in TrafficComposer's form, a list of
    /// strings such as `two lane road`, `traffic light`, `stop sign`).
    Mapping,
    /// A name; in TrafficComposer's form free text whose time-of-day words (`night`) set
    /// `environment { time }`.
    Weather,
    /// Free text split into the road type, the direction and special lanes
    /// (`two-way straight road with bike lane`); written as the road type alone.
    RoadType,
    /// A name written with `-` (`two-way`).
    Direction,
    /// One sign, `none` (`[]`) or a list or comma-separated string of them; written as
    /// `none`, the only sign or the first one (the full list then goes in `signs`).
    SignSummary,
    /// The relation part of a position (`left front`); without a target, relative to ego.
    Relation,
    /// The reference part of a position: the ego vehicle, an actor key or a road element.
    Target,
    /// A value that means nothing in TAD and is expected to be this one (other values are
    /// W0302); `export` writes it.
    Fixed(&'static str),
}

/// Whether a key identifies a dialect.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Identifies {
    No,
    /// Whenever it is written at its place.
    Always(Dialect),
    /// When its value is a list.
    AsList(Dialect),
}

/// One key of one place.
#[derive(Clone, Copy, Debug)]
pub struct Key {
    pub place: Place,
    /// The key as its form spells it.
    pub key: &'static str,
    /// Other spellings read as this key (not offered in suggestions).
    pub aliases: &'static [&'static str],
    /// Spellings that are not keys here but suggest this one (`lanes` → `lane_number`).
    pub hints: &'static [&'static str],
    pub origin: Origin,
    pub tad: Tad,
    pub form: Form,
    /// Offered in suggestions and in the list of a place's keys.
    pub offered: bool,
    /// The position among its mapping's keys at which `export` writes it, if it does.
    pub export: Option<u8>,
    pub identifies: Identifies,
}

impl Key {
    /// The TAD field the key states, if it states one.
    pub fn field(&self) -> Option<&'static FieldDef> {
        match self.tad {
            Tad::Field(section, name) => section.field(name),
            _ => None,
        }
    }

    /// Whether `key` (as written) is this key or one of its aliases.
    pub fn matches(&self, key: &str) -> bool {
        let key = normalize(key);
        normalize(self.key) == key || self.aliases.iter().any(|a| normalize(a) == key)
    }
}

const KEY: Key = Key {
    place: Place::Top,
    key: "",
    aliases: &[],
    hints: &[],
    origin: Origin::TrafficAlign,
    tad: Tad::Nothing,
    form: Form::Value,
    offered: true,
    export: None,
    identifies: Identifies::No,
};

use Origin::{Elsewhere, Extra, TrafficComposer as Composer};
use Place::*;
use schema::{ACTOR, ENVIRONMENT as ENV, SOURCE as SRC};

const ROAD_DEF: &SectionDef = &schema::ROAD;
const EGO_DEF: &SectionDef = &schema::EGO;
const TC: Identifies = Identifies::Always(Dialect::TrafficComposer);

const TIME_HINTS: &[&str] = &["time_of_day"];
const LIGHT_HINTS: &[&str] = &["light", "traffic_lights"];
const SIGN_HINTS: &[&str] = &["traffic_signs"];
const BEHAVIOR_HINTS: &[&str] = &["behaviour", "action"];
const CURRENT_BEHAVIOR_HINTS: &[&str] = &["current_behaviour"];
const LANE_HINTS: &[&str] = &["lane"];
const RELATION_HINTS: &[&str] = &["position", "relation"];
const TARGET_HINTS: &[&str] = &["target"];
const TYPE_HINTS: &[&str] = &["kind"];
const SPEED_HINTS: &[&str] = &["velocity"];

/// The key under `actors` that `export` writes for the ego vehicle (import also reads the
/// spellings of [`crate::norm::is_ego`]).
pub const EGO_KEY: &str = "ego_vehicle";

/// Every key of every place.
#[rustfmt::skip]
pub const KEYS: &[Key] = &[
    // ---- the top level
    Key { key: "environment", tad: Tad::Block(Environment), form: Form::Mapping, export: Some(5), ..KEY },
    Key { key: "road_network", hints: &["road"], tad: Tad::Block(Road), form: Form::Mapping, export: Some(6),
          identifies: Identifies::AsList(Dialect::TrafficComposer), ..KEY },
    Key { key: "actors", hints: &["ego", "npcs"], tad: Tad::Actors, form: Form::Mapping, export: Some(7), ..KEY },
    Key { key: "source", origin: Extra, tad: Tad::Block(Source), form: Form::Mapping, export: Some(4), ..KEY },
    Key { key: "profile", origin: Extra, tad: Tad::Profile, export: Some(1), ..KEY },
    Key { key: "scenario", origin: Extra, tad: Tad::ScenarioName, export: Some(2), ..KEY },
    Key { key: "use", origin: Extra, tad: Tad::Uses, export: Some(3), ..KEY },
    Key { key: "participant", aliases: &["participants"], origin: Composer, tad: Tad::Actors, form: Form::Mapping,
          identifies: TC, ..KEY },
    Key { key: "weather", origin: Composer, tad: Tad::Field(&ENV, "weather"), form: Form::Weather, identifies: TC, ..KEY },
    Key { key: "time", hints: TIME_HINTS, origin: Elsewhere, tad: Tad::Field(&ENV, "time"), ..KEY },
    Key { key: "lane_num", origin: Composer, tad: Tad::Field(ROAD_DEF, "lanes"), identifies: TC, ..KEY },
    Key { key: "traffic_signal", origin: Composer, tad: Tad::Field(ROAD_DEF, "light"), identifies: TC, ..KEY },
    Key { key: "traffic_light", hints: LIGHT_HINTS, origin: Elsewhere, tad: Tad::Field(ROAD_DEF, "light"), ..KEY },
    Key { key: "traffic_sign", hints: SIGN_HINTS, origin: Elsewhere, tad: Tad::Field(ROAD_DEF, "signs"),
          form: Form::SignSummary, ..KEY },
    // ---- environment
    Key { place: Environment, key: "weather", tad: Tad::Field(&ENV, "weather"), form: Form::Weather, export: Some(1), ..KEY },
    Key { place: Environment, key: "time", hints: TIME_HINTS, tad: Tad::Field(&ENV, "time"), export: Some(2), ..KEY },
    // ---- road_network
    Key { place: Road, key: "road_type", hints: &["type"], tad: Tad::Field(ROAD_DEF, "type"), form: Form::RoadType,
          export: Some(1), ..KEY },
    Key { place: Road, key: "road_context", hints: &["context"], tad: Tad::Field(ROAD_DEF, "context"), export: Some(2), ..KEY },
    Key { place: Road, key: "traffic_sign", hints: SIGN_HINTS, tad: Tad::Field(ROAD_DEF, "signs"), form: Form::SignSummary,
          export: Some(3), ..KEY },
    Key { place: Road, key: "traffic_light", hints: LIGHT_HINTS, tad: Tad::Field(ROAD_DEF, "light"), export: Some(5), ..KEY },
    Key { place: Road, key: "lane_number", aliases: &["lane_num"], hints: &["lanes", "num_lanes", "number_of_lanes"],
          tad: Tad::Field(ROAD_DEF, "lanes"), export: Some(6), ..KEY },
    Key { place: Road, key: "one-way_or_two-way", hints: &["direction"], tad: Tad::Field(ROAD_DEF, "direction"),
          form: Form::Direction, export: Some(7), ..KEY },
    Key { place: Road, key: "special_lane", tad: Tad::Field(ROAD_DEF, "special_lanes"), ..KEY },
    Key { place: Road, key: "special_lanes", origin: Extra, tad: Tad::Field(ROAD_DEF, "special_lanes"), export: Some(8), ..KEY },
    Key { place: Road, key: "signs", origin: Extra, tad: Tad::Field(ROAD_DEF, "signs"), export: Some(4), ..KEY },
    Key { place: Road, key: "traffic", origin: Extra, tad: Tad::Field(ROAD_DEF, "traffic"), export: Some(9), ..KEY },
    Key { place: Road, key: "hazards", origin: Extra, tad: Tad::Field(ROAD_DEF, "hazards"), export: Some(10), ..KEY },
    Key { place: Road, key: "roadworks", origin: Extra, tad: Tad::Field(ROAD_DEF, "roadworks"), export: Some(11), ..KEY },
    Key { place: Road, key: "emergency_vehicles", origin: Extra, tad: Tad::Field(ROAD_DEF, "emergency_vehicles"),
          export: Some(12), ..KEY },
    Key { place: Road, key: "roadside", origin: Extra, tad: Tad::Field(ROAD_DEF, "roadside"), export: Some(13), ..KEY },
    // ---- the ego vehicle
    Key { place: Ego, key: "type", hints: TYPE_HINTS, tad: Tad::Type, form: Form::Fixed("none"), export: Some(1), ..KEY },
    Key { place: Ego, key: "behavior", hints: BEHAVIOR_HINTS, tad: Tad::Field(EGO_DEF, "behavior"), export: Some(2), ..KEY },
    Key { place: Ego, key: "current_behavior", hints: CURRENT_BEHAVIOR_HINTS, origin: Composer,
          tad: Tad::Field(EGO_DEF, "behavior"), ..KEY },
    Key { place: Ego, key: "speed", hints: SPEED_HINTS, tad: Tad::Field(EGO_DEF, "speed"), export: Some(3), ..KEY },
    Key { place: Ego, key: "position_target", hints: TARGET_HINTS, form: Form::Fixed("unspecified"), export: Some(4), ..KEY },
    Key { place: Ego, key: "position_relation", hints: RELATION_HINTS, form: Form::Fixed("unspecified"), export: Some(5),
          ..KEY },
    Key { place: Ego, key: "lane_index", hints: LANE_HINTS, tad: Tad::Field(EGO_DEF, "lane"), export: Some(6), ..KEY },
    Key { place: Ego, key: "lane_idx", origin: Composer, tad: Tad::Field(EGO_DEF, "lane"), ..KEY },
    Key { place: Ego, key: "number", tad: Tad::Count, form: Form::Fixed("1"), offered: false, ..KEY },
    // ---- an actor group
    Key { place: Actor, key: "type", hints: TYPE_HINTS, tad: Tad::Type, export: Some(1), ..KEY },
    Key { place: Actor, key: "number", hints: &["count"], tad: Tad::Count, export: Some(2), ..KEY },
    Key { place: Actor, key: "behavior", hints: BEHAVIOR_HINTS, tad: Tad::Field(&ACTOR, "behavior"), export: Some(3), ..KEY },
    Key { place: Actor, key: "current_behavior", hints: CURRENT_BEHAVIOR_HINTS, origin: Composer,
          tad: Tad::Field(&ACTOR, "behavior"), ..KEY },
    Key { place: Actor, key: "speed", hints: SPEED_HINTS, tad: Tad::Field(&ACTOR, "speed"), export: Some(4), ..KEY },
    Key { place: Actor, key: "position_target", hints: TARGET_HINTS, tad: Tad::Field(&ACTOR, "position"),
          form: Form::Target, export: Some(5), ..KEY },
    Key { place: Actor, key: "position_relation", hints: RELATION_HINTS, tad: Tad::Field(&ACTOR, "position"),
          form: Form::Relation, export: Some(6), ..KEY },
    Key { place: Actor, key: "lane_index", hints: LANE_HINTS, tad: Tad::Field(&ACTOR, "lane"), export: Some(7), ..KEY },
    Key { place: Actor, key: "lane_idx", origin: Composer, tad: Tad::Field(&ACTOR, "lane"), ..KEY },
    Key { place: Actor, key: "distance", origin: Extra, tad: Tad::Field(&ACTOR, "distance"), export: Some(8), ..KEY },
    Key { place: Actor, key: "delay", origin: Extra, tad: Tad::Field(&ACTOR, "delay"), export: Some(9), ..KEY },
    Key { place: Actor, key: "trigger", origin: Extra, tad: Tad::Field(&ACTOR, "trigger"), export: Some(10), ..KEY },
    Key { place: Actor, key: "offset", origin: Extra, tad: Tad::Field(&ACTOR, "offset"), export: Some(11), ..KEY },
    // ---- source
    Key { place: Source, key: "video", origin: Extra, tad: Tad::Field(&SRC, "video"), export: Some(1), ..KEY },
    Key { place: Source, key: "time", hints: TIME_HINTS, origin: Extra, tad: Tad::Field(&SRC, "time"), export: Some(2), ..KEY },
    Key { place: Source, key: "frame", origin: Extra, tad: Tad::Field(&SRC, "frame"), export: Some(3), ..KEY },
    Key { place: Source, key: "region", origin: Extra, tad: Tad::Field(&SRC, "region"), export: Some(4), ..KEY },
    Key { place: Source, key: "description", origin: Extra, tad: Tad::Field(&SRC, "description"), export: Some(5), ..KEY },
];

/// The keys of `place`, in table order.
pub fn keys(place: Place) -> impl Iterator<Item = &'static Key> {
    KEYS.iter().filter(move |k| k.place == place)
}

/// The row of `key` (as written, or an alias) at `place`.
pub fn find(place: Place, key: &str) -> Option<&'static Key> {
    keys(place).find(|k| k.matches(key))
}

/// The keys offered at `place` in suggestions and in notes, in table order.
pub fn offered(place: Place) -> Vec<&'static str> {
    keys(place).filter(|k| k.offered).map(|k| k.key).collect()
}

/// The offered key at `place` that the unknown key `key` is another spelling of.
pub fn hint(place: Place, key: &str) -> Option<&'static str> {
    let key = normalize(key);
    keys(place).filter(|k| k.offered).find(|k| k.hints.iter().any(|h| normalize(h) == key)).map(|k| k.key)
}

/// The keys `export` writes at `place`, in the order it writes them.
pub fn written(place: Place) -> Vec<&'static Key> {
    let mut out: Vec<&'static Key> = keys(place).filter(|k| k.export.is_some()).collect();
    out.sort_by_key(|k| k.export);
    out
}

/// Whether `key` is a top-level key of one of the forms (not one read there from another
/// place), which marks text as a YAML scenario. Aliases count when `aliases` is set.
pub fn is_top_level(key: &str, aliases: bool) -> bool {
    let key = normalize(key);
    keys(Top)
        .filter(|k| k.origin != Elsewhere)
        .any(|k| normalize(k.key) == key || (aliases && k.aliases.iter().any(|a| normalize(a) == key)))
}

/// The dialect a top-level key identifies, given whether its value is a list.
pub fn identifies(key: &str, list: bool) -> Option<Dialect> {
    match find(Top, key)?.identifies {
        Identifies::Always(d) => Some(d),
        Identifies::AsList(d) if list => Some(d),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_is_in_the_schema_and_keys_are_unique() {
        for k in KEYS {
            if let Tad::Field(section, name) = k.tad {
                assert!(k.field().is_some(), "{:?} `{}`: no field `{name}` in `{}`", k.place, k.key, section.name);
            }
            let others = KEYS.iter().filter(|o| o.place == k.place);
            let spellings =
                |o: &Key| std::iter::once(o.key).chain(o.aliases.iter().copied()).map(normalize).collect::<Vec<_>>();
            for o in others.filter(|o| !std::ptr::eq(*o, k)) {
                assert!(spellings(k).iter().all(|s| !spellings(o).contains(s)), "{:?} `{}` twice", k.place, k.key);
            }
        }
    }

    #[test]
    fn export_positions_are_distinct() {
        for place in [Top, Environment, Road, Ego, Actor, Source] {
            let positions: Vec<u8> = written(place).iter().filter_map(|k| k.export).collect();
            assert_eq!(positions, (1..=positions.len() as u8).collect::<Vec<_>>(), "{place:?}");
        }
    }
}
