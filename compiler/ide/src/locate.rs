//! What is at an offset: the one place that maps a position to a thing of the language
//! (a section, a field key, a vocabulary name, a group, a reference, a unit, a `use`d
//! module, a declaration), read from the lowered model of `tad_db::analyze`.
//!
//! TO BE WRITTEN (helper): `pub fn at(db: &Database, file: SourceFile, offset: usize) -> Option<At>`.

use crate::{Database, SourceFile};

/// A thing of the language under the cursor, with the span of its text.
#[derive(Clone, Debug, PartialEq)]
pub enum At {}

pub fn at(_db: &Database, _file: SourceFile, _offset: usize) -> Option<At> {
    None
}
