//! `tadslc grammar`: TAD's grammar for constrained decoding, the vocabulary as closed
//! sets: GBNF (llama.cpp, XGrammar), Lark (llguidance) or the YAML form's JSON Schema.

use crate::output::CliError;
use crate::{Status, out};

/// `tadslc grammar`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The notation
    #[arg(long, value_enum, default_value_t = GrammarFormat::Gbnf)]
    pub format: GrammarFormat,
    /// Only the names a scenario of this region sees (default: every standard module)
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: Option<String>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum GrammarFormat {
    Gbnf,
    Lark,
    JsonSchema,
}

impl From<GrammarFormat> for tad_grammar::Format {
    fn from(format: GrammarFormat) -> tad_grammar::Format {
        match format {
            GrammarFormat::Gbnf => tad_grammar::Format::Gbnf,
            GrammarFormat::Lark => tad_grammar::Format::Lark,
            GrammarFormat::JsonSchema => tad_grammar::Format::JsonSchema,
        }
    }
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    let (format, region) = (tad_grammar::Format::from(args.format), args.region.as_deref());
    let (vocabulary, modules) = tad_grammar::scope(region).map_err(CliError::usage)?;
    let header = format!(
        "TAD {} grammar from tadslc {} ({}); regenerate with `tadslc grammar --format {}{}`",
        format.name(),
        env!("CARGO_PKG_VERSION"),
        region.map(|r| format!("region {r}")).unwrap_or_else(|| "every standard module".into()),
        format.name(),
        region.map(|r| format!(" --region {r}")).unwrap_or_default()
    );
    out!("{}", tad_grammar::export(format, &vocabulary, &modules, &header))?;
    Ok(Status::Ok)
}
