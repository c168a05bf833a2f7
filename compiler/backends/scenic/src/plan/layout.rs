//! Placement along the lanes: every actor's offset in metres along the ego's lane from the
//! ego's centre, group after group in placement order, bumper to bumper and never
//! overlapping; and the stretch of road (`ahead`, `behind`, the junction `approach`) that
//! the layout needs. Groups that do not fit on the chosen map's longest such stretch lose
//! actors, the longest group first (W0702).

use std::collections::HashMap;

use tad_diagnostics::Code;
use tad_ir::{Longitudinal, Scenario};

use super::Place;
use super::choice::Choice;
use super::ego::EgoPlan;
use super::groups::{Resolved, Target};
use super::report::{Annotate, Report, unsupported};
use crate::maps::Needs;

/// The laid-out actors.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Actors per group, after capping to the map.
    pub counts: Vec<usize>,
    /// Per group, each actor's offset.
    pub offsets: Vec<Vec<f64>>,
    /// Per group, the way its actors follow each other along the ego's lane (1 or -1):
    /// away from its reference.
    pub steps: Vec<f64>,
    /// The chosen needs with the window of this layout.
    pub needs: Needs,
}

/// The windows of the full layout (every actor of every group), away from a junction and
/// before one.
pub fn full_windows(groups: &[Resolved], ego_lane: i64, ego: (f64, f64), order: &[usize], base: &Needs) -> [Needs; 2] {
    let counts: Vec<usize> = groups.iter().map(|g| g.count).collect();
    let mut away = base.clone();
    layout(groups, &counts, ego_lane, ego, order, &mut away, false);
    let mut before = base.clone();
    layout(groups, &counts, ego_lane, ego, order, &mut before, true);
    [away, before]
}

/// Lay out every group on the chosen map, capping groups until the layout fits (W0702).
pub fn fit(
    scenario: &Scenario,
    groups: &[Resolved],
    order: &[usize],
    ego: &EgoPlan,
    choice: &Choice,
    report: &mut Report,
) -> Layout {
    let extent = (ego.length, ego.speed);
    let mut needs = choice.needs.clone();
    let mut counts: Vec<usize> = groups.iter().map(|g| g.count).collect();
    let (mut offsets, mut steps) = layout(groups, &counts, ego.lane, extent, order, &mut needs, choice.junction);
    if choice.map_known && !needs.feasible(&choice.map) {
        let wanted = counts.clone();
        // the group taking the longest stretch of lane loses an actor first
        let length = |i: usize, counts: &[usize]| counts[i] as f64 * (groups[i].extent() + groups[i].gap());
        while let Some(i) = (0..counts.len())
            .filter(|&i| counts[i] > 1)
            .max_by(|&a, &b| length(a, &counts).total_cmp(&length(b, &counts)))
        {
            counts[i] -= 1;
            (offsets, steps) = layout(groups, &counts, ego.lane, extent, order, &mut needs, choice.junction);
            if needs.feasible(&choice.map) {
                break;
            }
        }
        for (i, g) in groups.iter().enumerate() {
            if counts[i] < wanted[i] {
                let group = &scenario.groups[i];
                report
                    .warn(
                        Code::W0702,
                        format!("only {} of the {} actors of group `{}` fit", counts[i], wanted[i], g.name),
                        group.count.span().unwrap_or(group.name_span),
                        format!("{} placed", counts[i]),
                        unsupported(
                            format!("{} actors in group `{}`", wanted[i], g.name),
                            Some(format!("{} actors", counts[i])),
                        ),
                    )
                    .note(format!(
                        "the longest stretch of {} with this road is too short for the whole group",
                        choice.map
                    ));
            }
        }
    }
    Layout { counts, offsets, steps, needs }
}

/// Place every actor: offsets along the ego's lane from its centre, per group, and the
/// way each group extends from its reference. Sets the window (`ahead`, `behind`) and the
/// junction approach of `needs`. A group with a `distance` range is placed at its upper
/// end, and the stretch down to its lower end is kept free: Scenic moves it nearer.
pub fn layout(
    groups: &[Resolved],
    counts: &[usize],
    ego_lane: i64,
    (ego_length, ego_speed): (f64, f64),
    order: &[usize],
    needs: &mut Needs,
    junction: bool,
) -> (Vec<Vec<f64>>, Vec<f64>) {
    const MARGIN: f64 = 0.5;
    let mut occupied: HashMap<(i64, bool), Vec<(f64, f64)>> = HashMap::new();
    occupied.entry((ego_lane, false)).or_default().push((-ego_length / 2.0, ego_length / 2.0));
    let mut offsets: Vec<Vec<f64>> = vec![Vec::new(); groups.len()];
    let mut steps: Vec<f64> = vec![1.0; groups.len()];
    let mut approach = None;
    let mut ahead = ego_length / 2.0;
    for &i in order {
        let g = &groups[i];
        if g.target == Target::Junction && approach.is_none() {
            approach = Some((ahead + 3.0).max(12.0));
        }
        let (low, high, direction, reference_speed) = match g.target {
            Target::Ego => (-ego_length / 2.0, ego_length / 2.0, 1.0, ego_speed),
            Target::Group(j) if j < groups.len() && !offsets[j].is_empty() && j != i => {
                let r = &groups[j];
                let half = r.extent() / 2.0;
                let low = offsets[j].iter().map(|o| o - half).fold(f64::INFINITY, f64::min);
                let high = offsets[j].iter().map(|o| o + half).fold(f64::NEG_INFINITY, f64::max);
                let direction = if r.lane < 0 && !r.across() { -1.0 } else { 1.0 };
                (low, high, direction, r.speed)
            }
            Target::Group(_) => (-ego_length / 2.0, ego_length / 2.0, 1.0, ego_speed),
            Target::Junction => {
                let line = approach.unwrap_or(12.0);
                (line, line, -1.0, 0.0)
            }
        };
        let extent = g.extent();
        let half = extent / 2.0;
        let lead = g.lead_gap(reference_speed);
        let (mut centre, step) = match (g.target, g.longitudinal) {
            (Target::Junction, Longitudinal::Behind) => (low - g.distance.map_or(10.0, |d| d.1) - half, -1.0),
            (Target::Junction, _) => (low - g.distance.map_or(1.0, |d| d.1) - half, -1.0),
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
        steps[i] = step;
        let key = (g.lane, g.place() == Place::Sidewalk);
        let lane = occupied.entry(key).or_default();
        // the stretch a sampled distance may move the group into, kept free after placing it
        let edge = centre - step * half;
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
        if let Some((near, far)) = g.distance.filter(|(near, far)| near < far && g.longitudinal != Longitudinal::Same) {
            let edge = offsets[i].first().map_or(edge, |first| first - step * half);
            let swept = (edge - step * (far - near), edge);
            lane.push((swept.0.min(swept.1) + 1e-3, swept.0.max(swept.1) - 1e-3));
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
    (offsets, steps)
}
