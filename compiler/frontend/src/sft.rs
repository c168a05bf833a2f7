//! Supervised fine-tuning data, in TRL's two forms: conversational `messages.jsonl` and
//! prompt/completion `prompt_completion.jsonl`. From a corpus, each scenario (the bare
//! program, as the grammar-constrained decoder writes it, no code fence) is the answer to
//! the tuned generation prompt (`generate-tuned.v1`); from descriptions with their truths,
//! each truth is the answer to the request `translate` sends for its description.

use std::collections::BTreeMap;

use crate::Checker;

/// One scenario to export: its name, TAD text and the region it states.
pub struct Example<'a> {
    pub name: &'a str,
    pub tad: &'a str,
    pub region: Option<&'a str>,
}

/// The two files' texts, the examples per region, and the scenarios skipped for stating
/// no region.
#[derive(Default)]
pub struct Export {
    pub messages: String,
    pub prompt_completion: String,
    pub regions: BTreeMap<String, usize>,
    pub no_region: Vec<String>,
}

/// A translation to learn: a description and its hand-written truth (TAD).
pub struct Translation<'a> {
    pub description: &'a str,
    pub truth: &'a str,
}

/// The translations as SFT data: each the messages `translate` sends (the system message
/// with `checker`'s vocabulary and the worked examples, then the description), answered as
/// the constrained decoder writes a translation: the line listing the road users (the
/// truth's group names), then the program without `source` and comments.
pub fn export_translations<'a>(pairs: impl IntoIterator<Item = Translation<'a>>, checker: &Checker) -> Export {
    let mut out = Export::default();
    for pair in pairs {
        let prompt: Vec<serde_json::Value> =
            crate::translate_messages(pair.description.trim(), checker).iter().map(json).collect();
        out.push(prompt, crate::translation_answer(pair.truth));
        *out.regions.entry("translate".into()).or_insert(0) += 1;
    }
    out
}

fn json(m: &tad_llm::Message) -> serde_json::Value {
    serde_json::json!({"role": m.role.name(), "content": m.plain()})
}

impl Export {
    /// One example in both forms.
    fn push(&mut self, prompt: Vec<serde_json::Value>, answer: String) {
        let assistant = serde_json::json!({"role": "assistant", "content": answer});
        let mut all = prompt.clone();
        all.push(assistant.clone());
        self.messages.push_str(&serde_json::json!({ "messages": all }).to_string());
        self.messages.push('\n');
        self.prompt_completion
            .push_str(&serde_json::json!({ "prompt": prompt, "completion": [assistant] }).to_string());
        self.prompt_completion.push('\n');
    }
}

/// The examples as SFT data; `region` overrides what each scenario states.
pub fn export<'a>(examples: impl IntoIterator<Item = Example<'a>>, region: Option<&str>) -> Export {
    let mut out = Export::default();
    for (i, example) in examples.into_iter().enumerate() {
        let Some(r) = region.or(example.region) else {
            out.no_region.push(example.name.to_string());
            continue;
        };
        *out.regions.entry(r.to_string()).or_insert(0) += 1;
        let answer = crate::with_provenance(
            example.tad,
            &crate::Provenance { region: Some(r.to_string()), ..Default::default() },
        );
        let prompt: Vec<serde_json::Value> = crate::generate::tuned_messages(r, i).iter().map(json).collect();
        out.push(prompt, answer);
    }
    out
}
