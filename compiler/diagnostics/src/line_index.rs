//! Byte offsets to 1-based line and column numbers.
//!
//! Columns count Unicode scalar values (characters), not bytes, so a column means the same
//! thing to a person, a JSON consumer and a SARIF viewer (`columnKind: unicodeCodePoints`).
//! The language server converts to UTF-16 itself.

use crate::Span;
use serde::Serialize;

/// A 1-based line and column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct LineCol {
    pub line: usize,
    pub column: usize,
}

/// Start offsets of every line of one text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        LineIndex { starts }
    }

    /// 0-based line containing `offset`.
    pub fn line_of(&self, offset: usize) -> usize {
        match self.starts.binary_search(&offset) {
            Ok(line) => line,
            Err(next) => next - 1,
        }
    }

    pub fn line_start(&self, line: usize) -> usize {
        self.starts[line.min(self.starts.len() - 1)]
    }

    pub fn line_count(&self) -> usize {
        self.starts.len()
    }

    /// The 1-based position of `offset` in `text`; offsets past the end or inside a
    /// multi-byte character are clamped to the nearest valid position before them.
    pub fn line_col(&self, text: &str, offset: usize) -> LineCol {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.line_of(offset);
        let start = self.starts[line];
        LineCol { line: line + 1, column: text[start..offset].chars().count() + 1 }
    }

    pub fn span_range(&self, text: &str, span: Span) -> (LineCol, LineCol) {
        (self.line_col(text, span.start), self.line_col(text, span.end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_one_based_and_count_characters() {
        let text = "ab\nçd\n";
        let index = LineIndex::new(text);
        assert_eq!(index.line_col(text, 0), LineCol { line: 1, column: 1 });
        assert_eq!(index.line_col(text, 3), LineCol { line: 2, column: 1 });
        // `d` follows a two-byte character
        assert_eq!(index.line_col(text, 5), LineCol { line: 2, column: 2 });
        // inside the two-byte character: clamped back
        assert_eq!(index.line_col(text, 4), LineCol { line: 2, column: 1 });
        assert_eq!(index.line_col(text, 99), LineCol { line: 3, column: 1 });
    }
}
