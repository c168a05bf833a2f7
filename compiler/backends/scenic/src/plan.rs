//! From a checked scenario to a plan of the Scenic program: the map and what the ego's
//! surroundings must have, and every actor with its class, size, lane, place along the
//! lane and behavior.
//!
//! Placement is decided here, not sampled: every actor gets a TAD lane index and an offset
//! in metres along the ego's lane from the ego's centre, so actors never overlap and the
//! stretch of road the scenario needs is known before the map is chosen. Only the ego's
//! place on the map is left to Scenic, among places the map table says exist.

use std::collections::HashMap;

use tad_check::{Entry, Vocabulary};
use tad_diagnostics::{Code, Diagnostic, Span};
use tad_syntax::model::{ActorGroup, Attr, Known, Scenario, Symbol, Val};

use crate::mapping::{self, Blueprint, Class, Motion, RoadType};
use crate::maps::{self, JunctionKind, JunctionNeed, Needs, Shape};
use crate::python::Names;
use crate::{EmitOptions, Simulator};

/// The most actors one group becomes.
pub const MAX_GROUP: usize = 20;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// The centre of the lane.
    Centre,
    /// The curb side of the lane, when it is the outermost lane of its direction.
    Curb,
    /// The sidewalk beside the lane, when it is the outermost lane and has one.
    Sidewalk,
}

/// One object of the Scenic program.
#[derive(Clone, Debug)]
pub struct Actor {
    pub ident: String,
    pub class: Class,
    pub blueprint: &'static str,
    pub length: f64,
    pub width: f64,
    /// TAD lane index.
    pub lane: i64,
    /// Metres along the ego's lane from the ego's centre.
    pub offset: f64,
    pub place: Place,
    /// Facing across the road (to the left of its lane's direction) instead of along it.
    pub across: bool,
    /// Initial speed in m/s.
    pub speed: f64,
    /// The Scenic behavior call, if any.
    pub behavior: Option<String>,
}

pub struct Group {
    /// What the source says about the group, for a comment.
    pub summary: String,
    pub actors: Vec<Actor>,
}

pub struct Plan {
    pub scenario: String,
    pub map: String,
    /// Whether the map is one the table describes.
    pub map_known: bool,
    pub needs: Needs,
    pub ego: Actor,
    pub ego_summary: String,
    pub groups: Vec<Group>,
    /// `carla.WeatherParameters` and what they stand for.
    pub weather: Vec<(&'static str, f64)>,
    pub weather_summary: String,
    /// The CARLA light state to hold, and the TAD name it comes from.
    pub light: Option<(&'static str, String)>,
    /// The road features asked for, and those left out, for comments.
    pub kept: Vec<String>,
    pub dropped: Vec<String>,
}

/// Where a position points.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Reference {
    Ego,
    Group(usize),
    /// The stop line of the junction ahead of the ego.
    Junction,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Longitudinal {
    Front,
    Behind,
    Same,
}

/// An actor group with everything resolved but its place.
struct Resolved {
    ident_base: String,
    summary: String,
    blueprint: Blueprint,
    length: f64,
    width: f64,
    count: usize,
    motion: Option<Motion>,
    speed: f64,
    lane: i64,
    reference: Reference,
    longitudinal: Longitudinal,
    span: Span,
}

impl Resolved {
    fn across(&self) -> bool {
        self.motion == Some(Motion::Cross)
    }

    /// Length along the lane: crossing actors stand across it.
    fn extent(&self) -> f64 {
        if self.across() { self.width } else { self.length }
    }

    fn place(&self) -> Place {
        match self.motion {
            Some(Motion::Parked) => Place::Curb,
            Some(Motion::Walk) => Place::Sidewalk,
            _ => Place::Centre,
        }
    }

    /// Bumper-to-bumper gap inside the group.
    fn gap(&self) -> f64 {
        match self.blueprint.class {
            Class::Car => 1.0 + self.speed.min(25.0),
            Class::Pedestrian => 0.5,
            Class::Debris => 1.0,
        }
    }

    /// Gap to the reference.
    fn lead_gap(&self, reference_speed: f64) -> f64 {
        let base = if self.blueprint.class == Class::Car { 2.0 } else { 1.0 };
        (base + self.speed.max(reference_speed)).min(30.0)
    }
}

/// A road feature the scenario asks for, in priority order: when no map has them all, the
/// later ones are left out first.
#[derive(Clone, Debug, PartialEq)]
enum Feature {
    Lanes(u32),
    Other(u32),
    OtherAtLeast(u32),
    Junction(Option<JunctionKind>),
    Turn(char),
    Signalised(bool),
    Sign(&'static str, &'static str),
    Sidewalk,
    Shape(Shape),
}

impl Feature {
    fn apply(&self, needs: &mut Needs) {
        match self {
            Feature::Lanes(n) => needs.same = Some(*n),
            Feature::Other(n) => needs.other = Some(*n),
            Feature::OtherAtLeast(n) => needs.min_other = needs.min_other.max(*n),
            Feature::Junction(kind) => needs.junction.get_or_insert_with(JunctionNeed::default).kind = *kind,
            Feature::Turn(c) => needs.junction.get_or_insert_with(JunctionNeed::default).turn = Some(*c),
            Feature::Signalised(true) => {
                needs.junction.get_or_insert_with(JunctionNeed::default).signalised = Some(true)
            }
            Feature::Signalised(false) => {
                if let Some(junction) = &mut needs.junction {
                    junction.signalised = Some(false)
                }
            }
            Feature::Sign(name, _) => needs.junction.get_or_insert_with(JunctionNeed::default).signs.push(name),
            Feature::Sidewalk => needs.sidewalk = true,
            Feature::Shape(shape) => needs.shape = Some(*shape),
        }
    }

    fn priority(&self) -> u8 {
        match self {
            Feature::Lanes(_) => 0,
            Feature::Other(_) | Feature::OtherAtLeast(_) => 1,
            Feature::Junction(_) => 2,
            Feature::Turn(_) => 3,
            Feature::Signalised(_) => 4,
            Feature::Sign(..) => 5,
            Feature::Sidewalk => 6,
            Feature::Shape(_) => 7,
        }
    }

    fn describe(&self, needs: &Needs) -> String {
        let lanes = |n: u32| if n == 1 { "1 lane".to_string() } else { format!("{n} lanes") };
        match self {
            Feature::Lanes(n) => format!("{} in the ego's direction", lanes(*n)),
            Feature::Other(0) => "a one-way road".into(),
            Feature::Other(n) => format!("{} in the other direction", lanes(*n)),
            Feature::OtherAtLeast(n) => format!("at least {} in the other direction", lanes(*n)),
            Feature::Junction(Some(JunctionKind::Four)) => "a four-way junction".into(),
            Feature::Junction(Some(JunctionKind::Three)) => "a three-way junction".into(),
            Feature::Junction(_) => "a junction ahead".into(),
            Feature::Turn(c) => format!("a {} at the junction ahead", turn_words(*c)),
            Feature::Signalised(true) => "a junction with traffic lights".into(),
            Feature::Signalised(false) => "a junction without traffic lights".into(),
            Feature::Sign(name, _) => format!("a {name} sign at the junction ahead"),
            Feature::Sidewalk => "a sidewalk beside the ego's lane".into(),
            Feature::Shape(Shape::Straight) => format!("a straight stretch of {:.0} m", needs.ahead + needs.behind),
            Feature::Shape(Shape::Curved) => format!("a curved stretch of {:.0} m", needs.ahead + needs.behind),
        }
    }
}

fn turn_words(c: char) -> &'static str {
    match c {
        'L' => "left turn",
        'R' => "right turn",
        'U' => "U-turn",
        _ => "straight crossing",
    }
}

/// The canonical name of `symbol` in vocabulary `kind` (itself when unknown).
fn canonical<'v>(vocabulary: &'v Vocabulary, kind: &str, symbol: &'v Symbol) -> &'v str {
    vocabulary.get(kind, &symbol.name).map_or(symbol.name.as_str(), |e| e.name.as_str())
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}

fn list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.len() {
        0 => String::new(),
        1 => quoted[0].clone(),
        n => format!("{} and {}", quoted[..n - 1].join(", "), quoted[n - 1]),
    }
}

fn kmh(speed: f64) -> String {
    format!("{:.0} km/h", speed * 3.6)
}

/// Notes and help on a diagnostic already pushed.
trait Annotate {
    fn note(self, note: impl Into<String>) -> Self;
    fn help(self, help: impl Into<String>) -> Self;
}

impl Annotate for &mut Diagnostic {
    fn note(self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    fn help(self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
}

pub struct Planner<'a> {
    scenario: &'a Scenario,
    vocabulary: &'a Vocabulary,
    options: &'a EmitOptions,
    pub diagnostics: Vec<Diagnostic>,
}

impl<'a> Planner<'a> {
    pub fn new(scenario: &'a Scenario, vocabulary: &'a Vocabulary, options: &'a EmitOptions) -> Self {
        Planner { scenario, vocabulary, options, diagnostics: Vec::new() }
    }

    fn warn(
        &mut self,
        code: Code,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> &mut Diagnostic {
        self.diagnostics.push(Diagnostic::new(code, message, span, label));
        self.diagnostics.last_mut().expect("just pushed")
    }

    fn attr(&self, section: &str, field: &str) -> Option<&'a Attr> {
        self.scenario.attr(section, field)
    }

    /// A symbol attribute, resolved to its canonical name.
    fn symbol(&self, section: &str, field: &str, kind: &str) -> Option<(&'a str, Span)> {
        let attr = self.attr(section, field)?;
        let symbol = attr.symbol()?;
        Some((canonical(self.vocabulary, kind, symbol), symbol.span))
    }

    /// Report the names of a list field that have no mapping (`mapped` says which do).
    fn unmapped_list(&mut self, field: &str, kind: &str, mapped: impl Fn(&str) -> bool, why: &str) {
        let Some(attr) = self.attr("road", field) else { return };
        let Some(symbols) = attr.symbols() else { return };
        let missing: Vec<&Symbol> = symbols.iter().filter(|s| !mapped(canonical(self.vocabulary, kind, s))).collect();
        let Some(first) = missing.first() else { return };
        let names: Vec<&str> = missing.iter().map(|s| canonical(self.vocabulary, kind, s)).collect();
        let verb = if names.len() == 1 { "has" } else { "have" };
        let message = format!("{} (road {field}) {verb} no Scenic mapping", list(&names));
        let mut d = Diagnostic::new(Code::W0700, message, first.span, "left out of the Scenic program")
            .with_note(why.to_string());
        for other in &missing[1..] {
            d = d.with_secondary(other.span, "left out too");
        }
        self.diagnostics.push(d);
    }

    fn type_entry(&self, group: &ActorGroup) -> (String, Option<&'a Entry>) {
        match &group.kind.value {
            Known::Given(symbol) => {
                let entry = self.vocabulary.get("actor_type", &symbol.name);
                (entry.map_or(symbol.name.clone(), |e| e.name.clone()), entry)
            }
            Known::Unspecified => ("unspecified".to_string(), None),
        }
    }

    fn length_of(entry: Option<&Entry>, field: &str) -> Option<f64> {
        entry.and_then(|e| e.declaration.attr(field)).and_then(|a| a.quantity()).map(|q| q.si()).filter(|v| *v > 0.0)
    }

    /// The speed of an actor: written, else its type's typical speed; never above the
    /// behavior's `max_speed`.
    fn speed_of(&mut self, attr: Option<&Attr>, typical: f64, behavior: Option<&Entry>, who: &str, span: Span) -> f64 {
        let cap = behavior.and_then(|b| b.speed("max_speed")).unwrap_or(f64::INFINITY);
        match attr.and_then(|a| a.quantity()) {
            Some(q) => q.si().max(0.0),
            None => {
                let speed = typical.min(cap).max(0.0);
                let at = attr.map_or(span, |a| a.value_span);
                self.warn(
                    Code::W0706,
                    format!("the speed of {who} is not given"),
                    at,
                    format!("{} chosen", kmh(speed)),
                )
                .note("the actor type's typical speed, capped by the behavior's `max_speed`");
                speed
            }
        }
    }

    fn motion_of(
        &mut self,
        symbol: Option<&Symbol>,
        class: Class,
        who: &str,
        span: Span,
    ) -> (Option<Motion>, Option<&'a Entry>) {
        let Some(symbol) = symbol else {
            let at = span;
            let (motion, name) = match class {
                Class::Car => (Motion::Follow, "go_forward"),
                Class::Pedestrian => (Motion::Stand, "stand"),
                Class::Debris => (Motion::Parked, "parked"),
            };
            self.warn(Code::W0706, format!("the behavior of {who} is not given"), at, format!("`{name}` chosen"));
            return (Some(motion), self.vocabulary.get("behavior", name));
        };
        let entry = self.vocabulary.get("behavior", &symbol.name);
        let name = entry.map_or(symbol.name.as_str(), |e| e.name.as_str());
        let motion = mapping::behavior(name);
        match motion {
            None => {
                self.warn(Code::W0703, format!("behavior `{name}` has no Scenic mapping"), symbol.span, "approximated")
                    .note("it becomes lane following at the actor's speed (standing still at 0 km/h)");
            }
            Some(Motion::Turn('U')) => {
                self.warn(Code::W0703, "a U-turn has no Scenic mapping on these maps", symbol.span, "approximated")
                    .note("no junction of the CARLA maps offers a U-turn maneuver: the actor turns only where its lane has one and follows the lane otherwise");
            }
            Some(m) if class == Class::Debris && !matches!(m, Motion::Parked | Motion::Stop | Motion::Stand) => {
                self.warn(Code::W0703, format!("a static object cannot `{name}`"), symbol.span, "it stands still")
                    .note("static objects become Scenic `Debris`, which does not move");
            }
            _ => {}
        }
        (motion, entry)
    }

    /// The Scenic behavior call for a motion, for an actor of `class`.
    fn behavior_call(motion: Option<Motion>, class: Class, speed: f64) -> Option<String> {
        let v = crate::python::number(speed);
        match class {
            Class::Debris => None,
            Class::Car => Some(match motion {
                Some(Motion::Follow | Motion::Walk | Motion::Graze) => format!("FollowLaneBehavior(target_speed={v})"),
                None if speed > 0.0 => format!("FollowLaneBehavior(target_speed={v})"),
                None | Some(Motion::Stop | Motion::Stand) => "TadStop()".into(),
                Some(Motion::Parked) => "TadParked()".into(),
                Some(Motion::Cross) => format!("TadRide({v})"),
                Some(Motion::Turn(c)) => format!("TadTurn({v}, '{}')", mapping::maneuver(c)),
                Some(Motion::ChangeLane { left }) => {
                    format!("TadChangeLane({v}, {})", if left { "True" } else { "False" })
                }
                Some(Motion::Overtake) => format!("TadOvertake({v})"),
                Some(Motion::Yield) => format!("TadYield({v})"),
                Some(Motion::Reverse) => format!("TadReverse({v})"),
            }),
            Class::Pedestrian => Some(match motion {
                Some(Motion::Stop | Motion::Stand | Motion::Parked | Motion::Yield) => "TadStand()".into(),
                _ if speed <= 0.0 => "TadStand()".into(),
                _ => format!("TadWalk({v})"),
            }),
        }
    }

    /// Whether an actor starts moving at its speed.
    fn starts_moving(motion: Option<Motion>, class: Class) -> bool {
        class == Class::Car
            && matches!(
                motion,
                Some(
                    Motion::Follow
                        | Motion::Turn(_)
                        | Motion::ChangeLane { .. }
                        | Motion::Overtake
                        | Motion::Yield
                        | Motion::Cross
                        | Motion::Walk
                        | Motion::Graze
                ) | None
            )
    }

    pub fn plan(mut self) -> (Plan, Vec<Diagnostic>) {
        let scenario = self.scenario;
        let vocabulary = self.vocabulary;
        let scenario_span = scenario.name.as_ref().map_or(scenario.span, |n| n.span);
        let road_span = scenario.section("road").map_or(scenario_span, |s| s.name_span);
        let mut names = Names::default();
        names.reserve("ego");

        // --- road -------------------------------------------------------------------------
        let lanes_attr = self.attr("road", "lanes");
        let lanes: Option<u32> = lanes_attr.and_then(|a| a.integer()).filter(|n| *n >= 1).map(|n| n.min(1000) as u32);
        let direction = self.symbol("road", "direction", "direction");
        let opposite_lanes =
            direction.and_then(|(d, _)| vocabulary.get("direction", d)).and_then(|e| e.flag("opposite_lanes"));
        let light = self.symbol("road", "light", "light_state");
        let light_present =
            light.map(|(l, _)| vocabulary.get("light_state", l).and_then(|e| e.flag("present")).unwrap_or(true));
        let road_type = self.symbol("road", "type", "road_type");

        // --- ego ------------------------------------------------------------------------------
        let ego_section_span = scenario.section("ego").map_or(scenario_span, |s| s.name_span);
        let car = vocabulary.get("actor_type", "car");
        let ego_length = Self::length_of(car, "length").unwrap_or(4.5);
        let ego_width = Self::length_of(car, "width").unwrap_or(1.8);
        let ego_behavior_symbol = self.attr("ego", "behavior").and_then(|a| a.symbol());
        let behavior_span = self.attr("ego", "behavior").map_or(ego_section_span, |a| a.value_span);
        let (ego_motion, ego_behavior) =
            self.motion_of(ego_behavior_symbol, Class::Car, "the ego vehicle", behavior_span);
        let typical = car.and_then(|c| c.speed("typical_speed")).unwrap_or(50.0 / 3.6);
        let ego_speed =
            self.speed_of(self.attr("ego", "speed"), typical, ego_behavior, "the ego vehicle", ego_section_span);
        let ego_lane = match self.attr("ego", "lane").and_then(|a| a.integer()).filter(|l| *l != 0) {
            Some(lane) => lane,
            None => {
                let lane = lanes.map_or(1, |n| n.div_ceil(2) as i64);
                let at = self.attr("ego", "lane").map_or(ego_section_span, |a| a.value_span);
                self.warn(Code::W0706, "the lane of the ego vehicle is not given", at, format!("lane {lane} chosen"))
                    .note("the middle lane (the left one of the two middle lanes)");
                lane
            }
        };
        let mut ego_lane = if ego_lane < 0 {
            // The ego drives in its own direction: lane indexes are relative to it.
            let at = self.attr("ego", "lane").map_or(ego_section_span, |a| a.value_span);
            self.warn(Code::W0703, "the ego vehicle cannot be in an opposite lane", at, "lane 1 used")
                .note("lane indexes are relative to the ego's direction of travel");
            1
        } else {
            ego_lane
        };

        // --- groups ---------------------------------------------------------------------------
        let index_of: HashMap<&str, usize> =
            scenario.actors.iter().enumerate().map(|(i, g)| (g.name.text.as_str(), i)).collect();
        let mut resolved: Vec<Resolved> = Vec::new();
        let mut references: Vec<Reference> = Vec::new();
        let mut lateral: Vec<Option<String>> = Vec::new();
        for group in &scenario.actors {
            let who = format!("group `{}`", group.name.text);
            let (type_name, entry) = self.type_entry(group);
            let blueprint = match mapping::actor_type(&type_name) {
                Some(b) => b,
                None => mapping::actor_kind(entry.and_then(|e| e.symbol("kind"))),
            };
            if let Some(why) = blueprint.approximation {
                self.warn(
                    Code::W0703,
                    format!("actor type `{type_name}` has no exact Scenic counterpart"),
                    group.kind.span,
                    "approximated",
                )
                .note(why.to_string());
            }
            let (default_length, default_width) = match blueprint.class {
                Class::Car => (4.5, 1.8),
                Class::Pedestrian => (0.5, 0.6),
                Class::Debris => (0.5, 0.5),
            };
            let length = Self::length_of(entry, "length").unwrap_or(default_length);
            let width = Self::length_of(entry, "width").unwrap_or(default_width);
            let count = match group.count() {
                Some(n) if n >= 1 => n as usize,
                Some(_) => 1,
                None => {
                    let at = group.count.as_ref().map_or(group.name.span, |c| c.span);
                    self.warn(Code::W0706, format!("the number of actors of {who} is not given"), at, "1 chosen");
                    1
                }
            };
            let count = if count > MAX_GROUP {
                let at = group.count.as_ref().map_or(group.name.span, |c| c.span);
                self.warn(
                    Code::W0702,
                    format!("{who} is capped at {MAX_GROUP} actors"),
                    at,
                    format!("{count} written"),
                )
                .note("a Scenic scene with very many objects samples slowly and rarely fits on one stretch of road");
                MAX_GROUP
            } else {
                count
            };
            let behavior_attr = group.attr("behavior");
            let (motion, behavior) =
                self.motion_of(behavior_attr.and_then(|a| a.symbol()), blueprint.class, &who, group.name.span);
            let typical = entry.and_then(|e| e.speed("typical_speed")).unwrap_or(0.0);
            let speed = if blueprint.class == Class::Debris {
                0.0
            } else {
                self.speed_of(group.attr("speed"), typical, behavior, &who, group.name.span)
            };
            // position
            let position = group.attr("position").and_then(|a| match &a.value {
                Known::Given(Val::Position(p)) => Some(p),
                _ => None,
            });
            let (reference, longitudinal, side) = match position {
                None => {
                    let at = group.attr("position").map_or(group.name.span, |a| a.value_span);
                    self.warn(Code::W0706, format!("the position of {who} is not given"), at, "`front of ego` chosen");
                    (Reference::Ego, Longitudinal::Front, None)
                }
                Some(p) => {
                    let relation = vocabulary.get("relation", &p.relation.name);
                    let longitudinal = match relation.and_then(|r| r.symbol("longitudinal")) {
                        Some("front") => Longitudinal::Front,
                        Some("behind") => Longitudinal::Behind,
                        _ => Longitudinal::Same,
                    };
                    let side = relation.and_then(|r| r.symbol("lateral")).map(str::to_string);
                    let reference = if let Some(&i) = index_of.get(p.reference.name.as_str()) {
                        Reference::Group(i)
                    } else if vocabulary.get("reference", &p.reference.name).is_some() {
                        Reference::Ego
                    } else {
                        let element = canonical(vocabulary, "road_element", &p.reference);
                        if mapping::junction_element(element) {
                            Reference::Junction
                        } else {
                            self.warn(
                                Code::W0700,
                                format!("road element `{element}` has no Scenic mapping"),
                                p.reference.span,
                                "placed relative to the ego vehicle instead",
                            )
                            .note("the CARLA maps as Scenic reads them have junctions, lanes and sidewalks, but no bus stops or parking lots");
                            Reference::Ego
                        }
                    };
                    (reference, longitudinal, side)
                }
            };
            let lane = group.attr("lane").and_then(|a| a.integer()).filter(|l| *l != 0).unwrap_or(0);
            references.push(reference);
            lateral.push(side);
            let summary = group_summary(group, &type_name, count, vocabulary);
            resolved.push(Resolved {
                ident_base: group.name.text.clone(),
                summary,
                blueprint,
                length,
                width,
                count,
                motion,
                speed,
                lane,
                reference,
                longitudinal,
                span: group.span,
            });
        }

        // order: references first; groups depending on the junction last
        let order = placement_order(&references);

        // lanes not written: from the relation and the reference's lane
        let one_way = opposite_lanes == Some(false);
        for &i in &order {
            if resolved[i].lane != 0 {
                continue;
            }
            let reference_lane = match resolved[i].reference {
                Reference::Group(j) if resolved[j].lane != 0 => resolved[j].lane,
                _ => ego_lane,
            };
            let mut lane = match lateral[i].as_deref() {
                Some("left") => shift(reference_lane, -1),
                Some("right") => shift(reference_lane, 1),
                Some("opposite") => -reference_lane,
                _ => reference_lane,
            };
            if let Some(n) = lanes {
                lane = lane.clamp(-(n as i64), n as i64);
                if lane == 0 {
                    lane = reference_lane;
                }
            }
            if one_way && lane < 0 {
                lane = reference_lane.max(1);
            }
            let group = &scenario.actors[i];
            let at = group.attr("lane").map_or(group.name.span, |a| a.value_span);
            self.warn(
                Code::W0706,
                format!("the lane of group `{}` is not given", group.name.text),
                at,
                format!("lane {lane} chosen"),
            )
            .note("taken from the position's relation and the lane of its reference");
            resolved[i].lane = lane;
        }

        // --- what the road must have ------------------------------------------------------
        let max_positive = resolved.iter().map(|g| g.lane).chain([ego_lane]).max().unwrap_or(1).max(1) as u32;
        let max_negative = resolved.iter().map(|g| -g.lane).max().unwrap_or(0).max(0) as u32;
        let base =
            Needs { min_same: max_positive, min_other: max_negative, index: ego_lane as u32, ..Needs::default() };
        let mut features: Vec<(Feature, Span)> = Vec::new();
        if let Some(n) = lanes {
            features.push((Feature::Lanes(n), lanes_attr.map_or(road_span, |a| a.value_span)));
        }
        if let Some((_, span)) = direction {
            match (opposite_lanes, lanes) {
                (Some(false), _) => features.push((Feature::Other(0), span)),
                (Some(true), Some(n)) => features.push((Feature::Other(n), span)),
                (Some(true), None) => features.push((Feature::OtherAtLeast(1), span)),
                (None, _) => {}
            }
        }
        let mut preference: &[&str] = &[];
        if let Some((name, span)) = road_type {
            match mapping::road_type(name) {
                Some(RoadType::Shape(shape)) => features.push((Feature::Shape(shape), span)),
                Some(RoadType::Junction(kind)) => features.push((Feature::Junction(kind), span)),
                Some(RoadType::Missing(what)) => {
                    self.warn(
                        Code::W0701,
                        format!("no map has {what}"),
                        span,
                        "placed before an ordinary junction instead",
                    )
                    .note(format!("the maps are {}", maps::KNOWN.join(", ")));
                    features.push((Feature::Junction(None), span));
                }
                None => {
                    let junction = vocabulary.get("road_type", name).and_then(|e| e.flag("junction")) == Some(true);
                    if junction {
                        self.warn(
                            Code::W0703,
                            format!("road type `{name}` has no Scenic mapping"),
                            span,
                            "approximated",
                        )
                        .note("it is declared a junction: the ego is placed before a junction of any kind");
                        features.push((Feature::Junction(None), span));
                    } else {
                        self.warn(
                            Code::W0700,
                            format!("road type `{name}` has no Scenic mapping"),
                            span,
                            "left out of the Scenic program",
                        );
                    }
                }
            }
        }
        if let Some(Motion::Turn(c @ ('L' | 'R'))) = ego_motion {
            features.push((Feature::Turn(c), behavior_span));
        }
        if resolved.iter().any(|g| g.reference == Reference::Junction) {
            let span = resolved.iter().find(|g| g.reference == Reference::Junction).map_or(road_span, |g| g.span);
            features.push((Feature::Junction(None), span));
        }
        let mut light_state = None;
        let mut unsignalised = None;
        if let (Some((name, span)), Some(present)) = (light, light_present) {
            if present {
                match mapping::light(name) {
                    Some(state) => light_state = Some((state, name.to_string())),
                    None => {
                        self.warn(
                            Code::W0700,
                            format!("light state `{name}` has no Scenic mapping"),
                            span,
                            "no light is set",
                        )
                        .note("CARLA lights are red, yellow, green or off");
                    }
                }
                features.push((Feature::Signalised(true), span));
            } else {
                unsignalised = Some(span);
            }
        }
        if let Some(signs) = self.attr("road", "signs").and_then(|a| a.symbols()) {
            for s in signs {
                if let Some((table, code)) = mapping::sign(canonical(vocabulary, "traffic_sign", s)) {
                    features.push((Feature::Sign(table, code), s.span));
                }
            }
        }
        if let Some(span) = unsignalised.filter(|_| features_need_junction(&features)) {
            features.push((Feature::Signalised(false), span));
        }
        self.unmapped_list(
            "signs",
            "traffic_sign",
            |s| mapping::sign(s).is_some(),
            "CARLA's signs are part of the map: only stop and yield signs at junctions can be asked of it",
        );
        if let Some(roadside) = self.attr("road", "roadside").and_then(|a| a.symbols())
            && let Some(s) = roadside.iter().find(|s| canonical(vocabulary, "roadside", s) == "sidewalk")
        {
            features.push((Feature::Sidewalk, s.span));
        }
        self.unmapped_list(
            "roadside",
            "roadside",
            |s| s == "sidewalk",
            "the maps' scenery is fixed: only sidewalks can be asked of them",
        );
        self.unmapped_list(
            "special_lanes",
            "special_lane",
            |_| false,
            "Scenic's road network has no bus, tram, turn, parking or car-pool lanes to ask for",
        );
        self.unmapped_list(
            "hazards",
            "hazard",
            |_| false,
            "hazards are not generated; describe them as actor groups (e.g. a parked truck, traffic cones)",
        );
        self.unmapped_list(
            "roadworks",
            "roadwork",
            |_| false,
            "roadworks are not generated; describe them as actor groups (e.g. barriers, traffic cones)",
        );
        self.unmapped_list(
            "emergency_vehicles",
            "emergency_vehicle",
            |_| false,
            "emergency vehicles are not generated; describe them as actor groups (e.g. an ambulance)",
        );
        if let Some((name, span)) = self.symbol("road", "traffic", "traffic_density") {
            self.warn(
                Code::W0700,
                format!("traffic density `{name}` has no Scenic mapping"),
                span,
                "left out of the Scenic program",
            )
            .note("no background traffic is generated: only the ego and the actor groups are in the scene");
        }
        if let Some((name, span)) = self.symbol("road", "context", "road_context") {
            match mapping::road_context(name) {
                Some((maps, missing)) => {
                    preference = maps;
                    if let Some(why) = missing {
                        self.warn(
                            Code::W0700,
                            format!("road context `{name}` has no Scenic mapping"),
                            span,
                            "only the choice of map follows it",
                        )
                        .note(why);
                    }
                }
                None => {
                    self.warn(
                        Code::W0700,
                        format!("road context `{name}` has no Scenic mapping"),
                        span,
                        "left out of the Scenic program",
                    );
                }
            }
        }

        features.sort_by_key(|(f, _)| f.priority());

        // --- the map --------------------------------------------------------------------------
        let minimal: Vec<usize> = resolved.iter().map(|_| 1).collect();
        let ego_extent = (ego_length, ego_speed);
        let mut needs = base.clone();
        layout(&resolved, &minimal, ego_lane, ego_extent, &order, &mut needs, features_need_junction(&features));
        let requested = self.options.map.as_deref();
        let (map, map_known) = match requested {
            Some(m) => match maps::known(m) {
                Some(k) => (k.to_string(), true),
                None => {
                    self.warn(Code::W0705, format!("map `{m}` is not one the backend knows"), road_span, "its features are not checked")
                        .note(format!("the known maps are {}; Scenic reports at compile time if this one lacks what the scenario needs", maps::KNOWN.join(", ")));
                    (m.to_string(), false)
                }
            },
            None => (String::new(), true),
        };
        let candidates: Vec<&str> = if !map_known {
            vec![]
        } else if requested.is_some() {
            vec![maps::known(&map).unwrap_or("Town10HD")]
        } else {
            maps::KNOWN.to_vec()
        };
        let mut full = full_windows(&resolved, ego_lane, ego_extent, &order, &needs);
        let mut best = select(&needs, &full, &features, &candidates, preference);
        if let Some((false, m, _)) = best
            && map_known
        {
            // No map has every lane the scenario uses: move actors into the lanes of the
            // closest layout, and choose again on its map.
            let pool: Vec<&str> = if requested.is_some() { vec![m] } else { candidates.clone() };
            if let Some((m, same, other)) = maps::closest_layout(&pool, (needs.min_same, needs.min_other)) {
                let remap = |lane: i64| -> i64 {
                    if lane > 0 {
                        lane.min(same as i64)
                    } else if other > 0 {
                        lane.max(-(other as i64))
                    } else {
                        1
                    }
                };
                let moved = |this: &mut Self, lane: i64, span: Span, who: &str| {
                    let to = remap(lane);
                    if to != lane {
                        this.warn(Code::W0701, format!("{m} has no lane {lane} for {who}"), span, format!("placed in lane {to}"))
                            .note(format!("no map has all the lanes the scenario uses; {m} has a road with {} in the ego's direction and {} in the other", plural(same as usize, "lane"), plural(other as usize, "lane")));
                    }
                    to
                };
                let ego_lane_span = self.attr("ego", "lane").map_or(ego_section_span, |a| a.value_span);
                ego_lane = moved(&mut self, ego_lane, ego_lane_span, "the ego vehicle");
                for (i, g) in resolved.iter_mut().enumerate() {
                    let group = &scenario.actors[i];
                    let span = group.attr("lane").map_or(group.name.span, |a| a.value_span);
                    g.lane = moved(&mut self, g.lane, span, &format!("group `{}`", group.name.text));
                }
                needs.min_same = resolved.iter().map(|g| g.lane).chain([ego_lane]).max().unwrap_or(1).max(1) as u32;
                needs.min_other = resolved.iter().map(|g| -g.lane).max().unwrap_or(0).max(0) as u32;
                needs.index = ego_lane as u32;
                layout(
                    &resolved,
                    &minimal,
                    ego_lane,
                    ego_extent,
                    &order,
                    &mut needs,
                    features_need_junction(&features),
                );
                full = full_windows(&resolved, ego_lane, ego_extent, &order, &needs);
                best = select(&needs, &full, &features, &[m], preference);
            }
        }
        let (map, kept_flags) = match best {
            Some((base_ok, m, kept)) => {
                if !base_ok {
                    self.warn(
                        Code::W0701,
                        format!("no place on {m} has every lane the scenario uses"),
                        road_span,
                        "the Scenic program reports this when compiled",
                    )
                    .note(format!(
                        "the scenario needs {} in the ego's direction and {} in the other",
                        plural(needs.min_same as usize, "lane"),
                        plural(needs.min_other as usize, "lane")
                    ));
                }
                (m.to_string(), kept)
            }
            None => (map, vec![true; features.len()]),
        };
        let mut kept = Vec::new();
        let mut dropped = Vec::new();
        let mut chosen = needs.clone();
        for ((feature, span), keep) in features.iter().zip(&kept_flags) {
            if *keep {
                feature.apply(&mut chosen);
                kept.push(feature.describe(&chosen));
            }
            let _ = span;
        }
        for ((feature, span), keep) in features.iter().zip(&kept_flags) {
            if *keep {
                continue;
            }
            // a shape is tested with every actor in place (see `select`)
            let description = feature.describe(if let Feature::Shape(_) = feature { &full[0] } else { &chosen });
            let mut alone = needs.clone();
            feature.apply(&mut alone);
            let having: Vec<&str> = maps::KNOWN.iter().copied().filter(|m| alone.feasible(m)).collect();
            let note = if having.is_empty() {
                "no map has it together with the lanes the scenario uses".to_string()
            } else {
                format!("without the rest of the road, it is on {}", list(&having))
            };
            self.warn(
                Code::W0701,
                format!("{map} has no place with {description}"),
                *span,
                "left out of the road requirements",
            )
            .note(note)
            .help(format!(
                "the map was chosen for what it has; build with --map to choose another ({})",
                maps::KNOWN.join(", ")
            ));
            dropped.push(description);
        }

        // --- the full layout, capped to the longest matching stretch ------------------------
        let mut counts: Vec<usize> = resolved.iter().map(|g| g.count).collect();
        let junction_mode = chosen.junction.is_some();
        let mut offsets = layout(&resolved, &counts, ego_lane, ego_extent, &order, &mut chosen, junction_mode);
        if map_known && !chosen.feasible(&map) {
            let wanted = counts.clone();
            // the group taking the longest stretch of lane loses an actor first
            let length = |i: usize, counts: &[usize]| counts[i] as f64 * (resolved[i].extent() + resolved[i].gap());
            while let Some(i) = (0..counts.len())
                .filter(|&i| counts[i] > 1)
                .max_by(|&a, &b| length(a, &counts).total_cmp(&length(b, &counts)))
            {
                counts[i] -= 1;
                offsets = layout(&resolved, &counts, ego_lane, ego_extent, &order, &mut chosen, junction_mode);
                if chosen.feasible(&map) {
                    break;
                }
            }
            for (i, g) in resolved.iter().enumerate() {
                if counts[i] < wanted[i] {
                    let group = &scenario.actors[i];
                    let at = group.count.as_ref().map_or(group.name.span, |c| c.span);
                    self.warn(
                        Code::W0702,
                        format!("only {} of the {} actors of group `{}` fit", counts[i], wanted[i], g.ident_base),
                        at,
                        format!("{} placed", counts[i]),
                    )
                    .note(format!("the longest stretch of {map} with this road is too short for the whole group"));
                }
            }
        }

        // --- actors ---------------------------------------------------------------------------
        let ego = Actor {
            ident: "ego".into(),
            class: Class::Car,
            blueprint: mapping::EGO_BLUEPRINT,
            length: ego_length,
            width: ego_width,
            lane: ego_lane,
            offset: 0.0,
            place: Place::Centre,
            across: false,
            speed: if Self::starts_moving(ego_motion, Class::Car) { ego_speed } else { 0.0 },
            behavior: Self::behavior_call(ego_motion, Class::Car, ego_speed),
        };
        let ego_summary = ego_summary(scenario, vocabulary, ego_lane);
        let mut groups = Vec::new();
        for (i, g) in resolved.iter().enumerate() {
            let mut actors = Vec::new();
            for (k, &offset) in offsets[i].iter().enumerate() {
                let ident = if counts[i] == 1 && g.count == 1 {
                    names.fresh(&g.ident_base)
                } else {
                    names.fresh(&format!("{}_{}", g.ident_base, k + 1))
                };
                actors.push(Actor {
                    ident,
                    class: g.blueprint.class,
                    blueprint: g.blueprint.blueprint,
                    length: g.length,
                    width: g.width,
                    lane: g.lane,
                    offset,
                    place: g.place(),
                    across: g.across(),
                    speed: if Self::starts_moving(g.motion, g.blueprint.class) { g.speed } else { 0.0 },
                    behavior: Self::behavior_call(g.motion, g.blueprint.class, g.speed),
                });
            }
            groups.push(Group { summary: g.summary.clone(), actors });
        }

        // --- environment ------------------------------------------------------------------------
        let (weather, weather_summary) = self.weather();
        if light_state.is_some() && self.options.simulator == Simulator::Newtonian {
            let (_, span) = light.expect("a light state comes from the light field");
            self.warn(Code::W0704, "the Newtonian simulator has no traffic lights", span, "not simulated").note(
                "the CARLA program holds this light state with a monitor; build with --simulator carla to keep it",
            );
        }

        let plan = Plan {
            scenario: scenario.name.as_ref().map_or_else(|| "scenario".to_string(), |n| n.text.clone()),
            map,
            map_known,
            needs: chosen,
            ego,
            ego_summary,
            groups,
            weather,
            weather_summary,
            light: light_state,
            kept,
            dropped,
        };
        (plan, self.diagnostics)
    }

    fn weather(&mut self) -> (Vec<(&'static str, f64)>, String) {
        let weather = self.symbol("environment", "weather", "weather");
        let time = self.symbol("environment", "time", "time_of_day");
        let mut parameters = Vec::new();
        let mut said = Vec::new();
        if let Some((name, span)) = weather {
            match mapping::weather(name) {
                Some(p) => {
                    parameters.extend_from_slice(p);
                    said.push(name.to_string());
                }
                None => {
                    self.warn(
                        Code::W0700,
                        format!("weather `{name}` has no Scenic mapping"),
                        span,
                        "left out of `param weather`",
                    )
                    .note("CARLA's weather has clouds, rain, puddles, wetness, wind and fog, but no snow");
                }
            }
        }
        if let Some((name, span)) = time {
            match mapping::time_of_day(name) {
                Some(p) => {
                    parameters.extend_from_slice(p);
                    said.push(name.to_string());
                }
                None => {
                    self.warn(
                        Code::W0700,
                        format!("time of day `{name}` has no Scenic mapping"),
                        span,
                        "left out of `param weather`",
                    );
                }
            }
        }
        if !parameters.is_empty() && !parameters.iter().any(|(k, _)| *k == "sun_altitude_angle") {
            parameters.extend_from_slice(mapping::time_of_day("daytime").expect("daytime is mapped"));
            said.push("daytime (not given)".into());
        }
        if !parameters.is_empty() && !parameters.iter().any(|(k, _)| *k == "cloudiness") {
            parameters.extend_from_slice(mapping::weather("clear").expect("clear is mapped"));
            said.insert(0, "clear (not given)".into());
        }
        (parameters, said.join(", "))
    }
}

/// The best map among `candidates` for `needs` and `features`: whether its base needs hold,
/// the map, and which features it keeps. Features are kept greedily in priority order;
/// maps are compared by what they leave out (earlier features weigh more), then by the road
/// context's preference, then by their order.
fn select<'m>(
    needs: &Needs,
    full: &[Needs; 2],
    features: &[(Feature, Span)],
    candidates: &[&'m str],
    preference: &[&str],
) -> Option<(bool, &'m str, Vec<bool>)> {
    type Scored<'m> = (Vec<bool>, usize, usize, &'m str, Vec<bool>);
    let mut best: Option<Scored<'m>> = None;
    for (rank, candidate) in candidates.iter().enumerate() {
        let mut trial = needs.clone();
        let base_ok = trial.feasible(candidate);
        let mut kept = Vec::new();
        for (feature, _) in features {
            let mut next = trial.clone();
            feature.apply(&mut next);
            let ok = if let Feature::Shape(_) = feature {
                // the shape weighs less than fitting every actor: test it with all of them
                let window = &full[0];
                Needs { ahead: window.ahead, behind: window.behind, ..next.clone() }.feasible(candidate)
            } else {
                next.feasible(candidate)
            };
            if ok {
                trial = next;
            }
            kept.push(ok);
        }
        let mut score = vec![!base_ok];
        score.extend(kept.iter().map(|k| !k));
        // every actor of every group fits, without capping
        let window = &full[usize::from(trial.junction.is_some())];
        let whole = Needs { ahead: window.ahead, behind: window.behind, approach: window.approach, ..trial };
        score.push(!whole.feasible(candidate));
        let context = preference.iter().position(|p| p == candidate).unwrap_or(preference.len());
        if best.as_ref().is_none_or(|b| (&score, context, rank) < (&b.0, b.1, b.2)) {
            best = Some((score, context, rank, candidate, kept));
        }
    }
    best.map(|(score, _, _, m, kept)| (!score[0], m, kept))
}

/// The windows of the full layout (every actor of every group), away from a junction and
/// before one.
fn full_windows(groups: &[Resolved], ego_lane: i64, ego: (f64, f64), order: &[usize], base: &Needs) -> [Needs; 2] {
    let counts: Vec<usize> = groups.iter().map(|g| g.count).collect();
    let mut away = base.clone();
    layout(groups, &counts, ego_lane, ego, order, &mut away, false);
    let mut before = base.clone();
    layout(groups, &counts, ego_lane, ego, order, &mut before, true);
    [away, before]
}

fn features_need_junction(features: &[(Feature, Span)]) -> bool {
    features.iter().any(|(f, _)| {
        matches!(f, Feature::Junction(_) | Feature::Turn(_) | Feature::Signalised(true) | Feature::Sign(..))
    })
}

/// The lane `by` lanes to the right (negative: left) of `lane`, as its traffic sees it.
fn shift(lane: i64, by: i64) -> i64 {
    let (position, direction) = if lane > 0 { (lane, 1) } else { (lane + 1, -1) };
    let moved = position + by * direction;
    if moved >= 1 { moved } else { moved - 1 }
}

/// Groups in an order where each comes after its reference; groups that depend on the
/// junction come last (they are placed once the ego's approach to it is known).
fn placement_order(references: &[Reference]) -> Vec<usize> {
    let n = references.len();
    let depends_on_junction = |mut i: usize| {
        for _ in 0..=n {
            match references[i] {
                Reference::Junction => return true,
                Reference::Group(j) => i = j,
                Reference::Ego => return false,
            }
        }
        false
    };
    let mut order = Vec::new();
    let mut placed = vec![false; n];
    for late in [false, true] {
        loop {
            let before = order.len();
            for i in 0..n {
                if placed[i] || depends_on_junction(i) != late {
                    continue;
                }
                let ready = match references[i] {
                    Reference::Group(j) => placed[j] || j == i,
                    _ => true,
                };
                if ready {
                    placed[i] = true;
                    order.push(i);
                }
            }
            if order.len() == before {
                break;
            }
        }
    }
    // cycles cannot reach the backend (E0506), but never lose a group
    order.extend((0..n).filter(|i| !placed[*i]));
    order
}

/// Place every actor: offsets along the ego's lane from its centre, per group. Sets the
/// window (`ahead`, `behind`) and the junction approach of `needs`.
fn layout(
    groups: &[Resolved],
    counts: &[usize],
    ego_lane: i64,
    (ego_length, ego_speed): (f64, f64),
    order: &[usize],
    needs: &mut Needs,
    junction: bool,
) -> Vec<Vec<f64>> {
    const MARGIN: f64 = 0.5;
    let mut occupied: HashMap<(i64, bool), Vec<(f64, f64)>> = HashMap::new();
    occupied.entry((ego_lane, false)).or_default().push((-ego_length / 2.0, ego_length / 2.0));
    let mut offsets: Vec<Vec<f64>> = vec![Vec::new(); groups.len()];
    let mut approach = None;
    let mut ahead = ego_length / 2.0;
    for &i in order {
        let g = &groups[i];
        if g.reference == Reference::Junction && approach.is_none() {
            approach = Some((ahead + 3.0).max(12.0));
        }
        let (low, high, direction, reference_speed) = match g.reference {
            Reference::Ego => (-ego_length / 2.0, ego_length / 2.0, 1.0, ego_speed),
            Reference::Group(j) if !offsets[j].is_empty() && j != i => {
                let r = &groups[j];
                let half = r.extent() / 2.0;
                let low = offsets[j].iter().map(|o| o - half).fold(f64::INFINITY, f64::min);
                let high = offsets[j].iter().map(|o| o + half).fold(f64::NEG_INFINITY, f64::max);
                let direction = if r.lane < 0 && !r.across() { -1.0 } else { 1.0 };
                (low, high, direction, r.speed)
            }
            Reference::Group(_) => (-ego_length / 2.0, ego_length / 2.0, 1.0, ego_speed),
            Reference::Junction => {
                let line = approach.unwrap_or(12.0);
                (line, line, -1.0, 0.0)
            }
        };
        let extent = g.extent();
        let half = extent / 2.0;
        let lead = g.lead_gap(reference_speed);
        let (mut centre, step) = match (g.reference, g.longitudinal) {
            (Reference::Junction, Longitudinal::Behind) => (low - 10.0 - half, -1.0),
            (Reference::Junction, _) => (low - 1.0 - half, -1.0),
            (_, Longitudinal::Front) => {
                let edge = if direction > 0.0 { high } else { low };
                (edge + direction * (lead + half), direction)
            }
            (_, Longitudinal::Behind) => {
                let edge = if direction > 0.0 { low } else { high };
                (edge - direction * (lead + half), -direction)
            }
            (_, Longitudinal::Same) => ((low + high) / 2.0, direction),
        };
        let key = (g.lane, g.place() == Place::Sidewalk);
        let lane = occupied.entry(key).or_default();
        for k in 0..counts[i] {
            if k > 0 {
                centre += step * (extent + g.gap());
            }
            while let Some(&(a, b)) =
                lane.iter().find(|(a, b)| centre - half - MARGIN < *b - 1e-6 && centre + half + MARGIN > *a + 1e-6)
            {
                centre = if step > 0.0 { b + g.gap().max(MARGIN) + half } else { a - g.gap().max(MARGIN) - half };
            }
            lane.push((centre - half, centre + half));
            offsets[i].push(centre);
            ahead = ahead.max(centre + half);
        }
    }
    let mut behind: f64 = ego_length / 2.0;
    for (i, g) in groups.iter().enumerate() {
        for o in &offsets[i] {
            ahead = ahead.max(o + g.extent() / 2.0);
            behind = behind.max(-(o - g.extent() / 2.0));
        }
    }
    needs.ahead = (ahead + 1.0).ceil();
    needs.behind = (behind + 1.0).ceil();
    needs.approach =
        if junction { approach.unwrap_or((ahead + 3.0).max(12.0)).ceil().max(needs.ahead + 2.0) } else { 0.0 };
    offsets
}

fn group_summary(group: &ActorGroup, type_name: &str, count: usize, vocabulary: &Vocabulary) -> String {
    let mut parts = vec![format!("{} {type_name}", count)];
    if let Some(b) = group.attr("behavior").and_then(|a| a.symbol()) {
        parts.push(canonical(vocabulary, "behavior", b).to_string());
    }
    if let Some(q) = group.attr("speed").and_then(|a| a.quantity()) {
        parts.push(kmh(q.si()));
    }
    if let Some(Known::Given(Val::Position(p))) = group.attr("position").map(|a| &a.value) {
        parts.push(format!("{} of {}", canonical(vocabulary, "relation", &p.relation), p.reference.name));
    }
    if let Some(l) = group.attr("lane").and_then(|a| a.integer()) {
        parts.push(format!("lane {l}"));
    }
    format!("group `{}`: {}", group.name.text, parts.join(", "))
}

fn ego_summary(scenario: &Scenario, vocabulary: &Vocabulary, lane: i64) -> String {
    let mut parts = Vec::new();
    if let Some(b) = scenario.attr("ego", "behavior").and_then(|a| a.symbol()) {
        parts.push(canonical(vocabulary, "behavior", b).to_string());
    }
    if let Some(q) = scenario.attr("ego", "speed").and_then(|a| a.quantity()) {
        parts.push(kmh(q.si()));
    }
    parts.push(format!("lane {lane}"));
    format!("ego vehicle: {}", parts.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifting_lanes_crosses_the_centre_line() {
        assert_eq!(shift(1, -1), -1);
        assert_eq!(shift(1, 1), 2);
        assert_eq!(shift(-1, -1), 1);
        assert_eq!(shift(-1, 1), -2);
        assert_eq!(shift(3, -1), 2);
    }

    #[test]
    fn references_come_first() {
        let order = placement_order(&[Reference::Group(1), Reference::Ego, Reference::Junction, Reference::Group(2)]);
        assert_eq!(order, vec![1, 0, 2, 3]);
    }
}
