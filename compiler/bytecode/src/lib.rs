//! TADSL bytecode: a scenario's layout as a program the runtime runs (`spec/bytecode.md`).
//!
//! ```text
//! ir::Scenario + Layout ──lower──▶ Program ──encode──▶ .tadc bytes
//!                                  Program ◀──decode── .tadc bytes (checked: never panics)
//!                                  Program ──disasm──▶ text
//! ```
//!
//! [`Program`] is the decoded form; the runtime reads it, never the bytes.

pub mod program;

pub use program::*;
