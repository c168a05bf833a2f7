//! The TADSL checker: what a structurally valid scenario means, and whether it holds up.
//!
//! Input is the lowered [`Module`] and the [`Vocabulary`] its file sees; output is a
//! [`Checked`]: diagnostics (each with its typed payload) and the completeness [`Class`] of
//! the scenario. Four passes, each reporting and going on:
//!
//! 1. names: every name resolves in the vocabulary of its field (or is reported with the
//!    closest name); aliases and non-canonical units are warnings with fixes;
//! 2. declarations: the names a declaration refers to resolve too;
//! 3. semantics: lanes, behaviors per actor kind, speeds, relations against lanes,
//!    reference cycles, lights and signs;
//! 4. completeness: missing essential attributes, and the class they add up to.
//!
//! The checker states facts; requests in words for an extractor or a language model are
//! rendered from the payloads by `tad-feedback`.
//!
//! The checker knows no vocabulary lists: every name comes from declarations.

mod completeness;
mod names;
mod semantics;
pub mod vocab;

pub use completeness::{Class, Essential};
pub use names::{Groups, Target, target};
pub use semantics::{EGO_KIND, lanes_counted_from_zero, performs};
pub use vocab::{Conflict, Entry, Layer, Lookup, Vocabulary};

use tad_diagnostics::Diagnostic;
use tad_syntax::model::Module;

/// Rules that can be switched per run.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Options {
    pub profile: Profile,
    /// A scenario missing all of these is not a scenario.
    pub non_scenario: Vec<Essential>,
    /// The region of scenarios that name none (`--region`): its module is in scope.
    pub region: Option<String>,
    /// The file is a model's answer from the video pipeline (a YAML answer); set per file
    /// by the database.
    pub answer: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            profile: Profile::Auto,
            non_scenario: vec![Essential::Weather, Essential::Time, Essential::Road],
            region: None,
            answer: false,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Profile {
    /// The dash-cam rules for what comes from the video pipeline — a YAML answer, or a
    /// scenario whose `source` names a video, a frame or a time in one — and no camera
    /// rules otherwise.
    Auto,
    /// No camera rules.
    Default,
    /// TrafficAlign's extraction rules for forward-facing dash-cam frames: nothing is
    /// described behind the ego vehicle.
    Dashcam,
}

impl Options {
    /// Whether the dash-cam rules apply to `module`.
    pub fn dashcam(&self, module: &Module) -> bool {
        match self.profile {
            Profile::Dashcam => true,
            Profile::Default => false,
            Profile::Auto => {
                self.answer
                    || module.scenario.as_ref().and_then(|s| s.section("source")).is_some_and(|source| {
                        ["video", "frame", "time"]
                            .iter()
                            .any(|f| source.attr(f).is_some_and(|a| a.value.given().is_some()))
                    })
            }
        }
    }
}

/// The result of checking one module.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checked {
    pub diagnostics: Vec<Diagnostic>,
    /// `None` for a module without a scenario.
    pub class: Option<Class>,
}

/// Check `module` against `vocabulary`. `prior` are the problems found reading the file
/// (syntax, structure): where they are, what is missing is not judged, since the text
/// that states it may be what could not be read. Diagnostics are sorted by position.
pub fn check(module: &Module, vocabulary: &Vocabulary, options: &Options, prior: &[Diagnostic]) -> Checked {
    let mut out = Checked::default();
    names::declarations(module, vocabulary, &mut out.diagnostics);
    if let Some(scenario) = &module.scenario {
        let resolved = names::scenario(scenario, vocabulary, &mut out.diagnostics);
        semantics::check(scenario, vocabulary, &resolved, options.dashcam(module), &mut out.diagnostics);
        out.class = Some(completeness::classify(scenario, options, prior, &mut out.diagnostics));
    }
    tad_diagnostics::sort(&mut out.diagnostics);
    out
}

/// E0700: a backend was asked to build a file that declares names but holds no scenario.
pub fn no_scenario(module: &Module) -> Diagnostic {
    let span = module.declarations.first().map_or(tad_diagnostics::Span::new(0, 0), |d| d.span);
    Diagnostic::new(
        tad_diagnostics::Code::E0700,
        "there is no scenario to build",
        span,
        "this file only declares names",
    )
    .with_help("build a file with a `scenario`; modules of declarations are used by scenarios")
    .with_payload(tad_diagnostics::Payload::Syntax {
        expected: vec!["scenario".into()],
        found: Some("declarations only".into()),
    })
}
