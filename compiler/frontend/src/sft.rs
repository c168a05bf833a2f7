//! Supervised fine-tuning data from a corpus: each scenario (the bare program, as the
//! grammar-constrained decoder writes it, no code fence) the answer to the tuned
//! generation prompt (`generate-tuned.v1`), in TRL's two forms: conversational
//! `messages.jsonl` and prompt/completion `prompt_completion.jsonl`.

use std::collections::BTreeMap;

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
        let json = |m: &tad_llm::Message| serde_json::json!({"role": m.role.name(), "content": m.plain()});
        let prompt: Vec<serde_json::Value> = crate::generate::tuned_messages(r, i).iter().map(json).collect();
        let assistant = serde_json::json!({"role": "assistant", "content": answer});
        let mut all = prompt.clone();
        all.push(assistant.clone());
        out.messages.push_str(&serde_json::json!({ "messages": all }).to_string());
        out.messages.push('\n');
        out.prompt_completion.push_str(&serde_json::json!({ "prompt": prompt, "completion": [assistant] }).to_string());
        out.prompt_completion.push('\n');
    }
    out
}
