//! The GIF's bitmap font, designed for TADSL: a stroke font drawn with a square pen on a
//! pixel grid and rasterised once (on first use) into whole pixels. A GIF frame may hold
//! only the palette's colours, so text is drawn without anti-aliasing; a table built from a
//! few lines of source needs no font file or rasteriser at run time, and integer arithmetic
//! gives the same pixels everywhere.
//!
//! Each glyph of printable ASCII and of the few other signs the pictures write (`·`, `×`,
//! `–`, `≥`, `≤`, `…`) is a line of [`STROKES`]: polylines through points `xy`, each
//! coordinate one hexadecimal digit, in pixels from the glyph's top-left corner; strokes
//! are separated by spaces, and a single point is a dot. The pen is a 2 × 2 px square whose
//! top-left corner follows the line, so `00-08` inks columns 0–1 and rows 0–9. A segment
//! joined by `-` is drawn with it; one joined by `~` with a pen 2 wide and 1 high, for the
//! few bars that must be thin to leave a counter open (`a`, `e`, `s`, `$`) and for light
//! signs (`<`, `≥`, `~`). Curves are polylines with cut corners: one step on small bowls,
//! two on the round capitals. A segment is drawn from its upper end, so its pixels do not
//! depend on its direction and mirrored glyphs come out mirrored.
//!
//! The grid: capitals, figures and ascenders take rows 0–9, the x-height rows 3–9, and
//! descenders reach row 12, so a line is [`HEIGHT`] = 13 rows with the baseline under
//! row 9. A glyph is as wide as its ink and glyphs are set [`GAP`] apart; the figures are
//! all one width, so a changing time does not jitter. Other characters are drawn as `?`,
//! so any text can be given.

use std::sync::OnceLock;

/// A line of text's rows, px (its baseline is under row 9).
pub const HEIGHT: u32 = 13;
/// The gap between two glyphs, px.
const GAP: u32 = 2;
/// A space's advance, px: with the gap before it, words are 6 px apart.
const SPACE: u32 = 4;

/// Every glyph's strokes (see the module's header for the notation).
const STROKES: &[(char, &str)] = &[
    (' ', ""),
    ('!', "00-05 08"),
    ('"', "00-02 30-32"),
    ('#', "20-28 50-58 02-72 06-76"),
    ('$', "52-41-11-02-03~14~44~55-56-47-17-06 20~20 29~29"),
    ('%', "00 77 70-08"),
    ('&', "88-23-21-30-40-51-52-44~34~15-07-18-48-75"),
    ('\'', "00-02"),
    ('(', "20-02-09-2b"),
    (')', "00-22-29-0b"),
    ('*', "20~24 01~43 41~03"),
    ('+', "31-37 04-64"),
    (',', "18-19-0a"),
    ('-', "05-25"),
    ('.', "08"),
    ('/', "40-09"),
    ('0', "20-30-52-56-38-28-06-02-20"),
    ('1', "21-30-38 08-58"),
    ('2', "01-10-40-51-53-08-58"),
    ('3', "01-10-40-51-53-44-14 44-55-57-48-18-07"),
    ('4', "48-40-05-55"),
    ('5', "50-00-03-43-54-57-48-18-07"),
    ('6', "50-20-02-07-18-48-57-54-43-03"),
    ('7', "00-50-51-28"),
    ('8', "10-40-51-53-44-14-03-01-10 14-05-07-18-48-57-55-44"),
    ('9', "08-38-56-51-40-10-01-04-15-55"),
    (':', "03 08"),
    (';', "13 18-19-0a"),
    ('<', "62~05~68"),
    ('=', "03-63 06-66"),
    ('>', "02~65~08"),
    ('?', "01-10-40-51-52-34-35 38"),
    ('@', "76-74~54~45-46~57~77 74-77-87-82-60-20-02-08-2a-8a"),
    ('A', "08-04-30-64-68 06-66"),
    ('B', "30-00-08-48-57-55-44-04 30-41-43-34"),
    ('C', "51-40-20-02-06-28-48-57"),
    ('D', "00-30-52-56-38-08-00"),
    ('E', "50-00-08-58 04-44"),
    ('F', "50-00-08 04-44"),
    ('G', "51-40-20-02-06-28-48-57-54-34"),
    ('H', "00-08 50-58 04-54"),
    ('I', "00-40 20-28 08-48"),
    ('J', "30-50-57-48-18-07"),
    ('K', "00-08 50-14 24-58"),
    ('L', "00-08-58"),
    ('M', "08-00-44-80-88"),
    ('N', "08-00-58-50"),
    ('O', "20-40-62-66-48-28-06-02-20"),
    ('P', "08-00-40-51-53-44-04"),
    ('Q', "20-40-62-66-48-28-06-02-20 46-69"),
    ('R', "08-00-40-51-53-44-04 34-58"),
    ('S', "51-40-10-01-03-14-44-55-57-48-18-07"),
    ('T', "00-60 30-38"),
    ('U', "00-06-28-38-56-50"),
    ('V', "00-02-38-62-60"),
    ('W', "00-05-28-44-68-85-80"),
    ('X', "00-58 50-08"),
    ('Y', "00-34-60 34-38"),
    ('Z', "00-50-08-58"),
    ('[', "20-00-0b-2b"),
    ('\\', "00-49"),
    (']', "00-20-2b-0b"),
    ('^', "03-30-63"),
    ('_', "0b-5b"),
    ('`', "00-11"),
    ('a', "13~43~54-58 55~15~06-07-18-58"),
    ('b', "00-08-48-57-54-43-03"),
    ('c', "53-13-04-07-18-58"),
    ('d', "50-58-18-07-04-13-53"),
    ('e', "06~56~55-54-43-13-04-07-18-58"),
    ('f', "40-20-11-18 03-43"),
    ('g', "53-5a-4b-0b 53-13-04-07-18-58"),
    ('h', "00-08 03-43-54-58"),
    ('i', "00 03-08"),
    ('j', "20 23-2a-1b-0b"),
    ('k', "00-08 43-16 26-48"),
    ('l', "00-08"),
    ('m', "08-03-73-84-88 43-48"),
    ('n', "08-03-43-54-58"),
    ('o', "13-43-54-57-48-18-07-04-13"),
    ('p', "0b-03-43-54-57-48-08"),
    ('q', "5b-53-13-04-07-18-58"),
    ('r', "08-03-33-44"),
    ('s', "53-13-04-05~16~46~57-48-08"),
    ('t', "11-17-28-48 03-43"),
    ('u', "03-07-18-58-53"),
    ('v', "03-05-38-65-63"),
    ('w', "03-06-28-44-68-86-83"),
    ('x', "03-58 53-08"),
    ('y', "03-05-38 63-65-38-2b"),
    ('z', "03-53-08-58"),
    ('{', "30-20-13-14-05-16-17-2a-3a"),
    ('|', "00-0b"),
    ('}', "00-10-23-24-35-26-27-1a-0a"),
    ('~', "05~14~24~35~45~54"),
    ('·', "05"),
    ('×', "02-46 42-06"),
    ('–', "05-55"),
    ('≥', "00~53~06 08-58"),
    ('≤', "50~03~56 08-58"),
    ('…', "08 38 68"),
];

/// A glyph's ink: its width and its rows from the top, bit `k` for column `k`.
#[derive(Clone, Copy, Default)]
struct Glyph {
    width: u32,
    rows: [u16; HEIGHT as usize],
}

/// The pen a segment is drawn with: 2 × 2 px, or 2 px wide and 1 high.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Pen {
    Square,
    Thin,
}

/// A stroke: its points, each with the pen of the segment that reaches it (the first's
/// only draws a dot).
type Stroke = Vec<(Pen, i32, i32)>;

/// The strokes of a glyph's notation; `None` if it is not well formed.
fn parse(spec: &str) -> Option<Vec<Stroke>> {
    let mut strokes = Vec::new();
    for word in spec.split(' ').filter(|w| !w.is_empty()) {
        let mut stroke = Vec::new();
        let mut chars = word.chars();
        let mut pen = Pen::Square;
        loop {
            let x = chars.next()?.to_digit(16)? as i32;
            let y = chars.next()?.to_digit(16)? as i32;
            stroke.push((pen, x, y));
            pen = match chars.next() {
                None => break,
                Some('-') => Pen::Square,
                Some('~') => Pen::Thin,
                Some(_) => return None,
            };
        }
        strokes.push(stroke);
    }
    Some(strokes)
}

/// `a / n` rounded half away from zero, `n > 0`: `-a` gives the negation, so mirrored
/// strokes give mirrored pixels.
fn div_round(a: i32, n: i32) -> i32 {
    if a >= 0 { (2 * a + n) / (2 * n) } else { -((-2 * a + n) / (2 * n)) }
}

/// The pixels of a glyph's strokes, moved left so that its ink starts at column 0.
fn rasterise(strokes: &[Stroke]) -> Glyph {
    let mut ink: Vec<(i32, i32)> = Vec::new();
    let mut stamp = |pen: Pen, x: i32, y: i32| {
        let rows = if pen == Pen::Thin { 1 } else { 2 };
        for dy in 0..rows {
            ink.extend([(x, y + dy), (x + 1, y + dy)]);
        }
    };
    for stroke in strokes {
        if let [(_, x, y)] = stroke[..] {
            stamp(Pen::Square, x, y);
        }
        for pair in stroke.windows(2) {
            let ((_, mut x0, mut y0), (pen, mut x1, mut y1)) = (pair[0], pair[1]);
            // drawn downwards, so a segment's pixels do not depend on its direction
            if (y0, x0) > (y1, x1) {
                (x0, y0, x1, y1) = (x1, y1, x0, y0);
            }
            let n = (x1 - x0).abs().max((y1 - y0).abs()).max(1);
            for i in 0..=n {
                stamp(pen, x0 + div_round((x1 - x0) * i, n), y0 + div_round((y1 - y0) * i, n));
            }
        }
    }
    let left = ink.iter().map(|p| p.0).min().unwrap_or(0);
    let mut glyph = Glyph::default();
    for (x, y) in ink {
        let (col, row) = ((x - left) as u32, y as u32);
        if col < 16 && row < HEIGHT {
            glyph.rows[row as usize] |= 1 << col;
            glyph.width = glyph.width.max(col + 1);
        }
    }
    glyph
}

/// Every glyph, rasterised on first use.
fn table() -> &'static [(char, Glyph)] {
    static TABLE: OnceLock<Vec<(char, Glyph)>> = OnceLock::new();
    TABLE.get_or_init(|| {
        STROKES.iter().map(|&(c, spec)| (c, parse(spec).map(|s| rasterise(&s)).unwrap_or_default())).collect()
    })
}

fn glyph(c: char) -> Glyph {
    let table = table();
    let find = |c: char| table.iter().find(|g| g.0 == c).map(|g| g.1);
    find(c).or_else(|| find('?')).unwrap_or_default()
}

fn advance(c: char) -> u32 {
    if c == ' ' { SPACE } else { glyph(c).width + GAP }
}

/// The font pixels of a text, as `(column, row)` from its top-left corner.
pub fn pixels(text: &str) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    let mut x = 0;
    for c in text.chars() {
        let g = glyph(c);
        for (row, bits) in g.rows.iter().enumerate() {
            out.extend((0..g.width).filter(|col| bits & (1 << col) != 0).map(|col| (x + col, row as u32)));
        }
        x += advance(c);
    }
    out
}

/// A text's width in font pixels.
pub fn width(text: &str) -> u32 {
    text.chars().map(advance).sum::<u32>().saturating_sub(GAP)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    /// The extra signs the pictures write, besides printable ASCII.
    const EXTRA: &str = "·×–≥≤…";

    fn signs() -> impl Iterator<Item = char> {
        (33u8..127).map(char::from).chain(EXTRA.chars())
    }

    fn set(text: &str) -> BTreeSet<(u32, u32)> {
        pixels(text).into_iter().collect()
    }

    /// The rows a text inks, top and bottom.
    fn rows(text: &str) -> (u32, u32) {
        let p = pixels(text);
        (p.iter().map(|p| p.1).min().unwrap_or(0), p.iter().map(|p| p.1).max().unwrap_or(0))
    }

    #[test]
    fn every_sign_is_well_written_and_has_ink() {
        for &(c, spec) in STROKES {
            let strokes = parse(spec).unwrap_or_else(|| panic!("{c:?}: {spec:?} is not well formed"));
            let inside = strokes.iter().flatten().all(|&(_, x, y)| x <= 14 && y + 2 <= HEIGHT as i32);
            assert!(inside, "{c:?} leaves the grid");
        }
        let listed: BTreeSet<char> = STROKES.iter().map(|g| g.0).collect();
        assert_eq!(listed.len(), STROKES.len(), "a sign is listed twice");
        for c in signs() {
            assert!(listed.contains(&c), "{c:?} has no glyph");
            assert!(!pixels(&c.to_string()).is_empty(), "{c:?} has no ink");
        }
        assert!(pixels(" ").is_empty());
        assert_eq!(pixels("\u{1F600}"), pixels("?"), "unknown signs are drawn as `?`");
        assert_eq!(pixels("a\tb"), pixels("a?b"));
        assert!(parse("0-1").is_none() && parse("00+11").is_none() && parse("0g").is_none());
    }

    #[test]
    fn no_two_glyphs_look_alike() {
        let all: Vec<(char, BTreeSet<(u32, u32)>)> = signs().map(|c| (c, set(&c.to_string()))).collect();
        for (i, (a, pa)) in all.iter().enumerate() {
            for (b, pb) in &all[i + 1..] {
                assert_ne!(pa, pb, "{a:?} and {b:?} are drawn alike");
            }
        }
        // pairs a reader might confuse differ in more than a pixel or two
        for pair in
            ["O0", "0D", "Il", "I1", "l1", "l|", "1|", "1l", "5S", "2Z", "8B", "8S", "co", "oe", "uv", "ij", "-–", ".·"]
        {
            let (a, b): (Vec<char>, Vec<char>) = (pair.chars().take(1).collect(), pair.chars().skip(1).collect());
            let (pa, pb) = (set(&a[0].to_string()), set(&b[0].to_string()));
            let differ = pa.symmetric_difference(&pb).count();
            assert!(differ >= 6, "{pair}: {differ} pixels apart");
        }
        assert_ne!(set("rn"), set("m"));
    }

    #[test]
    fn width_is_the_ink_and_nothing_leaves_the_box() {
        let mut texts: Vec<String> = signs().map(String::from).collect();
        texts.extend(
            ["t = 4.1 s", "5 m", "ego", "straight_obstacle · seed 0 · ego naive", "Wg|j", "a × b ≥ c"]
                .map(String::from),
        );
        for text in &texts {
            let p = pixels(text);
            let w = width(text);
            assert_eq!(p.iter().map(|p| p.0).min(), Some(0), "{text:?} starts at column 0");
            assert_eq!(p.iter().map(|p| p.0).max().map(|x| x + 1), Some(w), "{text:?} is as wide as its ink");
            assert!(p.iter().all(|&(x, y)| x < w && y < HEIGHT), "{text:?} leaves its box");
            assert_eq!(p.len(), set(text).len(), "{text:?} has a pixel twice");
        }
        assert_eq!(width(""), 0);
        assert!(width("t = 1.5 s") > width("t=1.5s"));
        assert_eq!(width("ab"), width("a") + GAP + width("b"));
    }

    #[test]
    fn metrics() {
        // capitals and figures on rows 0–9, the x-height rows 3–9, descenders to row 12
        assert_eq!(rows("HE0123456789bdfhkl"), (0, 9));
        assert_eq!(rows("acemnorsuvwxz"), (3, 9));
        assert_eq!(rows("gjpqy").1, HEIGHT - 1);
        // figures are one width, so a changing time does not jitter
        let widths: BTreeSet<u32> = ('0'..='9').map(|c| width(&c.to_string())).collect();
        assert_eq!(widths.len(), 1, "{widths:?}");
        // every stroke is at least 2 px wide: no column of ink stands alone
        for c in signs() {
            let p = set(&c.to_string());
            let alone = p.iter().find(|&&(x, y)| !p.contains(&(x + 1, y)) && (x == 0 || !p.contains(&(x - 1, y))));
            assert!(alone.is_none(), "{c:?} has a one-pixel column at {alone:?}");
        }
    }
}
