//! Go to definition, find references, rename. TO BE WRITTEN (helper).

use crate::{Database, Location, SourceFile, Span, WorkspaceEdit};

pub fn definition(_db: &Database, _file: SourceFile, _offset: usize) -> Vec<Location> {
    Vec::new()
}

pub fn references(_db: &Database, _file: SourceFile, _offset: usize, _include_declaration: bool) -> Vec<Location> {
    Vec::new()
}

/// The span of the name a rename at `offset` would change (a group's name or a reference
/// to it), or why there is nothing to rename there.
pub fn prepare_rename(_db: &Database, _file: SourceFile, _offset: usize) -> Result<Span, String> {
    Err("nothing to rename here".into())
}

pub fn rename(_db: &Database, _file: SourceFile, _offset: usize, _new_name: &str) -> Result<WorkspaceEdit, String> {
    Err("nothing to rename here".into())
}
