//! "Did you mean" suggestions by edit distance.

use tad_diagnostics::{Applicability, Diagnostic, Payload, Span};

/// Optimal-string-alignment distance (Levenshtein plus adjacent transpositions),
/// case-insensitive.
pub fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let mut prev2 = vec![0; b.len() + 1];
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                cur[j] = cur[j].min(prev2[j - 2] + 1);
            }
        }
        std::mem::swap(&mut prev2, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// The candidate closest to `word`, if it is close enough to be a plausible typo:
/// at most a third of the word's length in edits (at least one). Ties keep the first.
pub fn closest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let length = word.chars().count();
    let limit = (length / 3).max(1);
    let mut best: Option<(usize, &str)> = None;
    for candidate in candidates.into_iter().filter(|c| within(length, c, limit)) {
        let d = distance(word, candidate);
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// Whether `candidate` can be within `limit` edits of a word of `length` characters: the
/// distance is at least the difference in length, so most candidates need no table.
fn within(length: usize, candidate: &str, limit: usize) -> bool {
    length.abs_diff(candidate.chars().count()) <= limit
}

/// The candidates within the typo limit of `word`, closest first (ties in the given
/// order), at most `n`.
pub fn ranked<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>, n: usize) -> Vec<&'a str> {
    let length = word.chars().count();
    let limit = (length / 3).max(1);
    let mut close: Vec<(usize, usize, &str)> = candidates
        .into_iter()
        .enumerate()
        .filter(|(_, c)| within(length, c, limit))
        .map(|(i, c)| (distance(word, c), i, c))
        .filter(|(d, ..)| *d <= limit)
        .collect();
    close.sort();
    close.dedup_by(|a, b| a.2 == b.2);
    close.into_iter().take(n).map(|(.., c)| c).collect()
}

/// Give `d` an [`Payload::Unknown`] for `name` in `namespace`, and when a candidate is
/// close, a "did you mean" help and a maybe-incorrect fix at `span`. Returns whether a
/// guess was made.
pub fn unknown<'a>(
    d: Diagnostic,
    namespace: &str,
    name: &str,
    span: Span,
    candidates: impl IntoIterator<Item = &'a str>,
) -> (Diagnostic, bool) {
    let close: Vec<String> = ranked(name, candidates, 5).into_iter().map(str::to_string).collect();
    let guess = close.first().cloned();
    let mut d = d.with_payload(Payload::Unknown {
        namespace: namespace.to_string(),
        name: name.to_string(),
        candidates: close,
        module: None,
    });
    let guessed = guess.is_some();
    if let Some(guess) = guess {
        d = d.with_help(format!("did you mean `{guess}`?")).with_fix(span, guess, Applicability::MaybeIncorrect);
    }
    (d, guessed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(distance("weather", "weather"), 0);
        assert_eq!(distance("wether", "weather"), 1);
        assert_eq!(distance("waether", "weather"), 1);
        assert_eq!(distance("", "abc"), 3);
    }

    #[test]
    fn closest_respects_the_limit() {
        let fields = ["weather", "time"];
        assert_eq!(closest("wether", fields), Some("weather"));
        assert_eq!(closest("tiem", fields), Some("time"));
        assert_eq!(closest("colour", fields), None);
    }

    #[test]
    fn ranked_orders_by_distance() {
        assert_eq!(ranked("tme", ["type", "time", "tame"], 5), vec!["time", "tame"]);
        assert!(ranked("colour", ["weather"], 5).is_empty());
    }
}
