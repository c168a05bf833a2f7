//! What the road section asks of the map: the lanes each way, the road type's junction
//! (`arms`) or shape, traffic lights (a light state's `signal`), junction signs (a sign's
//! `opendrive_type`), a sidewalk (a roadside that is a `walkway`), and the towns the road
//! context prefers (`carla_towns`). Everything the road section names that the maps cannot
//! have is reported here (W0700, W0701, W0703).

use tad_diagnostics::{Code, Diagnostic, Span};
use tad_ir::{Kind, Names, RoadShape, Scenario};

use super::Light;
use super::choice::Feature;
use super::list;
use super::report::{Annotate, Report, named, unsupported};
use crate::maps::{self, JunctionKind, Shape};

/// The road's requests, before the ego and the groups add theirs.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadRequest {
    /// The `road` keyword, or the scenario's name: where whole-road findings go.
    pub span: Span,
    /// Lanes per direction, when written.
    pub lanes: Option<u32>,
    /// The direction has no opposite lanes.
    pub one_way: bool,
    /// Features with the span that asks for each, in the order found.
    pub features: Vec<(Feature, Span)>,
    /// The CARLA towns the road context prefers, best first.
    pub preference: Vec<String>,
    /// The traffic light to hold, when the light state has a signal.
    pub light: Option<Light>,
    /// Where the light state is written, when it is one that is present.
    pub light_span: Option<Span>,
    /// Where a light state that is not present (`none`) is written: a junction ahead has no
    /// traffic lights.
    pub unsignalised: Option<Span>,
}

/// The road's requests; reports what the maps cannot have.
pub fn request(scenario: &Scenario, span: Span, report: &mut Report) -> RoadRequest {
    let road = &scenario.road;
    let opposite_lanes =
        road.direction.given().and_then(|d| scenario.entries.resolved(d)).and_then(|e| e.attrs.opposite_lanes);
    let mut request = RoadRequest {
        span,
        lanes: road.lanes.get().filter(|n| *n >= 1).map(|n| n.min(1000) as u32),
        one_way: opposite_lanes == Some(false),
        features: Vec::new(),
        preference: Vec::new(),
        light: None,
        light_span: None,
        unsignalised: None,
    };
    request.lanes_each_way(scenario, opposite_lanes);
    request.road_type(scenario, report);
    request.light(scenario, report);
    request.signs_and_sidewalk(scenario);
    unmapped_lists(scenario, report);
    traffic(scenario, report);
    request.preference = preference(scenario, report);
    request
}

impl RoadRequest {
    /// The lanes written, and the lanes the other way by the direction.
    fn lanes_each_way(&mut self, scenario: &Scenario, opposite_lanes: Option<bool>) {
        let road = &scenario.road;
        if let Some(n) = self.lanes {
            self.features.push((Feature::Lanes(n), road.lanes.span().unwrap_or(self.span)));
        }
        if let Some(direction_span) = road.direction.given().and(road.direction.span()) {
            match (opposite_lanes, self.lanes) {
                (Some(false), _) => self.features.push((Feature::Other(0), direction_span)),
                (Some(true), Some(n)) => self.features.push((Feature::Other(n), direction_span)),
                (Some(true), None) => self.features.push((Feature::OtherAtLeast(1), direction_span)),
                (None, _) => {}
            }
        }
    }

    /// The road type's junction (of any kind for a roundabout) or shape; W0700/W0701/W0703
    /// for what the maps cannot have.
    fn road_type(&mut self, scenario: &Scenario, report: &mut Report) {
        let road = &scenario.road;
        let entries = &scenario.entries;
        let (Some(written), Some(at)) = (road.road_type.given(), road.road_type.span()) else { return };
        let name = entries.name(written);
        let road_type = entries.resolved(written).map(|e| e.attrs);
        let kind = road_type.and_then(|t| match t.arms {
            Some(4) => Some(JunctionKind::Four),
            Some(3) => Some(JunctionKind::Three),
            _ => None,
        });
        match (road_type, kind) {
            (Some(t), _) if t.shape == Some(RoadShape::Roundabout) => {
                report
                    .warn(
                        Code::W0701,
                        "no map has a roundabout",
                        at,
                        "placed before an ordinary junction instead",
                        unsupported(named("road_type", name), Some("a junction of any kind".into())),
                    )
                    .note(format!("the maps are {}", maps::KNOWN.join(", ")));
                self.features.push((Feature::Junction(None), at));
            }
            (Some(t), Some(kind)) if t.junction => self.features.push((Feature::Junction(Some(kind)), at)),
            (Some(t), None) if t.junction => {
                report
                    .warn(
                        Code::W0703,
                        format!("road type `{name}` has no Scenic mapping"),
                        at,
                        "approximated",
                        unsupported(named("road_type", name), Some("a junction of any kind".into())),
                    )
                    .note("it is declared a junction: the ego is placed before a junction of any kind");
                self.features.push((Feature::Junction(None), at));
            }
            (Some(t), _) if matches!(t.shape, Some(RoadShape::Straight | RoadShape::Curved)) => {
                let shape = if t.shape == Some(RoadShape::Straight) { Shape::Straight } else { Shape::Curved };
                self.features.push((Feature::Shape(shape), at));
            }
            _ => {
                report.warn(
                    Code::W0700,
                    format!("road type `{name}` has no Scenic mapping"),
                    at,
                    "left out of the Scenic program",
                    unsupported(named("road_type", name), None),
                );
            }
        }
    }

    /// The light state: a present one asks for traffic lights (and is held when it has a
    /// signal); one that is not present says a junction ahead has none.
    fn light(&mut self, scenario: &Scenario, report: &mut Report) {
        let road = &scenario.road;
        let entries = &scenario.entries;
        let (Some(written), Some(at)) = (road.light.given(), road.light.span()) else { return };
        let name = entries.name(written);
        let state = entries.resolved(written).map(|e| e.attrs);
        if !state.is_none_or(|s| s.present) {
            self.unsignalised = Some(at);
            return;
        }
        match state.and_then(|s| s.signal) {
            Some(signal) => self.light = Some(Light { signal, name: name.to_string() }),
            None => {
                report
                    .warn(
                        Code::W0700,
                        format!("light state `{name}` has no Scenic mapping"),
                        at,
                        "no light is set",
                        unsupported(named("light_state", name), Some("a junction with traffic lights".into())),
                    )
                    .note("CARLA lights are red, yellow, green or off");
            }
        }
        self.light_span = Some(at);
        self.features.push((Feature::Signalised(true), at));
    }

    /// The junction signs (those with an OpenDRIVE type), and a sidewalk (a roadside that is
    /// a walkway).
    fn signs_and_sidewalk(&mut self, scenario: &Scenario) {
        let road = &scenario.road;
        if let Some(signs) = road.signs.given() {
            for sign in signs {
                if let Some(t) = scenario.entries.resolved(&sign.value).and_then(|e| e.attrs.opendrive_type) {
                    self.features.push((Feature::Sign(t), sign.span));
                }
            }
        }
        if let Some(sidewalk) = road.roadside.given().and_then(|r| r.iter().find(|s| walkway(scenario, s.value.id()))) {
            self.features.push((Feature::Sidewalk, sidewalk.span));
        }
    }
}

/// Whether a roadside is a walkway.
fn walkway(scenario: &Scenario, s: Option<tad_ir::Id<tad_ir::Roadside>>) -> bool {
    s.and_then(|e| scenario.entries.get(e)).is_some_and(|e| e.attrs.walkway)
}

/// W0700 for the names of the road's lists that the maps cannot have: signs that are not a
/// junction's, roadsides that are not walkways, special lanes, hazards, roadworks and
/// emergency vehicles.
fn unmapped_lists(scenario: &Scenario, report: &mut Report) {
    let road = &scenario.road;
    let entries = &scenario.entries;
    unmapped(
        scenario,
        &road.signs,
        "signs",
        |s| s.and_then(|e| entries.get(e)).is_some_and(|e| e.attrs.opendrive_type.is_some()),
        "CARLA's signs are part of the map: only stop and yield signs at junctions can be asked of it",
        report,
    );
    unmapped(
        scenario,
        &road.roadside,
        "roadside",
        |s| walkway(scenario, s),
        "the maps' scenery is fixed: only sidewalks can be asked of them",
        report,
    );
    unmapped(
        scenario,
        &road.special_lanes,
        "special_lanes",
        |_| false,
        "Scenic's road network has no bus, tram, turn, parking or car-pool lanes to ask for",
        report,
    );
    unmapped(
        scenario,
        &road.hazards,
        "hazards",
        |_| false,
        "hazards are not generated; describe them as actor groups (e.g. a parked truck, traffic cones)",
        report,
    );
    unmapped(
        scenario,
        &road.roadworks,
        "roadworks",
        |_| false,
        "roadworks are not generated; describe them as actor groups (e.g. barriers, traffic cones)",
        report,
    );
    unmapped(
        scenario,
        &road.emergency_vehicles,
        "emergency_vehicles",
        |_| false,
        "emergency vehicles are not generated; describe them as actor groups (e.g. an ambulance)",
        report,
    );
}

/// W0700 for a traffic density: no background traffic is generated.
fn traffic(scenario: &Scenario, report: &mut Report) {
    let road = &scenario.road;
    let (Some(written), Some(at)) = (road.traffic.given(), road.traffic.span()) else { return };
    let name = scenario.entries.name(written);
    report
        .warn(
            Code::W0700,
            format!("traffic density `{name}` has no Scenic mapping"),
            at,
            "left out of the Scenic program",
            unsupported(named("traffic_density", name), None),
        )
        .note("no background traffic is generated: only the ego and the actor groups are in the scene");
}

/// The CARLA towns the road context prefers, best first; W0700 for a context that only
/// chooses the map, or not even that.
fn preference(scenario: &Scenario, report: &mut Report) -> Vec<String> {
    let road = &scenario.road;
    let entries = &scenario.entries;
    let (Some(written), Some(at)) = (road.context.given(), road.context.span()) else { return Vec::new() };
    let name = entries.name(written);
    let context = entries.resolved(written).map(|e| &e.attrs);
    match context.filter(|c| !c.carla_towns.is_empty()) {
        Some(c) => {
            if let Some(why) = &c.carla_note {
                report
                    .warn(
                        Code::W0700,
                        format!("road context `{name}` has no Scenic mapping"),
                        at,
                        "only the choice of map follows it",
                        unsupported(named("road_context", name), Some("the choice of map".into())),
                    )
                    .note(why.clone());
            }
            c.carla_towns.clone()
        }
        None => {
            report.warn(
                Code::W0700,
                format!("road context `{name}` has no Scenic mapping"),
                at,
                "left out of the Scenic program",
                unsupported(named("road_context", name), None),
            );
            Vec::new()
        }
    }
}

/// Report the names of a list field that have no mapping (`mapped` says which do), in one
/// W0700 at the first.
fn unmapped<K: Kind>(
    scenario: &Scenario,
    field: &tad_ir::Field<Names<K>>,
    label: &str,
    mapped: impl Fn(Option<tad_ir::Id<K>>) -> bool,
    why: &str,
    report: &mut Report,
) {
    let Some(names) = field.given() else { return };
    let missing: Vec<_> = names.iter().filter(|s| !mapped(s.value.id())).collect();
    let Some(first) = missing.first() else { return };
    let written: Vec<&str> = missing.iter().map(|s| scenario.entries.name(&s.value)).collect();
    let verb = if written.len() == 1 { "has" } else { "have" };
    let message = format!("{} (road {label}) {verb} no Scenic mapping", list(&written));
    let construct = written.iter().map(|n| named(K::KIND, n)).collect::<Vec<_>>().join(", ");
    let mut d = Diagnostic::new(Code::W0700, message, first.span, "left out of the Scenic program")
        .with_note(why.to_string())
        .with_payload(unsupported(construct, None));
    for other in &missing[1..] {
        d = d.with_secondary(other.span, "left out too");
    }
    report.push(d);
}
