//! The workspace's leaf crate: small helpers that many crates need and that say nothing
//! about traffic scenarios.
//!
//! - [`SplitMix64`] and [`Rng`]: the one seeded generator (every random choice in the
//!   workspace takes a seed and draws from it);
//! - [`fnv1a`]: the one stable hash (FNV-1a, 64 bits), for names turned into seeds and
//!   content-addressed folders;
//! - [`Shard`]: one job of a job array (`--shard I/N`) and its files' names;
//! - [`plural`]: a count with its noun in the right number, for messages;
//! - [`xml_escape`]: text for an XML attribute or element.
//!
//! Each is written once here and read everywhere else; the crate depends on serde only.

mod hash;
mod rng;
mod shard;

pub use hash::{fnv1a, fnv1a_seeded};
pub use rng::{Rng, SplitMix64};
pub use shard::Shard;

/// `1 file`, `2 files`: a count with its noun in the right number (regular plurals).
pub fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}

/// `noun` with its indefinite article, by how it sounds: "an urban road", "an ambulance",
/// "a U-turn", "a one-way road", "a truck".
pub fn a(noun: &str) -> String {
    let lower = noun.trim_start().to_ascii_lowercase();
    let sounds_like_you = ["uni", "use", "usu", "u-", "u_", "eu", "one"].iter().any(|p| lower.starts_with(p));
    let vowel = lower.starts_with(['a', 'e', 'i', 'o', 'u']) && !sounds_like_you;
    format!("{} {noun}", if vowel { "an" } else { "a" })
}

/// Text for an XML attribute (double-quoted) or element: `& < > "` escaped, and every
/// control character XML 1.0 cannot hold replaced by U+FFFD.
pub fn xml_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c if c.is_control() && !matches!(c, '\n' | '\t' | '\r') => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod xml {
    #[test]
    fn names_are_escaped_for_xml() {
        // a file named by a user, an ego path: nothing breaks a report
        assert_eq!(super::xml_escape("a&b <c> \"d\"\u{1}e\n"), "a&amp;b &lt;c&gt; &quot;d&quot;\u{FFFD}e\n");
    }
}

#[cfg(test)]
mod articles {
    #[test]
    fn the_article_follows_the_sound() {
        for (noun, said) in [
            ("urban road", "an urban road"),
            ("ambulance", "an ambulance"),
            ("intersection", "an intersection"),
            ("truck", "a truck"),
            ("U-turn", "a U-turn"),
            ("one way road", "a one way road"),
            ("unicycle", "a unicycle"),
            ("off-ramp", "an off-ramp"),
        ] {
            assert_eq!(super::a(noun), said);
        }
    }
}
