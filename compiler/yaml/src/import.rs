//! YAML (TrafficAlign or TrafficComposer form) to the scenario model.

use crate::dialect::{self, Dialect, Form, Origin, Place, Tad};
use crate::norm::{self, normalize};
use crate::scan::{self, Tree};
use crate::{extract, parse};
use serde_norway::Value;
use tad_diagnostics::{Applicability, Code, Diagnostic, Payload, Span};
use tad_syntax::cst::{Name, Use};
use tad_syntax::model::*;
use tad_syntax::schema::{self, ClosedSet, FieldDef, LaneWord, SectionDef, Unit, ValueType};
use tad_syntax::suggest;

/// How strongly a key states a field, when several keys state the same one.
const DERIVED: u8 = 0; // read out of another value's text (`two-way straight road`)
const PAPER: u8 = 1; // the paper's or TrafficComposer's key for the field
const EXTRA: u8 = 2; // the TAD-named key `export` adds (`signs`, `special_lanes`)

fn no_yaml() -> Payload {
    Payload::Syntax { expected: vec!["a YAML mapping with the scenario".into()], found: None }
}

fn shape(key: &str, expected: &str, found: &str) -> Payload {
    Payload::WrongValue { field: key.into(), expected: expected.into(), found: found.into() }
}

pub fn lower(text: &str) -> (Module, Vec<Diagnostic>) {
    let (module, diagnostics, _) = lower_answer(text);
    (module, diagnostics)
}

/// [`lower`], and the camera profile the YAML states (its top-level `profile`, one of
/// [`crate::PROFILES`]; `None` when it states none or an unknown one, which is an error).
pub fn lower_answer(text: &str) -> (Module, Vec<Diagnostic>, Option<&'static str>) {
    let mut diagnostics = Vec::new();
    let Some(range) = extract::extract(text) else {
        let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
        let start = text.find(first).unwrap_or(0);
        let span = Span::new(start, start + first.trim_end().len());
        diagnostics.push(
            Diagnostic::new(Code::E0300, "no YAML scenario found in this answer", span, "expected YAML here")
                .with_payload(no_yaml())
                .with_help("put the scenario between `<YAML>` and `</YAML>`, or in a ```yaml code fence")
                .with_note("a plain YAML file must be a mapping with `environment`, `road_network` and `actors`"),
        );
        return (Module::default(), diagnostics, None);
    };
    let slice = &text[range.clone()];
    let whole = Span::new(range.start, range.end);
    if slice.trim().is_empty() {
        diagnostics.push(
            Diagnostic::new(Code::E0300, "the YAML block is empty", whole, "nothing here")
                .with_payload(no_yaml())
                .with_help("the block must hold the scenario: `environment`, `road_network` and `actors`"),
        );
        return (Module::default(), diagnostics, None);
    }
    let (work, value) = parse::parse(slice, range.start, &mut diagnostics);
    let Some(value) = value else {
        tad_diagnostics::sort(&mut diagnostics);
        return (Module::default(), diagnostics, None);
    };
    let tree = scan::scan(&work, range.start);
    let mut importer = Importer {
        text,
        tree,
        dialect: Dialect::TrafficAlign,
        diagnostics,
        sections: Vec::new(),
        actors: Vec::new(),
        pending: Vec::new(),
        name: None,
        uses: Vec::new(),
        whole,
        profile: None,
        rightmost: Vec::new(),
    };
    let module = importer.module(&value);
    let mut diagnostics = importer.diagnostics;
    tad_diagnostics::sort(&mut diagnostics);
    (module, diagnostics, importer.profile)
}

/// The dialect of a top-level mapping.
pub fn detect(map: &serde_norway::Mapping) -> Dialect {
    map.iter()
        .find_map(|(k, v)| dialect::identifies(&key_text(k), matches!(untag(v), Value::Sequence(_))))
        .unwrap_or(Dialect::TrafficAlign)
}

fn untag(v: &Value) -> &Value {
    match v {
        Value::Tagged(t) => untag(&t.value),
        other => other,
    }
}

fn key_text(k: &Value) -> String {
    match untag(k) {
        Value::String(s) => s.clone(),
        Value::Number(n) => n.to_string(),
        Value::Bool(b) => b.to_string(),
        Value::Null => "null".into(),
        _ => "?".into(),
    }
}

fn describe(v: &Value) -> &'static str {
    match untag(v) {
        Value::Null => "nothing",
        Value::Bool(_) => "`true`/`false`",
        Value::Number(_) => "a number",
        Value::String(_) => "text",
        Value::Sequence(_) => "a list",
        Value::Mapping(_) => "a mapping",
        Value::Tagged(_) => "a tagged value",
    }
}

/// One statement of a field by some key.
#[derive(Clone, Debug)]
struct Prop {
    def: &'static FieldDef,
    key: String,
    key_span: Span,
    value_span: Span,
    value: Known<Val>,
    rank: u8,
    /// A one-name summary of a list (`traffic_sign: stop sign` next to `signs: [...]`).
    summary: bool,
}

struct SectionBuild {
    def: &'static SectionDef,
    span: Span,
    name_span: Span,
    props: Vec<Prop>,
}

struct ActorBuild {
    key: String,
    name: Name,
    span: Span,
    count: Option<Spanned<Known<Count>>>,
    kind: Option<Spanned<Known<Symbol>>>,
    props: Vec<Prop>,
}

/// `position_relation` or `position_target` as written.
#[derive(Clone)]
struct Part {
    key_span: Span,
    value_span: Span,
    word: Option<String>,
}

/// An actor's position, resolved once every actor key is known.
struct PendingPosition {
    actor: usize,
    relation: Option<Part>,
    target: Option<Part>,
}

struct Importer<'a> {
    text: &'a str,
    tree: Tree,
    dialect: Dialect,
    diagnostics: Vec<Diagnostic>,
    sections: Vec<SectionBuild>,
    actors: Vec<ActorBuild>,
    pending: Vec<PendingPosition>,
    name: Option<Name>,
    uses: Vec<Use>,
    whole: Span,
    /// The camera profile the YAML states (`profile`).
    profile: Option<&'static str>,
    /// Where lanes are given as `rightmost`: the road's `lanes`, known at the end.
    rightmost: Vec<Span>,
}

/// Where a value is: its key's node in the scanned tree, with fallbacks.
#[derive(Clone, Copy)]
struct At {
    node: Option<usize>,
    key_span: Span,
    value_span: Span,
}

fn same_val(a: &Known<Val>, b: &Known<Val>) -> bool {
    fn names(s: &[Symbol]) -> Vec<&str> {
        let mut v: Vec<&str> = s.iter().map(|s| s.name.as_str()).collect();
        v.sort_unstable();
        v
    }
    match (a, b) {
        (Known::Unspecified, Known::Unspecified) => true,
        (Known::Given(a), Known::Given(b)) => match (a, b) {
            (Val::Symbol(a), Val::Symbol(b)) => a.name == b.name,
            (Val::Symbols(a), Val::Symbols(b)) => names(a) == names(b),
            (Val::Integer(a), Val::Integer(b)) => a == b,
            (Val::Quantity(a), Val::Quantity(b)) => a == b,
            (Val::Text(a), Val::Text(b)) => a == b,
            (Val::Position(a), Val::Position(b)) => {
                a.relation.name == b.relation.name && a.reference.name == b.reference.name
            }
            (Val::Flag(a), Val::Flag(b)) => a == b,
            _ => false,
        },
        _ => false,
    }
}

/// Whether two statements of one field agree, a list summary agreeing with any list that
/// contains its name.
fn agree(a: &Prop, b: &Prop) -> bool {
    if same_val(&a.value, &b.value) {
        return true;
    }
    let summary_of = |s: &Prop, list: &Prop| match (&s.value, &list.value) {
        (Known::Given(Val::Symbols(one)), Known::Given(Val::Symbols(all))) if s.summary => {
            one.iter().all(|o| all.iter().any(|a| a.name == o.name)) && (one.is_empty() == all.is_empty())
        }
        _ => false,
    };
    summary_of(a, b) || summary_of(b, a)
}

impl Importer<'_> {
    fn report(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    fn at(&self, node: Option<usize>, fallback: Span) -> At {
        match node {
            Some(n) => At { node, key_span: self.tree.node(n).key_span, value_span: self.tree.value_span(n) },
            None => At { node: None, key_span: fallback, value_span: fallback },
        }
    }

    /// The entries of a mapping value, each with where it is; E0304 for anything else.
    fn entries<'v>(&mut self, v: &'v Value, at: At, what: &str) -> Vec<(String, &'v Value, At)> {
        match untag(v) {
            Value::Mapping(map) => map
                .iter()
                .enumerate()
                .map(|(i, (k, v))| {
                    let key = key_text(k);
                    let node = self.tree.child(at.node, &key, i);
                    (key, v, self.at(node, at.key_span))
                })
                .collect(),
            Value::Null => Vec::new(),
            // TrafficComposer's `road_network: None`, or a model's `N/A`: nothing stated
            Value::String(s) if norm::is_none_word(s) || norm::is_unspecified(s) => Vec::new(),
            other => {
                self.report(
                    Diagnostic::new(
                        Code::E0304,
                        format!("`{what}` takes a mapping of keys, found {}", describe(other)),
                        at.value_span,
                        "expected `key: value` lines",
                    )
                    .with_payload(shape(what, "a mapping", describe(other)))
                    .with_help(format!("write the keys of `{what}` on their own lines, indented under it")),
                );
                Vec::new()
            }
        }
    }

    fn unknown_key(&mut self, key: &str, at: At, context: &str, place: Place) {
        let mut d = Diagnostic::new(
            Code::E0302,
            format!("unknown key `{key}` in {context}"),
            at.key_span,
            "not a key of this form",
        );
        let known = dialect::offered(place);
        let hint = dialect::hint(place, key);
        if let Some(guess) = hint.or_else(|| suggest::closest(key, known.iter().copied())) {
            let sure = if hint.is_some() { Applicability::MachineApplicable } else { Applicability::MaybeIncorrect };
            d = d.with_help(format!("did you mean `{guess}`?")).with_fix(at.key_span, guess, sure);
        } else {
            let list: Vec<String> = known.iter().map(|k| format!("`{k}`")).collect();
            d = d.with_note(format!("the keys of {context} are {}", list.join(", ")));
        }
        d = d.with_note("the value of this key is ignored").with_payload(Payload::Unknown {
            namespace: "key".into(),
            name: key.to_string(),
            candidates: hint.into_iter().chain(suggest::ranked(key, known.iter().copied(), 5)).fold(
                Vec::new(),
                |mut all, k| {
                    if !all.contains(&k.to_string()) {
                        all.push(k.to_string());
                    }
                    all
                },
            ),
            module: None,
        });
        self.report(d);
    }

    fn malformed(&mut self, key: &str, found: &str, span: Span, expected: &str, example: &str) {
        self.report(
            Diagnostic::new(
                Code::E0303,
                format!("`{key}` takes {expected}, found `{found}`"),
                span,
                format!("not {expected}"),
            )
            .with_help(format!(
                "write {expected} such as `{example}`, or `unspecified` if the description does not say"
            ))
            .with_payload(shape(key, expected, found))
            .with_fix(span, "unspecified", Applicability::MaybeIncorrect),
        );
    }

    /// A word that says something but gives no value (`several`, `slow`): read as
    /// `unspecified`, and said, so nothing the answer gave is lost without a word.
    fn vague(&mut self, key: &str, text: &str, span: Span, expected: &str, meaning: &str) {
        self.report(
            Diagnostic::new(
                Code::W0302,
                format!("`{key}: {}` gives no number: read as `unspecified`", text.trim()),
                span,
                format!("not {expected}"),
            )
            .with_payload(Payload::WrongValue {
                field: key.to_string(),
                expected: expected.to_string(),
                found: text.trim().to_string(),
            })
            .with_note(format!("{meaning}; the scenario counts it as missing"))
            .with_help(format!("write {expected} if the description gives one")),
        );
    }

    fn wrong_shape(&mut self, key: &str, v: &Value, span: Span, expected: &str) {
        self.report(
            Diagnostic::new(
                Code::E0304,
                format!("`{key}` takes {expected}, found {}", describe(v)),
                span,
                format!("expected {expected}"),
            )
            .with_payload(shape(key, expected, describe(v)))
            .with_help(format!("write one value after `{key}:`")),
        );
    }

    fn ignored(&mut self, span: Span, message: String, help: &str) {
        self.report(
            Diagnostic::new(Code::W0302, message, span, "ignored").with_help(help.to_string()).with_payload(
                Payload::Unsupported { backend: "tad".into(), construct: help.to_string(), instead: None },
            ),
        );
    }

    // ---- values ------------------------------------------------------------------------

    /// `None` (TrafficComposer's missing value) or null: read as `unspecified`.
    fn missing(&self, v: &Value, none_is_a_value: bool) -> bool {
        match untag(v) {
            Value::Null => true,
            Value::String(s) => {
                norm::is_unspecified(s)
                    || (norm::is_none_word(s) && (!none_is_a_value || self.dialect == Dialect::TrafficComposer))
            }
            _ => false,
        }
    }

    fn symbol_from(&mut self, key: &str, text: &str, span: Span, example: &str) -> Option<Symbol> {
        let name = normalize(text);
        if norm::is_identifier(&name) {
            Some(Symbol { name, span })
        } else {
            self.malformed(key, text.trim(), span, "a name", example);
            None
        }
    }

    fn symbol(&mut self, key: &str, v: &Value, at: At, example: &str) -> Option<Known<Symbol>> {
        if self.missing(v, true) {
            return Some(Known::Unspecified);
        }
        match untag(v) {
            Value::String(s) => self.symbol_from(key, s, at.value_span, example).map(Known::Given),
            Value::Number(n) => {
                self.malformed(key, &n.to_string(), at.value_span, "a name", example);
                None
            }
            Value::Bool(b) => {
                self.malformed(key, &b.to_string(), at.value_span, "a name", example);
                None
            }
            other => {
                self.wrong_shape(key, other, at.value_span, "one name");
                None
            }
        }
    }

    /// A list of names: a YAML list, a single name, a comma-separated string; `none` is
    /// the empty list in the paper's form.
    fn symbols(&mut self, key: &str, v: &Value, at: At, example: &str) -> Option<Known<Vec<Symbol>>> {
        if self.missing(v, true) {
            return Some(Known::Unspecified);
        }
        let mut out: Vec<Symbol> = Vec::new();
        let mut duplicate = None;
        let mut push = |s: Symbol, out: &mut Vec<Symbol>| {
            if out.iter().any(|o| o.name == s.name) {
                duplicate.get_or_insert(s.span);
            } else {
                out.push(s);
            }
        };
        match untag(v) {
            Value::String(s) => {
                if norm::is_none_word(s) {
                    return Some(Known::Given(Vec::new()));
                }
                let source = self.text.get(at.value_span.start..at.value_span.end).unwrap_or("");
                let mut cursor = 0;
                for piece in s.split(',') {
                    let piece = piece.trim();
                    if piece.is_empty() {
                        continue;
                    }
                    let span = match source.get(cursor..).and_then(|rest| rest.find(piece)) {
                        Some(i) => {
                            let start = at.value_span.start + cursor + i;
                            cursor += i + piece.len();
                            Span::new(start, start + piece.len())
                        }
                        None => at.value_span,
                    };
                    if let Some(sym) = self.symbol_from(key, piece, span, example) {
                        push(sym, &mut out);
                    }
                }
            }
            Value::Sequence(items) => {
                for (i, item) in items.iter().enumerate() {
                    let node = self.tree.item(at.node, i);
                    let span = node.map_or(at.value_span, |n| self.tree.value_span(n));
                    match untag(item) {
                        Value::Null => {}
                        // `[none]` is the paper's `none`; in a longer list `none` is a name
                        Value::String(s) if norm::is_none_word(s) && items.len() == 1 => {}
                        Value::String(s) if norm::is_unspecified(s) && items.len() == 1 => {
                            return Some(Known::Unspecified);
                        }
                        Value::String(s) => {
                            if let Some(sym) = self.symbol_from(key, s, span, example) {
                                push(sym, &mut out);
                            }
                        }
                        Value::Number(n) => self.malformed(key, &n.to_string(), span, "a name", example),
                        Value::Bool(b) => self.malformed(key, &b.to_string(), span, "a name", example),
                        other => self.wrong_shape(key, other, span, "a list of names"),
                    }
                }
            }
            Value::Number(n) => {
                self.malformed(key, &n.to_string(), at.value_span, "a list of names", example);
                return None;
            }
            Value::Bool(b) => {
                self.malformed(key, &b.to_string(), at.value_span, "a list of names", example);
                return None;
            }
            other => {
                self.wrong_shape(key, other, at.value_span, "a list of names");
                return None;
            }
        }
        if let Some(span) = duplicate {
            self.report(
                Diagnostic::new(Code::W0201, format!("`{key}` lists a name twice"), span, "already listed")
                    .with_payload(Payload::Duplicate {
                        namespace: key.to_string(),
                        name: String::new(),
                        earlier_module: None,
                    })
                    .with_help("list each name once"),
            );
        }
        Some(Known::Given(out))
    }

    fn integer(&mut self, key: &str, v: &Value, at: At, example: &str) -> Option<Known<i64>> {
        if self.missing(v, false) {
            return Some(Known::Unspecified);
        }
        let span = at.value_span;
        let whole = |f: f64| (f.fract() == 0.0 && f.abs() < 9.0e15).then_some(f as i64);
        match untag(v) {
            Value::Number(n) => {
                if let Some(i) = n.as_i64() {
                    return Some(Known::Given(i));
                }
                let text = n.to_string();
                let mut d = Diagnostic::new(
                    Code::E0303,
                    format!("`{key}` takes a whole number, found `{text}`"),
                    span,
                    "not a whole number",
                )
                .with_payload(shape(key, "a whole number", &text));
                if let Some(i) = n.as_f64().and_then(whole) {
                    d = d.with_help(format!("write `{i}`")).with_fix(
                        span,
                        i.to_string(),
                        Applicability::MachineApplicable,
                    );
                }
                self.report(d);
                None
            }
            Value::String(s) => {
                if let Some(i) = norm::parse_integer(s) {
                    return Some(Known::Given(i));
                }
                if let Some(i) = norm::number_word(s) {
                    // `two` means 2
                    return Some(Known::Given(i));
                }
                if norm::is_count_word(s) {
                    self.vague(key, s, span, "a count", "how many is not known");
                    return Some(Known::Unspecified);
                }
                self.malformed(key, s, span, "a whole number", example);
                None
            }
            Value::Bool(b) => {
                self.malformed(key, &b.to_string(), span, "a whole number", example);
                None
            }
            other => {
                self.wrong_shape(key, other, span, "a whole number");
                None
            }
        }
    }

    fn quantity(&mut self, key: &str, v: &Value, at: At, default: Unit, example: &str) -> Option<Known<Quantity>> {
        if self.missing(v, false) {
            return Some(Known::Unspecified);
        }
        let span = at.value_span;
        let what = match default {
            Unit::Seconds => "a duration",
            Unit::Metres => "a length",
            _ => "a speed",
        };
        match untag(v) {
            Value::Number(n) => match n.as_f64().filter(|f| f.is_finite()) {
                Some(value) => Some(Known::Given(Quantity { value, unit: default })),
                None => {
                    self.malformed(key, &n.to_string(), span, what, example);
                    None
                }
            },
            Value::String(s) => match norm::parse_quantity(s, default) {
                Some((value, unit)) => Some(Known::Given(Quantity { value, unit })),
                None => {
                    match norm::speed_word(s).filter(|_| default.measures() == Unit::KilometresPerHour.measures()) {
                        // the paper: a stopped vehicle is 0 km/h
                        Some(norm::SpeedWord::Still) => Some(Known::Given(Quantity { value: 0.0, unit: default })),
                        Some(norm::SpeedWord::Vague) => {
                            self.vague(key, s, span, what, "the speed is not known");
                            Some(Known::Unspecified)
                        }
                        None => {
                            self.malformed(key, s.trim(), span, what, example);
                            None
                        }
                    }
                }
            },
            Value::Bool(b) => {
                self.malformed(key, &b.to_string(), span, what, example);
                None
            }
            other => {
                self.wrong_shape(key, other, span, what);
                None
            }
        }
    }

    fn text_value(&mut self, key: &str, v: &Value, at: At) -> Option<Known<String>> {
        match untag(v) {
            Value::Null => Some(Known::Unspecified),
            Value::String(s) if norm::is_unspecified(s) => Some(Known::Unspecified),
            Value::String(s) => Some(Known::Given(s.clone())),
            Value::Number(n) => Some(Known::Given(n.to_string())),
            Value::Bool(b) => Some(Known::Given(b.to_string())),
            other => {
                self.wrong_shape(key, other, at.value_span, "text");
                None
            }
        }
    }

    fn part(&mut self, key: &str, v: &Value, at: At) -> Option<Part> {
        let mut part = Part { key_span: at.key_span, value_span: at.value_span, word: None };
        match untag(v) {
            Value::Null => {}
            Value::String(s) if norm::is_unspecified(s) || norm::is_none_word(s) => {}
            Value::String(s) => part.word = Some(s.clone()),
            Value::Number(n) => part.word = Some(n.to_string()),
            Value::Bool(b) => part.word = Some(b.to_string()),
            other => {
                self.wrong_shape(key, other, at.value_span, "one name");
                return None;
            }
        }
        Some(part)
    }

    // ---- collecting ----------------------------------------------------------------------

    fn section(&mut self, name: &str, span: Span, name_span: Span) -> usize {
        if let Some(i) = self.sections.iter().position(|s| s.def.name == name) {
            return i;
        }
        let def = schema::section(name).unwrap_or(&schema::EGO);
        self.sections.push(SectionBuild { def, span, name_span, props: Vec::new() });
        self.sections.len() - 1
    }

    /// The section `name`, created at `at` (its key) when it does not exist yet.
    fn section_at(&mut self, name: &str, at: At) -> usize {
        let block = at.node.map_or(at.key_span, |n| self.tree.block(n));
        self.section(name, block, at.key_span)
    }

    fn propose(&mut self, target: Target, prop: Prop) {
        let props = match target {
            Target::Section(i) => &mut self.sections[i].props,
            Target::Actor(i) => &mut self.actors[i].props,
        };
        let Some(i) = props.iter().position(|p| p.def.name == prop.def.name) else {
            props.push(prop);
            return;
        };
        let old = &props[i];
        let unspecified = |p: &Prop| matches!(p.value, Known::Unspecified);
        if agree(old, &prop) {
            let replace = prop.rank > old.rank || (old.summary && !prop.summary);
            if replace {
                props[i] = prop;
            }
            return;
        }
        match (unspecified(old), unspecified(&prop)) {
            (true, false) => {
                props[i] = prop;
                return;
            }
            (false, true) => return,
            _ => {}
        }
        let new_wins = prop.rank > old.rank;
        let (winner, loser) = if new_wins { (prop.clone(), old.clone()) } else { (old.clone(), prop.clone()) };
        if new_wins {
            props[i] = prop;
        }
        let message = if winner.key == loser.key {
            format!("`{}` is given twice with different values", loser.key)
        } else {
            format!("`{}` disagrees with `{}`", loser.key, winner.key)
        };
        self.report(
            Diagnostic::new(Code::W0301, message, loser.value_span, "this value is ignored")
                .with_payload(Payload::Duplicate {
                    namespace: "key".into(),
                    name: loser.key.clone(),
                    earlier_module: None,
                })
                .with_secondary(winner.value_span, "this one is used")
                .with_help("make the two agree, or remove one"),
        );
    }

    fn set(&mut self, claim: Claim, value: Known<Val>, summary: bool) {
        let Claim { target, field, key, at, rank } = claim;
        let def = match target {
            Target::Section(i) => self.sections[i].def.field(field),
            Target::Actor(_) => schema::ACTOR.field(field),
        };
        let Some(def) = def else { return };
        let prop =
            Prop { def, key: key.to_string(), key_span: at.key_span, value_span: at.value_span, value, rank, summary };
        self.propose(target, prop);
    }

    fn set_symbol(&mut self, claim: Claim, v: &Value) {
        let example = field_example(claim.target, claim.field);
        if let Some(s) = self.symbol(claim.key, v, claim.at, example) {
            self.set(claim, known_map(s, Val::Symbol), false);
        }
    }

    fn set_symbols(&mut self, claim: Claim, v: &Value) {
        let example = field_example(claim.target, claim.field);
        if let Some(s) = self.symbols(claim.key, v, claim.at, example) {
            self.set(claim, known_map(s, Val::Symbols), false);
        }
    }

    /// The paper's `traffic_sign`: one sign (or `none`), which a `signs` list may extend.
    fn set_traffic_sign(&mut self, road: Target, key: &str, v: &Value, at: At) {
        if let Some(s) = self.symbols(key, v, at, "stop sign") {
            let summary = matches!(&s, Known::Given(list) if list.len() <= 1);
            self.set(Claim { target: road, field: "signs", key, at, rank: PAPER }, known_map(s, Val::Symbols), summary);
        }
    }

    fn set_integer(&mut self, claim: Claim, v: &Value) {
        // a lane named by where it is (`rightmost`, `leftmost lane`)
        if let ("lane", Value::String(text)) = (claim.field, untag(v))
            && let Some(word) = LaneWord::parse(text.trim().to_ascii_lowercase().trim_end_matches(" lane").trim())
        {
            if word == LaneWord::Rightmost {
                self.rightmost.push(claim.at.value_span);
            }
            self.set(claim, Known::Given(Val::Integer(1)), false);
            return;
        }
        if let Some(n) = self.integer(claim.key, v, claim.at, "1") {
            self.set(claim, known_map(n, Val::Integer), false);
        }
    }

    fn set_quantity(&mut self, claim: Claim, v: &Value, unit: Unit) {
        let Claim { field, key, at, .. } = claim;
        let example = match unit {
            Unit::Seconds => "195 s",
            Unit::Metres => "15 m",
            _ => "30 km/h",
        };
        // a range, where the field takes one (`25-30 km/h`, `between 25 and 30 km/h`)
        let takes_range =
            schema::SECTIONS.iter().chain([&&schema::ACTOR]).any(|s| s.field(field).is_some_and(|f| f.param));
        if let (true, Value::String(s)) = (takes_range, untag(v))
            && let Some((low, high, unit)) = norm::parse_quantity_range(s, unit)
        {
            let range = Val::Range(Quantity { value: low, unit }, Quantity { value: high, unit });
            self.set(claim, Known::Given(range), false);
            return;
        }
        if let Some(q) = self.quantity(key, v, at, unit, example) {
            self.set(claim, known_map(q, Val::Quantity), false);
        }
    }

    /// A key that states a TAD field, read by its YAML form or else by the field's kind.
    fn field(&mut self, target: Target, row: &dialect::Key, key: &str, v: &Value, at: At) {
        let Some(def) = row.field() else { return };
        let rank = if row.origin == Origin::Extra { EXTRA } else { PAPER };
        let claim = Claim { target, field: def.name, key, at, rank };
        match row.form {
            Form::Weather => self.weather(target, key, v, at),
            Form::RoadType => self.road_type(target, key, v, at),
            Form::SignSummary => self.set_traffic_sign(target, key, v, at),
            Form::Value | Form::Direction => match def.ty {
                ValueType::Symbol => self.set_symbol(claim, v),
                ValueType::SymbolList => self.set_symbols(claim, v),
                ValueType::Integer => self.set_integer(claim, v),
                ValueType::Speed => self.set_quantity(claim, v, Unit::KilometresPerHour),
                ValueType::Duration => self.set_quantity(claim, v, Unit::Seconds),
                ValueType::Length => self.set_quantity(claim, v, Unit::Metres),
                ValueType::Text => {
                    if let Some(t) = self.text_value(key, v, at) {
                        self.set(claim, known_map(t, Val::Text), false);
                    }
                }
                ValueType::Position | ValueType::Flag | ValueType::Choice(_) => {}
            },
            // read by their place: the parts of a position, blocks, fixed values
            Form::Mapping | Form::Relation | Form::Target | Form::Fixed(_) => {}
        }
    }

    // ---- the forms -------------------------------------------------------------------------

    fn module(&mut self, value: &Value) -> Module {
        let root = self.at(Some(scan::ROOT), self.whole);
        let root = At { key_span: Span::new(self.whole.start, self.whole.start), value_span: self.whole, ..root };
        let value = match untag(value) {
            Value::Mapping(_) => value,
            Value::Null => {
                self.report(
                    Diagnostic::new(Code::E0300, "the YAML block holds no scenario", self.whole, "only comments here")
                        .with_payload(no_yaml())
                        .with_help("the block must hold the scenario: `environment`, `road_network` and `actors`"),
                );
                return Module::default();
            }
            other => {
                self.report(
                    Diagnostic::new(
                        Code::E0304,
                        format!("a scenario is a YAML mapping, found {}", describe(other)),
                        self.whole,
                        "expected `environment:`, `road_network:` and `actors:`",
                    )
                    .with_payload(shape("scenario", "a mapping", describe(other)))
                    .with_help("write the scenario as `key: value` lines, starting with `environment:`"),
                );
                return Module::default();
            }
        };
        let (value, root) = self.unwrap(value, root);
        if let Value::Mapping(map) = untag(value) {
            self.dialect = detect(map);
        }
        for (key, v, at) in self.entries(value, root, "the scenario") {
            let Some(row) = dialect::find(Place::Top, &key) else {
                self.unknown_key(&key, at, "the scenario", Place::Top);
                continue;
            };
            match row.tad {
                Tad::Block(Place::Environment) => self.environment(v, at),
                Tad::Block(Place::Road) => self.road_network(v, at),
                Tad::Block(Place::Source) => self.source(v, at),
                Tad::Actors => self.actors(&key, v, at),
                Tad::ScenarioName => self.scenario_name(&key, v, at),
                Tad::Uses => self.uses(&key, v, at),
                Tad::Profile => self.profile(&key, v, at),
                Tad::Field(section, _) => {
                    let target = Target::Section(self.section_at(section.name, at));
                    self.field(target, row, &key, v, at);
                }
                Tad::Block(_) | Tad::Type | Tad::Count | Tad::Nothing => {}
            }
        }
        self.resolve_positions();
        self.finish()
    }

    /// `scenario: { environment: ..., ... }` or any single wrapper key around the form.
    fn unwrap<'v>(&mut self, value: &'v Value, at: At) -> (&'v Value, At) {
        let Value::Mapping(map) = untag(value) else { return (value, at) };
        let known = |k: &Value| dialect::is_top_level(&key_text(k), false);
        if map.len() != 1 {
            return (value, at);
        }
        let Some((k, v)) = map.iter().next() else { return (value, at) };
        let wrapper = !known(k) || normalize(&key_text(k)) == "scenario";
        if wrapper && matches!(untag(v), Value::Mapping(m) if m.keys().any(known)) {
            let key = key_text(k);
            let node = self.tree.child(at.node, &key, 0);
            return (v, self.at(node, at.key_span));
        }
        (value, at)
    }

    fn scenario_name(&mut self, key: &str, v: &Value, at: At) {
        match untag(v) {
            Value::String(s) if !s.trim().is_empty() => {
                self.name = Some(Name { text: norm::identifier(s), span: at.value_span });
            }
            Value::Null => {}
            other => self.wrong_shape(key, other, at.value_span, "a name"),
        }
    }

    /// `profile`: the camera rules the host checks the file with ([`lower_answer`]).
    fn profile(&mut self, key: &str, v: &Value, at: At) {
        let name = untag(v).as_str().map(normalize);
        self.profile = crate::PROFILES.into_iter().find(|p| name.as_deref() == Some(*p));
        if self.profile.is_none() {
            let found = untag(v).as_str().map_or_else(|| format!("{v:?}"), |s| s.trim().to_string());
            self.malformed(key, &found, at.value_span, "a camera profile (`auto`, `default` or `dashcam`)", "auto");
        }
    }

    fn uses(&mut self, key: &str, v: &Value, at: At) {
        let items: Vec<(String, Span)> = match untag(v) {
            Value::String(s) => vec![(s.clone(), at.value_span)],
            Value::Sequence(items) => items
                .iter()
                .enumerate()
                .filter_map(|(i, item)| {
                    let span = self.tree.item(at.node, i).map_or(at.value_span, |n| self.tree.value_span(n));
                    match untag(item) {
                        Value::String(s) => Some((s.clone(), span)),
                        _ => None,
                    }
                })
                .collect(),
            Value::Null => Vec::new(),
            other => {
                self.wrong_shape(key, other, at.value_span, "a module name or a list of them");
                return;
            }
        };
        for (path, span) in items {
            let source = self.text.get(span.start..span.end).unwrap_or("");
            let located = source == path;
            let mut names = Vec::new();
            let mut offset = span.start;
            for segment in path.split('.') {
                let seg_span = if located { Span::new(offset, offset + segment.len()) } else { span };
                offset += segment.len() + 1;
                if !norm::is_identifier(segment.trim()) {
                    self.malformed(key, &path, span, "a module name", "national_park");
                    names.clear();
                    break;
                }
                names.push(Name { text: segment.trim().to_string(), span: seg_span });
            }
            if !names.is_empty() {
                self.uses.push(Use { span, path: names });
            }
        }
    }

    /// Whether `v` can be a block of keys; when not, E0304 is reported.
    fn keyed(&mut self, v: &Value, at: At, what: &str) -> bool {
        let ok = matches!(untag(v), Value::Mapping(_) | Value::Null);
        if !ok {
            self.entries(v, at, what);
        }
        ok
    }

    fn environment(&mut self, v: &Value, at: At) {
        if !self.keyed(v, at, "environment") {
            return;
        }
        let env = Target::Section(self.section_at("environment", at));
        for (key, v, at) in self.entries(v, at, "environment") {
            match dialect::find(Place::Environment, &key) {
                Some(row) => self.field(env, row, &key, v, at),
                None => self.unknown_key(&key, at, "`environment`", Place::Environment),
            }
        }
    }

    /// `weather`, which TrafficComposer also uses for the time of day (`night`).
    fn weather(&mut self, env: Target, key: &str, v: &Value, at: At) {
        let claim = |field, rank| Claim { target: env, field, key, at, rank };
        let text = match untag(v) {
            Value::String(s) if self.dialect == Dialect::TrafficComposer && !self.missing(v, true) => s.clone(),
            _ => return self.set_symbol(claim("weather", PAPER), v),
        };
        let (weather, time) = norm::split_weather(&text);
        if let Some(time) = time {
            let span = self.sub_span(at.value_span, &time);
            if let Some(sym) = self.symbol_from(key, &time, span, "daytime") {
                let at = At { value_span: span, ..at };
                self.set(Claim { at, ..claim("time", DERIVED) }, Known::Given(Val::Symbol(sym)), false);
            }
        }
        if let Some(weather) = weather {
            let span = self.sub_span(at.value_span, &weather);
            if let Some(sym) = self.symbol_from(key, &weather, span, "clear") {
                let at = At { value_span: span, ..at };
                self.set(Claim { at, ..claim("weather", PAPER) }, Known::Given(Val::Symbol(sym)), false);
            }
        }
    }

    /// Where `part` is inside the value at `span`, else `span`.
    fn sub_span(&self, span: Span, part: &str) -> Span {
        let source = self.text.get(span.start..span.end).unwrap_or("");
        let first = part.split_whitespace().next().unwrap_or(part);
        let last = part.split_whitespace().last().unwrap_or(part);
        match (source.find(first), source.rfind(last)) {
            (Some(a), Some(b)) if b + last.len() >= a => Span::new(span.start + a, span.start + b + last.len()),
            _ => span,
        }
    }

    fn road_network(&mut self, v: &Value, at: At) {
        let composer_item = self.dialect == Dialect::TrafficComposer && matches!(untag(v), Value::String(_));
        if !matches!(untag(v), Value::Sequence(_)) && !composer_item && !self.keyed(v, at, "road_network") {
            return;
        }
        let road = Target::Section(self.section_at("road", at));
        match untag(v) {
            Value::Sequence(items) => {
                for (i, item) in items.iter().enumerate() {
                    let node = self.tree.item(at.node, i);
                    let item_at = match node {
                        Some(n) => At { node, key_span: self.tree.value_span(n), value_span: self.tree.value_span(n) },
                        None => at,
                    };
                    match untag(item) {
                        Value::String(s) => self.road_item(road, s, item_at),
                        Value::Null => {}
                        other => self.wrong_shape("road_network", other, item_at.value_span, "a road element"),
                    }
                }
                return;
            }
            Value::String(s) if self.dialect == Dialect::TrafficComposer && !self.missing(v, true) => {
                let s = s.clone();
                return self.road_item(road, &s, at);
            }
            _ => {}
        }
        for (key, v, at) in self.entries(v, at, "road_network") {
            match dialect::find(Place::Road, &key) {
                Some(row) => self.field(road, row, &key, v, at),
                None => self.unknown_key(&key, at, "`road_network`", Place::Road),
            }
        }
    }

    /// `road_type`: its text may also say the direction and special lanes.
    fn road_type(&mut self, road: Target, key: &str, v: &Value, at: At) {
        let claim = |field, rank| Claim { target: road, field, key, at, rank };
        let text = match untag(v) {
            Value::String(s) if !self.missing(v, true) => s.clone(),
            _ => return self.set_symbol(claim("type", PAPER), v),
        };
        let parts = norm::split_road_type(&text);
        match &parts.road_type {
            Some(t) => {
                let span = self.sub_span(at.value_span, t);
                if let Some(sym) = self.symbol_from(key, t, span, "straight road") {
                    let at = At { value_span: span, ..at };
                    self.set(Claim { at, ..claim("type", PAPER) }, Known::Given(Val::Symbol(sym)), false);
                }
            }
            None => self.set(claim("type", PAPER), Known::Unspecified, false),
        }
        if let Some(direction) = parts.direction {
            let sym = Symbol { name: direction.to_string(), span: at.value_span };
            self.set(claim("direction", DERIVED), Known::Given(Val::Symbol(sym)), false);
        }
        if !parts.special_lanes.is_empty() {
            let mut lanes = Vec::new();
            for lane in &parts.special_lanes {
                let span = self.sub_span(at.value_span, lane);
                if let Some(sym) = self.symbol_from(key, lane, span, "bike lane") {
                    lanes.push(sym);
                }
            }
            self.set(claim("special_lanes", DERIVED), Known::Given(Val::Symbols(lanes)), false);
        }
    }

    /// One string of TrafficComposer's `road_network` list.
    fn road_item(&mut self, road: Target, text: &str, at: At) {
        let lower = text.trim().to_lowercase();
        let words: Vec<&str> = lower.split_whitespace().collect();
        let key = "road_network";
        let claim = |field, rank| Claim { target: road, field, key, at, rank };
        if matches!(
            lower.as_str(),
            "traffic light" | "traffic lights" | "traffic signal" | "traffic signals" | "traffic_light"
        ) {
            // a light is there; its state is not said
            self.set(claim("light", DERIVED), Known::Unspecified, false);
            return;
        }
        if words.last().is_some_and(|w| *w == "sign" || *w == "signs") {
            if let Some(sym) = self.symbol_from(key, text, at.value_span, "stop sign") {
                let mut list = match self.road_prop(road, "signs").map(|p| p.value.clone()) {
                    Some(Known::Given(Val::Symbols(list))) => list,
                    _ => Vec::new(),
                };
                list.push(sym);
                self.replace(road, "signs", key, at, Known::Given(Val::Symbols(list)));
            }
            return;
        }
        let count = words.first().and_then(|w| norm::parse_integer(w).or_else(|| norm::number_word(w)));
        if let (Some(n), true) = (count, words.len() >= 2 && words[1].starts_with("lane")) {
            self.set(claim("lanes", DERIVED), Known::Given(Val::Integer(n)), false);
            return;
        }
        if let Some(n) = words
            .first()
            .and_then(|w| w.strip_suffix("-lane"))
            .and_then(|w| norm::parse_integer(w).or_else(|| norm::number_word(w)))
        {
            self.set(claim("lanes", DERIVED), Known::Given(Val::Integer(n)), false);
            return;
        }
        let parts = norm::split_road_type(text);
        if let Some(direction) = parts.direction {
            let sym = Symbol { name: direction.to_string(), span: at.value_span };
            self.set(claim("direction", DERIVED), Known::Given(Val::Symbol(sym)), false);
        }
        let Some(road_type) = parts.road_type else { return };
        if let Some(existing) = self.road_prop(road, "type").and_then(|p| match &p.value {
            Known::Given(Val::Symbol(s)) => Some(s.name.clone()),
            _ => None,
        }) {
            self.ignored(
                at.value_span,
                format!("`{}` is a second road type", text.trim()),
                &format!("TAD gives a road one type; `{existing}` is used"),
            );
            return;
        }
        if let Some(sym) = self.symbol_from(key, &road_type, at.value_span, "intersection") {
            self.set(claim("type", PAPER), Known::Given(Val::Symbol(sym)), false);
        }
    }

    fn road_prop(&self, road: Target, field: &str) -> Option<&Prop> {
        match road {
            Target::Section(i) => self.sections[i].props.iter().find(|p| p.def.name == field),
            Target::Actor(_) => None,
        }
    }

    /// Set a field, replacing what is there without comparing (lists built item by item).
    fn replace(&mut self, road: Target, field: &str, key: &str, at: At, value: Known<Val>) {
        if let Target::Section(i) = road
            && let Some(p) = self.sections[i].props.iter_mut().find(|p| p.def.name == field)
        {
            p.value = value;
            p.value_span = p.value_span.to(at.value_span);
            return;
        }
        self.set(Claim { target: road, field, key, at, rank: DERIVED }, value, false);
    }

    fn source(&mut self, v: &Value, at: At) {
        if !self.keyed(v, at, "source") {
            return;
        }
        let source = Target::Section(self.section_at("source", at));
        for (key, v, at) in self.entries(v, at, "source") {
            match dialect::find(Place::Source, &key) {
                Some(row) => self.field(source, row, &key, v, at),
                None => self.unknown_key(&key, at, "`source`", Place::Source),
            }
        }
    }

    fn actors(&mut self, what: &str, v: &Value, at: At) {
        let what = what.to_string();
        for (key, v, at) in self.entries(v, at, &what) {
            if norm::is_ego(&normalize(&key)) {
                self.ego(&key, v, at);
            } else {
                self.actor(&key, v, at);
            }
        }
    }

    fn ego(&mut self, ego_key: &str, v: &Value, at: At) {
        if !self.keyed(v, at, ego_key) {
            return;
        }
        let ego = Target::Section(self.section_at("ego", at));
        let mut position: Option<Span> = None;
        for (key, v, at) in self.entries(v, at, ego_key) {
            let Some(row) = dialect::find(Place::Ego, &key) else {
                self.unknown_key(&key, at, &format!("`{ego_key}`"), Place::Ego);
                continue;
            };
            match row.tad {
                Tad::Type => {
                    let fine =
                        self.missing(v, false) || matches!(untag(v), Value::String(s) if norm::is_ego(&normalize(s)));
                    if !fine {
                        self.ignored(
                            at.value_span,
                            "TAD gives the ego vehicle no type".to_string(),
                            "the paper's form writes `type: none` for the ego vehicle",
                        );
                    }
                }
                Tad::Count => {
                    let fine = self.missing(v, false) || untag(v).as_i64() == Some(1);
                    if !fine {
                        self.ignored(at.value_span, "there is one ego vehicle".to_string(), "remove `number`");
                    }
                }
                Tad::Nothing => {
                    if !self.missing(v, false) {
                        position = Some(position.map_or(at.value_span, |p: Span| p.to(at.value_span)));
                    }
                }
                Tad::Field(..) => self.field(ego, row, &key, v, at),
                Tad::Block(_) | Tad::Actors | Tad::ScenarioName | Tad::Uses | Tad::Profile => {}
            }
        }
        if let Some(span) = position {
            self.ignored(
                span,
                "TAD gives the ego vehicle no position".to_string(),
                "other actors are placed relative to the ego vehicle; write `unspecified` for the ego's",
            );
        }
    }

    fn actor(&mut self, actor_key: &str, v: &Value, at: At) {
        if !self.keyed(v, at, actor_key) {
            return;
        }
        let base = norm::identifier(actor_key);
        let mut name = base.clone();
        let mut n = 2;
        while self.actors.iter().any(|a| a.name.text == name) {
            name = format!("{base}_{n}");
            n += 1;
        }
        if name != base {
            self.report(
                Diagnostic::new(
                    Code::W0303,
                    format!("actor `{actor_key}` is renamed `{name}`"),
                    at.key_span,
                    format!("`{base}` is taken"),
                )
                .with_payload(Payload::Duplicate {
                    namespace: "actor_group".into(),
                    name: base.clone(),
                    earlier_module: None,
                })
                .with_help("give each actor group a key of its own"),
            );
        }
        let span = at.node.map_or(at.key_span, |n| self.tree.block(n));
        let index = self.actors.len();
        self.actors.push(ActorBuild {
            key: actor_key.to_string(),
            name: Name { text: name, span: at.key_span },
            span,
            count: None,
            kind: None,
            props: Vec::new(),
        });
        let me = Target::Actor(index);
        let mut relation = None;
        let mut target = None;
        for (key, v, at) in self.entries(v, at, actor_key) {
            let Some(row) = dialect::find(Place::Actor, &key) else {
                self.unknown_key(&key, at, &format!("actor `{actor_key}`"), Place::Actor);
                continue;
            };
            match (row.tad, row.form) {
                (Tad::Type, _) => {
                    if let Some(kind) = self.symbol(&key, v, at, "sedan") {
                        self.actors[index].kind = Some(Spanned { value: kind, span: at.value_span });
                    }
                }
                (Tad::Count, _) => {
                    let range = match untag(v) {
                        Value::String(s) => norm::parse_integer_range(s),
                        _ => None,
                    };
                    if let Some((low, high)) = range {
                        let count = Known::Given(Count::Between(low, high));
                        self.actors[index].count = Some(Spanned { value: count, span: at.value_span });
                    } else if let Some(count) = self.integer(&key, v, at, "1") {
                        let count = match count {
                            Known::Given(n) => Known::Given(Count::Exactly(n)),
                            Known::Unspecified => Known::Unspecified,
                        };
                        self.actors[index].count = Some(Spanned { value: count, span: at.value_span });
                    }
                }
                (_, Form::Relation) => relation = self.part(&key, v, at),
                (_, Form::Target) => target = self.part(&key, v, at),
                (Tad::Field(..), _) => self.field(me, row, &key, v, at),
                _ => {}
            }
        }
        self.pending.push(PendingPosition { actor: index, relation, target });
    }

    /// The reference a `position_target` names: `ego`, an actor group, or a road element.
    fn reference(&mut self, part: &Part) -> Option<Symbol> {
        let word = part.word.as_deref().unwrap_or("");
        let normalized = normalize(word);
        if norm::is_ego(&normalized) {
            return Some(Symbol { name: "ego".into(), span: part.value_span });
        }
        let as_key = norm::identifier(word);
        let exact = self.actors.iter().find(|a| a.key == word.trim());
        let close = || self.actors.iter().find(|a| normalize(&a.key) == normalized || a.name.text == as_key);
        if let Some(actor) = exact.or_else(close) {
            return Some(Symbol { name: actor.name.text.clone(), span: part.value_span });
        }
        self.symbol_from("position_target", word, part.value_span, "ego_vehicle")
    }

    fn resolve_positions(&mut self) {
        for pending in std::mem::take(&mut self.pending) {
            let me = Target::Actor(pending.actor);
            let (relation, target) = (pending.relation, pending.target);
            let Some(first) = relation.clone().or(target.clone()) else { continue };
            let relation_word = relation.as_ref().and_then(|r| r.word.clone());
            let value = match relation_word {
                Some(word) => {
                    let relation_part = relation.clone().unwrap_or(first.clone());
                    let Some(rel) = self.symbol_from("position_relation", &word, relation_part.value_span, "front")
                    else {
                        continue;
                    };
                    let reference = match &target {
                        Some(t) if t.word.is_some() => match self.reference(t) {
                            Some(r) => r,
                            None => continue,
                        },
                        // the paper's actors are placed relative to the ego vehicle
                        _ => {
                            let end = relation_part.value_span.end;
                            Symbol { name: "ego".into(), span: Span::new(end, end) }
                        }
                    };
                    Known::Given(Val::Position(Position { relation: rel, reference }))
                }
                None => Known::Unspecified,
            };
            let key_span = first.key_span;
            let mut value_span = relation.as_ref().map_or(first.value_span, |r| r.value_span);
            if let Some(t) = &target
                && t.word.is_some()
                && relation.as_ref().is_some_and(|r| r.word.is_some())
            {
                value_span = value_span.to(t.value_span);
            }
            let key = if relation.is_some() { "position_relation" } else { "position_target" };
            let at = At { node: None, key_span, value_span };
            self.set(Claim { target: me, field: "position", key, at, rank: PAPER }, value, false);
        }
    }

    fn finish(&mut self) -> Module {
        let mut sections: Vec<Section> = std::mem::take(&mut self.sections)
            .into_iter()
            .map(|s| {
                let mut props = s.props;
                props.sort_by_key(|p| s.def.fields.iter().position(|f| f.name == p.def.name));
                Section {
                    def: s.def,
                    span: s.span,
                    name_span: s.name_span,
                    attrs: props.into_iter().map(attr).collect(),
                }
            })
            .collect();
        sections.sort_by_key(|s| schema::SECTIONS.iter().position(|d| d.name == s.def.name));
        let actors = std::mem::take(&mut self.actors)
            .into_iter()
            .map(|a| {
                let mut props = a.props;
                props.sort_by_key(|p| schema::ACTOR.fields.iter().position(|f| f.name == p.def.name));
                ActorGroup {
                    span: a.span,
                    kind: a.kind.unwrap_or(Spanned { value: Known::Unspecified, span: a.name.span }),
                    name: a.name,
                    count: a.count,
                    attrs: props.into_iter().map(attr).collect(),
                }
            })
            .collect();
        let mut scenario = Scenario { span: self.whole, name: self.name.take(), sections, actors };
        let rightmost = std::mem::take(&mut self.rightmost);
        self.diagnostics.extend(tad_syntax::lower::rightmost_lanes(&mut scenario, &rightmost));
        Module { uses: std::mem::take(&mut self.uses), declarations: Vec::new(), scenario: Some(scenario) }
    }
}

#[derive(Clone, Copy)]
enum Target {
    Section(usize),
    Actor(usize),
}

/// A key's claim on a field: the section or actor and the field it states, the key as written
/// and where it is, and how strongly it states the field ([`DERIVED`], [`PAPER`], [`EXTRA`]).
#[derive(Clone, Copy)]
struct Claim<'k> {
    target: Target,
    field: &'k str,
    key: &'k str,
    at: At,
    rank: u8,
}

fn attr(p: Prop) -> Attr {
    Attr { def: p.def, key_span: p.key_span, value_span: p.value_span, value: p.value }
}

fn known_map<T>(k: Known<T>, f: impl FnOnce(T) -> Val) -> Known<Val> {
    match k {
        Known::Given(v) => Known::Given(f(v)),
        Known::Unspecified => Known::Unspecified,
    }
}

/// An example value of a field, in the paper's spelling, for help messages.
fn field_example(target: Target, field: &str) -> &'static str {
    match (target, field) {
        (_, "weather") => "clear",
        (_, "time") => "daytime",
        (_, "type") => "straight road",
        (_, "context") => "urban",
        (_, "direction") => "two-way",
        (_, "light") => "green",
        (_, "signs") => "stop sign",
        (_, "special_lanes") => "bike lane",
        (_, "traffic") => "light",
        (_, "behavior") => "move forward",
        (_, "region") => "los angeles",
        (_, "hazards") => "accident",
        (_, "roadworks") => "lane closure",
        (_, "emergency_vehicles") => "ambulance",
        (_, "roadside") => "sidewalk",
        _ => "unspecified",
    }
}
