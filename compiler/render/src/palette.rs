//! Every colour and size the pictures use, in one table each, so that the SVG and the GIF
//! look alike and a change of style is a change here only.
//!
//! Sizes are in metres on the road (they scale with the picture) unless named `_PX`
//! (pixels of the SVG figure). The GIF's global colour table is [`all`]: its frames use
//! no other colour, so they are drawn without anti-aliasing and indexed exactly.

use crate::Kind;

/// An opaque sRGB colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Colour(pub u8, pub u8, pub u8);

impl Colour {
    /// `#rrggbb`.
    pub fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

// --- the ground and the road
pub const BACKGROUND: Colour = Colour(0xe9, 0xee, 0xe0);
pub const ASPHALT: Colour = Colour(0x74, 0x77, 0x7b);
pub const SIDEWALK: Colour = Colour(0xd6, 0xd0, 0xc2);
pub const ISLAND: Colour = Colour(0xb5, 0xcf, 0x9b);
pub const MARKING: Colour = Colour(0xff, 0xff, 0xff);
pub const CENTRE_LINE: Colour = Colour(0xf2, 0xc2, 0x00);

// --- what happened on it
pub const ROUTE: Colour = Colour(0x1b, 0x4f, 0x9c);
pub const EVENT: Colour = Colour(0xff, 0xd7, 0x00);
pub const EVENT_EDGE: Colour = Colour(0x00, 0x00, 0x00);
pub const INK: Colour = Colour(0x22, 0x22, 0x22);
pub const PAPER: Colour = Colour(0xff, 0xff, 0xff);
pub const FRAME: Colour = Colour(0x99, 0x99, 0x99);

/// A kind of actor's colours: the body, and a darker shade for its front and outline.
#[derive(Clone, Copy, Debug)]
pub struct KindStyle {
    pub fill: Colour,
    pub dark: Colour,
    /// Trajectory width, m.
    pub trail: f64,
    pub name: &'static str,
}

pub fn kind(kind: Kind) -> KindStyle {
    match kind {
        Kind::Ego => {
            KindStyle { fill: Colour(0xe0, 0x31, 0x2a), dark: Colour(0x8c, 0x12, 0x0e), trail: 0.45, name: "ego" }
        }
        Kind::Vehicle => {
            KindStyle { fill: Colour(0x2f, 0x7e, 0xd8), dark: Colour(0x12, 0x3f, 0x7a), trail: 0.25, name: "vehicle" }
        }
        Kind::Walker => {
            KindStyle { fill: Colour(0x1f, 0xa3, 0x4a), dark: Colour(0x0b, 0x57, 0x23), trail: 0.2, name: "walker" }
        }
        Kind::Animal => {
            KindStyle { fill: Colour(0xe8, 0x8a, 0x1a), dark: Colour(0x8a, 0x4d, 0x05), trail: 0.2, name: "animal" }
        }
        Kind::Object => {
            KindStyle { fill: Colour(0x8e, 0x5c, 0xc2), dark: Colour(0x4b, 0x2a, 0x70), trail: 0.2, name: "object" }
        }
    }
}

/// What a light shows, and off.
pub fn light(light: crate::Light) -> Colour {
    match light {
        crate::Light::Green => Colour(0x1e, 0xc2, 0x3c),
        crate::Light::Yellow => Colour(0xff, 0xb0, 0x00),
        crate::Light::Red => Colour(0xe8, 0x10, 0x10),
        crate::Light::Off => Colour(0x44, 0x44, 0x44),
    }
}

/// Every colour a GIF frame may hold, in a fixed order: its global colour table.
pub fn all() -> Vec<Colour> {
    let mut all =
        vec![BACKGROUND, ASPHALT, SIDEWALK, ISLAND, MARKING, CENTRE_LINE, ROUTE, EVENT, EVENT_EDGE, INK, PAPER, FRAME];
    for k in Kind::ALL {
        all.extend([kind(k).fill, kind(k).dark]);
    }
    all.extend(crate::LIGHTS.map(light));
    let mut seen = std::collections::HashSet::new();
    all.retain(|c| seen.insert(*c));
    all
}

// --- markings, m
pub const LINE: f64 = 0.15;
/// The gap between the two lines of a double centre line, m.
pub const CENTRE_GAP: f64 = 0.15;
/// Dashes between lanes of one direction: (paint, gap), m.
pub const DASH: (f64, f64) = (3.0, 6.0);
/// How far an edge line lies inside the curb, m.
pub const EDGE_INSET: f64 = 0.3;
pub const STOP_LINE: f64 = 0.5;
/// A crosswalk's extent along its road (the road's), and its stripes' width and pitch across it, m.
pub use tad_road::road::CROSSWALK_DEPTH;
pub const STRIPE: f64 = 0.5;
pub const STRIPE_PITCH: f64 = 1.0;
/// A roundabout's ring (the carriageway round the island) is this many lane widths wide.
pub const RING_LANES: f64 = 1.2;
/// A signal's dot radius, and how far beyond the right curb it stands, m.
pub const SIGNAL_RADIUS: f64 = 0.9;
pub const SIGNAL_OFFSET: f64 = 1.2;

// --- what happened, m
/// The route's width, and its dashes (paint, gap).
pub const ROUTE_WIDTH: f64 = 0.25;
pub const ROUTE_DASH: (f64, f64) = (1.5, 1.0);
/// A time tick's length across the trajectory (every second; every fifth is longer).
pub const TICK: f64 = 1.2;
pub const TICK_LONG: f64 = 2.2;
/// The start pose's outline width.
pub const OUTLINE: f64 = 0.2;
/// The share of a body's length painted dark at its front.
pub const FRONT: f64 = 0.22;
/// An event's ring: its radius and its stroke (hollow, so what collided stays visible).
pub const EVENT_RADIUS: f64 = 1.6;
pub const EVENT_STROKE: f64 = 0.35;
/// The smallest a body is drawn (walkers seen from afar), m.
pub const MIN_BODY: f64 = 0.5;

// --- the view
/// The margin round what happened, m, and the view's least extent, m.
pub const MARGIN: f64 = 5.0;
pub const MIN_VIEW: f64 = 20.0;
/// The SVG map's longer side, px, and its greatest aspect ratio.
pub const MAP_PX: f64 = 900.0;
pub const MAX_ASPECT: f64 = 3.5;
/// The SVG's title band and padding, px.
pub const TITLE_PX: f64 = 36.0;
pub const PAD_PX: f64 = 12.0;
pub const FONT_PX: f64 = 12.0;
pub const TITLE_FONT_PX: f64 = 16.0;
pub const LABEL_FONT_PX: f64 = 11.0;
/// Time marks' text ("4 s") and the least distance between two on a trajectory, px.
pub const TIME_FONT_PX: f64 = 9.0;
pub const TIME_GAP_PX: f64 = 48.0;
/// Actors of one group (`parked[0]`, `parked[1]`…) this near each other share a label, m.
pub const GROUP_M: f64 = 9.0;
/// A text's width per character, in font sizes (wide enough for DejaVu Sans, the usual
/// stand-in for Helvetica), for placing labels without measuring glyphs.
pub const CHAR_EM: f64 = 0.62;
/// The legend below the map: a row's height, a symbol's width, the gap between columns, px.
pub const LEGEND_ROW_PX: f64 = 20.0;
pub const LEGEND_SYMBOL_PX: f64 = 28.0;
pub const LEGEND_GAP_PX: f64 = 24.0;
/// Scale bars are this long at most, px; their lengths are 1, 2 or 5 times a power of ten, m.
pub const SCALE_BAR_PX: f64 = 120.0;

// --- the GIF
/// The picture's width and least width, px (its height follows the view's aspect).
pub const GIF_WIDTH: u32 = 800;
pub const GIF_MIN_WIDTH: u32 = 720;
/// The title band's and the legend band's height, px, and text's padding in them.
pub const GIF_BAND_PX: u32 = 24;
pub const GIF_PAD_PX: u32 = 6;
/// The progress bar's height, px.
pub const GIF_BAR_PX: u32 = 4;
/// The thinnest a line is drawn in the GIF, and the smallest a body, px.
pub const GIF_MIN_PX: f32 = 1.0;
pub const GIF_MIN_BODY_PX: f64 = 4.0;
/// The ego is drawn at least this long, with a halo this wide round it, px.
pub const GIF_EGO_MIN_PX: f64 = 12.0;
pub const GIF_HALO_PX: f32 = 2.0;
