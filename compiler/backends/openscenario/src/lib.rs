//! The OpenSCENARIO backend: a checked TAD scenario as OpenSCENARIO XML 1.2 on an OpenDRIVE
//! 1.7 road generated from the layout (`spec/backends/openscenario.md`).
//!
//! ```text
//! Scenario ──tad_layout──▶ Layout ──network──▶ Network ──xodr──▶ NAME.xodr
//!                            │   (or, --map: ──site──▶ Site on town::Town, TownNN.xodr referenced)
//!                            └──tad_bytecode::lower──▶ Program ──xosc──▶ NAME.xosc
//!                                                                 └────▶ NAME.distribution.xosc
//! ```
//!
//! Nothing is decided here: the road is the layout's (or the town's place for it), and every
//! actor's start, script and parameter slot is the lowered program's (the runtime's own),
//! written in OpenSCENARIO's terms. What has no counterpart is a coded warning (W0710, W0711;
//! W0712 for what the town lacks). [`emit`] and [`emit_on_town`] are pure.

pub mod environment;
pub mod mapping;
pub mod network;
pub mod site;
pub mod town;
pub mod xml;
pub mod xodr;
pub mod xosc;

use tad_diagnostics::Diagnostic;
use tad_ir::Scenario;

/// The date both files carry: fixed, so that the same source gives the same bytes.
pub const DATE: &str = "2026-01-01T00:00:00";

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EmitOptions {
    /// The scenario's file stem: the files are `STEM.xosc`, `STEM.xodr` and
    /// `STEM.distribution.xosc`, and reference each other by these names.
    pub stem: String,
    /// The source file's name, for the header.
    pub source: String,
}

/// The files of one scenario and the backend's warnings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Emitted {
    pub xosc: String,
    /// The generated road; `None` on a town, whose file the scenario names.
    pub xodr: Option<String>,
    /// The parameter value distribution, when the scenario has parameters.
    pub distribution: Option<String>,
    pub diagnostics: Vec<Diagnostic>,
}

/// The files' extensions: each is written as `STEM.EXT`, the name the others reference it by.
pub const XOSC: &str = "xosc";
pub const XODR: &str = "xodr";
pub const DISTRIBUTION: &str = "distribution.xosc";

impl Emitted {
    /// The files to write: `(extension, text)`.
    pub fn files(&self) -> Vec<(&'static str, &str)> {
        let mut files = vec![(XOSC, self.xosc.as_str())];
        if let Some(road) = &self.xodr {
            files.push((XODR, road.as_str()));
        }
        if let Some(d) = &self.distribution {
            files.push((DISTRIBUTION, d.as_str()));
        }
        files
    }
}

/// The OpenSCENARIO files of a resolved scenario.
pub fn emit(scenario: &Scenario, options: &EmitOptions) -> Emitted {
    let layout = tad_layout::lay_out(scenario);
    let program = tad_bytecode::lower(scenario, &layout, &options.source);
    let net = network::network(&layout);
    let name = program.name.clone();
    let xodr_file = format!("{}.{XODR}", options.stem);
    let ground = xosc::Ground::Generated(&net);
    let context = xosc::Context { scenario, layout: &layout, program: &program, ground, xodr_file: &xodr_file };
    let out = xosc::print(&context, &format!("{}.{XOSC}", options.stem));
    Emitted {
        xosc: out.text,
        xodr: Some(xodr::print(&net, &name)),
        distribution: out.distribution,
        diagnostics: sorted(out.diagnostics),
    }
}

/// The OpenSCENARIO files of a resolved scenario placed on a CARLA town (`site`), whose
/// OpenDRIVE file the scenario names by `town_file`. `Err`, in words, when the town has no
/// place of the layout's kind at all (no junction, or no road with driving lanes).
pub fn emit_on_town(
    scenario: &Scenario,
    options: &EmitOptions,
    town: &town::Town,
    town_file: &str,
) -> Result<Emitted, String> {
    let layout = tad_layout::lay_out(scenario);
    let program = tad_bytecode::lower(scenario, &layout, &options.source);
    let site = site::site(&layout, town).ok_or_else(|| match layout.road.junction {
        Some(_) => format!("`{}` has no junction to place the scenario at", town.name),
        None => format!("`{}` has no road with driving lanes", town.name),
    })?;
    let ground = xosc::Ground::Town(&site);
    let context = xosc::Context { scenario, layout: &layout, program: &program, ground, xodr_file: town_file };
    let out = xosc::print(&context, &format!("{}.{XOSC}", options.stem));
    let mut diagnostics = out.diagnostics;
    for m in &site.misfits {
        diagnostics.push(xosc::misfit(&context, &site, &m.what, m.lanes, "placed on its nearest match"));
    }
    Ok(Emitted { xosc: out.text, xodr: None, distribution: out.distribution, diagnostics: sorted(diagnostics) })
}

fn sorted(mut diagnostics: Vec<Diagnostic>) -> Vec<Diagnostic> {
    tad_diagnostics::sort(&mut diagnostics);
    diagnostics.dedup_by(|a, b| a.code == b.code && a.message == b.message);
    diagnostics
}
