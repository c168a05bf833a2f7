//! TADSL bytecode: a scenario's layout as a program the runtime runs (`spec/bytecode.md`).
//!
//! ```text
//! ir::Scenario + Layout ──lower──▶ Program ──encode──▶ .tadc bytes
//!                                  Program ◀──decode── .tadc bytes (verified: never panics)
//!                                  Program ──disasm──▶ text
//! ```
//!
//! [`Program`] is the decoded form; the runtime reads it, never the bytes. Modules:
//! `program` (the types, the runtime's contract), `format` (magic, version, opcodes and
//! tags, declared once), `encode`, `decode` (byte-level checks), `verify` (the rules the
//! runtime relies on), `error`, `lower` (from the layout), `disasm` (the listing). The road
//! and the words an actor is described by are `tad-road`'s contract; only `lower` reads
//! `tad-layout`.

mod decode;
mod disasm;
mod encode;
mod error;
pub mod format;
mod lower;
pub mod program;
mod verify;

pub use decode::decode;
pub use disasm::disasm;
pub use encode::encode;
pub use error::{ErrorKind, Invalid, Item, LoadError};
pub use format::FORMAT_VERSION;
pub use lower::lower;
pub use program::*;
pub use verify::{MAX_COORDINATE, MAX_LANES, MAX_STEPS, verify};
