//! A grammar as data, printed in two notations: llama.cpp's GBNF (read by llama.cpp,
//! llama-cpp-python, XGrammar in vLLM and SGLang) and llguidance's Lark (llguidance, vLLM's
//! `guidance` backend, mistral.rs, OpenAI's custom-tool grammars).
//!
//! Rules are sequences, alternatives, bounded repetitions, literals and character classes.
//! A rule marked as a *terminal* is regular; Lark gets it as one UPPERCASE lexeme (a
//! regular expression), which is what keeps llguidance's lexer fast, while GBNF gets the
//! same expression as an ordinary rule.

use std::fmt::Write;

#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Lit(String),
    /// Characters in the inclusive ranges, or (negated) any character outside them.
    Class {
        ranges: Vec<(char, char)>,
        negated: bool,
    },
    Ref(String),
    Seq(Vec<Expr>),
    Alt(Vec<Expr>),
    /// `min` to `max` (unbounded when `None`) repetitions.
    Repeat(Box<Expr>, u32, Option<u32>),
}

pub fn lit(s: impl Into<String>) -> Expr {
    Expr::Lit(s.into())
}
pub fn r(name: &str) -> Expr {
    Expr::Ref(name.to_string())
}
pub fn seq(items: impl IntoIterator<Item = Expr>) -> Expr {
    Expr::Seq(items.into_iter().collect())
}
pub fn alt(items: impl IntoIterator<Item = Expr>) -> Expr {
    Expr::Alt(items.into_iter().collect())
}
pub fn opt(e: Expr) -> Expr {
    Expr::Repeat(Box::new(e), 0, Some(1))
}
pub fn star(e: Expr) -> Expr {
    Expr::Repeat(Box::new(e), 0, None)
}
pub fn rep(e: Expr, min: u32, max: u32) -> Expr {
    Expr::Repeat(Box::new(e), min, Some(max))
}
pub fn class(ranges: &[(char, char)]) -> Expr {
    Expr::Class { ranges: ranges.to_vec(), negated: false }
}
pub fn not_class(chars: &[char]) -> Expr {
    Expr::Class { ranges: chars.iter().map(|&c| (c, c)).collect(), negated: true }
}

#[derive(Clone, Debug)]
pub struct Rule {
    /// In `kebab-case`; printed as `snake_case` (Lark rules) or `UPPER_CASE` (terminals).
    pub name: String,
    pub body: Expr,
    pub terminal: bool,
}

/// Rules; the first is the start rule.
#[derive(Clone, Debug, Default)]
pub struct Grammar {
    pub rules: Vec<Rule>,
}

impl Grammar {
    pub fn rule(&mut self, name: &str, body: Expr) {
        self.rules.push(Rule { name: name.to_string(), body, terminal: false });
    }
    pub fn terminal(&mut self, name: &str, body: Expr) {
        self.rules.push(Rule { name: name.to_string(), body, terminal: true });
    }
    fn is_terminal(&self, name: &str) -> bool {
        self.rules.iter().any(|rule| rule.name == name && rule.terminal)
    }

    /// llama.cpp's GBNF; the first rule is `root`.
    pub fn gbnf(&self, header: &str) -> String {
        let mut out = comment_lines(header, "#");
        for (i, rule) in self.rules.iter().enumerate() {
            let name = if i == 0 { "root".to_string() } else { rule.name.clone() };
            let _ = writeln!(out, "{name} ::= {}", gbnf_expr(&rule.body, false));
        }
        out
    }

    /// llguidance's Lark; the first rule is `start`.
    pub fn lark(&self, header: &str) -> String {
        let mut out = comment_lines(header, "//");
        for (i, rule) in self.rules.iter().enumerate() {
            if rule.terminal {
                let _ = writeln!(out, "{}: /{}/", lark_terminal(&rule.name), regex(&rule.body, self));
            } else {
                let name = if i == 0 { "start".to_string() } else { lark_rule(&rule.name) };
                let _ = writeln!(out, "{name}: {}", self.lark_expr(&rule.body, false));
            }
        }
        out
    }

    fn lark_expr(&self, e: &Expr, nested: bool) -> String {
        match e {
            Expr::Lit(s) => json_string(s),
            Expr::Class { .. } => format!("/{}/", regex(e, self)),
            Expr::Ref(name) if self.is_terminal(name) => lark_terminal(name),
            Expr::Ref(name) => lark_rule(name),
            Expr::Seq(items) => {
                group(items.iter().map(|i| self.lark_expr(i, true)).collect::<Vec<_>>().join(" "), nested)
            }
            Expr::Alt(items) => {
                group(items.iter().map(|i| self.lark_expr(i, true)).collect::<Vec<_>>().join(" | "), nested)
            }
            Expr::Repeat(inner, min, max) => format!("{}{}", self.lark_expr(inner, true), quantifier(*min, *max)),
        }
    }
}

fn comment_lines(text: &str, marker: &str) -> String {
    text.lines().map(|l| format!("{marker} {l}\n")).collect()
}

fn group(body: String, nested: bool) -> String {
    if nested { format!("({body})") } else { body }
}

fn quantifier(min: u32, max: Option<u32>) -> String {
    match (min, max) {
        (0, Some(1)) => "?".into(),
        (0, None) => "*".into(),
        (1, None) => "+".into(),
        (m, None) => format!("{{{m},}}"),
        (m, Some(n)) if m == n => format!("{{{m}}}"),
        (m, Some(n)) => format!("{{{m},{n}}}"),
    }
}

fn gbnf_expr(e: &Expr, nested: bool) -> String {
    match e {
        Expr::Lit(s) => json_string(s),
        Expr::Class { ranges, negated } => class_text(ranges, *negated),
        Expr::Ref(name) => name.clone(),
        Expr::Seq(items) => group(items.iter().map(|i| gbnf_expr(i, true)).collect::<Vec<_>>().join(" "), nested),
        Expr::Alt(items) => group(items.iter().map(|i| gbnf_expr(i, true)).collect::<Vec<_>>().join(" | "), nested),
        Expr::Repeat(inner, min, max) => format!("{}{}", gbnf_expr(inner, true), quantifier(*min, *max)),
    }
}

/// A double-quoted literal with the escapes both notations read.
fn json_string(s: &str) -> String {
    let mut out = String::from('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn class_char(c: char) -> String {
    match c {
        '\n' => "\\n".into(),
        '\t' => "\\t".into(),
        '\r' => "\\r".into(),
        // no class here holds `^`, `-` or `/`, which the notations escape differently
        '\\' | ']' | '[' => format!("\\{c}"),
        c => c.to_string(),
    }
}

fn class_text(ranges: &[(char, char)], negated: bool) -> String {
    let mut out = String::from(if negated { "[^" } else { "[" });
    for &(a, b) in ranges {
        out.push_str(&class_char(a));
        if a != b {
            out.push('-');
            out.push_str(&class_char(b));
        }
    }
    out.push(']');
    out
}

/// A terminal's expression as a regular expression (terminals refer to terminals only).
fn regex(e: &Expr, g: &Grammar) -> String {
    match e {
        Expr::Lit(s) => s.chars().map(regex_char).collect(),
        Expr::Class { ranges, negated } => class_text(ranges, *negated),
        Expr::Ref(name) => {
            let body = g.rules.iter().find(|rule| &rule.name == name).map(|rule| &rule.body);
            body.map(|b| format!("(?:{})", regex(b, g))).unwrap_or_default()
        }
        Expr::Seq(items) => items.iter().map(|i| regex(i, g)).collect(),
        Expr::Alt(items) => format!("(?:{})", items.iter().map(|i| regex(i, g)).collect::<Vec<_>>().join("|")),
        Expr::Repeat(inner, min, max) => format!("(?:{}){}", regex(inner, g), quantifier(*min, *max)),
    }
}

fn regex_char(c: char) -> String {
    match c {
        '\n' => "\\n".into(),
        '\t' => "\\t".into(),
        '\r' => "\\r".into(),
        '/' => "\\/".into(),
        c if "\\.+*?()|[]{}^$".contains(c) => format!("\\{c}"),
        c => c.to_string(),
    }
}

fn lark_rule(name: &str) -> String {
    name.replace('-', "_")
}

fn lark_terminal(name: &str) -> String {
    name.replace('-', "_").to_ascii_uppercase()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_notations_print_the_same_structure() {
        let mut g = Grammar::default();
        g.rule("file", seq([lit("a \"b\"\n"), r("name"), opt(r("tail"))]));
        g.rule("tail", alt([lit("x"), rep(lit("y"), 1, 3)]));
        g.terminal("name", seq([class(&[('a', 'z')]), star(not_class(&['"', '\n']))]));
        assert_eq!(
            g.gbnf("TAD"),
            "# TAD\nroot ::= \"a \\\"b\\\"\\n\" name tail?\ntail ::= \"x\" | \"y\"{1,3}\nname ::= [a-z] [^\"\\n]*\n"
        );
        assert_eq!(
            g.lark("TAD"),
            "// TAD\nstart: \"a \\\"b\\\"\\n\" NAME tail?\ntail: \"x\" | \"y\"{1,3}\nNAME: /[a-z](?:[^\"\\n])*/\n"
        );
    }
}
