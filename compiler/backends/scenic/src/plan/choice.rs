//! The choice of map: the road features the scenario asks for, in priority order, and the
//! map that keeps the most important ones with every actor in place (`spec/backends/scenic.md`
//! §3). When no map has every lane the actors use, the choice names the closest road
//! (a map and its lanes) for the layout to be laid out within ([`Choice::relayout`]): the
//! layout moves what that road lacks (W0701 from its findings). Every feature the chosen map
//! lacks is a W0701.

use tad_diagnostics::{Code, Payload, Span};
use tad_ir::Motion;

use super::ego::EgoPlan;
use super::groups::{Resolved, Target};
use super::layout;
use super::report::{Annotate, Report};
use super::road::RoadRequest;
use super::{list, plural};
use crate::maps::{self, JunctionKind, JunctionNeed, Needs, Shape};

/// A road feature the scenario asks for, in priority order: when no map has them all, the
/// later ones are left out first.
#[derive(Clone, Debug, PartialEq)]
pub enum Feature {
    Lanes(u32),
    Other(u32),
    OtherAtLeast(u32),
    Junction(Option<JunctionKind>),
    /// The maneuver letter of the map table (`L`, `R`).
    Turn(char),
    Signalised(bool),
    /// An OpenDRIVE signal type at the junction.
    Sign(i64),
    Sidewalk,
    Shape(Shape),
}

impl Feature {
    pub fn apply(&self, needs: &mut Needs) {
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
            Feature::Sign(t) => needs.junction.get_or_insert_with(JunctionNeed::default).signs.push(*t),
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

    pub fn describe(&self, needs: &Needs) -> String {
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
            Feature::Sign(t) => match maps::sign_name(*t) {
                Some(name) => format!("a {name} sign at the junction ahead"),
                None => format!("a sign of OpenDRIVE type {t} at the junction ahead"),
            },
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

pub fn features_need_junction(features: &[(Feature, Span)]) -> bool {
    features.iter().any(|(f, _)| {
        matches!(f, Feature::Junction(_) | Feature::Turn(_) | Feature::Signalised(true) | Feature::Sign(..))
    })
}

/// The map and what of the road it keeps.
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    pub map: String,
    /// Whether the map is one the table describes.
    pub map_known: bool,
    /// The base needs (lanes the actors use) with the kept features applied.
    pub needs: Needs,
    /// Descriptions of the features kept and of those left out, for comments.
    pub kept: Vec<String>,
    pub dropped: Vec<String>,
    /// Whether the ego is placed before a junction.
    pub junction: bool,
    /// No map has every lane the layout uses: the map of the closest road, and its lanes,
    /// for the layout to be laid out within before choosing again.
    pub relayout: Option<(String, tad_layout::Limits)>,
}

/// Every feature the scenario asks for, sorted by priority: the road's, the ego's turn, a
/// junction that groups are placed relative to, and no traffic lights at it.
fn features(road: &RoadRequest, ego: &EgoPlan, groups: &[Resolved]) -> Vec<(Feature, Span)> {
    let mut features = road.features.clone();
    // the light's and the signs' come after the turn and the junction in priority anyway
    match ego.motion {
        Some(Motion::TurnLeft) => features.push((Feature::Turn('L'), ego.behavior_span)),
        Some(Motion::TurnRight) => features.push((Feature::Turn('R'), ego.behavior_span)),
        _ => {}
    }
    if let Some(g) = groups.iter().find(|g| g.target == Target::Junction) {
        features.push((Feature::Junction(None), g.span));
    }
    if let Some(span) = road.unsignalised.filter(|_| features_need_junction(&features)) {
        features.push((Feature::Signalised(false), span));
    }
    features.sort_by_key(|(f, _)| f.priority());
    features
}

/// The lanes every actor uses as the base needs.
fn lane_needs(groups: &[Resolved], ego_lane: i64, needs: &mut Needs) {
    let on_ego_road = || groups.iter().filter(|g| g.arm == tad_layout::Arm::Ego);
    needs.min_same = on_ego_road().map(|g| g.lane).chain([ego_lane]).max().unwrap_or(1).max(1) as u32;
    needs.min_other = on_ego_road().map(|g| -g.lane).max().unwrap_or(0).max(0) as u32;
    needs.index = ego_lane as u32;
}

/// The map and what of the road it keeps (see the module's header).
pub fn choose(
    road: &RoadRequest,
    ego: &EgoPlan,
    groups: &[Resolved],
    laid: &tad_layout::Layout,
    requested: Option<&str>,
    report: &mut Report,
) -> Choice {
    let features = features(road, ego, groups);
    let junction = features_need_junction(&features);
    let preference: Vec<&str> = road.preference.iter().map(String::as_str).collect();
    let mut needs = Needs::default();
    lane_needs(groups, ego.lane, &mut needs);
    let first: Vec<usize> = laid.groups.iter().map(|g| g.agents.len().min(1)).collect();
    layout::windows(laid, &mut needs, junction, Some(&first));
    let (map, map_known) = requested_map(requested, road.span, report);
    let candidates: Vec<&str> = if !map_known {
        vec![]
    } else if requested.is_some() {
        vec![maps::known(&map).unwrap_or("Town10HD")]
    } else {
        maps::KNOWN.to_vec()
    };
    let full = full_windows(laid, &needs);
    let best = select(&needs, &full, &features, &candidates, &preference);
    let mut relayout = None;
    if let Some((false, m, _)) = best
        && map_known
    {
        // No map has every lane the scenario uses: the closest road, for the layout.
        let pool: Vec<&str> = if requested.is_some() { vec![m] } else { candidates.clone() };
        relayout = maps::closest_layout(&pool, (needs.min_same, needs.min_other))
            .map(|(m, same, other)| (m.to_string(), tad_layout::Limits { same, other }));
    }
    let (map, kept_flags) = match best {
        Some((base_ok, m, kept)) => {
            if !base_ok {
                lanes_missing(m, &needs, road.span, report);
            }
            (m.to_string(), kept)
        }
        None => (map, vec![true; features.len()]),
    };
    let (chosen, kept) = apply_kept(&features, &kept_flags, &needs);
    let dropped = features
        .iter()
        .zip(&kept_flags)
        .filter(|(_, keep)| !**keep)
        .map(|((feature, span), _)| {
            // a shape is tested with every actor in place (see `select`)
            let description = feature.describe(if let Feature::Shape(_) = feature { &full[0] } else { &chosen });
            left_out(feature, *span, description, &needs, &map, report)
        })
        .collect();
    let junction = chosen.junction.is_some();
    Choice { map, map_known, needs: chosen, kept, dropped, junction, relayout }
}

/// The map asked for with `--map`: (its name, whether the backend knows it; W0705 when
/// not); without one, a map still to choose.
fn requested_map(requested: Option<&str>, span: Span, report: &mut Report) -> (String, bool) {
    let Some(m) = requested else { return (String::new(), true) };
    if let Some(k) = maps::known(m) {
        return (k.to_string(), true);
    }
    report
        .warn(
            Code::W0705,
            format!("map `{m}` is not one the backend knows"),
            span,
            "its features are not checked",
            Payload::Unknown {
                namespace: "map".into(),
                name: m.to_string(),
                candidates: maps::KNOWN.iter().map(|k| k.to_string()).collect(),
                module: None,
            },
        )
        .note(format!(
            "the known maps are {}; Scenic reports at compile time if this one lacks what the scenario needs",
            maps::KNOWN.join(", ")
        ));
    (m.to_string(), false)
}

/// The windows of road every actor of every group needs: away from a junction, and before
/// one.
fn full_windows(laid: &tad_layout::Layout, needs: &Needs) -> [Needs; 2] {
    let (mut away, mut before) = (needs.clone(), needs.clone());
    layout::windows(laid, &mut away, false, None);
    layout::windows(laid, &mut before, true, None);
    [away, before]
}

/// W0701: no place on map `m` has every lane the scenario uses.
fn lanes_missing(m: &str, needs: &Needs, span: Span, report: &mut Report) {
    report
        .warn(
            Code::W0701,
            format!("no place on {m} has every lane the scenario uses"),
            span,
            "the Scenic program reports this when compiled",
            Payload::Incompatible {
                subject: m.to_string(),
                value: format!(
                    "{} in the ego's direction and {} in the other",
                    plural(needs.min_same as usize, "lane"),
                    plural(needs.min_other as usize, "lane")
                ),
                allowed: vec![],
            },
        )
        .note(format!(
            "the scenario needs {} in the ego's direction and {} in the other",
            plural(needs.min_same as usize, "lane"),
            plural(needs.min_other as usize, "lane")
        ));
}

/// `needs` with the kept features applied, and the descriptions of those.
fn apply_kept(features: &[(Feature, Span)], kept_flags: &[bool], needs: &Needs) -> (Needs, Vec<String>) {
    let mut chosen = needs.clone();
    let mut kept = Vec::new();
    for ((feature, _), keep) in features.iter().zip(kept_flags) {
        if *keep {
            feature.apply(&mut chosen);
            kept.push(feature.describe(&chosen));
        }
    }
    (chosen, kept)
}

/// W0701 for a feature the map lacks, with the maps that have it alone; returns its
/// description.
fn left_out(
    feature: &Feature,
    span: Span,
    description: String,
    needs: &Needs,
    map: &str,
    report: &mut Report,
) -> String {
    let mut alone = needs.clone();
    feature.apply(&mut alone);
    let having: Vec<&str> = maps::KNOWN.iter().copied().filter(|m| alone.feasible(m)).collect();
    let note = if having.is_empty() {
        "no map has it together with the lanes the scenario uses".to_string()
    } else {
        format!("without the rest of the road, it is on {}", list(&having))
    };
    report
        .warn(
            Code::W0701,
            format!("{map} has no place with {description}"),
            span,
            "left out of the road requirements",
            Payload::Incompatible {
                subject: map.to_string(),
                value: description.clone(),
                allowed: having.iter().map(|m| m.to_string()).collect(),
            },
        )
        .note(note)
        .help(format!(
            "the map was chosen for what it has; build with --map to choose another ({})",
            maps::KNOWN.join(", ")
        ));
    description
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
