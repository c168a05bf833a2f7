//! Long source lines, shown as a window around a diagnostic's labels.
//!
//! A terminal report echoes each labelled source line. A minified or hostile file can
//! have one line of a megabyte, and echoing it once per diagnostic makes the report
//! quadratic. So for each diagnostic, every line longer than [`LONG_LINE`] bytes is cut to
//! the part around that diagnostic's labels on it (nothing, for a line without one), with
//! `…` where text was left out. The spans are mapped into the cut text; the line numbers
//! are the file's, and the columns are counted in the whole line ([`Sources`] adds what a
//! cut left out), so `file:line:column` is the same as without the cut.

use std::ops::Range;

use codespan_reporting::files::{Error, Files, column_index};

/// Lines longer than this (bytes) are cut.
pub const LONG_LINE: usize = 200;
/// Bytes kept on each side of the labels of a cut line.
const CONTEXT: usize = 40;
const MARK: &str = "…";

/// One file as shown for one diagnostic.
pub struct Shown {
    name: String,
    text: String,
    line_starts: Vec<usize>,
    /// Cut lines, in order.
    cuts: Vec<Cut>,
}

struct Cut {
    /// The line in the original text (without its line break) and the part kept.
    line: Range<usize>,
    keep: Range<usize>,
    /// Where the kept part starts in the shown text, and the line's index.
    at: usize,
    index: usize,
    /// Characters of the line before the kept part, less the mark shown for them.
    columns: usize,
    /// Shown length minus original length, up to the end of this line.
    delta: isize,
}

/// Whether `text` has a line longer than [`LONG_LINE`].
pub fn has_long_lines(text: &str) -> bool {
    text.split('\n').any(|line| line.len() > LONG_LINE)
}

impl Shown {
    /// `text`, its long lines cut around `spans` (the labels in this file).
    pub fn new(name: String, text: &str, spans: &[Range<usize>]) -> Shown {
        let mut shown = String::with_capacity(text.len().min(1 << 16));
        let mut cuts = Vec::new();
        let mut start = 0;
        for (index, line) in text.split('\n').enumerate() {
            let end = start + line.len();
            if line.len() <= LONG_LINE {
                shown.push_str(line);
            } else {
                let keep = window(text, start..end, spans);
                let before = start < keep.start;
                let columns = text[start..keep.start].chars().count() - usize::from(before);
                if before {
                    shown.push_str(MARK);
                }
                let at = shown.len();
                shown.push_str(&text[keep.clone()]);
                if keep.end < end {
                    shown.push_str(MARK);
                }
                let delta = shown.len() as isize - end as isize;
                cuts.push(Cut { line: start..end, keep, at, index, columns, delta });
            }
            if end < text.len() {
                shown.push('\n');
            }
            start = end + 1;
        }
        let line_starts = codespan_reporting::files::line_starts(&shown).collect();
        Shown { name, text: shown, line_starts, cuts }
    }

    /// Where an offset of the original text is in the shown one.
    pub fn map(&self, offset: usize) -> usize {
        let i = self.cuts.partition_point(|c| c.line.start <= offset);
        let Some(cut) = i.checked_sub(1).map(|i| &self.cuts[i]) else { return offset };
        if offset <= cut.line.end {
            return cut.at + offset.clamp(cut.keep.start, cut.keep.end) - cut.keep.start;
        }
        offset.saturating_add_signed(cut.delta)
    }

    pub fn len(&self) -> usize {
        self.text.len()
    }
}

/// The part of `line` to keep: around the labels that touch it, at most about
/// [`LONG_LINE`] bytes, on character boundaries; empty at its start without one.
fn window(text: &str, line: Range<usize>, spans: &[Range<usize>]) -> Range<usize> {
    let touching = spans.iter().filter(|s| s.start <= line.end && s.end >= line.start);
    let (lo, hi) = touching.fold((usize::MAX, 0), |(lo, hi), s| (lo.min(s.start), hi.max(s.end)));
    if lo == usize::MAX {
        return line.start..line.start;
    }
    let lo = lo.clamp(line.start, line.end);
    let hi = hi.clamp(lo, line.end).min(lo + LONG_LINE);
    let start = floor(text, lo.saturating_sub(CONTEXT).max(line.start));
    let end = ceil(text, (hi + CONTEXT).min(line.end));
    start..end
}

fn floor(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn ceil(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i += 1;
    }
    i
}

/// The files of one report, as codespan reads them.
#[derive(Default)]
pub struct Sources(pub Vec<Shown>);

impl Sources {
    pub fn add(&mut self, shown: Shown) -> usize {
        self.0.push(shown);
        self.0.len() - 1
    }

    fn get(&self, id: usize) -> Result<&Shown, Error> {
        self.0.get(id).ok_or(Error::FileMissing)
    }
}

impl<'a> Files<'a> for Sources {
    type FileId = usize;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: usize) -> Result<&'a str, Error> {
        Ok(&self.get(id)?.name)
    }

    fn source(&'a self, id: usize) -> Result<&'a str, Error> {
        Ok(&self.get(id)?.text)
    }

    fn line_index(&'a self, id: usize, byte_index: usize) -> Result<usize, Error> {
        let starts = &self.get(id)?.line_starts;
        Ok(starts.partition_point(|s| *s <= byte_index).saturating_sub(1))
    }

    fn line_range(&'a self, id: usize, line_index: usize) -> Result<Range<usize>, Error> {
        let file = self.get(id)?;
        let start = *file
            .line_starts
            .get(line_index)
            .ok_or(Error::LineTooLarge { given: line_index, max: file.line_starts.len().saturating_sub(1) })?;
        let end = file.line_starts.get(line_index + 1).copied().unwrap_or(file.text.len());
        Ok(start..end)
    }

    fn column_number(&'a self, id: usize, line_index: usize, byte_index: usize) -> Result<usize, Error> {
        let file = self.get(id)?;
        let cut = file.cuts.iter().find(|c| c.index == line_index).map_or(0, |c| c.columns);
        Ok(column_index(&file.text, self.line_range(id, line_index)?, byte_index) + 1 + cut)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_is_cut_around_its_label_and_keeps_its_columns() {
        let text = format!("short\n{}X{}\nlast", "a".repeat(1000), "b".repeat(1000));
        let x = text.find('X').unwrap();
        let label = std::ops::Range { start: x, end: x + 1 };
        let shown = Shown::new("f".into(), &text, std::slice::from_ref(&label));
        let line = shown.text.lines().nth(1).unwrap();
        assert!(line.len() < 2 * CONTEXT + 10, "{line}");
        assert!(line.starts_with(MARK) && line.ends_with(MARK));
        let at = shown.map(x);
        assert_eq!(&shown.text[at..at + 1], "X");
        let sources = Sources(vec![shown]);
        let line = sources.line_index(0, at).unwrap();
        assert_eq!((line, sources.column_number(0, line, at).unwrap()), (1, 1001));
        // offsets after the cut line move with it
        let last = text.rfind("last").unwrap();
        assert_eq!(&sources.0[0].text[sources.0[0].map(last)..], "last");
    }

    #[test]
    fn unlabelled_long_lines_are_left_out() {
        let text = format!("{}\nok\n", "é".repeat(500));
        let shown = Shown::new("f".into(), &text, &[]);
        assert_eq!(shown.text, format!("{MARK}\nok\n"));
        assert_eq!(shown.map(text.find("ok").unwrap()), MARK.len() + 1);
    }
}
