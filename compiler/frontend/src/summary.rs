//! What a batch of items came to: syntax-valid at round 1, valid at round 1 and after
//! repair, mean rounds to valid, the class distribution, tokens.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::session::Outcome;

#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Summary {
    pub items: usize,
    /// The first answer held a program with no lexical, syntax or YAML error.
    pub syntax_valid_first: usize,
    /// The first answer's program had no errors at all.
    pub valid_first: usize,
    /// The best program had no errors.
    pub valid_after_repair: usize,
    /// The best program had errors, and the checker's suggestions left it without
    /// ([`Outcome::suggested`]); not counted as valid after repair.
    pub valid_with_suggestions: usize,
    /// Over the items that became valid: the round it happened.
    pub mean_rounds_to_valid: Option<f64>,
    /// Items per final class (`complete`, `incomplete`, `non_scenario`, `invalid`, `no_program`).
    pub classes: BTreeMap<String, usize>,
    /// Items stopped by a server failure or a bound.
    pub stopped: usize,
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
    #[serde(skip)]
    rounds_to_valid: Vec<u32>,
    /// Whether every item was asked for a scenario (`gen`, `synth`'s scenes): then a
    /// non-scenario is a failure, not a valid answer. A description may be of a title card
    /// (`translate`), where it is the right one.
    #[serde(skip)]
    scenarios_asked: bool,
}

impl Summary {
    /// The summary of a run that asked every item for a scenario.
    pub fn of_scenarios() -> Summary {
        Summary { scenarios_asked: true, ..Summary::default() }
    }

    pub fn add(&mut self, o: &Outcome) {
        self.items += 1;
        self.syntax_valid_first += usize::from(o.syntax_valid_first);
        let counts = !(self.scenarios_asked && o.class == Some("non_scenario"));
        self.valid_first += usize::from(o.valid_round == Some(1) && counts);
        let valid = o.class.is_some_and(|c| c != "invalid") && counts;
        let valid_now = valid && o.suggested.is_empty();
        self.valid_after_repair += usize::from(valid_now);
        self.valid_with_suggestions += usize::from(valid && !o.suggested.is_empty());
        if let (Some(r), true) = (o.valid_round, valid_now) {
            self.rounds_to_valid.push(r);
            self.mean_rounds_to_valid =
                Some(self.rounds_to_valid.iter().map(|&r| r as f64).sum::<f64>() / self.rounds_to_valid.len() as f64);
        }
        *self.classes.entry(o.class.unwrap_or("no_program").to_string()).or_default() += 1;
        self.stopped += usize::from(o.stopped.is_some());
        self.prompt_tokens += o.usage.prompt_tokens;
        self.completion_tokens += o.usage.completion_tokens;
    }

    /// A few lines for people.
    pub fn render(&self) -> String {
        let pct = |n: usize| if self.items == 0 { 0.0 } else { 100.0 * n as f64 / self.items as f64 };
        let classes: Vec<String> = self.classes.iter().map(|(c, n)| format!("{c} {n}")).collect();
        let mut out = format!(
            "{} items: syntax-valid at round 1 {} ({:.0}%), valid at round 1 {} ({:.0}%), valid after repair {} ({:.0}%)",
            self.items,
            self.syntax_valid_first,
            pct(self.syntax_valid_first),
            self.valid_first,
            pct(self.valid_first),
            self.valid_after_repair,
            pct(self.valid_after_repair),
        );
        if let Some(m) = self.mean_rounds_to_valid {
            out.push_str(&format!(", mean rounds to valid {m:.2}"));
        }
        if self.valid_with_suggestions > 0 {
            out.push_str(&format!(", valid with the checker's suggestions {}", self.valid_with_suggestions));
        }
        out.push_str(&format!(
            "\nclasses: {}; tokens: {} prompt + {} completion",
            classes.join(", "),
            self.prompt_tokens,
            self.completion_tokens
        ));
        if self.stopped > 0 {
            out.push_str(&format!("; {} stopped early", self.stopped));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_non_scenario_is_valid_only_where_it_can_be_the_answer() {
        let card = Outcome { class: Some("non_scenario"), valid_round: Some(1), rounds: 1, ..Outcome::default() };
        let mut described = Summary::default();
        described.add(&card);
        assert_eq!((described.valid_first, described.valid_after_repair), (1, 1));
        let mut generated = Summary::of_scenarios();
        generated.add(&card);
        assert_eq!((generated.valid_first, generated.valid_after_repair), (0, 0));
        assert_eq!(generated.classes["non_scenario"], 1);
    }

    #[test]
    fn a_program_the_checkers_suggestions_made_valid_is_counted_apart() {
        let guessed = Outcome {
            class: Some("complete"),
            rounds: 4,
            suggested: vec!["E0402 `parked_van` → `delivery_van`".into()],
            ..Outcome::default()
        };
        let repaired = Outcome { class: Some("complete"), valid_round: Some(2), rounds: 2, ..Outcome::default() };
        let mut summary = Summary::default();
        summary.add(&guessed);
        summary.add(&repaired);
        assert_eq!((summary.valid_after_repair, summary.valid_with_suggestions), (1, 1));
        assert_eq!(summary.mean_rounds_to_valid, Some(2.0));
        assert!(
            summary.render().contains(
                "valid after repair 1 (50%), mean rounds to valid 2.00, valid with the checker's suggestions 1"
            )
        );
    }
}
