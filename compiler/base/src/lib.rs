//! The workspace's leaf crate: small helpers that many crates need and that say nothing
//! about traffic scenarios.
//!
//! - [`SplitMix64`] and [`Rng`]: the one seeded generator (every random choice in the
//!   workspace takes a seed and draws from it);
//! - [`fnv1a`]: the one stable hash (FNV-1a, 64 bits), for names turned into seeds and
//!   content-addressed folders;
//! - [`Shard`]: one job of a job array (`--shard I/N`) and its files' names;
//! - [`plural`]: a count with its noun in the right number, for messages.
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
