//! Where an evaluation's scenarios come from, per region.
//!
//! - [`Generator::Fitted`]: `tad-fit`'s count tables fitted on the region's own scenarios;
//!   scenario `i` is drawn with seed `seed + i`, again while it has errors (at most
//!   [`ATTEMPTS`] draws);
//! - [`Generator::Baseline`]: the region-agnostic [`baseline`](crate::baseline) generator,
//!   each region drawing its own sample;
//! - [`Generator::ChatScene`]: ChatScene's eight safety-critical categories as templates
//!   with its parameter ranges ([`chatscene`](crate::chatscene)), the paper's strongest
//!   baseline;
//! - [`Generator::Llm`]: a language model through `tadslc gen`'s check-and-repair loop (the
//!   host runs it: it needs a server or the local model), with one of three prompts;
//! - [`Generator::Directory`]: scenarios written elsewhere.
//!
//! Every generator's scenarios pass [`counts`](crate::corpus::counts) before they are run.

use std::fmt;
use std::path::{Path, PathBuf};

use tad_base::SplitMix64;
use tad_check::Class;
use tad_db::{Database, Language, RealFs};

use crate::corpus::{Item, counts};

/// Draws per scenario before the fitted generator gives up on it (`gen --attempts`).
pub const ATTEMPTS: usize = 50;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Generator {
    Fitted,
    Baseline,
    ChatScene,
    Llm(Prompt),
    Directory(PathBuf),
}

/// The prompt of a language-model generator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prompt {
    /// `llm`: the region's examples (aligned).
    Aligned,
    /// `llm-baseline`: the paper's unaligned prompt, the region's name only.
    Unaligned,
    /// `llm-tuned`: the short prompt a fine-tuned model learnt.
    Tuned,
}

impl Generator {
    /// A generator by its command-line name; any other word is a directory.
    pub fn parse(text: &str) -> Generator {
        match text {
            "fitted" => Generator::Fitted,
            "baseline" => Generator::Baseline,
            "chatscene" => Generator::ChatScene,
            "llm" => Generator::Llm(Prompt::Aligned),
            "llm-baseline" => Generator::Llm(Prompt::Unaligned),
            "llm-tuned" => Generator::Llm(Prompt::Tuned),
            path => Generator::Directory(PathBuf::from(path)),
        }
    }

    /// The names [`parse`](Generator::parse) knows, in words.
    pub const NAMES: &'static str =
        "`chatscene`, `fitted`, `baseline`, `llm`, `llm-baseline`, `llm-tuned` or a directory of scenarios";
}

impl fmt::Display for Generator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Generator::Fitted => f.write_str("fitted"),
            Generator::Baseline => f.write_str("baseline"),
            Generator::ChatScene => f.write_str("chatscene"),
            Generator::Llm(Prompt::Aligned) => f.write_str("llm"),
            Generator::Llm(Prompt::Unaligned) => f.write_str("llm-baseline"),
            Generator::Llm(Prompt::Tuned) => f.write_str("llm-tuned"),
            Generator::Directory(path) => write!(f, "{}", path.display()),
        }
    }
}

/// The generator fitted to `items`, and how many of them it was fitted on.
pub fn fit<'a>(items: impl Iterator<Item = &'a Item>) -> (tad_fit::Fitted, usize) {
    let examples: Vec<tad_fit::Example> =
        items.filter_map(|i| tad_fit::Example::of(&i.tad, &tad_syntax::analyze(&i.tad).0)).collect();
    (tad_fit::Fitted::fit(&examples), examples.len())
}

/// Scenario `name` drawn from `fitted` with `seed` and checked, drawn again while it does
/// not count (at most `attempts` draws): the text and its class, and the number of draws.
pub fn draw_fitted(
    db: &mut Database,
    fitted: &tad_fit::Fitted,
    name: &str,
    seed: u64,
    attempts: usize,
) -> (Option<(String, Class)>, usize) {
    let mut rng = SplitMix64::new(seed);
    for draw in 1..=attempts.max(1) {
        let text = fitted.sample(name, &mut rng);
        let file = db.set_source(PathBuf::from(format!("{name}.tad")), text.clone(), Language::Tad, &RealFs);
        let class = tad_db::check(db, file).class;
        if let Some(class) = class.filter(|_| counts(class)) {
            return (Some((text, class)), draw);
        }
    }
    (None, attempts.max(1))
}

/// What a run of the fitted generator did (`gen --generator fitted:` writes it as
/// `summary.json`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FittedSummary {
    pub generator: String,
    pub region: Option<String>,
    pub requested: usize,
    pub generated: usize,
    pub complete: usize,
    pub incomplete: usize,
    pub draws: usize,
    pub rejected: usize,
    pub seed: u64,
}

/// One scenario of [`draw_many`]: its name, seed, and text (`None` when no draw counted).
pub struct Drawn {
    pub index: usize,
    pub name: String,
    pub seed: u64,
    pub text: Option<String>,
}

/// A run of the fitted generator: `n` scenarios named `STEM_fitted_00i`, scenario `i`
/// drawn with seed `seed + i`, at most `attempts` draws each.
pub struct Draws<'a> {
    /// How the summary names the generator (`fitted:PATH`).
    pub generator: &'a str,
    pub stem: &'a str,
    pub n: usize,
    pub seed: u64,
    pub attempts: usize,
}

/// The scenarios of `run` drawn from `fitted` by [`draw_fitted`]; `each` takes them in
/// order and may stop the run.
pub fn draw_many<E>(
    fitted: &tad_fit::Fitted,
    run: &Draws,
    mut each: impl FnMut(Drawn) -> Result<(), E>,
) -> Result<FittedSummary, E> {
    let Draws { generator, stem, n, seed, attempts } = *run;
    let mut db = Database::new(tad_check::Options::default());
    let mut summary = FittedSummary {
        generator: generator.to_string(),
        region: fitted.region.clone(),
        requested: n,
        seed,
        ..FittedSummary::default()
    };
    for index in 0..n {
        let seed = seed.wrapping_add(index as u64);
        let name = format!("{stem}_fitted_{:03}", index + 1);
        let (accepted, draws) = draw_fitted(&mut db, fitted, &name, seed, attempts);
        summary.draws += draws;
        summary.rejected += draws - usize::from(accepted.is_some());
        if let Some((_, class)) = &accepted {
            summary.generated += 1;
            if *class == Class::Complete {
                summary.complete += 1;
            } else {
                summary.incomplete += 1;
            }
        }
        each(Drawn { index, name, seed, text: accepted.map(|(text, _)| text) })?;
    }
    Ok(summary)
}

/// `n` scenarios of the generator fitted on `own` (the region's scenarios): (name, TAD).
pub fn fitted(db: &mut Database, own: &[&Item], region: &str, n: usize, seed: u64) -> Vec<(String, String)> {
    let (fitted, _) = fit(own.iter().copied());
    (0..n)
        .filter_map(|i| {
            let name = format!("{region}_fitted_{:03}", i + 1);
            let (drawn, _) = draw_fitted(db, &fitted, &name, seed.wrapping_add(i as u64), ATTEMPTS);
            drawn.map(|(text, _)| (name, text))
        })
        .collect()
}

/// `n` scenarios of the baseline generator for `region`: (name, TAD).
pub fn baseline(db: &mut Database, region: &str, n: usize, seed: u64) -> Vec<(String, String)> {
    crate::baseline::sample(db, n, crate::baseline::region_seed(seed, region), |i| {
        format!("{region}_baseline_{:03}", i + 1)
    })
}

/// `n` scenarios of the ChatScene-style generator for `region`: (name, TAD).
pub fn chatscene(db: &mut Database, region: &str, n: usize, seed: u64) -> Vec<(String, String)> {
    crate::chatscene::sample(db, region, n, crate::baseline::region_seed(seed, region))
}

/// Where a language-model generator writes region `region`'s scenarios under `base`.
pub fn llm_dir(base: &Path, region: &str, generator: &Generator) -> PathBuf {
    base.join("generated").join(region).join(generator.to_string())
}
