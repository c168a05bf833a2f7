//! A small XML writer: elements with attributes in the order given, two-space indentation,
//! text escaped by `tad_base::xml_escape`, and numbers written the same way everywhere ([`num`]).

use std::fmt::Write as _;

use tad_base::xml_escape;

/// A number as the files write it: at most six decimals, no trailing zeros, never `-0`.
pub fn num(v: f64) -> String {
    if !v.is_finite() {
        return "0".into();
    }
    let mut s = format!("{v:.6}");
    while s.ends_with('0') {
        s.pop();
    }
    if s.ends_with('.') {
        s.pop();
    }
    if s == "-0" { "0".into() } else { s }
}

#[derive(Default)]
pub struct Xml {
    out: String,
    open: Vec<&'static str>,
}

impl Xml {
    pub fn new() -> Xml {
        let mut x = Xml::default();
        x.out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        x
    }

    fn indent(&mut self) {
        for _ in 0..self.open.len() {
            self.out.push_str("  ");
        }
    }

    fn tag(&mut self, name: &str, attrs: &[(&str, String)]) {
        self.indent();
        let _ = write!(self.out, "<{name}");
        for (k, v) in attrs {
            let _ = write!(self.out, " {k}=\"{}\"", xml_escape(v));
        }
    }

    /// `<name a="…">`, closed by [`Xml::close`].
    pub fn open(&mut self, name: &'static str, attrs: &[(&str, String)]) {
        self.tag(name, attrs);
        self.out.push_str(">\n");
        self.open.push(name);
    }

    /// `<name a="…"/>`.
    pub fn empty(&mut self, name: &str, attrs: &[(&str, String)]) {
        self.tag(name, attrs);
        self.out.push_str("/>\n");
    }

    /// `<name>text</name>`.
    pub fn text(&mut self, name: &str, text: &str) {
        self.indent();
        let _ = writeln!(self.out, "<{name}>{}</{name}>", xml_escape(text));
    }

    /// `<!-- text -->` (a `--` inside becomes `- -`).
    pub fn comment(&mut self, text: &str) {
        self.indent();
        let _ = writeln!(self.out, "<!-- {} -->", xml_escape(text).replace("--", "- -"));
    }

    pub fn close(&mut self) {
        if let Some(name) = self.open.pop() {
            self.indent();
            let _ = writeln!(self.out, "</{name}>");
        }
    }

    pub fn finish(mut self) -> String {
        while !self.open.is_empty() {
            self.close();
        }
        self.out
    }
}

/// Attributes from pairs of a name and anything printable.
#[macro_export]
macro_rules! attrs {
    ($($k:literal => $v:expr),* $(,)?) => { &[$(($k, $v.to_string())),*] };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_text_is_escaped() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(-0.0000001), "0");
        assert_eq!(num(3.25), "3.25");
        assert_eq!(num(f64::NAN), "0");
        let mut x = Xml::new();
        x.open("a", &[("b", "<\"&'>".into())]);
        x.comment("a -- b");
        x.empty("c", &[]);
        let s = x.finish();
        assert!(s.contains("<a b=\"&lt;&quot;&amp;'&gt;\">"), "{s}");
        assert!(s.contains("<!-- a - - b -->") && s.contains("  <c/>") && s.ends_with("</a>\n"), "{s}");
    }
}
