//! The Scenic backend: a checked TAD scenario as a Scenic 3 program.
//!
//! [`emit`] is pure: a lowered [`Module`], the [`Vocabulary`] its file sees and the
//! [`EmitOptions`] in, the program text and the backend's diagnostics out. Only scenarios
//! without errors should be emitted (the command line refuses the others).
//!
//! The program targets Scenic 3.1.1 with either the CARLA world model or Scenic's built-in
//! Newtonian simulator. It has four parts:
//!
//! 1. a header of comments: where it comes from, the source's description, and everything
//!    the backend left out or approximated (each also a coded warning);
//! 2. `param map` (and `param carla_map`), `param weather` and the `model`;
//! 3. a fixed prelude (`src/prelude/`): Python helpers that find where the ego vehicle can
//!    be on the map's road network and where every actor goes relative to it, and
//!    behaviors for what actors do;
//! 4. the scenario: the road requirements as data, the ego and every actor placed at its
//!    lane and offset, and (CARLA) a monitor holding the traffic light's state.
//!
//! The mapping from vocabulary to Scenic is documented in `spec/backends/scenic.md`.

pub mod mapping;
pub mod maps;
mod plan;
pub mod python;

use std::fmt::Write;

use tad_check::Vocabulary;
use tad_diagnostics::{Code, Diagnostic, Span};
use tad_syntax::model::{Known, Module, Val};

use plan::{Actor, Place, Plan};
use python::{comment_lines, comment_text, number, string};

/// The prelude's Python helpers, verbatim in every program.
pub const PRELUDE_PLACEMENT: &str = include_str!("prelude/placement.py");
/// The prelude's behaviors, verbatim in every program.
pub const PRELUDE_BEHAVIORS: &str = include_str!("prelude/behaviors.scenic");

/// The simulator a program is written for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Simulator {
    /// `model scenic.simulators.carla.model`: CARLA blueprints, weather, traffic lights.
    #[default]
    Carla,
    /// `model scenic.simulators.newtonian.driving_model`: runs headless in Scenic itself.
    Newtonian,
}

impl Simulator {
    pub fn parse(name: &str) -> Option<Simulator> {
        match name.to_ascii_lowercase().as_str() {
            "carla" => Some(Simulator::Carla),
            "newtonian" => Some(Simulator::Newtonian),
            _ => None,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Simulator::Carla => "carla",
            Simulator::Newtonian => "newtonian",
        }
    }

    pub fn model(self) -> &'static str {
        match self {
            Simulator::Carla => "scenic.simulators.carla.model",
            Simulator::Newtonian => "scenic.simulators.newtonian.driving_model",
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EmitOptions {
    pub simulator: Simulator,
    /// The map (a CARLA town such as `Town10HD`); `None` chooses the known map that has
    /// most of what the scenario needs.
    pub map: Option<String>,
    /// The directory holding `TOWN.xodr`. Absolute: written as is. Relative: resolved by
    /// Scenic from the `.scenic` file's directory (`localPath`). `None`: the map is expected
    /// next to the `.scenic` file. Scenic writes its parsed-map cache (`TOWN.snet`) into this
    /// directory, so it must be writable.
    pub map_dir: Option<String>,
    /// The name of the source file, for the header.
    pub source: Option<String>,
}

/// A generated program and what the backend has to say about it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Emitted {
    pub text: String,
    pub diagnostics: Vec<Diagnostic>,
    /// The map the program uses.
    pub map: String,
}

/// The Scenic program for the scenario of `module`.
pub fn emit(module: &Module, vocabulary: &Vocabulary, options: &EmitOptions) -> Emitted {
    let Some(scenario) = &module.scenario else {
        let span = module.declarations.first().map_or(Span::new(0, 0), |d| d.span);
        return Emitted {
            text: String::new(),
            diagnostics: vec![
                Diagnostic::new(Code::E0700, "there is no scenario to build", span, "this file only declares names")
                    .with_help("build a file with a `scenario`; modules of declarations are used by scenarios"),
            ],
            map: String::new(),
        };
    };
    let (plan, mut diagnostics) = plan::Planner::new(scenario, vocabulary, options).plan();
    tad_diagnostics::sort(&mut diagnostics);
    let text = render(module, &plan, &diagnostics, options);
    Emitted { text, diagnostics, map: plan.map }
}

fn source_text(module: &Module, field: &str) -> Option<String> {
    let attr = module.scenario.as_ref()?.attr("source", field)?;
    match &attr.value {
        Known::Given(Val::Text(t)) => Some(t.clone()),
        Known::Given(Val::Symbol(s)) => Some(s.name.clone()),
        Known::Given(Val::Quantity(q)) => Some(format!("{} {}", q.value, q.unit.as_str())),
        Known::Given(Val::Integer(n)) => Some(n.to_string()),
        _ => None,
    }
}

fn render(module: &Module, plan: &Plan, diagnostics: &[Diagnostic], options: &EmitOptions) -> String {
    let mut out = String::new();
    let sim = options.simulator;
    // --- header
    out.push_str(&comment_lines(
        &format!("Scenic 3 program generated by tadslc from the TAD scenario `{}`.", plan.scenario),
        "",
    ));
    if let Some(source) = &options.source {
        let _ = writeln!(out, "# Source file: {}", comment_text(source));
    }
    let target = match sim {
        Simulator::Carla => "CARLA",
        Simulator::Newtonian => "Scenic's Newtonian simulator",
    };
    let _ = writeln!(
        out,
        "# Target: {target} through Scenic 3.1.1 (model {}), map {}.",
        sim.model(),
        comment_text(&plan.map)
    );
    out.push_str("# Regenerate with `tadslc build --target scenic`: edits are lost. Sample in 2D mode (--2d).\n");
    for (field, label) in [("video", "Video"), ("time", "Time in the video"), ("frame", "Frame"), ("region", "Region")]
    {
        if let Some(value) = source_text(module, field) {
            let _ = writeln!(out, "# {label}: {}", comment_text(&value));
        }
    }
    if let Some(description) = source_text(module, "description") {
        out.push_str("# Description:\n");
        out.push_str(&comment_lines(description.trim_end(), "  "));
    }
    let notes: Vec<&Diagnostic> = diagnostics.iter().filter(|d| d.code != Code::W0706).collect();
    if !notes.is_empty() {
        out.push_str("# Left out or approximated (the build's warnings say where):\n");
        for d in notes {
            out.push_str(&comment_lines(&format!("{} {}", d.code, d.message), "  "));
        }
    }
    out.push('\n');

    // --- parameters and model
    let map_file = format!("{}.xodr", plan.map);
    let map_expr = match options.map_dir.as_deref() {
        None => format!("localPath({})", string(&map_file)),
        Some(dir) if std::path::Path::new(dir).is_absolute() => {
            string(&std::path::Path::new(dir).join(&map_file).to_string_lossy())
        }
        Some(dir) => {
            let dir = dir.trim_end_matches(['/', '\\']);
            let joined = if dir.is_empty() { map_file.clone() } else { format!("{dir}/{map_file}") };
            format!("localPath({})", string(&joined))
        }
    };
    let _ = writeln!(out, "param map = {map_expr}");
    if sim == Simulator::Carla {
        let _ = writeln!(out, "param carla_map = {}", string(&plan.map));
    }
    if plan.weather.is_empty() {
        out.push_str("# Weather and time of day not given: CARLA's default, a random weather preset.\n");
    } else {
        out.push_str(&comment_lines(&format!("Weather and time of day: {}.", plan.weather_summary), ""));
        if sim == Simulator::Newtonian {
            out.push_str("# (The Newtonian simulator does not render weather; the parameter is kept for CARLA.)\n");
        }
        let entries: Vec<String> = plan.weather.iter().map(|(k, v)| format!("{}: {}", string(k), number(*v))).collect();
        let _ = writeln!(out, "param weather = {{{}}}", entries.join(", "));
    }
    let _ = writeln!(out, "model {}", sim.model());
    out.push('\n');

    // --- prelude
    out.push_str("# ---- TADSL prelude: placement along lanes, and behaviors (the same in every program) ----\n");
    out.push_str(PRELUDE_PLACEMENT.trim_end());
    out.push_str("\n\n");
    out.push_str(PRELUDE_BEHAVIORS.trim_end());
    out.push_str("\n# ---- end of the prelude ----\n\n");

    // --- road
    let needs = &plan.needs;
    out.push_str("# The road around the ego vehicle");
    if plan.kept.is_empty() {
        out.push_str(": no particular features asked for.\n");
    } else {
        out.push_str(&comment_text(&format!(": {}.", plan.kept.join(", "))));
        out.push('\n');
    }
    if !plan.dropped.is_empty() {
        out.push_str(&comment_lines(
            &format!("Left out, as {} has no place with them and the rest: {}.", plan.map, plan.dropped.join(", ")),
            "",
        ));
    }
    if !plan.map_known {
        out.push_str("# The backend does not know this map: Scenic reports it if no place on it has this road.\n");
    }
    out.push_str(
        "# The ego is placed where the lane layout holds from `behind` metres behind it to `ahead` metres\n\
         # in front (and, with `approach`, that many metres before the junction its lane ends at).\n",
    );
    let opt_int = |v: Option<u32>| v.map_or("None".to_string(), |n| n.to_string());
    let junction = needs.junction.as_ref();
    let kind = match junction.and_then(|j| j.kind) {
        Some(maps::JunctionKind::Four) => "'4way'",
        Some(maps::JunctionKind::Three) => "'3way'",
        _ => "None",
    };
    let signalised = match junction.and_then(|j| j.signalised) {
        Some(true) => "True",
        Some(false) => "False",
        None => "None",
    };
    let maneuver = junction.and_then(|j| j.turn).map_or("None".to_string(), |c| string(mapping::maneuver(c)));
    let signs: Vec<String> = junction
        .map(|j| {
            j.signs
                .iter()
                .filter_map(|s| {
                    if *s == "stop" {
                        Some("'206'")
                    } else if *s == "yield" {
                        Some("'205'")
                    } else {
                        None
                    }
                })
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default();
    let signs = match signs.len() {
        0 => "()".to_string(),
        1 => format!("({},)", signs[0]),
        _ => format!("({})", signs.join(", ")),
    };
    let shape = match (junction, needs.shape) {
        (None, Some(maps::Shape::Straight)) => "'straight'",
        (None, Some(maps::Shape::Curved)) => "'curved'",
        _ => "None",
    };
    let approach = if junction.is_some() { number(needs.approach) } else { "None".into() };
    let _ = writeln!(
        out,
        "tadRoad = dict(same={}, other={}, minSame={}, minOther={}, index={}, sidewalk={},\n               \
         junction={kind}, signalised={signalised}, maneuver={maneuver}, signs={signs},\n               \
         shape={shape}, ahead={}, behind={}, approach={approach})",
        opt_int(needs.same),
        opt_int(needs.other),
        needs.min_same,
        needs.min_other,
        needs.index,
        if needs.sidewalk { "True" } else { "False" },
        number(needs.ahead),
        number(needs.behind),
    );
    out.push_str("tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))\n\n");

    // --- actors
    out.push_str(&comment_lines(&plan.ego_summary, ""));
    actor(&mut out, &plan.ego, "tadEgoAt");
    let mut spot = 0;
    for group in &plan.groups {
        out.push('\n');
        out.push_str(&comment_lines(&group.summary, ""));
        for a in &group.actors {
            spot += 1;
            actor(&mut out, a, &format!("tadAt{spot}"));
        }
    }

    // --- traffic light
    if let Some((state, name)) = &plan.light {
        out.push('\n');
        match sim {
            Simulator::Carla => {
                out.push_str(&comment_lines(
                    &format!(
                        "The traffic light facing the ego vehicle is `{name}`: hold the nearest one in that state."
                    ),
                    "",
                ));
                out.push_str(
                    "# (Without CARLA's model, as under Scenic's Newtonian simulator, the monitor does nothing.)\n\
                     monitor TadTrafficLight(state):\n    \
                     hold = globals().get('setClosestTrafficLightStatus')\n    \
                     while True:\n        \
                     if hold is not None:\n            \
                     hold(ego, state)\n        \
                     wait\n",
                );
                let _ = writeln!(out, "require monitor TadTrafficLight({})", string(state));
            }
            Simulator::Newtonian => {
                out.push_str(&comment_lines(
                    &format!("The traffic light facing the ego vehicle is `{name}`: the Newtonian simulator has no traffic lights (W0704)."),
                    "",
                ));
            }
        }
    }
    out
}

/// `SPOT = tadSpot(...)` and `NAME = new CLASS at SPOT[0], facing SPOT[1], ...`.
fn actor(out: &mut String, a: &Actor, spot: &str) {
    let place = match a.place {
        Place::Centre => String::new(),
        Place::Curb => format!(", 'curb', {}", number(a.width)),
        Place::Sidewalk => ", 'sidewalk'".to_string(),
    };
    let _ = writeln!(out, "{spot} = tadSpot(tadAnchor, {}, {}{place})", number(a.offset), a.lane);
    let facing = if a.across { format!("{spot}[1] + 90 deg") } else { format!("{spot}[1]") };
    let _ = write!(
        out,
        "{} = new {} at {spot}[0], facing {facing},\n    with blueprint {}",
        a.ident,
        a.class.as_str(),
        string(a.blueprint)
    );
    if a.ident == "ego" {
        out.push_str(", with rolename 'hero'");
    }
    let _ = write!(out, ", with width {}, with length {}", number(a.width), number(a.length));
    if a.ident != "ego" {
        out.push_str(",\n    with regionContainedIn None");
    }
    if a.class == mapping::Class::Debris {
        // the Newtonian model's Debris is a plain object, which must be visible by default
        out.push_str(", with requireVisible False");
    }
    if a.speed > 0.0 {
        let _ = write!(out, ", with speed {}", number(a.speed));
    }
    if let Some(behavior) = &a.behavior {
        let _ = write!(out, ", with behavior {behavior}");
    }
    out.push('\n');
}
