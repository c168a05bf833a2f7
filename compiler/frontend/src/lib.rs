//! The LLM front-end: TrafficAlign's pipeline with the compiler in the loop.
//!
//! ```text
//! video ──ffmpeg, every 15 s──▶ frame ──describe (image)──▶ description ──translate──▶ program
//!                                   ▲                                        │ session: check, repair, refine
//!                                   └── re-describe with the refinement ◀── incomplete
//! region ──generate (aligned: the region's module and examples; baseline: its name only)──▶ program
//! ```
//!
//! [`prompt`] renders the versioned templates (the vocabulary from the declarations in
//! scope), [`extract`] finds the program in an answer, [`session`] runs the
//! check-and-repair loop on `tad-db` (the same checks as `tadslc check`) over `tad-llm`,
//! [`synth`], [`generate`] and [`translate`] are the pipelines, [`backend`] picks who
//! answers (a server or the model in process), [`store`] writes what they produce (sanitised
//! names, atomic files, JSON Lines), [`summary`] counts what happened, [`shots`] retrieves translations to show before a description, [`sft`] turns a corpus into fine-tuning data. Everything a model
//! writes is untrusted: it never names a path, never breaks a record, and every loop is
//! bounded in rounds, tokens and time.

pub mod backend;
pub mod extract;
pub mod generate;
pub mod prompt;
pub mod session;
pub mod sft;
pub mod shots;
pub mod store;
pub mod summary;
pub mod synth;
pub mod translate;

use tad_check::Vocabulary;
use tad_llm::{Constraint, Dialect};
use tad_syntax::model::Val;

pub use session::{Checker, Limits, Outcome, Round, Session};
pub use summary::Summary;

/// The constraint `--constrain` sends to a server of `dialect`: TAD's GBNF where the
/// server reads a grammar, the YAML form's JSON Schema on OpenAI.
pub fn constraint(dialect: Dialect, vocabulary: &Vocabulary, modules: &[String]) -> Constraint {
    let header = "TAD, as tadslc grammar prints it";
    match dialect {
        Dialect::OpenAi => Constraint::JsonSchema(tad_grammar::json_schema(vocabulary, header)),
        _ => Constraint::Gbnf(tad_grammar::export(tad_grammar::Format::Gbnf, vocabulary, modules, header)),
    }
}

/// The in-context example of the describe prompt: TrafficAlign's first translation example.
const EXAMPLE: &str = include_str!("../../../examples/paper/nl_to_dsl_example_1.tad");

/// The translate prompt's worked examples, written for it (not from the benchmark): each a
/// program whose `source.description` is what it translates.
const TRANSLATE_EXAMPLES: &[&str] = &[
    include_str!("../prompts/examples/junction_at_dusk.tad"),
    include_str!("../prompts/examples/country_road_at_dawn.tad"),
    include_str!("../prompts/examples/highway_merge.tad"),
];

/// The describe prompt's example: its description and its program.
pub fn prompt_example() -> (String, String) {
    example_parts(EXAMPLE)
}

/// The comment line that opens a translation: the road users the description names
/// besides the ego, listed before the program is written so that each gets one group. The
/// examples show it; it is dropped from the answer with the other comment lines.
const ROAD_USERS: &str = "// road users:";

/// An example's description and its program (without `source` and comments, but for its
/// list of road users, which opens it).
fn example_parts(text: &str) -> (String, String) {
    let (module, _) = tad_syntax::analyze(text);
    let description = module
        .scenario
        .as_ref()
        .and_then(|s| s.attr("source", "description"))
        .and_then(|a| match a.value.given() {
            Some(Val::Text(t)) => Some(t.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let mut program: String = text.lines().filter(|l| l.starts_with(ROAD_USERS)).map(|l| format!("{l}\n")).collect();
    program.push_str(&with_provenance(text, &Provenance::default()));
    (description.trim_end().to_string(), program.trim().to_string())
}

/// A truth as a translation answers: the line listing its road users (its groups' names,
/// `none` without groups), then the program without `source` and comments.
pub fn translation_answer(truth: &str) -> String {
    let (module, _) = tad_syntax::analyze(truth);
    let names: Vec<String> =
        module.scenario.iter().flat_map(|s| &s.actors).map(|g| g.name.text.replace('_', " ")).collect();
    let users = if names.is_empty() { "none".to_string() } else { names.join("; ") };
    format!("{ROAD_USERS} {users}\n{}", with_provenance(truth, &Provenance::default()).trim())
}

/// The translate prompt's examples, as the model reads them: each description, then its
/// program in a code block.
pub fn translate_examples() -> String {
    let shown = TRANSLATE_EXAMPLES.iter().map(|text| {
        let (description, program) = example_parts(text);
        format!("Description:\n{description}\n\nProgram:\n```tad\n{program}\n```")
    });
    shown.collect::<Vec<_>>().join("\n\n")
}

/// The first request of a translation: the prompt with the vocabulary of the checker's
/// region, the worked examples, and the description.
pub fn translate_messages(description: &str, checker: &Checker) -> Vec<tad_llm::Message> {
    let scope = tad_grammar::scope(checker.options.region.as_deref()).or_else(|_| tad_grammar::scope(None));
    let vocabulary = scope.map(|(v, _)| prompt::vocabulary(&v)).unwrap_or_default();
    prompt::TRANSLATE.messages(&[
        ("vocabulary", &vocabulary),
        ("examples", &translate_examples()),
        ("description", description),
    ])
}

/// A declaration's `description` text.
pub fn description(vocabulary: &Vocabulary, kind: &str, name: &str) -> Option<String> {
    let entry = vocabulary.get(kind, name)?;
    match entry.declaration.attr("description")?.value.given()? {
        Val::Text(t) => Some(t.clone()),
        _ => None,
    }
}

/// Where a program came from, written into its file.
#[derive(Clone, Debug, Default)]
pub struct Provenance {
    /// Comment lines (without `//`).
    pub comments: Vec<String>,
    pub video: Option<String>,
    pub time_s: Option<f64>,
    pub frame: Option<u64>,
    pub region: Option<String>,
    pub description: Option<String>,
}

/// `program` (canonical TAD) with its provenance: comment lines on top and a `source`
/// section written by us (the model's own is dropped), then formatted.
pub fn with_provenance(program: &str, provenance: &Provenance) -> String {
    let mut lines: Vec<&str> = program.lines().collect();
    // drop the model's source section and comment lines
    if let Some(start) = lines.iter().position(|l| *l == "  source {")
        && let Some(len) = lines[start..].iter().position(|l| *l == "  }")
    {
        lines.drain(start..=start + len);
    }
    lines.retain(|l| !l.trim_start().starts_with("//"));
    let mut source = Vec::new();
    if let Some(video) = &provenance.video {
        source.push(format!("    video: {}", tad_syntax::lexer::string_literal(video)));
    }
    if let Some(t) = provenance.time_s {
        source.push(format!("    time: {} s", tad_number(t)));
    }
    if let Some(frame) = provenance.frame {
        source.push(format!("    frame: {frame}"));
    }
    if let Some(region) = &provenance.region {
        source.push(format!("    region: {region}"));
    }
    if let Some(description) = &provenance.description {
        source.push("    description: \"\"\"".into());
        for line in text_block(description).lines() {
            source.push(if line.is_empty() { String::new() } else { format!("      {line}") });
        }
        source.push("    \"\"\"".into());
    }
    let mut out = String::new();
    for c in &provenance.comments {
        let c: String = c.chars().filter(|c| !c.is_control()).collect();
        out.push_str(&format!("// {c}\n"));
    }
    if !provenance.comments.is_empty() {
        out.push('\n');
    }
    for line in lines {
        out.push_str(line);
        out.push('\n');
        if line.starts_with("scenario ") && line.ends_with('{') && !source.is_empty() {
            out.push_str("  source {\n");
            for s in &source {
                out.push_str(s);
                out.push('\n');
            }
            out.push_str("  }\n");
        }
    }
    tad_syntax::format::format(&out).unwrap_or(out)
}

fn tad_number(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e12 { format!("{}", x as i64) } else { format!("{x:.3}") }
}

/// Untrusted text as a text block's content: no `"""`, no control characters but line
/// breaks, wrapped at 88 columns.
fn text_block(text: &str) -> String {
    let clean: String =
        text.replace("\"\"\"", "\"'\"").chars().filter(|c| !c.is_control() || *c == '\n').collect::<String>();
    let mut out = Vec::new();
    for paragraph in clean.lines() {
        let mut line = String::new();
        for word in paragraph.split_whitespace() {
            if !line.is_empty() && line.len() + word.len() + 1 > 88 {
                out.push(std::mem::take(&mut line));
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
        out.push(line);
    }
    let text = out.join("\n");
    // a text block cannot end in a quote that would run into its closing `"""`
    text.trim_end_matches('"').trim().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn provenance_replaces_the_models_source_and_survives_hostile_text() {
        let program =
            "// model says hi\nscenario a {\n  source {\n    video: \"evil.mp4\"\n  }\n  ego {\n    lane: 1\n  }\n}\n";
        let p = Provenance {
            comments: vec!["made by a test\u{7}".into()],
            video: Some("dash \"cam\".mp4".into()),
            time_s: Some(15.0),
            region: Some("yellowstone".into()),
            description: Some("A bison.\n\"\"\" } scenario evil {\nEnd \"".into()),
            ..Default::default()
        };
        let out = with_provenance(program, &p);
        assert!(
            out.starts_with(
                "// made by a test\n\nscenario a {\n  source {\n    video: \"dash \\\"cam\\\".mp4\"\n    time: 15 s\n"
            ),
            "{out}"
        );
        assert!(!out.contains("evil.mp4") && !out.contains("model says hi"));
        let (module, diagnostics) = tad_syntax::analyze(&out);
        assert!(diagnostics.is_empty(), "{out}\n{diagnostics:?}");
        assert_eq!(module.scenario.unwrap().name.map(|n| n.text).as_deref(), Some("a"));
    }

    #[test]
    fn the_translate_examples_are_complete_as_the_model_reads_them() {
        let checker = Checker::default();
        for text in TRANSLATE_EXAMPLES {
            let (description, program) = example_parts(text);
            assert!(description.len() > 100, "{text}");
            let verdict = checker.check(&program, tad_db::Language::Tad);
            assert_eq!(verdict.class, tad_check::Class::Complete, "{program}\n{:?}", verdict.lines);
            // a speed keeps the description's unit, so mph is only warned about (W0402)
            assert!(verdict.lines.iter().all(|l| l.starts_with("W0402")), "{:?}", verdict.lines);
            // the program opens with its road users, one group each
            let users = program.lines().next().and_then(|l| l.strip_prefix(ROAD_USERS)).expect(&program);
            assert_eq!(users.split(';').count(), program.matches("\n  actor ").count(), "{program}");
        }
        let shown = translate_examples();
        assert_eq!(shown.matches("```tad\n").count(), TRANSLATE_EXAMPLES.len());
        assert!(shown.contains("\nuse rural\n\nscenario country_road_at_dawn {"), "{shown}");
        assert!(!shown.contains("source {") && !shown.contains("worked example"), "{shown}");
        assert_eq!(shown.matches("//").count(), TRANSLATE_EXAMPLES.len(), "{shown}");
    }
}
