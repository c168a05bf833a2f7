//! Python and Scenic text that scenario text cannot break out of: identifiers, string
//! literals and comments.
//!
//! Scenario names come from TAD identifiers (ASCII letters, digits, `_`), but the backend
//! does not rely on that: every identifier is rebuilt from `[A-Za-z0-9_]`, and names that
//! Python or Scenic already use are prefixed. Strings become ASCII-only Python literals, so
//! no quote, backslash, line break or Unicode trick survives; comments keep printable text
//! only, one line each.

use std::collections::HashSet;

/// Names a generated identifier must not take: Python keywords, soft keywords and builtins,
/// every word of Scenic 3.1.1's grammar, and every global name of a driving program under
/// the CARLA and Newtonian models (dumped from Scenic 3.1.1; sorted). Names starting with
/// `_` or with `tad` (any case) are reserved as well: the first for Python's private and
/// special names, the second for the backend's own helpers.
pub const RESERVED: &[&str] = &[
    "ATM",
    "Above",
    "AccelerateForwardBehavior",
    "Action",
    "Advertisement",
    "Ahead",
    "AltitudeFrom",
    "AltitudeTo",
    "Always",
    "AngleFrom",
    "AngleTo",
    "ApparentHeading",
    "ApparentlyFacing",
    "ArithmeticError",
    "AssertionError",
    "At",
    "AtomicProposition",
    "AttributeError",
    "AutopilotBehavior",
    "Back",
    "BackLeft",
    "BackRight",
    "Barrel",
    "Barrier",
    "BaseException",
    "BaseExceptionGroup",
    "Behavior",
    "Behind",
    "Below",
    "Bench",
    "Beyond",
    "Bicycle",
    "BlockConclusion",
    "BlockingIOError",
    "Bottom",
    "BottomBackLeft",
    "BottomBackRight",
    "BottomFrontLeft",
    "BottomFrontRight",
    "Box",
    "BoxRegion",
    "BoxShape",
    "BrokenPipeError",
    "BufferError",
    "Bus",
    "BusStop",
    "BytesWarning",
    "CanSee",
    "Car",
    "CarlaActor",
    "CarlaSimulator",
    "Case",
    "Chair",
    "ChildProcessError",
    "CircularRegion",
    "Color",
    "Cone",
    "ConeShape",
    "ConnectionAbortedError",
    "ConnectionError",
    "ConnectionRefusedError",
    "ConnectionResetError",
    "ConstantThrottleBehavior",
    "ContainedIn",
    "Container",
    "CreasedBox",
    "CrossingBehavior",
    "CylinderShape",
    "Debris",
    "DeprecationWarning",
    "Discrete",
    "DiscreteRange",
    "DistanceFrom",
    "DistancePast",
    "DriveAvoidingCollisions",
    "DrivingObject",
    "DrivingWorkspace",
    "DynamicScenario",
    "EOFError",
    "Ellipsis",
    "EncodingWarning",
    "EnvironmentError",
    "Eventually",
    "Exception",
    "ExceptionGroup",
    "FC",
    "Facing",
    "FacingAwayFrom",
    "FacingDirectlyAwayFrom",
    "FacingDirectlyToward",
    "FacingToward",
    "False",
    "FieldAt",
    "File",
    "FileExistsError",
    "FileNotFoundError",
    "Files",
    "FloatingPointError",
    "Follow",
    "FollowLaneBehavior",
    "FollowTrajectoryBehavior",
    "Following",
    "Front",
    "FrontLeft",
    "FrontRight",
    "FutureWarning",
    "Garbage",
    "GeneratorExit",
    "Gnome",
    "GuardViolation",
    "IOError",
    "Implies",
    "ImportError",
    "ImportWarning",
    "In",
    "IndentationError",
    "IndexError",
    "InterruptedError",
    "Intersection",
    "Intersects",
    "InvariantViolation",
    "IronPlate",
    "IsADirectoryError",
    "KeyError",
    "KeyboardInterrupt",
    "Kiosk",
    "Lane",
    "LaneChangeBehavior",
    "LaneGroup",
    "LaneSection",
    "Left",
    "LeftSpec",
    "LookupError",
    "Mailbox",
    "ManeuverType",
    "MemoryError",
    "MeshShape",
    "MeshSurfaceRegion",
    "MeshVolumeRegion",
    "Modifier",
    "ModuleNotFoundError",
    "Monitor",
    "Motorcycle",
    "Mutator",
    "NPCCar",
    "NameError",
    "Network",
    "NetworkElement",
    "NewtonianActor",
    "NewtonianSimulator",
    "Next",
    "Node",
    "None",
    "Normal",
    "NotADirectoryError",
    "NotImplemented",
    "NotImplementedError",
    "NotVisible",
    "NotVisibleFrom",
    "NotVisibleFromOp",
    "NotVisibleSpec",
    "OSError",
    "Object",
    "OffsetAction",
    "OffsetAlong",
    "OffsetAlongSpec",
    "OffsetBy",
    "On",
    "Optional",
    "Options",
    "Orientation",
    "OrientedPoint",
    "OverflowError",
    "PathRegion",
    "Pedestrian",
    "PedestrianCrossing",
    "PendingDeprecationWarning",
    "PermissionError",
    "PlantPot",
    "Point",
    "PointSetRegion",
    "PolygonalRegion",
    "PolygonalVectorField",
    "PolylineRegion",
    "PreconditionViolation",
    "ProcessLookupError",
    "Prop",
    "PropositionAnd",
    "PropositionNot",
    "PropositionOr",
    "RGBSensor",
    "Range",
    "RectangularRegion",
    "RecursionError",
    "ReferenceError",
    "Region",
    "RegulatedControlAction",
    "RejectionException",
    "RelativeHeading",
    "RelativePosition",
    "RelativeTo",
    "ResourceWarning",
    "Right",
    "RightSpec",
    "Road",
    "RuntimeError",
    "RuntimeWarning",
    "SSSensor",
    "SectorRegion",
    "Sensor",
    "SetBrakeAction",
    "SetHandBrakeAction",
    "SetPositionAction",
    "SetReverseAction",
    "SetSpeedAction",
    "SetSteerAction",
    "SetThrottleAction",
    "SetVelocityAction",
    "SetWalkingDirectionAction",
    "SetWalkingSpeedAction",
    "Shape",
    "SimulatorInterfaceWarning",
    "SpheroidRegion",
    "SpheroidShape",
    "SteeringAction",
    "Steers",
    "StopAsyncIteration",
    "StopIteration",
    "SyntaxError",
    "SyntaxWarning",
    "SystemError",
    "SystemExit",
    "TabError",
    "Table",
    "TimeoutError",
    "Top",
    "TopBackLeft",
    "TopBackRight",
    "TopFrontLeft",
    "TopFrontRight",
    "TrafficWarning",
    "Trash",
    "Truck",
    "True",
    "TruncatedNormal",
    "TurnBehavior",
    "TypeError",
    "UnboundLocalError",
    "UnicodeDecodeError",
    "UnicodeEncodeError",
    "UnicodeError",
    "UnicodeTranslateError",
    "UnicodeWarning",
    "Uniform",
    "Until",
    "UserWarning",
    "ValueError",
    "Van",
    "Vector",
    "VectorField",
    "Vehicle",
    "VendingMachine",
    "VerifaiDiscreteRange",
    "VerifaiOptions",
    "VerifaiParameter",
    "VerifaiRange",
    "Visible",
    "VisibleFrom",
    "VisibleFromOp",
    "VisibleSpec",
    "WalkBehavior",
    "WalkForwardBehavior",
    "WalkingAction",
    "Walks",
    "Warning",
    "With",
    "Workspace",
    "ZeroDivisionError",
    "a",
    "abort",
    "above",
    "abs",
    "additive",
    "after",
    "ahead",
    "aiter",
    "all",
    "along",
    "altitude",
    "always",
    "and",
    "anext",
    "angle",
    "any",
    "apparent",
    "apparently",
    "as",
    "ascii",
    "assert",
    "async",
    "at",
    "attribute",
    "await",
    "away",
    "back",
    "behavior",
    "behind",
    "below",
    "beyond",
    "bin",
    "blueprints",
    "bool",
    "bottom",
    "break",
    "breakpoint",
    "by",
    "bytearray",
    "bytes",
    "callWithStarArgs",
    "callable",
    "can",
    "case",
    "choose",
    "chr",
    "class",
    "classmethod",
    "comparison",
    "compile",
    "complex",
    "compose",
    "concatenateCenterlines",
    "contained",
    "continue",
    "copyright",
    "cos",
    "credits",
    "curb",
    "def",
    "deg",
    "del",
    "delattr",
    "dict",
    "dir",
    "directly",
    "distance",
    "divmod",
    "do",
    "dsfsdf",
    "dynamic",
    "ego",
    "elif",
    "ellipsis",
    "else",
    "enumerate",
    "eval",
    "eventually",
    "every",
    "everywhere",
    "except",
    "exec",
    "exit",
    "expression",
    "facing",
    "file",
    "filter",
    "final",
    "finally",
    "float",
    "follow",
    "following",
    "for",
    "format",
    "freezeTrafficLights",
    "from",
    "front",
    "frozenset",
    "getClosestTrafficLightStatus",
    "getTrafficLightStatus",
    "getattr",
    "global",
    "globalParameters",
    "globals",
    "hasattr",
    "hash",
    "heading",
    "help",
    "hex",
    "hypot",
    "id",
    "if",
    "implies",
    "import",
    "in",
    "in_initial_scenario",
    "initial",
    "input",
    "int",
    "interrupt",
    "intersection",
    "intersects",
    "invariant",
    "is",
    "is2DMode",
    "isinstance",
    "issubclass",
    "iter",
    "kind",
    "lambda",
    "left",
    "len",
    "license",
    "list",
    "literal",
    "localPath",
    "locals",
    "map",
    "map_town",
    "match",
    "math",
    "max",
    "memoryview",
    "min",
    "model",
    "monitor",
    "mutate",
    "name",
    "network",
    "new",
    "next",
    "nonlocal",
    "not",
    "nowhere",
    "obj",
    "object",
    "oct",
    "of",
    "offset",
    "on",
    "open",
    "or",
    "ord",
    "override",
    "param",
    "pass",
    "past",
    "pathlib",
    "position",
    "pow",
    "precondition",
    "print",
    "property",
    "quit",
    "r",
    "raise",
    "range",
    "record",
    "record_final",
    "record_initial",
    "relative",
    "render",
    "repr",
    "require",
    "require_monitor",
    "resample",
    "return",
    "reversed",
    "right",
    "road",
    "roadDirection",
    "roadOrShoulder",
    "round",
    "runTryInterrupt",
    "s",
    "scenario",
    "seconds",
    "see",
    "set",
    "setAllIntersectionTrafficLightsStatus",
    "setClosestTrafficLightStatus",
    "setTrafficLightStatus",
    "setattr",
    "setup",
    "shoulder",
    "shuffle",
    "sidewalk",
    "simulation",
    "simulator",
    "sin",
    "slice",
    "sorted",
    "starred",
    "staticmethod",
    "steps",
    "str",
    "subscript",
    "sum",
    "super",
    "take",
    "terminate",
    "terminate_after",
    "terminate_simulation_when",
    "terminate_when",
    "to",
    "top",
    "toward",
    "try",
    "tuple",
    "type",
    "u",
    "unfreezeTrafficLights",
    "until",
    "vars",
    "verbosePrint",
    "visible",
    "wait",
    "warnings",
    "when",
    "while",
    "with",
    "withinDistanceToAnyCars",
    "withinDistanceToAnyObjs",
    "withinDistanceToAnyPedestrians",
    "withinDistanceToObjsInLane",
    "withinDistanceToRedYellowTrafficLight",
    "withinDistanceToTrafficLight",
    "workspace",
    "wrapStarredValue",
    "yield",
    "zip",
];

/// Whether `name` may not be used as a generated identifier.
pub fn is_reserved(name: &str) -> bool {
    name.starts_with('_') || name.to_ascii_lowercase().starts_with("tad") || RESERVED.binary_search(&name).is_ok()
}

/// Allocates identifiers for the generated program: valid Python identifiers, never
/// reserved, never twice.
#[derive(Debug, Default)]
pub struct Names {
    taken: HashSet<String>,
}

impl Names {
    /// An identifier for scenario name `name`: the name itself when it is safe, else `g_`
    /// followed by it; characters outside `[A-Za-z0-9_]` become `_`; a clash gets `_2`, `_3`...
    pub fn fresh(&mut self, name: &str) -> String {
        let mut base: String =
            name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
        if base.is_empty() || base.starts_with(|c: char| c.is_ascii_digit()) || is_reserved(&base) {
            base = format!("g_{base}");
        }
        let mut candidate = base.clone();
        let mut n = 2;
        while self.taken.contains(&candidate) || is_reserved(&candidate) {
            candidate = format!("{base}_{n}");
            n += 1;
        }
        self.taken.insert(candidate.clone());
        candidate
    }

    /// Reserve an identifier the generator uses itself (`ego`).
    pub fn reserve(&mut self, name: &str) {
        self.taken.insert(name.to_string());
    }
}

/// A Python string literal with the value `text`, in ASCII only: quotes, backslashes and
/// every character outside printable ASCII are escaped.
pub fn string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('\'');
    for c in text.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '\'' => out.push_str("\\'"),
            '"' => out.push_str("\\\""),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            ' '..='~' => out.push(c),
            c if (c as u32) < 0x100 => out.push_str(&format!("\\x{:02x}", c as u32)),
            c if (c as u32) < 0x10000 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push_str(&format!("\\U{:08x}", c as u32)),
        }
    }
    out.push('\'');
    out
}

/// Characters kept out of comments although they print: line and paragraph separators,
/// bidirectional controls, zero-width and other invisible format characters.
fn invisible(c: char) -> bool {
    matches!(c as u32,
        0x00AD | 0x034F | 0x061C | 0x115F | 0x1160 | 0x17B4 | 0x17B5 | 0x180B..=0x180F
        | 0x200B..=0x200F | 0x2028..=0x202E | 0x2060..=0x206F | 0x3164 | 0xFE00..=0xFE0F
        | 0xFEFF | 0xFFA0 | 0xFFF0..=0xFFFB | 0x1D173..=0x1D17A | 0xE0000..=0xE0FFF)
}

/// Text made safe for one line of a `#` comment: control and invisible characters are
/// written as `\u{..}`, so nothing can end the comment or hide in it.
pub fn comment_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() || invisible(c) {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// `#` comment lines for a text of any number of lines, each prefixed with `indent`.
pub fn comment_lines(text: &str, indent: &str) -> String {
    let mut out = String::new();
    for line in text.split('\n') {
        let line = comment_text(line.strip_suffix('\r').unwrap_or(line));
        let line = line.trim_end();
        if line.is_empty() {
            out.push_str("#\n");
        } else {
            out.push_str(&format!("# {indent}{line}\n"));
        }
    }
    out
}

/// A number as a Python float literal, rounded to millimetres (or mm/s, or 0.001 degrees).
pub fn number(value: f64) -> String {
    let rounded = (value * 1000.0).round() / 1000.0;
    let rounded = if rounded == 0.0 { 0.0 } else { rounded };
    let text = format!("{rounded}");
    if text.contains('.') || text.contains('e') || text.contains("inf") || text.contains("NaN") {
        if rounded.is_finite() { text } else { "0.0".to_string() }
    } else {
        format!("{text}.0")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserved_list_is_sorted_for_binary_search() {
        assert!(RESERVED.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn identifiers_avoid_keywords_builtins_and_scenic_names() {
        let mut names = Names::default();
        names.reserve("ego");
        for (name, expected) in [
            ("bus", "bus"),
            ("class", "g_class"),
            ("new", "g_new"),
            ("require", "g_require"),
            ("import", "g_import"),
            ("ego2", "ego2"),
            ("Car", "g_Car"),
            ("network", "g_network"),
            ("tadAnchor", "g_tadAnchor"),
            ("_hidden", "g__hidden"),
            ("3d", "g_3d"),
            ("bus", "bus_2"),
            ("a b\"c", "a_b_c"),
            ("", "g_"),
        ] {
            assert_eq!(names.fresh(name), expected);
        }
    }

    #[test]
    fn strings_are_ascii_and_escaped() {
        assert_eq!(string("a'b\"c\\d"), r#"'a\'b\"c\\d'"#);
        assert_eq!(string("x\ny\r\u{2028}é😀\u{0}"), r"'x\ny\r\u2028\xe9\U0001f600\x00'");
        assert!(string("'''\"\"\"").is_ascii());
    }

    #[test]
    fn comments_stay_on_their_line() {
        assert_eq!(comment_lines("a\nb\r\n\u{2028}c\u{202e}", ""), "# a\n# b\n# \\u{2028}c\\u{202e}\n");
        assert_eq!(comment_text("x\u{85}y\u{b}z"), "x\\u{85}y\\u{b}z");
    }

    #[test]
    fn numbers_are_float_literals() {
        assert_eq!(number(2.0), "2.0");
        assert_eq!(number(10.0 / 3.6), "2.778");
        assert_eq!(number(-0.0001), "0.0");
        assert_eq!(number(f64::NAN), "0.0");
    }
}
