//! TADSL syntax: everything from source text to the scenario model, without I/O.
//!
//! ```text
//! text ──lexer──▶ tokens ──parse──▶ cst::File ──lower──▶ model::Module
//!                    └── comments ──────┴──▶ format (canonical text)
//! ```
//!
//! Every step is total: it returns its result and a list of diagnostics and never panics,
//! whatever the input. Vocabulary and scenario semantics are checked elsewhere.

pub mod cst;
pub mod format;
pub mod lexer;
pub mod lower;
pub mod model;
mod parse;
pub mod schema;
pub mod suggest;

mod sniff;

pub use parse::{Parsed, parse};
pub use sniff::begins_like_tad;
use tad_diagnostics::Diagnostic;

/// Parse and lower one file: its model and every lexical, syntax and structure
/// diagnostic, sorted by position. A text that is not TAD at all (Markdown, JSON, YAML,
/// prose) is one E0007 naming what it looks like, not hundreds of syntax errors.
pub fn analyze(src: &str) -> (model::Module, Vec<Diagnostic>) {
    let parsed = parse(src);
    let (module, lowered) = lower::lower(src, &parsed.file);
    let mut diagnostics = parsed.diagnostics;
    diagnostics.extend(lowered);
    tad_diagnostics::sort(&mut diagnostics);
    if let Some(not_tad) = sniff::not_tad(src, &diagnostics) {
        return (model::Module::default(), vec![not_tad]);
    }
    (module, diagnostics)
}
