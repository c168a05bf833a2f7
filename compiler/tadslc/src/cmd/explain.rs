//! `tadslc explain CODE`: print a code's reference text from `spec/diagnostics.md`.
//!
//! A code is found by its number, whatever its letter and case: `E0203`, `e203`, `203`
//! and `0203` are E0203; `600`, `w600` and `E0600` are W0600. Where an error and a
//! warning share a number, the letter given chooses, and a bare number means the error.

use crate::output::CliError;
use crate::{Status, errln, outln};
use tad_diagnostics::Code;

/// `tadslc explain`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The code, or its number whatever its letter (`203`, `w600`); omit it to list
    /// every code
    pub code: Option<String>,
}

pub fn run(args: &Args) -> Result<Status, CliError> {
    let Some(text) = args.code.as_deref() else {
        for code in Code::ALL {
            outln!("{code}  {}", code.title())?;
        }
        return Ok(Status::Ok);
    };
    let code = resolve(text).map_err(|nearest| {
        let hint = if nearest.is_empty() {
            "note: a code is a number such as `203`, with or without its letter (`E0203`)".to_string()
        } else {
            let names: Vec<String> = nearest.iter().map(|c| format!("{c} ({})", c.title())).collect();
            format!("help: the closest codes are {}", names.join(", "))
        };
        CliError::usage(format!(
            "`{text}` is not a TADSL diagnostic code\n{hint}\nnote: `tadslc explain` without a code lists them all"
        ))
    })?;
    outln!("{}", code.reference().trim_start_matches("## "))?;
    if let Some(twin) = twin(code) {
        errln!("note: {twin} ({}) has the same number: `tadslc explain {twin}`", twin.title())?;
    }
    Ok(Status::Ok)
}

/// The number of a code: 203 for E0203.
fn number(code: Code) -> u32 {
    code.as_str()[1..].parse().unwrap_or(u32::MAX)
}

/// The letter a code is written with, and its number, if `text` is one: `[EeWw]?digits`.
fn split(text: &str) -> Option<(Option<char>, u32)> {
    let text = text.trim();
    let (letter, digits) = match text.chars().next()? {
        c @ ('e' | 'E' | 'w' | 'W') => (Some(c.to_ascii_uppercase()), &text[1..]),
        _ => (None, text),
    };
    if digits.is_empty() || digits.len() > 6 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((letter, digits.parse().ok()?))
}

/// The code `text` names, or the codes with the closest numbers (none if `text` is not
/// a number at all).
pub fn resolve(text: &str) -> Result<Code, Vec<Code>> {
    let Some((letter, n)) = split(text) else {
        return Err(Vec::new());
    };
    let same: Vec<Code> = Code::ALL.iter().copied().filter(|c| number(*c) == n).collect();
    let preferred = letter.unwrap_or('E');
    if let Some(code) = same.iter().find(|c| c.as_str().starts_with(preferred)).or(same.first()) {
        return Ok(*code);
    }
    let mut nearest: Vec<Code> = Code::ALL.to_vec();
    // closest number first; among as close, the letter given, then the smaller number
    nearest.sort_by_key(|c| (number(*c).abs_diff(n), !c.as_str().starts_with(preferred), number(*c)));
    nearest.truncate(3);
    nearest.sort();
    Err(nearest)
}

/// The code of the other severity with the same number, if there is one.
fn twin(code: Code) -> Option<Code> {
    Code::ALL.iter().copied().find(|c| *c != code && number(*c) == number(code))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_resolve_whatever_the_letter() {
        assert_eq!(resolve("E0203"), Ok(Code::E0203));
        assert_eq!(resolve("e203"), Ok(Code::E0203));
        assert_eq!(resolve("203"), Ok(Code::E0203));
        assert_eq!(resolve("600"), Ok(Code::W0600));
        assert_eq!(resolve("w600"), Ok(Code::W0600));
        assert_eq!(resolve("E0600"), Ok(Code::W0600));
        assert_eq!(resolve("w0200"), Ok(Code::W0200));
        assert_eq!(resolve("0200"), Ok(Code::E0200));
        assert_eq!(resolve("x203"), Err(Vec::new()));
        assert_eq!(resolve(""), Err(Vec::new()));
        let nearest = resolve("E0299").unwrap_err();
        assert_eq!(nearest.len(), 3);
        assert_eq!(nearest[0], Code::E0300);
        assert!(nearest.iter().all(|c| (200..=400).contains(&number(*c))), "{nearest:?}");
    }
}
