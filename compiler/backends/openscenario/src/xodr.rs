//! The network as OpenDRIVE 1.7 XML (`spec/backends/openscenario.md` §2): the header, every
//! road (links, plan view, lanes with widths and marks, crosswalk objects, signals), one
//! controller per signalised arm, and the junction's connections.

use crate::attrs;
use crate::network::{Curve, LaneKind, Link, Network, RoadDef};
use crate::xml::{Xml, num};

/// The OpenDRIVE version written.
pub const REV_MINOR: u32 = 7;

/// The `.xodr` text of a network; `name` is the scenario's.
pub fn print(net: &Network, name: &str) -> String {
    let mut x = Xml::new();
    x.open("OpenDRIVE", &[]);
    let (west, south, east, north) = bounds(net);
    x.empty(
        "header",
        attrs!("revMajor" => 1, "revMinor" => REV_MINOR, "name" => name, "version" => "1", "date" => crate::DATE,
               "north" => num(north), "south" => num(south), "east" => num(east), "west" => num(west), "vendor" => "TADSL"),
    );
    for road in &net.roads {
        print_road(&mut x, road);
    }
    for c in &net.controllers {
        x.open("controller", attrs!("id" => c.id, "name" => format!("{}_lights", c.arm.as_str())));
        for s in &c.signals {
            x.empty("control", attrs!("signalId" => s, "type" => "0"));
        }
        x.close();
    }
    if net.has_junction() {
        x.open(
            "junction",
            attrs!("id" => crate::network::JUNCTION, "name" => if net.roundabout { "roundabout" } else { "junction" }),
        );
        for c in &net.connections {
            x.open(
                "connection",
                attrs!("id" => c.id, "incomingRoad" => c.incoming, "connectingRoad" => c.connecting, "contactPoint" => "start"),
            );
            x.empty("laneLink", attrs!("from" => c.from, "to" => -1));
            x.close();
        }
        for c in &net.controllers {
            x.empty("controller", attrs!("id" => c.id, "type" => "0"));
        }
        x.close();
    }
    x.finish()
}

fn bounds(net: &Network) -> (f64, f64, f64, f64) {
    let mut b = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    for road in &net.roads {
        let n = (road.length() / 5.0).ceil().max(1.0) as usize;
        for k in 0..=n {
            let p = road.pose(road.length() * k as f64 / n as f64).position;
            b = (b.0.min(p.x), b.1.min(p.y), b.2.max(p.x), b.3.max(p.y));
        }
    }
    if b.0.is_finite() { b } else { (0.0, 0.0, 0.0, 0.0) }
}

fn link(x: &mut Xml, which: &str, link: Link) {
    match link {
        Link::Road { id, contact } => {
            x.empty(which, attrs!("elementType" => "road", "elementId" => id, "contactPoint" => contact.as_str()))
        }
        Link::Junction(id) => x.empty(which, attrs!("elementType" => "junction", "elementId" => id)),
    }
}

fn print_road(x: &mut Xml, road: &RoadDef) {
    let junction = road.junction.map_or(-1, i64::from);
    x.open(
        "road",
        attrs!("name" => road.name, "length" => num(road.length()), "id" => road.id, "junction" => junction, "rule" => "RHT"),
    );
    x.open("link", &[]);
    if let Some(l) = road.predecessor {
        link(x, "predecessor", l);
    }
    if let Some(l) = road.successor {
        link(x, "successor", l);
    }
    x.close();
    x.open("type", attrs!("s" => 0, "type" => "town"));
    x.empty("speed", attrs!("max" => 50, "unit" => "km/h"));
    x.close();
    x.open("planView", &[]);
    for g in &road.geometry {
        x.open(
            "geometry",
            attrs!("s" => num(g.s), "x" => num(g.start.position.x), "y" => num(g.start.position.y),
                   "hdg" => num(g.start.yaw), "length" => num(g.length)),
        );
        match &g.curve {
            Curve::Line => x.empty("line", &[]),
            Curve::Arc(k) => x.empty("arc", attrs!("curvature" => num(*k))),
            Curve::Poly3 { u, v } => x.empty(
                "paramPoly3",
                attrs!("aU" => num(u[0]), "bU" => num(u[1]), "cU" => num(u[2]), "dU" => num(u[3]),
                       "aV" => num(v[0]), "bV" => num(v[1]), "cV" => num(v[2]), "dV" => num(v[3]),
                       "pRange" => "normalized"),
            ),
        }
        x.close();
    }
    x.close();
    x.empty("elevationProfile", &[]);
    x.empty("lateralProfile", &[]);
    x.open("lanes", &[]);
    x.empty("laneOffset", attrs!("s" => 0, "a" => num(road.lane_offset), "b" => 0, "c" => 0, "d" => 0));
    x.open("laneSection", attrs!("s" => 0));
    if !road.left.is_empty() {
        x.open("left", &[]);
        for lane in road.left.iter().rev() {
            print_lane(x, road, lane);
        }
        x.close();
    }
    x.open("center", &[]);
    x.open("lane", attrs!("id" => 0, "type" => "none", "level" => "false"));
    let centre =
        if road.junction.is_some() || road.left.is_empty() || road.right.is_empty() { "none" } else { "solid" };
    road_mark(x, centre, "yellow");
    x.close();
    x.close();
    if !road.right.is_empty() {
        x.open("right", &[]);
        for lane in &road.right {
            print_lane(x, road, lane);
        }
        x.close();
    }
    x.close();
    x.close();
    if !road.crosswalks.is_empty() {
        x.open("objects", &[]);
        for c in &road.crosswalks {
            let (length, width) = (c.to - c.from, c.left - c.right);
            x.open(
                "object",
                attrs!("id" => format!("crosswalk{}", c.id), "name" => "crosswalk", "type" => "crosswalk",
                       "s" => num(c.s), "t" => 0, "zOffset" => 0, "hdg" => 0, "pitch" => 0, "roll" => 0,
                       "orientation" => "none", "length" => num(length), "width" => num(width), "height" => 0),
            );
            x.open("outlines", &[]);
            x.open("outline", attrs!("id" => 0, "closed" => "true", "outer" => "true"));
            for (u, v) in [(c.from, c.right), (c.to, c.right), (c.to, c.left), (c.from, c.left)] {
                x.empty("cornerLocal", attrs!("u" => num(u), "v" => num(v), "z" => 0, "height" => 0));
            }
            x.close();
            x.close();
            x.close();
        }
        x.close();
    }
    if !road.signals.is_empty() {
        x.open("signals", &[]);
        for s in &road.signals {
            x.empty(
                "signal",
                attrs!("s" => num(s.s), "t" => num(s.t), "id" => s.id, "name" => s.name,
                       "dynamic" => if s.dynamic { "yes" } else { "no" }, "orientation" => if s.along { "+" } else { "-" },
                       "zOffset" => 0, "country" => "DE", "countryRevision" => "2017", "type" => s.kind, "subtype" => "-1",
                       "value" => -1, "height" => num(s.height), "width" => num(s.width), "hOffset" => 0, "pitch" => 0, "roll" => 0),
            );
        }
        x.close();
    }
    x.close();
}

fn road_mark(x: &mut Xml, kind: &str, colour: &str) {
    x.empty(
        "roadMark",
        attrs!("sOffset" => 0, "type" => kind, "weight" => "standard", "color" => colour, "width" => "0.15", "laneChange" => "none"),
    );
}

fn print_lane(x: &mut Xml, road: &RoadDef, lane: &crate::network::Lane) {
    let kind = match lane.kind {
        LaneKind::Driving => "driving",
        LaneKind::Sidewalk => "sidewalk",
    };
    x.open("lane", attrs!("id" => lane.id, "type" => kind, "level" => "false"));
    if lane.predecessor.is_some() || lane.successor.is_some() {
        x.open("link", &[]);
        if let Some(p) = lane.predecessor {
            x.empty("predecessor", attrs!("id" => p));
        }
        if let Some(s) = lane.successor {
            x.empty("successor", attrs!("id" => s));
        }
        x.close();
    }
    x.empty("width", attrs!("sOffset" => 0, "a" => num(lane.width), "b" => 0, "c" => 0, "d" => 0));
    let side = if lane.id > 0 { &road.left } else { &road.right };
    let outer_driving = lane.kind == LaneKind::Driving
        && side
            .iter()
            .find(|l| l.id.unsigned_abs() == lane.id.unsigned_abs() + 1)
            .is_none_or(|l| l.kind != LaneKind::Driving);
    let mark = match lane.kind {
        _ if road.junction.is_some() => "none",
        LaneKind::Sidewalk => "none",
        LaneKind::Driving if outer_driving => "solid",
        LaneKind::Driving => "broken",
    };
    road_mark(x, mark, "standard");
    x.close();
}
