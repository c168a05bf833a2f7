//! The layout (`tad_layout`) on a CARLA map: the stretch of road it needs around the ego
//! (`ahead`, `behind`, and with a junction the ego's `approach` to its stop line and the
//! junction's arms), for the map choice. Where every actor stands, its path and its timing
//! are the layout's; this step only measures them for the map.

use tad_diagnostics::Code;
use tad_ir::Scenario;
use tad_layout::{Arm, Layout};

use super::report::{Annotate, Report, unsupported};
use crate::maps::Needs;

/// Set the window of `needs` from the layout: metres of lane ahead of the ego's centre and
/// behind it on its own road, the approach to the junction, and the arms actors stand on;
/// of the first `kept[g]` actors of each group (all with `None`).
pub fn windows(layout: &Layout, needs: &mut Needs, junction: bool, kept: Option<&[usize]>) {
    let (mut ahead, mut behind) = (layout.ego.length / 2.0, layout.ego.length / 2.0);
    for (i, g) in layout.groups.iter().enumerate() {
        let n = kept.map_or(g.agents.len(), |k| k.get(i).copied().unwrap_or(0));
        for a in g.agents.iter().take(n).filter(|a| a.station.arm == Arm::Ego) {
            // what the program may sample: the group's shift, an adversary's spread
            let half = a.length.max(a.width) / 2.0 + g.slack + layout.conflict_spread(a);
            ahead = ahead.max(a.station.along + half);
            behind = behind.max(half - a.station.along);
        }
    }
    needs.ahead = (ahead + 1.0).ceil();
    needs.behind = (behind + 1.0).ceil();
    needs.approach = if junction { (layout.road.approach * 1000.0).round() / 1000.0 } else { 0.0 };
    needs.arms = if junction {
        let mut arms: Vec<&'static str> =
            layout.agents().map(|a| a.station.arm).filter(|arm| *arm != Arm::Ego).map(Arm::as_str).collect();
        arms.sort_unstable();
        arms.dedup();
        arms
    } else {
        Vec::new()
    };
    needs.arm_reach = needs
        .arms
        .iter()
        .map(|&name| {
            let on = layout.agents().filter(|a| a.station.arm.as_str() == name);
            let (mut incoming, mut outgoing): (f64, f64) = (0.0, 0.0);
            for a in on {
                let far = a.station.along + a.length / 2.0 + layout.conflict_spread(a) + 2.0;
                if a.lane > 0 { incoming = incoming.max(far) } else { outgoing = outgoing.max(far) }
            }
            (name, incoming.ceil(), outgoing.ceil())
        })
        .collect();
}

/// How many actors of each group the chosen map has room for: the whole layout when its
/// window fits, else groups lose their farthest actors, the group reaching farthest first
/// (W0702).
pub fn fit(
    scenario: &Scenario,
    layout: &Layout,
    needs: &Needs,
    map: &str,
    junction: bool,
    report: &mut Report,
) -> Vec<usize> {
    let mut kept: Vec<usize> = layout.groups.iter().map(|g| g.agents.len()).collect();
    let fits = |kept: &[usize]| {
        let mut n = needs.clone();
        windows(layout, &mut n, junction, Some(kept));
        n.feasible(map)
    };
    if fits(&kept) {
        return kept;
    }
    let reach = |i: usize, kept: &[usize]| {
        layout.groups[i]
            .agents
            .get(kept[i].wrapping_sub(1))
            .filter(|a| a.station.arm == Arm::Ego)
            .map_or(0.0, |a| a.station.along.abs())
    };
    // the actor reaching farthest along the ego's road goes first, even a group's last
    while let Some(i) = (0..kept.len())
        .filter(|&i| kept[i] > 0 && reach(i, &kept) > 0.0)
        .max_by(|&a, &b| reach(a, &kept).total_cmp(&reach(b, &kept)))
    {
        kept[i] -= 1;
        if fits(&kept) {
            break;
        }
    }
    for (i, g) in layout.groups.iter().enumerate() {
        let wanted = g.agents.len();
        if kept[i] < wanted {
            let Some(group) = scenario.group(g.group) else { continue };
            report
                .warn(
                    Code::W0702,
                    format!("only {} of the {wanted} actors of group `{}` fit", kept[i], group.name),
                    group.count.span().unwrap_or(group.name_span),
                    format!("{} placed", kept[i]),
                    unsupported(
                        format!("{wanted} actors in group `{}`", group.name),
                        Some(format!("{} actors", kept[i])),
                    ),
                )
                .note(format!("the longest stretch of {map} with this road is too short for the whole group"));
        }
    }
    kept
}
