//! The `.tadc` format's vocabulary, declared once for the encoder, the loader, the
//! disassembler and the spec's tables (`spec/bytecode.md` §2–§4): the magic, the version,
//! the opcodes with their mnemonics, and the one-byte tags of the closed sets.

use crate::program::Light;
use tad_ir::Signal;
use tad_road::{Arm, Body, Facing, Place, Shape, Side, Turn};

/// The first four bytes of every `.tadc` file.
pub const MAGIC: [u8; 4] = *b"TADC";
/// The format this crate writes and reads (`spec/bytecode.md` §7: any change to the bytes
/// or their meaning takes a new number).
pub const FORMAT_VERSION: u16 = 2;
/// Bytes before the first section: magic, version, flags, three section lengths.
pub const HEADER_LEN: usize = 20;

macro_rules! opcodes {
    ($($(#[$doc:meta])* $op:ident = $byte:literal, $mnemonic:literal, $blocks:literal;)+) => {
        /// An instruction's first byte.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Op {
            $($(#[$doc])* $op = $byte),+
        }

        impl Op {
            pub const ALL: &'static [Op] = &[$(Op::$op),+];

            pub fn from_byte(byte: u8) -> Option<Op> {
                match byte {
                    $($byte => Some(Op::$op),)+
                    _ => None,
                }
            }

            /// Its name in listings.
            pub fn mnemonic(self) -> &'static str {
                match self {
                    $(Op::$op => $mnemonic),+
                }
            }

            /// Whether it blocks its actor's script until it holds (set-up and the other
            /// behaviour instructions return at once).
            pub fn blocks(self) -> bool {
                match self {
                    $(Op::$op => $blocks),+
                }
            }
        }
    };
}

opcodes! {
    Road = 0x01, "road", false;
    Limits = 0x02, "limits", false;
    Signal = 0x03, "signal", false;
    Ego = 0x04, "ego", false;
    Spawn = 0x05, "spawn", false;
    Wait = 0x10, "wait", true;
    WaitNear = 0x11, "waitnear", true;
    Drive = 0x12, "drive", false;
    Follow = 0x13, "follow", false;
    Cross = 0x14, "cross", false;
    ChangeLane = 0x15, "lane", false;
    Speed = 0x16, "speed", false;
    Stop = 0x17, "stop", false;
    Signals = 0x18, "signals", false;
    Mobil = 0x19, "mobil", false;
    Meet = 0x1a, "meet", true;
}

impl Op {
    /// Whether it sets the scene up (before step 0) rather than drives an actor.
    pub fn is_setup(self) -> bool {
        (self as u8) < 0x10
    }
}

/// A closed set stored as one byte.
pub trait Tag: Sized + Copy {
    /// What it is, in errors: `an arm`.
    const WHAT: &'static str;
    fn tag(self) -> u8;
    fn from_tag(tag: u8) -> Option<Self>;
}

macro_rules! tags {
    ($ty:ty, $what:literal { $($variant:path = $byte:literal),+ $(,)? }) => {
        impl Tag for $ty {
            const WHAT: &'static str = $what;
            fn tag(self) -> u8 {
                match self {
                    $($variant => $byte),+
                }
            }
            fn from_tag(tag: u8) -> Option<Self> {
                match tag {
                    $($byte => Some($variant),)+
                    _ => None,
                }
            }
        }
    };
}

tags!(Arm, "an arm" { Arm::Ego = 0, Arm::Left = 1, Arm::Right = 2, Arm::Opposite = 3 });
tags!(Turn, "a turn" { Turn::Straight = 0, Turn::Left = 1, Turn::Right = 2, Turn::UTurn = 3 });
tags!(Body, "a body" { Body::Vehicle = 0, Body::Walker = 1, Body::Object = 2 });
tags!(Place, "a place" { Place::Lane = 0, Place::Curb = 1, Place::Shoulder = 2, Place::Sidewalk = 3 });
tags!(Light, "a light" { Light::Off = 0, Light::Red = 1, Light::Yellow = 2, Light::Green = 3 });

impl Tag for Facing {
    const WHAT: &'static str = "a facing";
    fn tag(self) -> u8 {
        match self {
            Facing::Along => 0,
            Facing::Across { from: Side::Left } => 1,
            Facing::Across { from: Side::Right } => 2,
        }
    }
    fn from_tag(tag: u8) -> Option<Self> {
        match tag {
            0 => Some(Facing::Along),
            1 => Some(Facing::Across { from: Side::Left }),
            2 => Some(Facing::Across { from: Side::Right }),
            _ => None,
        }
    }
}

/// The road's shape; a junction's arm count is a byte of its own.
impl Tag for Shape {
    const WHAT: &'static str = "a road shape";
    fn tag(self) -> u8 {
        match self {
            Shape::Straight => 0,
            Shape::Curve { left: true } => 1,
            Shape::Curve { left: false } => 2,
            Shape::Junction { roundabout: false, .. } => 3,
            Shape::Junction { roundabout: true, .. } => 4,
        }
    }
    /// A junction's `arms` is 0 here; the loader reads it from the next byte.
    fn from_tag(tag: u8) -> Option<Self> {
        match tag {
            0 => Some(Shape::Straight),
            1 => Some(Shape::Curve { left: true }),
            2 => Some(Shape::Curve { left: false }),
            3 => Some(Shape::Junction { arms: 0, roundabout: false }),
            4 => Some(Shape::Junction { arms: 0, roundabout: true }),
            _ => None,
        }
    }
}

/// What the light facing the ego shows; 0 is none.
impl Tag for Option<Signal> {
    const WHAT: &'static str = "a light state";
    fn tag(self) -> u8 {
        match self {
            None => 0,
            Some(Signal::Green) => 1,
            Some(Signal::Red) => 2,
            Some(Signal::Yellow) => 3,
            Some(Signal::Off) => 4,
        }
    }
    fn from_tag(tag: u8) -> Option<Self> {
        match tag {
            0 => Some(None),
            1 => Some(Some(Signal::Green)),
            2 => Some(Some(Signal::Red)),
            3 => Some(Some(Signal::Yellow)),
            4 => Some(Some(Signal::Off)),
            _ => None,
        }
    }
}

/// The bit of an arm in a junction's arm set.
pub fn arm_bit(arm: Arm) -> u8 {
    1 << arm.tag()
}

/// Flags of the `Road` instruction.
pub const ROAD_SIDEWALKS: u8 = 1;
pub const ROAD_CROSSWALKS: u8 = 2;
/// Flags of a junction.
pub const JUNCTION_ROUNDABOUT: u8 = 1;
pub const JUNCTION_SIGNALISED: u8 = 2;
pub const JUNCTION_STOP_SIGNS: u8 = 4;

/// Names of the closed sets in listings.
pub fn arm_name(arm: Arm) -> &'static str {
    arm.as_str()
}

pub fn turn_name(turn: Turn) -> &'static str {
    match turn {
        Turn::Straight => "straight",
        Turn::Left => "left",
        Turn::Right => "right",
        Turn::UTurn => "u_turn",
    }
}

pub fn body_name(body: Body) -> &'static str {
    match body {
        Body::Vehicle => "vehicle",
        Body::Walker => "walker",
        Body::Object => "object",
    }
}

pub fn place_name(place: Place) -> &'static str {
    match place {
        Place::Lane => "lane",
        Place::Curb => "curb",
        Place::Shoulder => "shoulder",
        Place::Sidewalk => "sidewalk",
    }
}

pub fn light_name(light: Light) -> &'static str {
    tad_ir::ClosedSet::as_str(light)
}
