//! A tiny bitmap font for the GIF's time label: digits and the few signs `t = 12.5 s`
//! needs, five pixels wide and seven high. Other characters are drawn as blanks, so any
//! text can be given; the GIF writes nothing else in words (its title and labels are
//! the SVG's business).

/// Glyph size in font pixels, and the advance from one glyph to the next.
pub const WIDTH: u32 = 5;
pub const HEIGHT: u32 = 7;
pub const ADVANCE: u32 = 6;

/// Rows from the top, the most significant of five bits leftmost.
fn glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e],
        '1' => [0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e],
        '2' => [0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f],
        '3' => [0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e],
        '4' => [0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02],
        '5' => [0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e],
        '6' => [0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e],
        '7' => [0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e],
        '9' => [0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c],
        ':' => [0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00],
        '=' => [0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00],
        '-' => [0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00],
        '/' => [0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10],
        's' => [0x00, 0x00, 0x0e, 0x10, 0x0e, 0x01, 0x1e],
        't' => [0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06],
        _ => [0; 7],
    }
}

/// The font pixels of a text, as `(column, row)` from its top-left corner.
pub fn pixels(text: &str) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for (i, c) in text.chars().enumerate() {
        let rows = glyph(c);
        for (row, bits) in rows.iter().enumerate() {
            for col in 0..WIDTH {
                if bits & (1 << (WIDTH - 1 - col)) != 0 {
                    out.push((i as u32 * ADVANCE + col, row as u32));
                }
            }
        }
    }
    out
}

/// A text's width in font pixels.
pub fn width(text: &str) -> u32 {
    (text.chars().count() as u32 * ADVANCE).saturating_sub(ADVANCE - WIDTH)
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_sign_of_a_time_label_has_a_glyph() {
        for c in "0123456789.:=-/st".chars() {
            assert!(!super::pixels(&c.to_string()).is_empty(), "{c}");
        }
        assert!(super::pixels(" ").is_empty());
        assert_eq!(super::width("t = 1.5 s"), 9 * 6 - 1);
    }
}
