//! The repository's example scenarios, embedded at build time: the default corpus of
//! `tadslc eval` (every example) and of `gen`'s aligned prompt (`examples/regions/`), so an
//! installed `tadslc` needs no files beside it.

use std::path::PathBuf;

use crate::corpus::{Corpus, Source};

include!(concat!(env!("OUT_DIR"), "/examples.rs"));

/// The embedded examples whose path starts with `prefix` (`examples/regions/`), as the
/// corpus `name`; every path is the one it has in the repository.
pub fn corpus(name: &str, prefix: &str) -> Corpus {
    let sources = EXAMPLES
        .iter()
        .filter(|(path, _)| path.starts_with(prefix))
        .map(|(path, text)| Source { path: PathBuf::from(path), text: text.to_string() })
        .collect();
    Corpus::new(name.to_string(), sources)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_examples_are_embedded_and_count() {
        assert!(EXAMPLES.iter().any(|(p, _)| p.starts_with("examples/regions/")));
        assert!(EXAMPLES.iter().any(|(p, _)| p.starts_with("examples/safety/")));
        let all = corpus("examples", "examples/");
        assert_eq!(all.items.len() + all.skipped(), EXAMPLES.len());
        assert!(all.items.iter().all(|i| !i.tad.is_empty()));
        let regions = corpus("regions", "examples/regions/");
        assert!(!regions.items.is_empty() && regions.items.len() < all.items.len());
        assert!(regions.items.iter().all(|i| i.region.is_some()), "every regional example names its region");
    }
}
