//! A CARLA town's road network, read from its OpenDRIVE file: what `--map TownNN` places the
//! layout on (`spec/backends/openscenario.md` §4).
//!
//! Only what placement needs is kept: each road's reference line (lines and arcs, the only
//! pieces CARLA's towns use; a spiral or polynomial piece is refused by name), its lane
//! offset, its lane sections with their lanes' kinds, widths (cubic in `s`) and links, its
//! links to roads and junctions, and the signals referenced on each connecting road. The
//! file is untrusted: a missing attribute or a number that does not parse is an error that
//! names the element, never a panic.

use std::collections::BTreeMap;

use tad_road::geom::{Pose, Vec2};

/// A cubic `a + b·ds + c·ds² + d·ds³` from `s` on.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cubic {
    s: f64,
    a: f64,
    b: f64,
    c: f64,
    d: f64,
}

impl Cubic {
    fn at(&self, s: f64) -> f64 {
        let ds = s - self.s;
        self.a + ds * (self.b + ds * (self.c + ds * self.d))
    }
}

/// The cubic of a list that holds at `s`: the last one starting at or before it.
fn piecewise(list: &[Cubic], s: f64) -> f64 {
    list.iter().rev().find(|c| c.s <= s + 1e-9).or(list.first()).map_or(0.0, |c| c.at(s))
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    s: f64,
    start: Pose,
    length: f64,
    /// 1/m, positive to the left; 0 for a line.
    curvature: f64,
}

impl Piece {
    fn pose(&self, ds: f64) -> Pose {
        let (p, h, k) = (self.start.position, self.start.yaw, self.curvature);
        if k.abs() < 1e-12 {
            return Pose { position: p + Vec2::from_yaw(h) * ds, yaw: h };
        }
        let yaw = h + k * ds;
        let position = p + Vec2::new((yaw.sin() - h.sin()) / k, (h.cos() - yaw.cos()) / k);
        Pose { position, yaw }
    }
}

/// One lane of a lane section.
#[derive(Clone, Debug, PartialEq)]
pub struct Lane {
    /// OpenDRIVE's id: negative on the right of the reference line, positive on its left.
    pub id: i32,
    /// OpenDRIVE's `type` (`driving`, `sidewalk`, `shoulder`, …).
    pub kind: String,
    widths: Vec<Cubic>,
    pub predecessor: Option<i32>,
    pub successor: Option<i32>,
}

impl Lane {
    pub fn driving(&self) -> bool {
        self.kind == "driving"
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    pub s: f64,
    /// Its lanes except the centre lane, in the file's order.
    pub lanes: Vec<Lane>,
}

/// Where a road's end leads: a road or a junction, and which end of a road.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    pub junction: bool,
    pub id: u32,
    /// The linked road is entered at its end (`contactPoint="end"`).
    pub at_end: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Road {
    pub id: u32,
    pub length: f64,
    /// The junction a connecting road belongs to.
    pub junction: Option<u32>,
    pieces: Vec<Piece>,
    offsets: Vec<Cubic>,
    pub sections: Vec<Section>,
    pub predecessor: Option<Link>,
    pub successor: Option<Link>,
    /// Traffic lights on the road or referenced by it, and their `s`.
    pub signals: Vec<(u32, f64)>,
}

impl Road {
    /// The reference line's pose at `s` (clamped to the road).
    pub fn pose(&self, s: f64) -> Pose {
        let s = s.clamp(0.0, self.length);
        match self.pieces.iter().rev().find(|p| p.s <= s + 1e-9).or(self.pieces.first()) {
            Some(p) => p.pose(s - p.s),
            None => Pose { position: Vec2::new(0.0, 0.0), yaw: 0.0 },
        }
    }

    /// The point `t` metres left of the reference line at `s`.
    pub fn point(&self, s: f64, t: f64) -> Vec2 {
        let p = self.pose(s);
        p.position + Vec2::from_yaw(p.yaw).left() * t
    }

    /// The lane section at `s`.
    pub fn section(&self, s: f64) -> Option<&Section> {
        self.sections.iter().rev().find(|k| k.s <= s + 1e-9).or(self.sections.first())
    }

    /// The lanes at `s`.
    pub fn lanes_at(&self, s: f64) -> &[Lane] {
        self.section(s).map_or(&[], |k| &k.lanes)
    }

    /// A lane's inner and outer edge at `s`, `t` (left positive).
    pub fn lane_span(&self, s: f64, id: i32) -> Option<(f64, f64)> {
        let section = self.section(s)?;
        let sign = f64::from(id.signum());
        let width = |lane: &Lane| piecewise(&lane.widths, s - section.s).max(0.0);
        let inner: f64 =
            section.lanes.iter().filter(|l| l.id.signum() == id.signum() && l.id.abs() < id.abs()).map(width).sum();
        let lane = section.lanes.iter().find(|l| l.id == id)?;
        let centre = piecewise(&self.offsets, s);
        Some((centre + sign * inner, centre + sign * (inner + width(lane))))
    }

    /// A lane's centre at `s`, `t`.
    pub fn lane_centre(&self, s: f64, id: i32) -> Option<f64> {
        self.lane_span(s, id).map(|(a, b)| (a + b) / 2.0)
    }

    /// The driving lanes at `s` on one side (`sign` −1: right, 1: left), innermost first.
    pub fn driving(&self, s: f64, sign: i32) -> Vec<i32> {
        let Some(section) = self.section(s) else { return Vec::new() };
        let mut ids: Vec<i32> =
            section.lanes.iter().filter(|l| l.driving() && l.id.signum() == sign).map(|l| l.id).collect();
        ids.sort_by_key(|id| id.abs());
        ids
    }

    /// The lane at `(s, t)` (the nearest when `t` is beyond every lane) and the offset from
    /// its centre.
    pub fn lane_at(&self, s: f64, t: f64) -> Option<(i32, f64)> {
        let section = self.section(s)?;
        let spans = section.lanes.iter().filter_map(|l| self.lane_span(s, l.id).map(|(a, b)| (l.id, a, b)));
        let gap = |t: f64, a: f64, b: f64| if t < a.min(b) { a.min(b) - t } else { (t - a.max(b)).max(0.0) };
        let best = spans.min_by(|x, y| gap(t, x.1, x.2).total_cmp(&gap(t, y.1, y.2)))?;
        Some((best.0, t - (best.1 + best.2) / 2.0))
    }
}

/// A junction's connection: traffic of `incoming` enters `connecting`.
#[derive(Clone, Debug, PartialEq)]
pub struct Connection {
    pub incoming: u32,
    pub connecting: u32,
    /// The connecting road is entered at its end (its traffic drives against its reference line).
    pub at_end: bool,
    /// `(incoming lane, connecting lane)`.
    pub lanes: Vec<(i32, i32)>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Junction {
    pub id: u32,
    pub connections: Vec<Connection>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Town {
    pub name: String,
    /// By id.
    pub roads: BTreeMap<u32, Road>,
    /// By id.
    pub junctions: BTreeMap<u32, Junction>,
}

impl Town {
    pub fn road(&self, id: u32) -> Option<&Road> {
        self.roads.get(&id)
    }

    /// Reads an OpenDRIVE file. `name` is the town's (`Town10HD`).
    pub fn parse(name: &str, text: &str) -> Result<Town, String> {
        let doc = roxmltree::Document::parse(text).map_err(|e| format!("`{name}.xodr` is not XML: {e}"))?;
        let root = doc.root_element();
        let mut town = Town { name: name.to_string(), roads: BTreeMap::new(), junctions: BTreeMap::new() };
        for node in root.children().filter(|n| n.is_element()) {
            match node.tag_name().name() {
                "road" => {
                    let road = read_road(node)?;
                    town.roads.insert(road.id, road);
                }
                "junction" => {
                    let junction = read_junction(node)?;
                    town.junctions.insert(junction.id, junction);
                }
                _ => {}
            }
        }
        if town.roads.is_empty() {
            return Err(format!("`{name}.xodr` has no roads"));
        }
        Ok(town)
    }
}

fn attr<T: std::str::FromStr>(node: roxmltree::Node, name: &str) -> Result<T, String> {
    // the line is found only for the message: finding it scans the file
    let at = || format!("line {}: <{}>", node.document().text_pos_at(node.range().start).row, node.tag_name().name());
    let raw = node.attribute(name).ok_or_else(|| format!("{} has no `{name}`", at()))?;
    raw.trim().parse().map_err(|_| format!("{} `{name}` is `{raw}`, not a number", at()))
}

/// A finite number (`NaN` and infinities parse as `f64`, and no road is made of them).
fn number(node: roxmltree::Node, name: &str) -> Result<f64, String> {
    let x: f64 = attr(node, name)?;
    if x.is_finite() {
        Ok(x)
    } else {
        let line = node.document().text_pos_at(node.range().start).row;
        Err(format!("line {line}: <{}> `{name}` is {x}, not a finite number", node.tag_name().name()))
    }
}

fn children<'a, 'i>(node: roxmltree::Node<'a, 'i>, tag: &'a str) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> {
    node.children().filter(move |n| n.has_tag_name(tag))
}

fn cubic(node: roxmltree::Node, s: &str) -> Result<Cubic, String> {
    Ok(Cubic {
        s: number(node, s)?,
        a: number(node, "a")?,
        b: number(node, "b")?,
        c: number(node, "c")?,
        d: number(node, "d")?,
    })
}

fn read_road(node: roxmltree::Node) -> Result<Road, String> {
    let id: u32 = attr(node, "id")?;
    let junction: i64 = attr(node, "junction")?;
    let mut road = Road {
        id,
        length: number(node, "length")?.max(0.0),
        junction: u32::try_from(junction).ok(),
        pieces: Vec::new(),
        offsets: Vec::new(),
        sections: Vec::new(),
        predecessor: None,
        successor: None,
        signals: Vec::new(),
    };
    for link in children(node, "link") {
        road.predecessor = children(link, "predecessor").next().map(read_link).transpose()?;
        road.successor = children(link, "successor").next().map(read_link).transpose()?;
    }
    for geometry in children(node, "planView").flat_map(|p| children(p, "geometry")) {
        let start =
            Pose { position: Vec2::new(number(geometry, "x")?, number(geometry, "y")?), yaw: number(geometry, "hdg")? };
        let shape = geometry.children().find(|n| n.is_element());
        let curvature = match shape.map(|n| n.tag_name().name()) {
            Some("line") => 0.0,
            Some("arc") => number(shape.unwrap_or(geometry), "curvature")?,
            other => {
                return Err(format!(
                    "road {id}: a `{}` piece of its reference line is not read",
                    other.unwrap_or("empty")
                ));
            }
        };
        road.pieces.push(Piece { s: number(geometry, "s")?, start, length: number(geometry, "length")?, curvature });
    }
    if road.pieces.is_empty() {
        return Err(format!("road {id} has no reference line"));
    }
    let lanes = children(node, "lanes").next();
    for offset in lanes.into_iter().flat_map(|l| children(l, "laneOffset")) {
        road.offsets.push(cubic(offset, "s")?);
    }
    for section in lanes.into_iter().flat_map(|l| children(l, "laneSection")) {
        road.sections.push(read_section(section)?);
    }
    for reference in children(node, "signals").flat_map(|s| children(s, "signalReference")) {
        road.signals.push((attr(reference, "id")?, number(reference, "s")?));
    }
    for signal in children(node, "signals").flat_map(|s| children(s, "signal")) {
        if signal.attribute("dynamic") == Some("yes") {
            road.signals.push((attr(signal, "id")?, number(signal, "s")?));
        }
    }
    Ok(road)
}

fn read_link(node: roxmltree::Node) -> Result<Link, String> {
    Ok(Link {
        junction: node.attribute("elementType") == Some("junction"),
        id: attr(node, "elementId")?,
        at_end: node.attribute("contactPoint") == Some("end"),
    })
}

fn read_section(node: roxmltree::Node) -> Result<Section, String> {
    let mut lanes = Vec::new();
    for side in ["left", "right"] {
        for lane in children(node, side).flat_map(|s| children(s, "lane")) {
            let mut widths = Vec::new();
            for w in children(lane, "width") {
                widths.push(cubic(w, "sOffset")?);
            }
            let link = children(lane, "link").next();
            let linked = |tag: &str| -> Result<Option<i32>, String> {
                link.and_then(|l| children(l, tag).next()).map(|n| attr(n, "id")).transpose()
            };
            lanes.push(Lane {
                id: attr(lane, "id")?,
                kind: lane.attribute("type").unwrap_or("none").to_string(),
                widths,
                predecessor: linked("predecessor")?,
                successor: linked("successor")?,
            });
        }
    }
    Ok(Section { s: number(node, "s")?, lanes })
}

fn read_junction(node: roxmltree::Node) -> Result<Junction, String> {
    let mut connections = Vec::new();
    for c in children(node, "connection") {
        let mut lanes = Vec::new();
        for link in children(c, "laneLink") {
            lanes.push((attr(link, "from")?, attr(link, "to")?));
        }
        connections.push(Connection {
            incoming: attr(c, "incomingRoad")?,
            connecting: attr(c, "connectingRoad")?,
            at_end: c.attribute("contactPoint") == Some("end"),
            lanes,
        });
    }
    Ok(Junction { id: attr(node, "id")?, connections })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROAD: &str = r#"<OpenDRIVE>
  <road name="r" length="100" id="7" junction="-1">
    <link><successor elementType="junction" elementId="3"/></link>
    <planView>
      <geometry s="0" x="0" y="0" hdg="0" length="50"><line/></geometry>
      <geometry s="50" x="50" y="0" hdg="0" length="50"><arc curvature="0.02"/></geometry>
    </planView>
    <lanes>
      <laneOffset s="0" a="0.5" b="0" c="0" d="0"/>
      <laneSection s="0">
        <left><lane id="1" type="driving"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane></left>
        <center><lane id="0" type="none"/></center>
        <right>
          <lane id="-1" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>
          <lane id="-2" type="sidewalk"><width sOffset="0" a="2" b="0" c="0" d="0"/></lane>
        </right>
      </laneSection>
    </lanes>
  </road>
</OpenDRIVE>"#;

    #[test]
    fn reads_lines_arcs_and_lanes() {
        let town = Town::parse("T", ROAD).unwrap();
        let road = town.road(7).unwrap();
        assert_eq!(road.successor, Some(Link { junction: true, id: 3, at_end: false }));
        let end = road.pose(100.0);
        // a quarter of … 50 m at 1/50: one radian to the left
        assert!((end.yaw - 1.0).abs() < 1e-9);
        assert!((end.position.x - (50.0 + 50.0 * 1f64.sin())).abs() < 1e-9);
        assert!((end.position.y - 50.0 * (1.0 - 1f64.cos())).abs() < 1e-9);
        assert_eq!(road.lane_span(10.0, -1), Some((0.5, -3.0)));
        assert_eq!(road.lane_span(10.0, -2), Some((-3.0, -5.0)));
        assert_eq!(road.lane_centre(10.0, 1), Some(2.0));
        assert_eq!(road.driving(10.0, -1), vec![-1]);
        assert_eq!(road.lane_at(10.0, -6.0), Some((-2, -2.0)));
    }

    #[test]
    fn bad_files_are_errors_that_name_the_element() {
        assert!(Town::parse("T", "<OpenDRIVE/>").unwrap_err().contains("no roads"));
        let bad = ROAD.replace(r#"length="100""#, r#"length="long""#);
        let e = Town::parse("T", &bad).unwrap_err();
        assert!(e.contains("<road> `length` is `long`"), "{e}");
        let nan = ROAD.replace(r#"length="100""#, r#"length="NaN""#);
        assert!(Town::parse("T", &nan).unwrap_err().contains("not a finite number"));
        // a negative length is an empty road, not a panic
        let negative = Town::parse("T", &ROAD.replace(r#"length="100""#, r#"length="-5""#)).unwrap();
        assert_eq!(negative.road(7).unwrap().pose(3.0).position, Vec2::new(0.0, 0.0));
        let spiral = ROAD.replace("<line/>", r#"<spiral curvStart="0" curvEnd="0.1"/>"#);
        assert!(Town::parse("T", &spiral).unwrap_err().contains("`spiral` piece"));
        assert!(Town::parse("T", "<Open").is_err());
    }
}
