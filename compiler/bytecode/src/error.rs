//! What can be wrong with a `.tadc` file or a program, in words (`spec/bytecode.md` §6).
//!
//! One [`ErrorKind`] for both stages: the loader's byte-level errors and the verifier's
//! rules. The verifier says which item is wrong ([`Invalid`]); the loader turns that into
//! the item's byte offset ([`LoadError`]).

use std::fmt;

/// Why a file does not load, and where: a byte offset into the file.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadError {
    pub offset: usize,
    pub kind: ErrorKind,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (at byte {})", self.kind, self.offset)
    }
}

impl std::error::Error for LoadError {}

/// Which part of a program breaks a rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// The program as a whole (something missing).
    Program,
    Param(usize),
    Path(usize),
    Instr(usize),
}

impl fmt::Display for Item {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Item::Program => write!(f, "the program"),
            Item::Param(i) => write!(f, "parameter slot {i}"),
            Item::Path(i) => write!(f, "path #{i}"),
            Item::Instr(i) => write!(f, "instruction {i}"),
        }
    }
}

/// A program that breaks a rule of `spec/bytecode.md` §6.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    pub at: Item,
    pub kind: ErrorKind,
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.at, self.kind)
    }
}

impl std::error::Error for Invalid {}

#[derive(Clone, Debug, PartialEq)]
pub enum ErrorKind {
    // ── bytes ────────────────────────────────────────────────────────────────────────
    /// The magic is not `TADC`.
    NotBytecode,
    /// A format this loader does not read.
    NewerFormat {
        found: u16,
        reads: u16,
    },
    UnknownFormat {
        found: u16,
    },
    /// Reserved header flags set.
    Flags(u16),
    /// The bytes (of the file, or of a section) end inside something.
    Truncated {
        inside: &'static str,
    },
    /// Bytes after the last section.
    TrailingBytes {
        count: usize,
    },
    /// A section's content ends before its announced length.
    SectionLeftover {
        section: &'static str,
        count: usize,
    },
    /// A varint longer than its value needs, or too large.
    BadVarint,
    BadUtf8,
    /// A count larger than the bytes left could hold.
    TooMany {
        what: &'static str,
        count: u64,
        left: usize,
    },
    IndexOutOfRange {
        what: &'static str,
        index: u64,
        len: usize,
    },
    UnknownOpcode(u8),
    /// A byte that is none of its closed set's tags.
    BadTag {
        what: &'static str,
        tag: u8,
    },
    // ── rules ────────────────────────────────────────────────────────────────────────
    NonFinite {
        what: &'static str,
    },
    /// A number outside its range; `expected` says the range in words.
    OutOfRange {
        what: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// A behaviour instruction names an actor no `Spawn` made.
    UnknownActor {
        actor: u16,
        spawned: usize,
    },
    /// Spawns number their actors 0, 1, 2, ... in order.
    SpawnOrder {
        actor: u16,
        expected: usize,
    },
    Missing(&'static str),
    Duplicate(&'static str),
    Misplaced(&'static str),
    /// A parameter slot whose range is empty or whose default is outside it.
    BadSlot {
        name: String,
        problem: &'static str,
    },
    /// A polyline the runtime cannot follow.
    BadPath(&'static str),
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::NotBytecode => write!(f, "not a TADSL bytecode file (it does not start with `TADC`)"),
            ErrorKind::NewerFormat { found, reads } => {
                write!(f, "built by a newer tadslc (format {found}, this reads {reads})")
            }
            ErrorKind::UnknownFormat { found } => write!(f, "unknown format version {found}"),
            ErrorKind::Flags(flags) => write!(f, "reserved header flags set ({flags:#06x})"),
            ErrorKind::Truncated { inside } => write!(f, "truncated inside {inside}"),
            ErrorKind::TrailingBytes { count } => {
                write!(f, "{} after the last section", bytes(*count, "trailing byte"))
            }
            ErrorKind::SectionLeftover { section, count } => {
                write!(f, "the {section} section has {} after its content", bytes(*count, "byte"))
            }
            ErrorKind::BadVarint => write!(f, "malformed number encoding (over-long or too large)"),
            ErrorKind::BadUtf8 => write!(f, "a string is not valid UTF-8"),
            ErrorKind::TooMany { what, count, left } => {
                write!(f, "{count} {what} cannot fit in the {} left", bytes(*left, "byte"))
            }
            ErrorKind::IndexOutOfRange { what, index, len } => {
                write!(f, "{what} index {index} out of range (there are {len})")
            }
            ErrorKind::UnknownOpcode(op) => write!(f, "unknown opcode {op:#04x}"),
            ErrorKind::BadTag { what, tag } => write!(f, "byte {tag} is not {what}"),
            ErrorKind::NonFinite { what } => write!(f, "{what} is not a finite number"),
            ErrorKind::OutOfRange { what, value, expected } => {
                write!(f, "{what} is {value}, expected {expected}")
            }
            ErrorKind::UnknownActor { actor, spawned } => {
                write!(f, "actor a{actor} is never spawned (only {})", bytes(*spawned, "actor"))
            }
            ErrorKind::SpawnOrder { actor, expected } => {
                write!(f, "spawn of actor a{actor} where a{expected} is next (actors are numbered in spawn order)")
            }
            ErrorKind::Missing(what) => write!(f, "no {what}"),
            ErrorKind::Duplicate(what) => write!(f, "more than one {what}"),
            ErrorKind::Misplaced(what) => write!(f, "{what}"),
            ErrorKind::BadSlot { name, problem } => write!(f, "parameter slot `{name}`: {problem}"),
            ErrorKind::BadPath(problem) => write!(f, "{problem}"),
        }
    }
}

/// `1 byte`, `2 bytes`.
fn bytes(n: usize, noun: &str) -> String {
    if n == 1 { format!("1 {noun}") } else { format!("{n} {noun}s") }
}
