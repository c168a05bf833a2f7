//! No input panics the lexer, parser, lowering or formatter, and formatting preserves
//! meaning. Thousands of seeded byte-level and token-level mutations of the examples and
//! UI fixtures; a failure names the seed and iteration, and saves the input.

mod common;
use tad_ir::Rng as _;
use tad_test_support::mutate::{self, Rng};

const SEED: u64 = 0x7AD5;
const BYTE_MUTATIONS: usize = 3000;
const TOKEN_MUTATIONS: usize = 3000;

fn corpus() -> Vec<String> {
    let root = common::repo();
    let mut files = common::tad_files(&root.join("examples"));
    files.extend(common::tad_files(&root.join("tests/ui")));
    let texts: Vec<String> =
        files.iter().filter_map(|p| std::fs::read(p).ok()).map(|b| String::from_utf8_lossy(&b).into_owned()).collect();
    assert!(texts.len() >= 20, "the corpus needs the examples and the UI fixtures");
    texts
}

fn codes(text: &str) -> Vec<String> {
    let (_, diagnostics) = tad_syntax::analyze(text);
    let mut codes: Vec<String> = diagnostics.iter().map(|d| d.code.to_string()).collect();
    codes.sort();
    codes
}

fn exercise(db: &mut tad_db::Database, input: &str, what: &str, iteration: usize) {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // the whole checker, with the standard library, through the database
        let file = tad_db::host::Input {
            name: "mutated.tad".into(),
            path: Some(std::env::temp_dir().join("tadsl-mutated.tad")),
            text: input.to_string(),
            invalid_utf8: None,
        };
        // one database for the whole run: each input replaces the last, as edits would
        let checked = tad_db::host::diagnose_in(db, &file);
        for d in &checked.diagnostics {
            assert!(
                d.primary.span.start <= d.primary.span.end && d.primary.span.end <= input.len(),
                "span out of range"
            );
        }
        if let Ok(formatted) = tad_syntax::format::format(input) {
            let again = tad_syntax::format::format(&formatted).expect("formatted output parses");
            assert_eq!(again, formatted, "formatting is idempotent");
            assert_eq!(
                tad_syntax::parse(input).comments.len(),
                tad_syntax::parse(&formatted).comments.len(),
                "formatting keeps every comment"
            );
            assert_eq!(codes(input), codes(&formatted), "formatting keeps the meaning");
        }
    }));
    if result.is_err() {
        let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("robustness-{what}-{iteration}.tad"));
        let _ = std::fs::write(&path, input);
        panic!("{what} mutation {iteration} (seed {SEED:#x}) failed; input saved to {}", path.display());
    }
}

#[test]
fn byte_mutations_never_panic() {
    let corpus = corpus();
    let mut rng = Rng::new(SEED);
    let mut db = tad_db::Database::new(tad_check::Options::default());
    for i in 0..BYTE_MUTATIONS {
        let source = rng.pick(&corpus).clone();
        exercise(&mut db, &mutate::bytes(&mut rng, &source), "byte", i);
    }
}

#[test]
fn token_mutations_never_panic() {
    let corpus = corpus();
    let mut rng = Rng::new(SEED ^ 1);
    let mut db = tad_db::Database::new(tad_check::Options::default());
    for i in 0..TOKEN_MUTATIONS {
        let source = rng.pick(&corpus).clone();
        exercise(&mut db, &mutate::tokens(&mut rng, &source), "token", i);
    }
}

#[test]
fn pathological_inputs() {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    for input in [
        String::new(),
        "{".repeat(10_000),
        "}".repeat(10_000),
        "[".repeat(10_000),
        format!("scenario a {{ road {{ signs: {}", "[".repeat(5_000)),
        "\"".repeat(999),
        "\"\"\"".repeat(333),
        "//".repeat(5_000),
        "a ".repeat(20_000),
        "\u{0}\u{FFFD}\u{FEFF}".repeat(100),
    ] {
        exercise(&mut db, &input, "pathological", input.len());
    }
}
