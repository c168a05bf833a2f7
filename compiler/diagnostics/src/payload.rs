//! The typed fact behind a diagnostic.
//!
//! One variant per family of facts, not per code: a code says which rule was broken, the
//! payload says with what values. Programs read these and never the message (the repair
//! and refinement requests of the LLM front-end are rendered from them; the language
//! server builds completions from `candidates`). Serialised with a `kind` tag; names are
//! the vocabulary's and the schema's own spellings.

use serde::Serialize;

/// A part of a scenario that states attributes.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "element", rename_all = "snake_case")]
pub enum Element {
    Environment,
    Road,
    Ego,
    Group { name: String },
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Payload {
    #[default]
    None,
    /// Text that does not fit the grammar: what could come here, and what came.
    Syntax { expected: Vec<String>, found: Option<String> },
    /// A name nothing declares. `namespace` is a vocabulary kind (`weather`, `behavior`),
    /// or `section`, `field`, `key`, `reference`, `module`, `declaration_kind`, `unit`.
    /// `candidates` are the closest known names, best first; `module` a module that
    /// declares the name, when one does.
    Unknown { namespace: String, name: String, candidates: Vec<String>, module: Option<String> },
    /// Another spelling of a known name.
    Alias { namespace: String, written: String, canonical: String },
    /// A value of the wrong kind, or in the wrong unit.
    WrongValue { field: String, expected: String, found: String },
    /// A name given twice where once is allowed.
    Duplicate { namespace: String, name: String, earlier_module: Option<String> },
    /// A section or block with nothing in it.
    Empty { section: String },
    /// A name the language keeps for itself.
    Reserved { name: String },
    /// A scenario element without attributes it must state.
    Missing { element: Element, fields: Vec<String> },
    /// A scenario with none of what makes a traffic scenario.
    NonScenario { absent: Vec<String> },
    /// A number outside what it may be. `unit` is the written unit of `value`, `min` and
    /// `max` (km/h for speeds).
    OutOfRange { quantity: String, value: f64, min: Option<f64>, max: Option<f64>, unit: Option<String> },
    /// A combination the vocabulary rules out: `subject` cannot have `value` (a behavior
    /// its actor kind cannot perform, a light on an unsignalised road); `allowed` lists
    /// what could be there, when known.
    Incompatible { subject: String, value: String, allowed: Vec<String> },
    /// Groups positioned relative to each other in a circle.
    Cycle { groups: Vec<String> },
    /// A used module with errors of its own.
    ModuleErrors { module: String, errors: usize },
    /// A construct a backend cannot express exactly, and what it does instead.
    Unsupported { backend: String, construct: String, instead: Option<String> },
}

impl Payload {
    pub fn is_none(&self) -> bool {
        matches!(self, Payload::None)
    }

    /// The kind tag, as serialised.
    pub fn kind(&self) -> &'static str {
        match self {
            Payload::None => "none",
            Payload::Syntax { .. } => "syntax",
            Payload::Unknown { .. } => "unknown",
            Payload::Alias { .. } => "alias",
            Payload::WrongValue { .. } => "wrong_value",
            Payload::Duplicate { .. } => "duplicate",
            Payload::Empty { .. } => "empty",
            Payload::Reserved { .. } => "reserved",
            Payload::Missing { .. } => "missing",
            Payload::NonScenario { .. } => "non_scenario",
            Payload::OutOfRange { .. } => "out_of_range",
            Payload::Incompatible { .. } => "incompatible",
            Payload::Cycle { .. } => "cycle",
            Payload::ModuleErrors { .. } => "module_errors",
            Payload::Unsupported { .. } => "unsupported",
        }
    }
}
