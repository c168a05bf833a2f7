//! YAML interchange for TADSL: the YAML scenarios LLMs answer with (TrafficAlign's
//! translation prompt, TrafficComposer's IR) to the scenario model, and back.
//!
//! ```text
//! raw answer ──extract──▶ YAML text ──serde_norway──▶ values ──┐
//!                              └──scan (spans by line)──────────┴──lower──▶ model::Module
//! model::Module ──export──▶ TrafficAlign YAML (with extra keys)
//! model::Module ──to_tad──▶ canonical TAD source
//! ```
//!
//! Pure (no I/O) and total: every function returns a result for any input and never
//! panics; problems are diagnostics (codes `E03xx`/`W03xx`) whose spans are byte ranges
//! of the text given to [`lower`], so they point at the YAML lines.
//!
//! The two dialects' keys are one table, [`dialect::KEYS`]; how their values map to TAD
//! is described in `spec/yaml.md`.

pub mod dialect;
mod export;
mod extract;
mod import;
pub mod norm;
mod parse;
mod scan;
mod tad;

pub use dialect::Dialect;
pub use export::export;
pub use extract::extract;
pub use import::{lower, lower_answer};
pub use tad::to_tad;

/// The camera rules a YAML file may state for itself (its top-level `profile`), as
/// `tadslc check --profile` names them: `auto` (the dash-cam rules only for a `source` that
/// names a video, frame or time, as for TAD), `default` (none), `dashcam`. `export` writes
/// `auto`; an answer that states none is checked with the dash-cam rules.
pub const PROFILES: [&str; 3] = ["auto", "default", "dashcam"];

/// The dialect of the YAML in `answer`, if there is a YAML mapping to judge.
pub fn dialect(answer: &str) -> Option<Dialect> {
    let range = extract(answer)?;
    let text = &answer[range];
    if parse::too_deep(text).is_some() {
        return None;
    }
    match serde_norway::from_str::<serde_norway::Value>(text).ok()? {
        serde_norway::Value::Mapping(map) => Some(import::detect(&map)),
        _ => None,
    }
}
