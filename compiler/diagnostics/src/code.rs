//! Stable diagnostic codes.
//!
//! `E` codes are errors, `W` codes warnings (or hints: W0401, an alias, is only a
//! different spelling). Hundreds group the phase: 0xx lexical, 1xx
//! syntax, 2xx structure (sections, fields, values). A code, once released, keeps its
//! meaning forever; retired codes stay in the list. The title and explanation of each code
//! live in `spec/diagnostics.md` (one `## CODE title` section each), embedded here.

use crate::Severity;
use serde::{Serialize, Serializer};

const REFERENCE: &str = include_str!("../../../spec/diagnostics.md");

macro_rules! codes {
    ($($code:ident => $severity:ident,)*) => {
        /// A stable diagnostic code.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Code { $($code,)* }

        impl Code {
            pub const ALL: &'static [Code] = &[$(Code::$code,)*];

            pub fn as_str(self) -> &'static str {
                match self { $(Code::$code => stringify!($code),)* }
            }

            /// The severity a diagnostic with this code has unless a profile changes it.
            pub fn severity(self) -> Severity {
                match self { $(Code::$code => Severity::$severity,)* }
            }
        }
    };
}

codes! {
    E0001 => Error,
    E0002 => Error,
    E0003 => Error,
    E0004 => Error,
    E0005 => Error,
    E0006 => Error,
    E0007 => Error,
    E0100 => Error,
    E0101 => Error,
    E0102 => Error,
    E0103 => Error,
    E0200 => Error,
    E0201 => Error,
    E0202 => Error,
    E0203 => Error,
    E0204 => Error,
    E0205 => Error,
    E0206 => Error,
    E0207 => Error,
    E0208 => Error,
    E0209 => Error,
    E0210 => Error,
    E0211 => Error,
    E0212 => Error,
    E0213 => Error,
    E0214 => Error,
    E0215 => Error,
    E0216 => Error,
    E0217 => Error,
    // YAML import (3xx): add codes below this line
    E0300 => Error,
    E0301 => Error,
    E0302 => Error,
    E0303 => Error,
    E0304 => Error,
    W0300 => Warning,
    W0301 => Warning,
    W0302 => Warning,
    W0303 => Warning,
    // end of YAML codes
    // names and vocabulary (4xx), semantics (5xx), completeness (6xx)
    E0400 => Error,
    E0402 => Error,
    E0403 => Error,
    E0404 => Error,
    E0405 => Error,
    E0500 => Error,
    E0501 => Error,
    E0502 => Error,
    E0503 => Error,
    E0506 => Error,
    E0509 => Error,
    E0510 => Error,
    E0511 => Error,
    W0200 => Warning,
    W0201 => Warning,
    W0401 => Hint,
    W0402 => Warning,
    W0403 => Warning,
    W0504 => Warning,
    W0505 => Warning,
    W0507 => Warning,
    W0508 => Warning,
    W0512 => Warning,
    W0513 => Warning,
    W0600 => Warning,
    W0601 => Warning,
    // Scenic backend (7xx): add codes below this line
    E0700 => Error,
    W0700 => Warning,
    W0701 => Warning,
    W0702 => Warning,
    W0703 => Warning,
    W0704 => Warning,
    W0705 => Warning,
    W0706 => Warning,
    W0707 => Warning,
    // end of Scenic codes
    // OpenSCENARIO backend
    W0710 => Warning,
    W0711 => Warning,
    W0712 => Warning,
    W0720 => Warning,
}

impl Code {
    /// Parse `E0203` (case-insensitive; `0203` and `203` mean the error code).
    pub fn parse(text: &str) -> Option<Code> {
        let text = text.trim().to_ascii_uppercase();
        let full = if text.starts_with('E') || text.starts_with('W') { text } else { format!("E{:0>4}", text) };
        Code::ALL.iter().copied().find(|c| c.as_str() == full)
    }

    /// The section of `spec/diagnostics.md` for this code, heading included.
    pub fn reference(self) -> &'static str {
        let heading = format!("## {}", self.as_str());
        let Some(start) = REFERENCE.find(&heading) else {
            return "";
        };
        let rest = &REFERENCE[start..];
        let body = &rest[heading.len()..];
        let end =
            ["\n## ", "\n<!--"].iter().filter_map(|m| body.find(m)).min().map_or(rest.len(), |i| i + heading.len() + 1);
        rest[..end].trim_end()
    }

    /// The one-line title of this code, e.g. "unknown field".
    pub fn title(self) -> &'static str {
        let reference = self.reference();
        let first = reference.lines().next().unwrap_or("");
        first.get(3 + self.as_str().len()..).unwrap_or("").trim()
    }

    /// The reference text without its heading.
    pub fn explanation(self) -> &'static str {
        let reference = self.reference();
        reference.split_once('\n').map_or("", |(_, body)| body.trim())
    }
}

impl std::fmt::Display for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Serialize for Code {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_code_has_a_titled_reference_section() {
        for code in Code::ALL {
            assert!(!code.title().is_empty(), "{code} has no `## {code} title` section in spec/diagnostics.md");
            assert!(!code.explanation().is_empty(), "{code} has no explanation");
            // `E` errors; `W` warnings, or hints for a mere difference of spelling
            let letter_fits = match code.severity() {
                Severity::Error => code.as_str().starts_with('E'),
                Severity::Warning | Severity::Hint => code.as_str().starts_with('W'),
            };
            assert!(letter_fits, "{code}: the letter must match the severity");
        }
    }

    #[test]
    fn every_reference_section_names_a_code() {
        for line in REFERENCE.lines().filter(|l| l.starts_with("## ")) {
            let name = line[3..].split_whitespace().next().unwrap_or("");
            assert!(Code::parse(name).is_some_and(|c| c.as_str() == name), "section `{line}` names no code");
        }
    }

    #[test]
    fn parse_accepts_short_forms() {
        assert_eq!(Code::parse("e0203"), Some(Code::E0203));
        assert_eq!(Code::parse("203"), Some(Code::E0203));
        assert_eq!(Code::parse("W0200"), Some(Code::W0200));
        assert_eq!(Code::parse("E9999"), None);
    }
}
