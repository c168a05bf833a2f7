//! The check-and-repair loop: ask, extract the program, check it with the same database as
//! `tadslc check`, and send back what is wrong until the program is valid or a bound is hit.
//!
//! ```text
//! messages ──model──▶ answer ──extract──▶ program (TAD or YAML) ──check──▶ class + diagnostics
//!    ▲                                                                         │
//!    └── repair request (every diagnostic: code line:column message fix) ◀── invalid
//!    └── refinement request (each missing essential, with its names)    ◀── incomplete
//!                                                       complete / non-scenario ──▶ done
//! ```
//!
//! The outcome is the best program of the rounds (complete, then incomplete, then
//! non-scenario, then invalid with the fewest errors; the later among equals), so a repair
//! that makes things worse loses nothing. A best program still invalid when the rounds are
//! spent gets the checker's maybe-incorrect suggestions as a last resort, kept only when
//! they leave no error ([`Checker::salvage`]). Only the newest exchange is kept in the
//! conversation (the first request, the last answer and the request about it), so the
//! context does not grow with the rounds. Every round is reported to the caller as a
//! [`Round`] for the transcript. Bounds: rounds, tokens per answer, tokens per item, and
//! wall time per item.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use serde::Serialize;
use tad_check::{Class, Options};
use tad_db::{Database, Language, NoFs, SourceFile};
use tad_diagnostics::{Applicability, Severity};
use tad_llm::{Chat, ChatFuture, Constraint, Message, OnText, Request, Role, Usage};

use crate::extract;
use crate::prompt;

/// How far one item may go.
#[derive(Clone, Debug)]
pub struct Limits {
    /// Requests after the first answer (repairs and refinements).
    pub max_rounds: u32,
    /// Tokens per answer.
    pub max_tokens: u32,
    /// Tokens (prompt and answer) for the whole item.
    pub token_budget: u64,
    /// Wall time for the whole item.
    pub deadline: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Limits { max_rounds: 3, max_tokens: 1024, token_budget: 60_000, deadline: Duration::from_secs(600) }
    }
}

/// What the checker says of one program.
#[derive(Clone, Debug)]
pub struct Verdict {
    pub class: Class,
    /// No lexical, syntax or YAML-reading error.
    pub syntax_valid: bool,
    /// `CODE line:column: message (fix)`, one per diagnostic (errors first).
    pub lines: Vec<String>,
    /// Requests for the missing essentials, when incomplete.
    pub requests: Vec<String>,
    /// The program as canonical TAD (a YAML answer converted), when it parses.
    pub tad: Option<String>,
    pub errors: usize,
}

/// Checks programs as `tadslc check` does, with the run's options.
#[derive(Clone, Debug, Default)]
pub struct Checker {
    pub options: Options,
}

impl Checker {
    /// The verdict on `text`, after the machine-applicable fixes of its errors: what the
    /// compiler knows for certain is not sent back to the model as a repair.
    pub fn check(&self, text: &str, language: Language) -> Verdict {
        let (verdict, fixed) = self.check_as_is(text, language);
        match fixed {
            Some(fixed) => {
                let (after, _) = self.check_as_is(&fixed, language);
                if after.errors < verdict.errors { after } else { verdict }
            }
            None => verdict,
        }
    }

    /// The last resort for a TAD program the rounds left with errors: the program with the
    /// checker's suggestions applied, its maybe-incorrect guesses too (`did you mean
    /// `delivery_van`?`), when that leaves it without errors; with its verdict and each
    /// applied suggestion as ``CODE `was` → `now` ``.
    pub fn salvage(&self, text: &str) -> Option<(String, Verdict, Vec<String>)> {
        let (db, file) = self.answer(text, Language::Tad);
        let diagnostics = &tad_db::check(&db, file).diagnostics;
        let errors: Vec<_> = diagnostics.iter().filter(|d| d.is_error()).collect();
        let fixes = tad_diagnostics::fixes_at_least(errors.iter().copied(), text.len(), Applicability::MaybeIncorrect);
        if fixes.is_empty() {
            return None;
        }
        let applied = fixes
            .iter()
            .map(|fix| {
                let code = errors.iter().find(|d| d.fixes.iter().any(|f| std::ptr::eq(f, *fix))).map(|d| d.code);
                let code = code.map_or(String::new(), |c| format!("{} ", c.as_str()));
                let was = text.get(fix.span.start..fix.span.end).unwrap_or_default();
                format!("{code}`{was}` → `{}`", fix.replacement)
            })
            .collect();
        let fixed = tad_diagnostics::apply(text, &fixes);
        let (verdict, _) = self.check_as_is(&fixed, Language::Tad);
        (verdict.errors == 0).then(|| (verdict.tad.clone().unwrap_or(fixed), verdict, applied))
    }

    /// A database with the run's options holding `text` as the answer's file.
    fn answer(&self, text: &str, language: Language) -> (Database, SourceFile) {
        let mut db = Database::new(self.options.clone());
        let path = PathBuf::from(if language == Language::Yaml { "answer.yaml" } else { "answer.tad" });
        let file = db.set_source(path, text.to_string(), language, &NoFs);
        (db, file)
    }

    /// The verdict on `text` as it is, and for a TAD program with errors that have
    /// machine-applicable fixes, the text with those fixes applied.
    fn check_as_is(&self, text: &str, language: Language) -> (Verdict, Option<String>) {
        let (db, file) = self.answer(text, language);
        let checked = tad_db::check(&db, file);
        let vocabulary = &tad_db::vocabulary(&db, file).vocabulary;
        let diagnostics = &checked.diagnostics;
        let errors = diagnostics.iter().filter(|d| d.severity == Severity::Error).count();
        let fixed = match tad_diagnostics::apply_fixes(text, diagnostics.iter().filter(|d| d.is_error())) {
            (fixed, n) if language == Language::Tad && n > 0 => Some(fixed),
            _ => None,
        };
        let syntax_valid = !diagnostics.iter().any(|d| {
            let code = d.code.as_str();
            d.severity == Severity::Error
                && (code.starts_with("E00") || code.starts_with("E01") || code.starts_with("E030"))
        });
        let mut ordered: Vec<_> = diagnostics.iter().filter(|d| d.severity == Severity::Error).cloned().collect();
        ordered.extend(diagnostics.iter().filter(|d| d.severity != Severity::Error).cloned());
        let lines = tad_feedback::repair(&ordered, text);
        let class = checked.class.unwrap_or(Class::Invalid);
        let requests =
            if class == Class::Incomplete { tad_feedback::refinement(diagnostics, vocabulary) } else { Vec::new() };
        let module = &tad_db::analyze(&db, file).module;
        let tad = match language {
            Language::Tad if syntax_valid => tad_syntax::format::format(text).ok(),
            Language::Yaml if module.scenario.is_some() => Some(tad_yaml::to_tad(module)),
            _ => None,
        };
        (Verdict { class, syntax_valid, lines, requests, tad, errors }, fixed)
    }
}

/// How good a program of this class is, to keep the best of the rounds.
fn rank(class: Class) -> u8 {
    match class {
        Class::Complete => 3,
        Class::Incomplete => 2,
        Class::NonScenario => 1,
        Class::Invalid => 0,
    }
}

/// One request and its answer, for the transcript.
#[derive(Clone, Debug, Serialize)]
pub struct Round {
    pub item: String,
    pub round: u32,
    /// `first`, `repair` or `refine`.
    pub kind: &'static str,
    pub prompt: &'static str,
    /// The messages sent that the previous round did not send.
    pub request: Vec<(String, String)>,
    pub answer: String,
    pub finish: String,
    pub language: Option<&'static str>,
    pub class: Option<&'static str>,
    pub syntax_valid: bool,
    pub diagnostics: Vec<String>,
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
    pub elapsed_ms: u128,
    pub error: Option<String>,
}

impl Round {
    fn new(item: &str, round: u32, kind: &'static str, prompt: &'static str, request: Vec<(String, String)>) -> Round {
        Round {
            item: item.to_string(),
            round,
            kind,
            prompt,
            request,
            answer: String::new(),
            finish: String::new(),
            language: None,
            class: None,
            syntax_valid: false,
            diagnostics: Vec::new(),
            prompt_tokens: 0,
            completion_tokens: 0,
            elapsed_ms: 0,
            error: None,
        }
    }
}

/// How an item ended.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Outcome {
    /// The best program of the rounds, as canonical TAD when it parses (else as answered).
    pub program: Option<String>,
    /// The best program's class; `None` when no answer held a program.
    pub class: Option<&'static str>,
    #[serde(skip)]
    pub verdict_class: Option<Class>,
    /// Answers received.
    pub rounds: u32,
    pub syntax_valid_first: bool,
    /// The round whose program first had no errors.
    pub valid_round: Option<u32>,
    pub usage: Usage,
    /// Why the loop stopped early: a server failure, a bound.
    pub stopped: Option<String>,
    /// The refinement requests of an incomplete best program.
    pub requests: Vec<String>,
    /// The best program's diagnostics.
    pub diagnostics: Vec<String>,
    /// The checker's suggestions applied to the best program when the rounds left it with
    /// errors and they leave it without ([`Checker::salvage`]); `valid_round` stays the
    /// model's.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub suggested: Vec<String>,
}

impl Outcome {
    /// The line that says which of the checker's suggestions made the program valid, for
    /// its provenance and the terminal; `None` when the model's program needed none.
    pub fn suggested_line(&self) -> Option<String> {
        let applied = self.suggested.join(", ");
        (!applied.is_empty()).then(|| format!("the checker's suggestions applied after the last round: {applied}"))
    }

    /// Whether the model could not be used: no program, and the loop stopped early.
    pub fn unreachable(&self) -> bool {
        self.class.is_none() && self.stopped.is_some()
    }
}

pub struct Session<'a> {
    pub client: &'a dyn Chat,
    pub checker: &'a Checker,
    pub limits: Limits,
    pub constraint: Constraint,
    pub temperature: f64,
    pub seed: Option<u64>,
    /// Receives each answer's text as the model writes it.
    pub on_text: Option<&'a OnText>,
}

impl<'a> Session<'a> {
    fn ask<'r>(&'r self, request: &'r Request) -> ChatFuture<'r> {
        match self.on_text {
            Some(on_text) => self.client.chat_streaming(request, on_text),
            None => self.client.chat(request),
        }
    }

    /// The same session asking with `seed`.
    pub fn with_seed(&self, seed: u64) -> Session<'a> {
        Session {
            client: self.client,
            checker: self.checker,
            limits: self.limits.clone(),
            constraint: self.constraint.clone(),
            temperature: self.temperature,
            seed: Some(seed),
            on_text: self.on_text,
        }
    }

    /// One request whose answer is prose (a frame's description): no checking, one round.
    pub async fn describe(
        &self,
        item: &str,
        messages: Vec<Message>,
        on_round: &mut dyn FnMut(&Round),
    ) -> Result<String, String> {
        let mut request = Request::new(messages.clone());
        request.max_tokens = self.limits.max_tokens;
        request.temperature = self.temperature;
        request.seed = self.seed;
        let sent = Instant::now();
        let result = tokio::time::timeout(self.limits.deadline, self.ask(&request)).await;
        let result = result.unwrap_or_else(|_| {
            Err(tad_llm::Error::new(
                tad_llm::ErrorKind::Timeout,
                format!("no description within {} s", self.limits.deadline.as_secs()),
            ))
        });
        let last = messages.last().map(|m| vec![(m.role.name().to_string(), m.plain())]).unwrap_or_default();
        let mut round = Round::new(item, 0, "describe", crate::prompt::DESCRIBE.id, last);
        round.elapsed_ms = sent.elapsed().as_millis();
        match result {
            Ok(answer) => {
                round.answer = answer.text.clone();
                round.finish = format!("{:?}", answer.finish).to_ascii_lowercase();
                round.prompt_tokens = answer.usage.prompt_tokens;
                round.completion_tokens = answer.usage.completion_tokens;
                on_round(&round);
                Ok(answer.text)
            }
            Err(e) => {
                round.error = Some(e.to_string());
                on_round(&round);
                Err(e.to_string())
            }
        }
    }

    /// Runs the loop from `first` (the first request's messages) for `item`.
    pub async fn run(
        &self,
        item: &str,
        first: Vec<Message>,
        first_prompt: &'static str,
        on_round: &mut dyn FnMut(&Round),
    ) -> Outcome {
        let mut outcome = self.rounds(item, first, first_prompt, on_round).await;
        self.salvage(&mut outcome);
        outcome
    }

    /// The last resort for a best program with errors: the checker's suggestions, when
    /// they leave it without ([`Checker::salvage`]).
    fn salvage(&self, outcome: &mut Outcome) {
        if outcome.verdict_class != Some(Class::Invalid) {
            return;
        }
        let Some((program, verdict, applied)) = outcome.program.as_deref().and_then(|p| self.checker.salvage(p)) else {
            return;
        };
        outcome.program = Some(program);
        outcome.class = Some(verdict.class.as_str());
        outcome.verdict_class = Some(verdict.class);
        outcome.diagnostics = verdict.lines;
        outcome.requests = verdict.requests;
        outcome.suggested = applied;
    }

    /// The rounds: ask, check, repair or refine, until done or a bound is hit.
    async fn rounds(
        &self,
        item: &str,
        first: Vec<Message>,
        first_prompt: &'static str,
        on_round: &mut dyn FnMut(&Round),
    ) -> Outcome {
        let start = Instant::now();
        let mut outcome = Outcome::default();
        let mut conversation = first.clone();
        let mut new_messages = first;
        let (mut kind, mut prompt_id) = ("first", first_prompt);
        let mut best_errors = usize::MAX;
        loop {
            let mut request = Request::new(conversation.clone());
            request.max_tokens = self.limits.max_tokens;
            request.temperature = self.temperature;
            request.seed = self.seed;
            request.constraint = self.constraint.clone();
            let sent = Instant::now();
            let remaining = self.limits.deadline.saturating_sub(start.elapsed());
            let answer = match tokio::time::timeout(remaining, self.ask(&request)).await {
                Ok(result) => result,
                Err(_) => {
                    outcome.stopped = Some(format!("the item's time ({} s) ran out", self.limits.deadline.as_secs()));
                    return outcome;
                }
            };
            let request = new_messages.iter().map(|m| (m.role.name().to_string(), m.plain())).collect();
            let mut round = Round::new(item, outcome.rounds + 1, kind, prompt_id, request);
            round.elapsed_ms = sent.elapsed().as_millis();
            let answer = match answer {
                Ok(answer) => answer,
                Err(error) => {
                    round.error = Some(error.to_string());
                    on_round(&round);
                    outcome.stopped = Some(error.to_string());
                    return outcome;
                }
            };
            outcome.rounds += 1;
            outcome.usage.add(answer.usage);
            round.answer = answer.text.clone();
            round.finish = format!("{:?}", answer.finish).to_ascii_lowercase();
            round.prompt_tokens = answer.usage.prompt_tokens;
            round.completion_tokens = answer.usage.completion_tokens;

            let follow_up: Option<(&'static str, prompt::Template, String)> = match extract::program(&answer.text) {
                None => {
                    round.diagnostics = vec!["no program in the answer".into()];
                    let text =
                        "Your answer holds no TAD program. Answer with the whole program only, in a ```tad code block.";
                    Some(("repair", prompt::REPAIR, text.to_string()))
                }
                Some((text, language)) => {
                    let verdict = self.checker.check(&text, language);
                    round.language = Some(if language == Language::Yaml { "yaml" } else { "tad" });
                    round.class = Some(verdict.class.as_str());
                    round.syntax_valid = verdict.syntax_valid;
                    round.diagnostics = verdict.lines.clone();
                    if outcome.rounds == 1 {
                        outcome.syntax_valid_first = verdict.syntax_valid;
                    }
                    if verdict.errors == 0 && outcome.valid_round.is_none() {
                        outcome.valid_round = Some(outcome.rounds);
                    }
                    // the outcome is the best program so far, not the last one
                    let better = match outcome.verdict_class {
                        None => true,
                        Some(best) => {
                            rank(verdict.class) > rank(best)
                                || (rank(verdict.class) == rank(best)
                                    && (verdict.class != Class::Invalid || verdict.errors <= best_errors))
                        }
                    };
                    if better {
                        best_errors = verdict.errors;
                        outcome.program = Some(verdict.tad.clone().unwrap_or(text));
                        outcome.class = Some(verdict.class.as_str());
                        outcome.verdict_class = Some(verdict.class);
                        outcome.diagnostics = verdict.lines.clone();
                        outcome.requests = verdict.requests.clone();
                    }
                    match verdict.class {
                        Class::Complete | Class::NonScenario => None,
                        Class::Invalid => {
                            let lines = verdict.lines.join("\n");
                            Some(("repair", prompt::REPAIR, prompt::REPAIR.render(&[("diagnostics", &lines)]).user))
                        }
                        Class::Incomplete => {
                            let requests =
                                verdict.requests.iter().map(|r| format!("- {r}")).collect::<Vec<_>>().join("\n");
                            Some(("refine", prompt::REFINE, prompt::REFINE.render(&[("requests", &requests)]).user))
                        }
                    }
                }
            };
            on_round(&round);
            let Some((next_kind, template, text)) = follow_up else { return outcome };
            if outcome.rounds > self.limits.max_rounds {
                return outcome;
            }
            if outcome.usage.total() >= self.limits.token_budget {
                outcome.stopped = Some(format!("the item's token budget ({}) is spent", self.limits.token_budget));
                return outcome;
            }
            let base = conversation.iter().take_while(|m| m.role != Role::Assistant).cloned();
            let reply = Message::text(Role::User, text);
            conversation = base.chain([Message::text(Role::Assistant, answer.text), reply.clone()]).collect();
            new_messages = vec![reply];
            kind = next_kind;
            prompt_id = template.id;
        }
    }
}
