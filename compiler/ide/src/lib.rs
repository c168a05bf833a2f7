//! Editor features over the TADSL database: what an editor asks about a position or a
//! file, answered from the same queries the CLI runs (`tad_db::analyze`, `check`,
//! `vocabulary`) — there is no second analysis path.
//!
//! Everything here speaks byte offsets and [`Span`]s into a file's text and knows nothing
//! of the protocol: the language server (`tad-lsp`) converts positions (UTF-16 or UTF-8)
//! and shapes. Every function is total: a malformed document, an offset past the end or
//! inside a character gives an empty answer, never a panic.
//!
//! | feature | module |
//! |---|---|
//! | what is at an offset (shared by hover, navigation, rename) | [`locate`] |
//! | hover | [`hover`] |
//! | go to definition, find references, rename | [`navigate`] |
//! | completion | [`completion`] |
//! | document symbols, folding ranges | [`outline`] |
//! | semantic tokens | [`tokens`] |
//! | inlay hints | [`inlay`] |
//! | code actions (from diagnostics' fixes), formatting | [`actions`] |

pub mod actions;
pub mod completion;
pub mod hover;
pub mod inlay;
pub mod locate;
pub mod navigate;
pub mod outline;
pub mod tokens;

pub use tad_db::{Database, Language, SourceFile};
pub use tad_diagnostics::Span;

/// A place in some file (a stdlib file is a [`SourceFile`] whose path starts with
/// [`tad_db::STDLIB_PREFIX`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Location {
    pub file: SourceFile,
    pub span: Span,
}

/// Replace the text at `span` with `text`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Edit {
    pub span: Span,
    pub text: String,
}

/// Edits to several files, each file's edits not overlapping.
pub type WorkspaceEdit = Vec<(SourceFile, Vec<Edit>)>;

/// The offset clamped into `text` and moved back to a character boundary.
pub fn clamp(text: &str, offset: usize) -> usize {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

/// Test fixtures: a document with a `$0` cursor, in a fresh database.
#[cfg(test)]
pub(crate) mod testing {
    use std::path::PathBuf;

    use crate::{Database, Language, SourceFile};

    /// The text without its `$0` marker, the file registered as `/fixture/scenario.tad`
    /// (no file system: only standard modules resolve), and the marker's offset.
    pub fn cursor(text: &str) -> (Database, SourceFile, usize) {
        let offset = text.find("$0").expect("a $0 marker");
        let text = text.replacen("$0", "", 1);
        let (db, file) = file(&text);
        (db, file, offset)
    }

    pub fn file(text: &str) -> (Database, SourceFile) {
        with_language(text, Language::Tad)
    }

    pub fn with_language(text: &str, language: Language) -> (Database, SourceFile) {
        let mut db = Database::new(tad_check::Options::default());
        let path =
            PathBuf::from(if language == Language::Yaml { "/fixture/answer.yaml" } else { "/fixture/scenario.tad" });
        let file = db.set_source(path, text.to_string(), language, &tad_db::NoFs);
        (db, file)
    }
}
