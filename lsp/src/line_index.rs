//! Protocol positions ↔ byte offsets, the one place that knows about encodings.
//!
//! LSP positions are a line and a column counted in the negotiated encoding: UTF-16 code
//! units (the default every client supports) or UTF-8 bytes (when the client offers
//! `utf-8` in `general.positionEncodings`). Lines end at `\n`; a `\r` before it belongs
//! to the line. A position past the end of its line clamps to the line's end, one past
//! the last line to the end of the text, and a column inside a character to its start —
//! a client's stale or wrong position is answered, never a panic.

use tower_lsp_server::ls_types::{Position, Range};

use tad_diagnostics::Span;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    #[default]
    Utf16,
    Utf8,
}

/// Start offsets of every line of one text, and whether it is all ASCII (then every
/// encoding counts the same).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LineIndex {
    starts: Vec<usize>,
    ascii: bool,
    len: usize,
}

impl LineIndex {
    pub fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        LineIndex { starts, ascii: text.is_ascii(), len: text.len() }
    }

    /// The byte offset of `position` in `text` (the text this index was built from).
    pub fn offset(&self, text: &str, position: Position, encoding: Encoding) -> usize {
        let line = position.line as usize;
        if line >= self.starts.len() {
            return self.len;
        }
        let start = self.starts[line];
        let end = self.starts.get(line + 1).map_or(self.len, |next| next - 1);
        let column = position.character as usize;
        if self.ascii || encoding == Encoding::Utf8 {
            let mut offset = (start + column).min(end);
            while !text.is_char_boundary(offset) {
                offset -= 1;
            }
            return offset;
        }
        let mut units = 0;
        for (i, c) in text[start..end].char_indices() {
            if units >= column {
                return start + i;
            }
            units += c.len_utf16();
            if units > column {
                // inside a surrogate pair: the character's start
                return start + i;
            }
        }
        end
    }

    /// The protocol position of byte `offset` (clamped into the text).
    pub fn position(&self, text: &str, offset: usize, encoding: Encoding) -> Position {
        let mut offset = offset.min(self.len);
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = match self.starts.binary_search(&offset) {
            Ok(line) => line,
            Err(next) => next - 1,
        };
        let start = self.starts[line];
        let character = if self.ascii || encoding == Encoding::Utf8 {
            offset - start
        } else {
            text[start..offset].chars().map(char::len_utf16).sum()
        };
        Position { line: line as u32, character: character as u32 }
    }

    pub fn range(&self, text: &str, span: Span, encoding: Encoding) -> Range {
        Range { start: self.position(text, span.start, encoding), end: self.position(text, span.end, encoding) }
    }

    pub fn span(&self, text: &str, range: Range, encoding: Encoding) -> Span {
        let start = self.offset(text, range.start, encoding);
        let end = self.offset(text, range.end, encoding).max(start);
        Span::new(start, end)
    }

    pub fn line_count(&self) -> usize {
        self.starts.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos(line: u32, character: u32) -> Position {
        Position { line, character }
    }

    #[test]
    fn utf16_columns_count_code_units() {
        // é is 2 bytes, 1 UTF-16 unit; 🚗 is 4 bytes, 2 units
        let text = "a é🚗b\nx";
        let index = LineIndex::new(text);
        let b = text.find('b').unwrap();
        assert_eq!(index.position(text, b, Encoding::Utf16), pos(0, 5));
        assert_eq!(index.offset(text, pos(0, 5), Encoding::Utf16), b);
        assert_eq!(index.position(text, b, Encoding::Utf8), pos(0, b as u32));
        // inside the surrogate pair: the car's start
        let car = text.find('🚗').unwrap();
        assert_eq!(index.offset(text, pos(0, 4), Encoding::Utf16), car);
        // UTF-8 column inside é: its start
        assert_eq!(index.offset(text, pos(0, 3), Encoding::Utf8), 2);
        assert_eq!(index.position(text, text.len(), Encoding::Utf16), pos(1, 1));
    }

    #[test]
    fn positions_out_of_the_text_clamp() {
        let text = "ab\r\ncd";
        let index = LineIndex::new(text);
        // past the end of line 0: its end (the \r stays on the line)
        assert_eq!(index.offset(text, pos(0, 99), Encoding::Utf16), 3);
        assert_eq!(index.offset(text, pos(7, 0), Encoding::Utf16), text.len());
        assert_eq!(index.position(text, 999, Encoding::Utf16), pos(1, 2));
    }

    #[test]
    fn round_trips_every_offset() {
        let text = "// ünïcødé 🚦\nroad {\n  lanes: 2\n}\n";
        let index = LineIndex::new(text);
        for encoding in [Encoding::Utf16, Encoding::Utf8] {
            for (offset, _) in text.char_indices() {
                let p = index.position(text, offset, encoding);
                assert_eq!(index.offset(text, p, encoding), offset, "{encoding:?} at {offset}");
            }
        }
    }
}
