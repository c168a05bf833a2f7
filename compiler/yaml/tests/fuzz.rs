//! Seeded random mutations of the YAML fixtures never make the importer panic; every
//! span stays in the text, and whatever model comes out prints as TAD that checks.

mod common;
use common::*;

use tad_base::{Rng, SplitMix64};

const PIECES: &[&str] = &[
    ":",
    ": ",
    "- ",
    "\t",
    "\"",
    "'",
    "[",
    "]",
    "{",
    "}",
    "#",
    "\n",
    "None",
    "none",
    "unspecified",
    "~",
    "&a ",
    "*a",
    "!!str ",
    "|",
    ">",
    "---\n",
    "...",
    "é",
    "🚗",
    "\u{0}",
    "\r",
    "\u{85}",
    "\u{3000}",
    "\u{a0}",
    "\u{feff}",
    "\u{2028}",
    "\r\n",
    "    ",
    "  ",
    "<YAML>",
    "</YAML>",
    "```",
    "```yaml\n",
    "ego_vehicle",
    "position_target: ",
    "30 mph",
    "-1",
    "1.5",
    "99999999999999999999",
    "? ",
    "%YAML 1.2\n",
    "<<: *a\n",
    "\\",
    ",",
    "road_network:\n  - x\n",
    "actors:\n",
    "  a:\n    type: car\n",
];

fn boundary(text: &str, mut at: usize) -> usize {
    at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

fn mutate(rng: &mut SplitMix64, text: &str) -> String {
    let mut out = text.to_string();
    for _ in 0..1 + rng.below(4) {
        let len = out.len();
        match rng.below(8) {
            0 => {
                let a = boundary(&out, rng.below(len + 1));
                let b = boundary(&out, a + rng.below(40));
                out.replace_range(a..b, "");
            }
            1 | 2 => {
                let a = boundary(&out, rng.below(len + 1));
                out.insert_str(a, PIECES[rng.below(PIECES.len())]);
            }
            3 => {
                let lines: Vec<&str> = out.lines().collect();
                if !lines.is_empty() {
                    let i = rng.below(lines.len());
                    let mut v: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
                    let line = v[i].clone();
                    v.insert(rng.below(v.len() + 1), line);
                    out = v.join("\n");
                }
            }
            4 => {
                let mut v: Vec<String> = out.lines().map(str::to_string).collect();
                if v.len() > 1 {
                    let (i, j) = (rng.below(v.len()), rng.below(v.len()));
                    v.swap(i, j);
                    out = v.join("\n");
                }
            }
            5 => {
                let mut v: Vec<String> = out.lines().map(str::to_string).collect();
                if !v.is_empty() {
                    let i = rng.below(v.len());
                    let n = rng.below(6);
                    v[i] = if rng.below(2) == 0 {
                        format!("{}{}", " ".repeat(n), v[i])
                    } else {
                        v[i].trim_start().to_string()
                    };
                    out = v.join("\n");
                }
            }
            6 => {
                let a = boundary(&out, rng.below(len + 1));
                out.truncate(a);
            }
            _ => {
                let a = boundary(&out, rng.below(len + 1));
                let byte = (rng.next_u64() & 0x7f) as u8;
                out.insert(a, byte as char);
            }
        }
    }
    out
}

#[test]
fn mutated_answers_never_panic() {
    let mut inputs: Vec<String> = files(&repo().join("tests/yaml"), "yaml").iter().map(|p| read(p)).collect();
    for example in files(&repo().join("examples"), "tad").iter().take(6) {
        let src = read(example);
        let (model, _) = tad_syntax::analyze(&src);
        inputs.push(tad_yaml::export(&model, &src));
    }
    assert!(inputs.len() >= 15);
    // TAD_FUZZ_SEED / TAD_FUZZ_ROUNDS explore further than the default run
    let env = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<u64>().ok());
    let mut rng = SplitMix64(env("TAD_FUZZ_SEED").unwrap_or(0x7ad5_1c0f_fee0_2026));
    let rounds = env("TAD_FUZZ_ROUNDS").map_or(4000, |r| r as usize);
    let mut with_scenario = 0;
    for round in 0..rounds {
        let base = &inputs[round % inputs.len()];
        let text = mutate(&mut rng, base);
        let (model, diagnostics) = tad_yaml::lower(&text);
        assert_spans_valid(&text, &diagnostics);
        let _ = tad_yaml::extract(&text);
        let _ = tad_yaml::dialect(&text);
        if model.scenario.is_some() {
            with_scenario += 1;
            let tad = tad_yaml::to_tad(&model);
            let (_, again) = tad_syntax::analyze(&tad);
            assert!(errors(&again).is_empty(), "round {round}: {again:?}\n--- input\n{text}\n--- tad\n{tad}");
            let yaml = tad_yaml::export(&model, "");
            let (back, d) = tad_yaml::lower(&yaml);
            assert!(errors(&d).is_empty(), "round {round}: re-import of the export: {d:?}\n{yaml}");
            assert_eq!(tad_yaml::to_tad(&back), tad, "round {round}: export → lower\n{yaml}");
        }
    }
    assert!(with_scenario > rounds / 4, "{with_scenario}");
}
