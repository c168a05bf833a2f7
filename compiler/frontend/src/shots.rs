//! Retrieved examples: the translations of a pool that read most like a description, shown
//! to the model before it (`translate --pool DIR`).
//!
//! The fixed examples of the prompt teach TAD's form; these teach the conventions on cases
//! like the one at hand (a region's corpus, a user's checked translations). A pool is a
//! directory of programs whose `source.description` says what they translate, or the
//! benchmark's layout (`truth/NAME.tad` beside `descriptions/NAME.txt`). A program is
//! shown as the checker reads it, after its machine-applicable fixes; one with an error
//! left, without a description or unreadable is not shown, and the pool says why.
//! Descriptions are ranked by Okapi BM25 over their lower-cased words (k1 = 1.2,
//! b = 0.75), ties by name, so the choice is deterministic; a pool entry whose description
//! is the one being translated is never shown, so a pool may hold the set it is asked
//! about. The examples go after the system message, as earlier turns of the chat, so the
//! cached system message stays the same.

use std::collections::HashMap;
use std::path::Path;

use tad_db::Language;
use tad_llm::{Message, Role};

use crate::session::Checker;

/// BM25's term-frequency saturation and length normalisation.
const K1: f64 = 1.2;
const B: f64 = 0.75;

/// One translation of the pool: the description and its program (canonical, without
/// comments and `source`).
#[derive(Clone, Debug)]
pub struct Shot {
    pub name: String,
    pub description: String,
    pub program: String,
}

/// The pool, indexed for retrieval.
#[derive(Debug, Default)]
pub struct Pool {
    shots: Vec<Shot>,
    /// Each shot's word counts, length in words, and description with its whitespace
    /// normalised (to know the question's own).
    words: Vec<(HashMap<String, u32>, usize, String)>,
    /// In how many descriptions each word occurs.
    documents: HashMap<String, u32>,
    /// Programs left out, each with why: no description, an error, unreadable.
    pub skipped: Vec<String>,
}

impl Pool {
    /// The pool under `dir`: every `*.tad` with a description (its own `source.description`,
    /// or `../descriptions/NAME.txt` for a file in a `truth` directory) and no error.
    pub fn load(dir: &Path) -> Result<Pool, String> {
        if !dir.is_dir() {
            return Err(format!("the pool `{}` is not a directory", dir.display()));
        }
        let checker = Checker::default();
        let mut pool = Pool::default();
        for path in tad_db::host::with_extension(dir, "tad") {
            match entry(&checker, &path) {
                Ok(shot) => pool.push(shot),
                Err(why) => pool.skipped.push(format!("{} ({why})", path.display())),
            }
        }
        if pool.shots.is_empty() {
            return Err(format!("the pool `{}` holds no checked program with a description", dir.display()));
        }
        Ok(pool)
    }

    pub fn len(&self) -> usize {
        self.shots.len()
    }

    pub fn is_empty(&self) -> bool {
        self.shots.is_empty()
    }

    fn push(&mut self, shot: Shot) {
        let words = words(&shot.description);
        let mut counts: HashMap<String, u32> = HashMap::new();
        for w in &words {
            *counts.entry(w.clone()).or_default() += 1;
        }
        for w in counts.keys() {
            *self.documents.entry(w.clone()).or_default() += 1;
        }
        self.words.push((counts, words.len(), normalise(&shot.description)));
        self.shots.push(shot);
    }

    /// The `k` shots whose descriptions read most like `description`, the nearest last
    /// (next to the question); never one with the same description.
    pub fn nearest(&self, description: &str, k: usize) -> Vec<&Shot> {
        let query = words(description);
        let same = normalise(description);
        let n = self.shots.len() as f64;
        let mean = self.words.iter().map(|(_, len, _)| *len as f64).sum::<f64>() / n.max(1.0);
        let mut scored: Vec<(f64, &Shot)> = Vec::new();
        for (shot, (counts, len, normalised)) in self.shots.iter().zip(&self.words) {
            if *normalised == same {
                continue;
            }
            let mut score = 0.0;
            for w in &query {
                let (Some(&tf), Some(&df)) = (counts.get(w), self.documents.get(w)) else { continue };
                let idf = ((n - df as f64 + 0.5) / (df as f64 + 0.5) + 1.0).ln();
                let tf = tf as f64;
                score += idf * tf * (K1 + 1.0) / (tf + K1 * (1.0 - B + B * *len as f64 / mean.max(1.0)));
            }
            scored.push((score, shot));
        }
        scored.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.name.cmp(&b.1.name)));
        let mut chosen: Vec<&Shot> = scored.into_iter().take(k).map(|(_, s)| s).collect();
        chosen.reverse();
        chosen
    }
}

/// The pool entry of the program at `path`, as the checker reads it (its machine-applicable
/// fixes applied), or why it is left out.
fn entry(checker: &Checker, path: &Path) -> Result<Shot, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot be read: {e}"))?;
    let (own, program) = crate::example_parts(&text);
    let description = match own.is_empty() {
        false => Some(own),
        true => beside(path).and_then(|p| std::fs::read_to_string(p).ok()),
    };
    let description = description.map(|d| d.trim().to_string()).filter(|d| !d.is_empty());
    let description = description.ok_or("no description")?;
    let verdict = checker.check(&program, Language::Tad);
    if verdict.errors > 0 {
        return Err(format!("{} error{}", verdict.errors, if verdict.errors == 1 { "" } else { "s" }));
    }
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(Shot { name, description, program: verdict.tad.map_or(program, |t| t.trim().to_string()) })
}

/// `messages` (system, then the question) with `shots` as earlier turns between them, each
/// asked as `ask` renders a description and answered with its program in a code block.
pub fn interleave(messages: Vec<Message>, shots: &[&Shot], ask: impl Fn(&str) -> String) -> Vec<Message> {
    let mut out = Vec::with_capacity(messages.len() + 2 * shots.len());
    let mut rest = messages.into_iter().peekable();
    while let Some(m) = rest.next_if(|m| m.role == Role::System) {
        out.push(m);
    }
    for shot in shots {
        out.push(Message::text(Role::User, ask(&shot.description)));
        out.push(Message::text(Role::Assistant, format!("```tad\n{}\n```", shot.program)));
    }
    out.extend(rest);
    out
}

/// The file `../descriptions/NAME.txt` for `.../truth/NAME.tad`.
fn beside(path: &Path) -> Option<std::path::PathBuf> {
    let dir = path.parent()?;
    if dir.file_name()? != "truth" {
        return None;
    }
    Some(dir.parent()?.join("descriptions").join(path.file_stem()?).with_extension("txt"))
}

/// The lower-cased words of `text` (letters and digits).
fn words(text: &str) -> Vec<String> {
    text.split(|c: char| !c.is_alphanumeric()).filter(|w| !w.is_empty()).map(str::to_lowercase).collect()
}

fn normalise(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pool(descriptions: &[(&str, &str)]) -> Pool {
        let mut pool = Pool::default();
        for (name, d) in descriptions {
            pool.push(Shot {
                name: name.to_string(),
                description: d.to_string(),
                program: format!("scenario {name} {{}}"),
            });
        }
        pool
    }

    #[test]
    fn the_nearest_description_comes_last_and_the_same_one_never() {
        let pool = pool(&[
            ("rain", "A rainy highway at night, a truck merging from the right."),
            ("deer", "A deer crosses a country road at dawn in the fog."),
            ("bus", "A bus stops at a stop ahead of the ego on a city street."),
        ]);
        let names = |d: &str, k| pool.nearest(d, k).iter().map(|s| s.name.clone()).collect::<Vec<_>>();
        assert_eq!(names("Fog on a country road; two deer cross ahead.", 1), ["deer"]);
        assert_eq!(names("A truck merges onto the highway in the rain.", 2).last().unwrap(), "rain");
        assert_eq!(names("A deer crosses a country road at dawn in the fog.", 3).len(), 2, "itself is left out");
        assert!(!names("A deer  crosses a country road at dawn in the fog.", 3).contains(&"deer".to_string()));
    }

    #[test]
    fn shots_are_turns_between_the_system_message_and_the_question() {
        let pool = pool(&[("a", "one"), ("b", "two")]);
        let messages = vec![Message::text(Role::System, "sys"), Message::text(Role::User, "Q")];
        let shots = pool.nearest("one two", 2);
        let out = interleave(messages, &shots, |d| format!("Description:\n{d}"));
        let roles: Vec<Role> = out.iter().map(|m| m.role).collect();
        assert_eq!(roles, [Role::System, Role::User, Role::Assistant, Role::User, Role::Assistant, Role::User]);
        assert_eq!(out[2].plain(), format!("```tad\nscenario {} {{}}\n```", shots[0].name));
    }
}
