//! Renderers: adapters from [`Diagnostic`](crate::Diagnostic) to a terminal, JSON and SARIF.
//!
//! Each renderer takes the file's name and text alongside the diagnostics; nothing here
//! reads files or decides exit codes.

pub mod human;
pub mod json;
pub mod sarif;

/// A file's name, text and diagnostics, as the renderers need them.
pub struct FileReport<'a> {
    pub name: &'a str,
    pub text: &'a str,
    pub diagnostics: &'a [crate::Diagnostic],
}
