//! `tadslc man [-o DIR]`: the manual pages (`clap_mangen`), generated from the command
//! line's own definition, so they never disagree with it, then EXIT STATUS (the one
//! sentence of [`crate::EXIT_STATUSES`]) and EXAMPLES (command lines a user can paste,
//! [`EXAMPLES`]).

use std::path::PathBuf;

use crate::output::CliError;
use crate::{Status, errln, plural};

/// `tadslc man`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Write `tadslc.1` and a page per subcommand (`tadslc-check.1`, ...) into this
    /// directory instead of printing `tadslc.1`
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Command lines for each page's EXAMPLES (by the subcommand's name; `tadslc` for the
/// main page). Every one runs as written from the repository's root.
pub const EXAMPLES: &[(&str, &[&str])] = &[
    ("tadslc", &["tadslc check examples/", "tadslc eval", "tadslc run examples/safety/ --ego idm,naive --seeds 0..3"]),
    (
        "check",
        &[
            "tadslc check examples/",
            "tadslc check --format json --region yellowstone scene.tad",
            "tadslc check --format sarif examples/ > check.sarif",
        ],
    ),
    ("fmt", &["tadslc fmt examples/", "tadslc fmt --check examples/"]),
    (
        "build",
        &[
            "tadslc build examples/safety/right_turn.tad -o out/",
            "tadslc build --target bytecode examples/safety/ -o out/",
            "tadslc build --target openscenario examples/safety/right_turn.tad -o out/",
        ],
    ),
    ("import", &["tadslc import answer.yaml -o scene.tad"]),
    ("export", &["tadslc export examples/safety/right_turn.tad -o right_turn.yaml"]),
    (
        "run",
        &[
            "tadslc run examples/safety/ --ego idm,naive,sac --seeds 0..4",
            "tadslc run examples/safety/right_turn.tad --ego naive --render right_turn.png",
        ],
    ),
    ("search", &["tadslc search examples/safety/ --ego sac -o searched/"]),
    ("eval", &["tadslc eval", "tadslc eval --region los_angeles --egos ppo,sac,td3 --finetune 500"]),
    ("merge", &["tadslc merge results/"]),
    ("disasm", &["tadslc disasm out/right_turn.tadc"]),
    ("lsp", &["tadslc lsp"]),
    ("explain", &["tadslc explain E0203", "tadslc explain"]),
    (
        "bench",
        &[
            "tadslc bench",
            "tadslc bench --runtime --no-scenic",
            "tadslc bench --translate --model local:qwen2.5-coder-0.5b",
        ],
    ),
    (
        "translate",
        &[
            "tadslc translate --text \"A cyclist crosses in front of the ego at a red light.\"",
            "tadslc translate tests/llm/descriptions/ -o translated/",
        ],
    ),
    (
        "synth",
        &[
            "TADSL_LLM_BASE_URL=http://127.0.0.1:8080/v1 tadslc synth --video drive.mp4 --region los_angeles --out scenes/",
        ],
    ),
    ("gen", &["tadslc gen --region yellowstone -n 10 --out generated/"]),
    ("stats", &["tadslc stats examples/"]),
    ("compare", &["tadslc compare examples/regions/ generated/"]),
    ("fit", &["tadslc fit examples/regions/ -o fitted.json"]),
    ("sft-export", &["tadslc sft-export examples/regions/ -o sft/"]),
    ("finetune", &["tadslc finetune sft/ -o adapter/"]),
    ("train-ego", &["tadslc train-ego --algo td3 examples/safety/ -o td3.safetensors"]),
    ("model", &["tadslc model list", "tadslc model fetch qwen2.5-coder-0.5b"]),
    ("grammar", &["tadslc grammar --format gbnf > tad.gbnf"]),
    ("completions", &["tadslc completions bash > /etc/bash_completion.d/tadslc"]),
    ("man", &["tadslc man -o man/"]),
];

/// Print `tadslc.1`, or write it and a page per subcommand into the directory;
/// `command` is the command line's definition.
pub fn run(args: &Args, command: clap::Command) -> Result<Status, CliError> {
    let mut command = command.disable_help_subcommand(true);
    command.build();
    let Some(dir) = args.output.as_deref() else {
        let page =
            page(&command, "tadslc").map_err(|e| CliError::usage(format!("cannot render the manual page: {e}")))?;
        crate::output::out_bytes(&page)?;
        return Ok(Status::Ok);
    };
    std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
    let written = write_pages(&command, "tadslc", dir)
        .map_err(|e| CliError::usage(format!("cannot write the manual pages into `{}`: {e}", dir.display())))?;
    errln!("wrote {} into `{}`", plural(written, "manual page"), dir.display())?;
    Ok(Status::Ok)
}

/// `command`'s page and its visible subcommands' pages, into `dir`; how many.
fn write_pages(command: &clap::Command, name: &str, dir: &std::path::Path) -> std::io::Result<usize> {
    let mut written = 0;
    for sub in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        written += write_pages(sub, sub.get_name(), dir)?;
    }
    let file = dir.join(clap_mangen::Man::new(command.clone()).get_filename());
    std::fs::write(file, page(command, name)?)?;
    Ok(written + 1)
}

/// One page: clap_mangen's sections, then EXIT STATUS and EXAMPLES.
fn page(command: &clap::Command, name: &str) -> std::io::Result<Vec<u8>> {
    let mut page = Vec::new();
    clap_mangen::Man::new(command.clone()).render(&mut page)?;
    page.extend_from_slice(format!(".SH \"EXIT STATUS\"\n{}\n", roff(crate::EXIT_STATUSES)).as_bytes());
    if let Some((_, lines)) = EXAMPLES.iter().find(|(page, _)| *page == name) {
        page.extend_from_slice(b".SH EXAMPLES\n");
        for line in *lines {
            page.extend_from_slice(format!(".PP\n.nf\n{}\n.fi\n", roff(line)).as_bytes());
        }
    }
    Ok(page)
}

/// Text as roff reads it literally: backslashes and hyphens escaped, a leading dot or
/// quote kept from being a request.
fn roff(text: &str) -> String {
    let escaped = text.replace('\\', "\\e").replace('-', "\\-");
    if escaped.starts_with(['.', '\'']) { format!("\\&{escaped}") } else { escaped }
}
