//! TAD's grammar for constrained decoding, in the notations servers and decoders read.
//!
//! ```text
//! schema (sections, fields, value kinds) ─┐
//! vocabulary (declared names, by kind) ───┴─▶ ir::Grammar ──▶ GBNF (llama.cpp, XGrammar: vLLM, SGLang)
//!                                                         └─▶ Lark (llguidance: vLLM guidance, mistral.rs, OpenAI grammars)
//! schema + tad-yaml's key table + vocabulary ───────────────▶ JSON Schema of the YAML form
//! ```
//!
//! Nothing here lists a field or a name: the TAD grammar is generated from
//! `tad_syntax::schema` and the vocabulary in scope (the standard library and the region's
//! module), the JSON Schema from `tad_yaml::dialect::KEYS`. Pure, no I/O.

pub mod ir;
mod json;
mod tad;

use tad_check::Vocabulary;

pub use json::json_schema;

/// The vocabulary a model may write for `region` (the prelude and the region's module), or
/// for any region (every standard module), and the modules a `use` line may name.
pub fn scope(region: Option<&str>) -> Result<(Vocabulary, Vec<String>), String> {
    let modules = match region {
        None => tad_db::standard_modules(),
        Some(region) => {
            let region = tad_db::region(region)?;
            tad_db::region_module(&tad_db::vocabulary_of(&[]), &region).into_iter().collect()
        }
    };
    Ok((tad_db::vocabulary_of(&modules), modules))
}

/// The notations `tadslc grammar` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Gbnf,
    Lark,
    JsonSchema,
}

impl Format {
    pub const ALL: &[Format] = &[Format::Gbnf, Format::Lark, Format::JsonSchema];

    pub fn name(self) -> &'static str {
        match self {
            Format::Gbnf => "gbnf",
            Format::Lark => "lark",
            Format::JsonSchema => "json-schema",
        }
    }
}

/// TAD's grammar over `vocabulary`, with `use` lines naming `modules`.
pub fn grammar(vocabulary: &Vocabulary, modules: &[String]) -> ir::Grammar {
    tad::grammar(vocabulary, modules)
}

/// The grammar or schema in `format`, with a header naming what it was made from.
pub fn export(format: Format, vocabulary: &Vocabulary, modules: &[String], header: &str) -> String {
    match format {
        Format::Gbnf => grammar(vocabulary, modules).gbnf(header),
        Format::Lark => grammar(vocabulary, modules).lark(header),
        Format::JsonSchema => {
            let mut text = serde_json::to_string_pretty(&json_schema(vocabulary, header)).unwrap_or_default();
            text.push('\n');
            text
        }
    }
}
