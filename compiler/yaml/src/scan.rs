//! Where things are in the YAML text.
//!
//! serde_norway gives values without positions, so this module reads the same text line
//! by line and records, for every mapping key and sequence item, the span of the key and
//! of its scalar value, following the indentation structure. It understands the block
//! style LLMs write (`key: value`, `key:` + indented block, `- item`, `- key: value`),
//! comments, quoted scalars, block scalars (`|`, `>`), multi-line plain scalars and flow
//! collections (`[a, b]`, `{a: 1}`), and never fails: text it does not understand is
//! skipped. The importer only uses it for spans; values come from serde_norway.

use tad_diagnostics::Span;

#[derive(Clone, Debug, Default)]
pub struct Node {
    /// The key as written, quotes removed ("" for a sequence item or the root).
    pub key: String,
    /// The key (for an item, its `-`).
    pub key_span: Span,
    /// Just after the `:` (or the `-`): where an empty value is.
    pub colon_end: usize,
    /// The scalar or flow value on the key's line(s), quotes excluded.
    pub value: Option<Span>,
    /// End of the last non-blank line that belongs to this node.
    pub end: usize,
    pub children: Vec<usize>,
    pub items: Vec<usize>,
}

#[derive(Clone, Debug)]
pub struct Tree {
    pub nodes: Vec<Node>,
}

pub const ROOT: usize = 0;

impl Tree {
    pub fn node(&self, id: usize) -> &Node {
        &self.nodes[id]
    }

    /// The child of `parent` with key `key`; else its `index`-th child.
    pub fn child(&self, parent: Option<usize>, key: &str, index: usize) -> Option<usize> {
        let parent = self.nodes.get(parent?)?;
        if let Some(&c) = parent.children.get(index).filter(|&&c| self.nodes[c].key == key) {
            return Some(c);
        }
        parent
            .children
            .iter()
            .copied()
            .find(|&c| self.nodes[c].key == key)
            .or_else(|| parent.children.get(index).copied())
    }

    pub fn item(&self, parent: Option<usize>, index: usize) -> Option<usize> {
        self.nodes.get(parent?)?.items.get(index).copied()
    }

    /// From the key to the end of the node's block.
    pub fn block(&self, id: usize) -> Span {
        let n = &self.nodes[id];
        Span::new(n.key_span.start, n.end.max(n.key_span.end))
    }

    /// The value of a node: its inline scalar, else its block of items or children, else
    /// the empty span after its `:`.
    pub fn value_span(&self, id: usize) -> Span {
        let n = &self.nodes[id];
        if let Some(v) = n.value {
            return v;
        }
        let first = n.items.first().or(n.children.first());
        match first {
            Some(&f) => Span::new(self.nodes[f].key_span.start, n.end.max(self.nodes[f].key_span.start)),
            None => Span::new(n.colon_end, n.colon_end),
        }
    }

    /// Every pair of children of one mapping with the same key: (mapping, first, second).
    pub fn duplicates(&self) -> Vec<(usize, usize, usize)> {
        let mut out = Vec::new();
        for (id, n) in self.nodes.iter().enumerate() {
            let mut first: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
            for &c in &n.children {
                match first.get(self.nodes[c].key.as_str()) {
                    Some(&a) => out.push((id, a, c)),
                    None => {
                        first.insert(self.nodes[c].key.as_str(), c);
                    }
                }
            }
        }
        out
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Root,
    Key,
    Item,
}

#[derive(Clone, Copy)]
struct Open {
    indent: isize,
    node: usize,
    kind: Kind,
}

enum Pending {
    None,
    /// A block scalar (`|`, `>`) of the key at `indent`.
    Block {
        indent: isize,
        node: usize,
    },
    /// A plain scalar that may continue on more indented lines.
    Plain {
        indent: isize,
        node: usize,
    },
    /// A quoted scalar not closed on its first line.
    Quoted {
        node: usize,
        quote: u8,
        start: usize,
    },
    /// A flow collection not closed on its first line.
    Flow {
        node: usize,
        start: usize,
        depth: usize,
        quote: Option<u8>,
    },
}

const MAX_FLOW_DEPTH: usize = 64;

/// Scan `text`, whose byte 0 is at `base` in the file.
pub fn scan(text: &str, base: usize) -> Tree {
    let mut s = Scanner {
        text,
        base,
        nodes: vec![Node { end: base, ..Node::default() }],
        stack: vec![Open { indent: -1, node: ROOT, kind: Kind::Root }],
        pending: Pending::None,
    };
    let mut offset = 0;
    for raw in text.split_inclusive('\n') {
        let start = offset;
        offset += raw.len();
        let line = raw.trim_end_matches(['\n', '\r']);
        s.line(start, line);
    }
    if let Pending::Quoted { node, start, .. } | Pending::Flow { node, start, .. } = s.pending {
        let end = base + text.len();
        s.nodes[node].value = Some(Span::new(base + start, end));
        s.touch(node, end);
    }
    Tree { nodes: s.nodes }
}

struct Scanner<'a> {
    text: &'a str,
    base: usize,
    nodes: Vec<Node>,
    stack: Vec<Open>,
    pending: Pending,
}

fn indent_of(line: &str) -> usize {
    line.len() - line.trim_start_matches([' ', '\t']).len()
}

/// The end of a quoted scalar that starts after its opening quote at `from`: the index of
/// the closing quote.
fn close_quote(bytes: &[u8], from: usize, quote: u8) -> Option<usize> {
    let mut i = from;
    while i < bytes.len() {
        let b = bytes[i];
        if quote == b'"' && b == b'\\' {
            i += 2;
            continue;
        }
        if b == quote {
            if quote == b'\'' && bytes.get(i + 1) == Some(&b'\'') {
                i += 2;
                continue;
            }
            return Some(i);
        }
        i += 1;
    }
    None
}

/// Track flow brackets over `bytes[from..]`; returns the index just after the closing
/// bracket when depth reaches 0.
fn flow_close(bytes: &[u8], from: usize, depth: &mut usize, quote: &mut Option<u8>) -> Option<usize> {
    let mut i = from;
    while i < bytes.len() {
        let b = bytes[i];
        match *quote {
            Some(q) => {
                if q == b'"' && b == b'\\' {
                    i += 1;
                } else if b == q {
                    if q == b'\'' && bytes.get(i + 1) == Some(&b'\'') {
                        i += 1;
                    } else {
                        *quote = None;
                    }
                }
            }
            None => match b {
                b'"' | b'\'' => *quote = Some(b),
                b'[' | b'{' => *depth += 1,
                b']' | b'}' => {
                    *depth = depth.saturating_sub(1);
                    if *depth == 0 {
                        return Some(i + 1);
                    }
                }
                b'#' if i == 0 || matches!(bytes[i - 1], b' ' | b'\t') => return None,
                _ => {}
            },
        }
        i += 1;
    }
    None
}

/// The key of a line's content: (key text, key start, key end, index after the colon).
fn parse_key(content: &str) -> Option<(String, usize, usize, usize)> {
    let bytes = content.as_bytes();
    match bytes.first()? {
        b'"' | b'\'' => {
            let q = bytes[0];
            let close = close_quote(bytes, 1, q)?;
            let mut i = close + 1;
            while i < bytes.len() && matches!(bytes[i], b' ' | b'\t') {
                i += 1;
            }
            if bytes.get(i) != Some(&b':') || !bytes.get(i + 1).is_none_or(|b| matches!(b, b' ' | b'\t')) {
                return None;
            }
            let inner = &content[1..close];
            let key =
                if q == b'"' { inner.replace("\\\"", "\"").replace("\\\\", "\\") } else { inner.replace("''", "'") };
            Some((key, 1, close, i + 1))
        }
        b'[' | b'{' | b'#' | b'?' | b'|' | b'>' | b'%' | b'@' | b'`' => None,
        _ => {
            let mut i = 0;
            while i < bytes.len() {
                match bytes[i] {
                    b':' if bytes.get(i + 1).is_none_or(|b| matches!(b, b' ' | b'\t')) => {
                        let key = content[..i].trim_end();
                        if key.is_empty() {
                            return None;
                        }
                        return Some((key.to_string(), 0, key.len(), i + 1));
                    }
                    b'#' if i > 0 && matches!(bytes[i - 1], b' ' | b'\t') => return None,
                    _ => {}
                }
                i += 1;
            }
            None
        }
    }
}

impl Scanner<'_> {
    fn span(&self, start: usize, end: usize) -> Span {
        Span::new(self.base + start, self.base + end)
    }

    fn new_node(&mut self, parent: usize, item: bool, key: String, key_span: Span, colon_end: usize) -> usize {
        let id = self.nodes.len();
        let end = key_span.end;
        self.nodes.push(Node { key, key_span, colon_end, value: None, end, children: Vec::new(), items: Vec::new() });
        if item {
            self.nodes[parent].items.push(id);
        } else {
            self.nodes[parent].children.push(id);
        }
        id
    }

    /// Extend the end of `node` and of every open node that contains it.
    fn touch(&mut self, node: usize, end: usize) {
        self.nodes[node].end = self.nodes[node].end.max(end);
        for open in &self.stack {
            let n = &mut self.nodes[open.node];
            n.end = n.end.max(end);
        }
    }

    fn line(&mut self, start: usize, line: &str) {
        let indent = indent_of(line);
        let content = &line[indent..];
        let blank = content.is_empty() || content.starts_with('#');
        let line_end = start + line.trim_end().len();
        // continuation of a multi-line construct
        match self.pending {
            Pending::None => {}
            Pending::Block { indent: key_indent, node } => {
                if blank || indent as isize > key_indent {
                    if !content.is_empty() {
                        let first = self.nodes[node].value.map_or(start + indent + self.base, |v| v.start);
                        self.nodes[node].value = Some(Span::new(first, self.base + line_end));
                        self.touch(node, self.base + line_end);
                    }
                    return;
                }
                self.pending = Pending::None;
            }
            Pending::Plain { indent: key_indent, node } => {
                if !blank && indent as isize > key_indent {
                    let end = self.base + start + indent + plain_end(content);
                    if let Some(v) = &mut self.nodes[node].value {
                        v.end = end;
                    }
                    self.touch(node, end);
                    return;
                }
                if !content.is_empty() {
                    self.pending = Pending::None;
                }
            }
            Pending::Quoted { node, quote, start: value_start } => {
                if let Some(close) = close_quote(line.as_bytes(), 0, quote) {
                    let end = self.base + start + close;
                    self.nodes[node].value = Some(Span::new(self.base + value_start, end));
                    self.touch(node, end + 1);
                    self.pending = Pending::None;
                }
                return;
            }
            Pending::Flow { node, start: value_start, mut depth, mut quote } => {
                match flow_close(line.as_bytes(), 0, &mut depth, &mut quote) {
                    Some(close) => {
                        let end = start + close;
                        self.nodes[node].value = Some(self.span(value_start, end));
                        self.touch(node, self.base + end);
                        self.flow(node, value_start, end);
                        self.pending = Pending::None;
                    }
                    None => self.pending = Pending::Flow { node, start: value_start, depth, quote },
                }
                return;
            }
        }
        if blank {
            return;
        }
        if indent == 0 && (content.starts_with("---") || content.starts_with("...")) {
            let rest = content[3..].trim_start();
            if rest.is_empty() || rest.starts_with('#') {
                return;
            }
        }
        self.content(start, indent, content);
    }

    /// Structured content at byte `start + col` of the text.
    fn content(&mut self, start: usize, col: usize, content: &str) {
        let bytes = content.as_bytes();
        if bytes[0] == b'-' && bytes.get(1).is_none_or(|b| matches!(b, b' ' | b'\t')) {
            // a sequence item
            let dash = col as isize;
            while let Some(top) = self.stack.last() {
                if top.indent > dash || (top.indent == dash && top.kind == Kind::Item) {
                    self.stack.pop();
                } else {
                    break;
                }
            }
            let owner = self.stack.last().map_or(ROOT, |o| o.node);
            let at = start + col;
            let item = self.new_node(owner, true, String::new(), self.span(at, at + 1), self.base + at + 1);
            self.touch(item, self.base + at + 1);
            self.stack.push(Open { indent: dash, node: item, kind: Kind::Item });
            let rest = &content[1..];
            let skip = indent_of(rest);
            if rest.len() > skip {
                let col2 = col + 1 + skip;
                let rest = &rest[skip..];
                if parse_key(rest).is_some() || rest.starts_with("- ") || rest == "-" {
                    self.content(start, col2, rest);
                } else {
                    self.value(item, start, col2, rest, dash);
                }
            }
            return;
        }
        let Some((key, key_start, key_end, after)) = parse_key(content) else {
            // a flow document, or text this scanner does not follow
            if matches!(bytes[0], b'[' | b'{') {
                let owner = self.stack.last().map_or(ROOT, |o| o.node);
                self.value(owner, start, col, content, col as isize - 1);
            }
            return;
        };
        let indent = col as isize;
        while self.stack.last().is_some_and(|top| top.indent >= indent) {
            self.stack.pop();
        }
        let parent = self.stack.last().map_or(ROOT, |o| o.node);
        let at = start + col;
        let node = self.new_node(parent, false, key, self.span(at + key_start, at + key_end), self.base + at + after);
        self.touch(node, self.base + at + key_end + usize::from(key_start > 0));
        let rest = &content[after..];
        let skip = indent_of(rest);
        let value = &rest[skip..];
        if value.is_empty() || value.starts_with('#') {
            self.stack.push(Open { indent, node, kind: Kind::Key });
        } else {
            self.stack.push(Open { indent, node, kind: Kind::Key });
            self.value(node, start, col + after + skip, value, indent);
        }
    }

    /// A value starting at byte `start + col`, owned by `node` (whose key is at `indent`).
    fn value(&mut self, node: usize, start: usize, col: usize, value: &str, indent: isize) {
        let mut col = col;
        let mut value = value;
        // anchors and tags before the value
        while value.starts_with(['&', '!']) {
            let word = value.find([' ', '\t']).unwrap_or(value.len());
            let rest = &value[word..];
            let skip = indent_of(rest);
            col += word + skip;
            value = &rest[skip..];
        }
        if value.is_empty() || value.starts_with('#') {
            return;
        }
        let at = start + col;
        let bytes = value.as_bytes();
        match bytes[0] {
            b'"' | b'\'' => match close_quote(bytes, 1, bytes[0]) {
                Some(close) => {
                    self.nodes[node].value = Some(self.span(at + 1, at + close));
                    self.touch(node, self.base + at + close + 1);
                }
                None => {
                    self.nodes[node].value = Some(self.span(at + 1, at + value.len()));
                    self.touch(node, self.base + at + value.len());
                    self.pending = Pending::Quoted { node, quote: bytes[0], start: at + 1 };
                }
            },
            b'[' | b'{' => {
                let mut depth = 0;
                let mut quote = None;
                match flow_close(bytes, 0, &mut depth, &mut quote) {
                    Some(close) => {
                        self.nodes[node].value = Some(self.span(at, at + close));
                        self.touch(node, self.base + at + close);
                        self.flow(node, at, at + close);
                    }
                    None => {
                        self.nodes[node].value = Some(self.span(at, at + plain_end(value)));
                        self.touch(node, self.base + at + value.len());
                        self.pending = Pending::Flow { node, start: at, depth, quote };
                    }
                }
            }
            b'|' | b'>' => {
                self.pending = Pending::Block { indent, node };
            }
            _ => {
                let end = at + plain_end(value);
                self.nodes[node].value = Some(self.span(at, end));
                self.touch(node, self.base + end);
                self.pending = Pending::Plain { indent, node };
            }
        }
    }

    /// Record the items or entries of the flow collection `text[from..to]` under `node`.
    fn flow(&mut self, node: usize, from: usize, to: usize) {
        let mut pos = from;
        self.flow_collection(node, &mut pos, to, 0);
    }

    fn flow_collection(&mut self, node: usize, pos: &mut usize, to: usize, depth: usize) {
        let bytes = self.text.as_bytes();
        if depth > MAX_FLOW_DEPTH || *pos >= to {
            return;
        }
        let open = bytes[*pos];
        let mapping = open == b'{';
        let close = if mapping { b'}' } else { b']' };
        *pos += 1;
        loop {
            skip_space(bytes, pos, to);
            if *pos >= to {
                return;
            }
            let before = *pos;
            match bytes[*pos] {
                b if b == close => {
                    *pos += 1;
                    return;
                }
                b',' => {
                    *pos += 1;
                    continue;
                }
                _ => {}
            }
            if mapping {
                let (key, key_span) = self.flow_scalar(pos, to, true);
                skip_space(bytes, pos, to);
                let colon_end = if *pos < to && bytes[*pos] == b':' {
                    *pos += 1;
                    *pos
                } else {
                    key_span.end
                };
                let child =
                    self.new_node(node, false, key, self.span(key_span.start, key_span.end), self.base + colon_end);
                self.flow_value(child, pos, to, depth);
            } else {
                let item = self.new_node(node, true, String::new(), self.span(*pos, *pos), self.base + *pos);
                self.flow_value(item, pos, to, depth);
                let v = self.nodes[item].value.unwrap_or(self.span(*pos, *pos));
                self.nodes[item].key_span = Span::new(v.start, v.start);
            }
            if *pos == before {
                // a stray bracket of the other kind: step over it
                *pos += 1;
            }
        }
    }

    fn flow_value(&mut self, node: usize, pos: &mut usize, to: usize, depth: usize) {
        let bytes = self.text.as_bytes();
        skip_space(bytes, pos, to);
        if *pos >= to {
            return;
        }
        match bytes[*pos] {
            b'[' | b'{' => {
                let start = *pos;
                self.flow_collection(node, pos, to, depth + 1);
                self.nodes[node].value = Some(self.span(start, *pos));
                self.nodes[node].end = self.base + *pos;
            }
            b',' | b']' | b'}' => {}
            _ => {
                let (_, span) = self.flow_scalar(pos, to, false);
                self.nodes[node].value = Some(self.span(span.start, span.end));
                self.nodes[node].end = self.base + span.end;
            }
        }
    }

    /// A scalar in a flow collection; returns its text and its span (relative to text).
    fn flow_scalar(&mut self, pos: &mut usize, to: usize, key: bool) -> (String, Span) {
        let bytes = self.text.as_bytes();
        let start = *pos;
        if matches!(bytes[start], b'"' | b'\'') {
            let close = close_quote(&bytes[..to], start + 1, bytes[start]).unwrap_or(to);
            *pos = (close + 1).min(to);
            let inner = self.text.get(start + 1..close).unwrap_or("");
            return (inner.to_string(), Span::new(start + 1, close));
        }
        let mut i = start;
        while i < to {
            match bytes[i] {
                b',' | b']' | b'}' => break,
                b':' if key && bytes.get(i + 1).is_none_or(|b| matches!(b, b' ' | b'\t' | b',' | b'}' | b'\n')) => {
                    break;
                }
                _ => i += 1,
            }
        }
        *pos = i;
        let raw = self.text.get(start..i).unwrap_or("");
        let trimmed = raw.trim_end();
        (trimmed.to_string(), Span::new(start, start + trimmed.len()))
    }
}

fn skip_space(bytes: &[u8], pos: &mut usize, to: usize) {
    while *pos < to && matches!(bytes[*pos], b' ' | b'\t' | b'\n' | b'\r') {
        *pos += 1;
    }
}

/// The length of a plain scalar's text on its line: up to a ` #` comment, trailing spaces
/// removed.
fn plain_end(value: &str) -> usize {
    let bytes = value.as_bytes();
    let mut end = value.len();
    for i in 1..bytes.len() {
        if bytes[i] == b'#' && matches!(bytes[i - 1], b' ' | b'\t') {
            end = i;
            break;
        }
    }
    value[..end].trim_end().len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text_of(src: &str, span: Span) -> &str {
        &src[span.start..span.end]
    }

    #[test]
    fn block_mappings_and_sequences() {
        let src = "env:\n    weather: clear  # comment\n    time: \"day time\"\nlist:\n- a\n-   b\nmap:\n  - k: v\n    j: w\n";
        let tree = scan(src, 0);
        let env = tree.child(Some(ROOT), "env", 0).unwrap();
        let weather = tree.child(Some(env), "weather", 0).unwrap();
        assert_eq!(text_of(src, tree.node(weather).key_span), "weather");
        assert_eq!(text_of(src, tree.node(weather).value.unwrap()), "clear");
        let time = tree.child(Some(env), "time", 1).unwrap();
        assert_eq!(text_of(src, tree.node(time).value.unwrap()), "day time");
        let list = tree.child(Some(ROOT), "list", 1).unwrap();
        let items: Vec<&str> =
            tree.node(list).items.iter().map(|&i| text_of(src, tree.node(i).value.unwrap())).collect();
        assert_eq!(items, ["a", "b"]);
        let map = tree.child(Some(ROOT), "map", 2).unwrap();
        let item = tree.item(Some(map), 0).unwrap();
        let j = tree.child(Some(item), "j", 1).unwrap();
        assert_eq!(text_of(src, tree.node(j).value.unwrap()), "w");
        assert_eq!(text_of(src, tree.block(env)), "env:\n    weather: clear  # comment\n    time: \"day time\"");
    }

    #[test]
    fn flow_and_multiline() {
        let src = "a: [x, 'y z', {k: v}]\nb: {c: 1, d: [2]}\ntext: |\n  one\n  two\nplain: one\n  two\nq: \"a\n  b\"\nlast: 1\n";
        let tree = scan(src, 10);
        let at = |s: Span| &src[s.start - 10..s.end - 10];
        let a = tree.child(Some(ROOT), "a", 0).unwrap();
        let items: Vec<&str> = tree.node(a).items.iter().map(|&i| at(tree.node(i).value.unwrap())).collect();
        assert_eq!(items, ["x", "y z", "{k: v}"]);
        let b = tree.child(Some(ROOT), "b", 1).unwrap();
        let d = tree.child(Some(b), "d", 1).unwrap();
        assert_eq!(at(tree.node(d).value.unwrap()), "[2]");
        let text = tree.child(Some(ROOT), "text", 2).unwrap();
        assert_eq!(at(tree.node(text).value.unwrap()), "one\n  two");
        let plain = tree.child(Some(ROOT), "plain", 3).unwrap();
        assert_eq!(at(tree.node(plain).value.unwrap()), "one\n  two");
        let q = tree.child(Some(ROOT), "q", 4).unwrap();
        assert_eq!(at(tree.node(q).value.unwrap()), "a\n  b");
        let last = tree.child(Some(ROOT), "last", 5).unwrap();
        assert_eq!(at(tree.node(last).value.unwrap()), "1");
    }

    #[test]
    fn duplicates_are_found() {
        let tree = scan("a: 1\nb:\n  c: 1\n  c: 2\n", 0);
        let dups = tree.duplicates();
        assert_eq!(dups.len(), 1);
        assert_eq!(tree.node(dups[0].2).key, "c");
    }
}
