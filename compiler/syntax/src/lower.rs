//! Lowering: the concrete tree to the scenario model, checking structure on the way.
//!
//! Structure means what the schema ([`crate::schema`]) says: one scenario per file, known
//! sections and fields, each once, each value of the kind its field takes (a word of its
//! closed set, for a [`ValueType::Choice`] field), units that fit.
//! Every problem is a coded diagnostic, and lowering always goes on: a bad field is left
//! out of the model, a multi-word name is reported and then used joined, so one mistake
//! does not hide the next.

use crate::cst::{self, Name, Value, words_span};
use crate::lexer;
use crate::model::*;
use crate::schema::{self, ClosedSet, FieldDef, LaneWord, SectionDef, Unit, ValueType};
use crate::suggest;
use tad_diagnostics::{Applicability, Code, Diagnostic, Payload, Span};

pub fn lower(src: &str, file: &cst::File) -> (Module, Vec<Diagnostic>) {
    let mut lowerer = Lowerer {
        src,
        diagnostics: Vec::new(),
        groups: Default::default(),
        taken: Default::default(),
        next: Default::default(),
        rightmost: Vec::new(),
    };
    let module = lowerer.file(file);
    (module, lowerer.diagnostics)
}

struct Lowerer<'a> {
    src: &'a str,
    diagnostics: Vec<Diagnostic>,
    /// The scenario's actor groups by name, for duplicates without a quadratic search.
    groups: std::collections::HashMap<String, usize>,
    /// The names E0209's fixes may not give: every group's name in the scenario, and each
    /// name a fix has given, so that a name declared three times gets two different ones.
    taken: std::collections::HashSet<String>,
    /// Per redeclared name, the number its next rename tries first: every number below
    /// it is taken, so renaming many copies of a name stays linear.
    next: std::collections::HashMap<String, u32>,
    /// Where the scenario's `lane: rightmost` values are: the road's `lanes`, known once
    /// the whole scenario is read.
    rightmost: Vec<Span>,
}

impl Lowerer<'_> {
    fn report(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    fn file(&mut self, file: &cst::File) -> Module {
        let mut module = Module::default();
        let mut first: Option<Span> = None;
        for item in &file.items {
            match item {
                cst::Item::Use(u) => module.uses.push(u.clone()),
                cst::Item::Scenario(s) => match first {
                    None => {
                        first = Some(s.keyword);
                        module.scenario = Some(self.scenario(s));
                    }
                    Some(first) => self.report(
                        Diagnostic::new(Code::E0201, "a file holds one scenario", s.keyword, "a second scenario")
                            .with_payload(Payload::Duplicate {
                                namespace: "scenario".into(),
                                name: s.name.as_ref().map_or_else(String::new, |n| n.text.clone()),
                                earlier_module: None,
                            })
                            .with_secondary(first, "the file's scenario")
                            .with_help("move this scenario to a file of its own"),
                    ),
                },
                cst::Item::Declaration(d) => {
                    if let Some(declaration) = self.declaration(d, &module.declarations) {
                        module.declarations.push(declaration);
                    }
                }
                cst::Item::Error(_) => {}
            }
        }
        let recovered = file.items.iter().any(|i| matches!(i, cst::Item::Error(_) | cst::Item::Declaration(_)));
        if first.is_none() && !recovered {
            let end = self.src.len();
            self.report(
                Diagnostic::new(Code::E0200, "no scenario in this file", Span::new(end, end), "the file ends here")
                    .with_help("a file holds one `scenario NAME { ... }`")
                    .with_payload(Payload::Syntax { expected: vec!["`scenario NAME { ... }`".into()], found: None }),
            );
        }
        module
    }

    fn declaration(&mut self, d: &cst::Declaration, previous: &[Declaration]) -> Option<Declaration> {
        let Some(def) = schema::declaration(&d.kind.text) else {
            let diagnostic = Diagnostic::new(
                Code::E0213,
                format!("unknown declaration kind `{}`", d.kind.text),
                d.kind.span,
                "not a kind of declaration",
            );
            let candidates = schema::DECLARATIONS.iter().map(|k| k.name).chain(["scenario", "use"]);
            let (mut diagnostic, guessed) =
                suggest::unknown(diagnostic, "declaration_kind", &d.kind.text, d.kind.span, candidates);
            if !guessed {
                diagnostic = diagnostic.with_note(
                    "declarations are written `KIND NAME { ... }`; the kinds are listed in spec/vocabulary.md",
                );
            }
            self.report(diagnostic);
            return None;
        };
        if let Some(first) = previous.iter().find(|p| p.def.name == def.name && p.name.text == d.name.text) {
            self.report(
                Diagnostic::new(
                    Code::E0214,
                    format!("{} `{}` is declared twice", def.name, d.name.text),
                    d.name.span,
                    "declared again here",
                )
                .with_payload(Payload::Duplicate {
                    namespace: def.name.into(),
                    name: d.name.text.clone(),
                    earlier_module: None,
                })
                .with_secondary(first.name.span, "first declared here")
                .with_help("remove one of the declarations"),
            );
            return None;
        }
        let attrs = match &d.body {
            Some(body) => self.fields(def, &body.items),
            None => Vec::new(),
        };
        Some(Declaration { def, span: d.span, name: d.name.clone(), attrs })
    }

    fn scenario(&mut self, s: &cst::Scenario) -> Scenario {
        if s.name.is_none() {
            self.report(
                Diagnostic::new(Code::E0210, "this scenario has no name", s.keyword, "a name goes after `scenario`")
                    .with_help("write `scenario my_scenario { ... }`")
                    .with_payload(Payload::Syntax { expected: vec!["a name".into()], found: None })
                    .with_fix(Span::new(s.keyword.end, s.keyword.end), " unnamed", Applicability::HasPlaceholders),
            );
        }
        let mut scenario = Scenario { span: s.span, name: s.name.clone(), sections: Vec::new(), actors: Vec::new() };
        self.taken = s
            .body
            .items
            .iter()
            .filter_map(|m| match m {
                cst::Member::Actor(a) => Some(a.name.text.clone()),
                _ => None,
            })
            .collect();
        for member in &s.body.items {
            match member {
                cst::Member::Section(section) => self.section(section, &mut scenario),
                cst::Member::Actor(actor) => {
                    if let Some(group) = self.actor(actor, &scenario) {
                        self.groups.entry(group.name.text.clone()).or_insert(scenario.actors.len());
                        scenario.actors.push(group);
                    }
                }
                cst::Member::Error(_) => {}
            }
        }
        let pending = std::mem::take(&mut self.rightmost);
        self.diagnostics.extend(rightmost_lanes(&mut scenario, &pending));
        scenario
    }

    fn section(&mut self, section: &cst::Section, scenario: &mut Scenario) {
        let name = &section.name;
        let Some(def) = schema::section(&name.text) else {
            let d = Diagnostic::new(
                Code::E0202,
                format!("unknown section `{}`", name.text),
                name.span,
                "not a section of a scenario",
            );
            let (mut d, guessed) =
                suggest::unknown(d, "section", &name.text, name.span, schema::SECTIONS.iter().map(|s| s.name));
            if !guessed && ["actors", "actor_group", "npc", "npcs", "agents"].contains(&name.text.as_str()) {
                d = d.with_help("declare each group as `actor NAME: COUNT TYPE { ... }`");
            } else if !guessed {
                d = d
                    .with_note("the sections are `source`, `environment`, `road` and `ego`; groups are `actor` blocks");
            }
            self.report(d);
            return;
        };
        if let Some(previous) = scenario.section(def.name) {
            let first = previous.name_span;
            self.report(
                Diagnostic::new(
                    Code::E0204,
                    format!("section `{}` is given twice", def.name),
                    name.span,
                    "given again here",
                )
                .with_payload(Payload::Duplicate {
                    namespace: "section".into(),
                    name: def.name.into(),
                    earlier_module: None,
                })
                .with_secondary(first, "first given here")
                .with_help("merge the two sections into one"),
            );
            return;
        }
        if section.body.items.is_empty() {
            self.report(
                Diagnostic::new(Code::W0200, format!("section `{}` is empty", def.name), name.span, "has no fields")
                    .with_help("remove it, or add its fields")
                    .with_payload(Payload::Empty { section: def.name.into() })
                    .with_fix(section.span, "", Applicability::MachineApplicable),
            );
        }
        let attrs = self.fields(def, &section.body.items);
        scenario.sections.push(Section { def, span: section.span, name_span: name.span, attrs });
    }

    fn actor(&mut self, actor: &cst::Actor, scenario: &Scenario) -> Option<ActorGroup> {
        let name = &actor.name;
        if name.text == "ego" {
            self.report(
                Diagnostic::new(
                    Code::E0212,
                    "`ego` is reserved for the ego vehicle",
                    name.span,
                    "cannot name an actor group",
                )
                .with_payload(Payload::Reserved { name: "ego".into() })
                .with_help("describe the ego vehicle in the `ego { ... }` section, or rename this group"),
            );
        } else if let Some(previous) = self.groups.get(&name.text).map(|&i| &scenario.actors[i]) {
            // the next `NAME_N` no group of the scenario has and no other fix gives: a
            // rename the compiler can make (`car_2` again is `car_3`, not `car_2_2`)
            let (stem, last) = numbered(&name.text);
            let first = self.next.get(&name.text).copied().unwrap_or(last + 1);
            let n = (first..).find(|n| !self.taken.contains(&format!("{stem}_{n}"))).unwrap_or(first);
            let free = format!("{stem}_{n}");
            self.next.insert(name.text.clone(), n + 1);
            self.taken.insert(free.clone());
            self.report(
                Diagnostic::new(
                    Code::E0209,
                    format!("actor group `{}` is declared twice", name.text),
                    name.span,
                    "declared again here",
                )
                .with_payload(Payload::Duplicate {
                    namespace: "actor_group".into(),
                    name: name.text.clone(),
                    earlier_module: None,
                })
                .with_secondary(previous.name.span, "first declared here")
                .with_help(format!("give each group its own name, such as `{free}`"))
                .with_fix(name.span, free, Applicability::MachineApplicable),
            );
            return None;
        }
        let count = actor.count.as_ref().and_then(|value| {
            let span = value.span();
            let value = match value {
                Value::Unspecified(_) => Known::Unspecified,
                Value::Number { number, .. } => Known::Given(Count::Exactly(self.integer(*number, "count")?)),
                Value::Range { low, high, span } => {
                    let (lo, hi) = (self.integer(low.number, "count")?, self.integer(high.number, "count")?);
                    if lo > hi {
                        self.reversed("count", *span, (lo as f64, hi as f64), &format!("{hi}..{lo}"), None);
                        return None;
                    }
                    Known::Given(Count::Between(lo, hi))
                }
                _ => return None,
            };
            Some(Spanned { value, span })
        });
        let kind_value = match &actor.kind {
            Value::Words(words) => Known::Given(self.symbol_from_words(words)),
            _ => Known::Unspecified,
        };
        let kind = Spanned { value: kind_value, span: actor.kind.span() };
        let attrs = self.fields(&schema::ACTOR, &actor.body.items);
        Some(ActorGroup { span: actor.span, name: name.clone(), count, kind, attrs })
    }

    fn fields(&mut self, def: &'static SectionDef, entries: &[cst::Entry]) -> Vec<Attr> {
        let mut attrs: Vec<Attr> = Vec::new();
        for entry in entries {
            let cst::Entry::Field(field) = entry else {
                continue;
            };
            let key = &field.key;
            let Some(field_def) = def.field(&key.text) else {
                self.unknown_field(def, key);
                continue;
            };
            if let Some(previous) = attrs.iter().find(|a| a.def.name == field_def.name) {
                let first = previous.key_span;
                self.report(
                    Diagnostic::new(
                        Code::E0204,
                        format!("field `{}` is given twice", key.text),
                        key.span,
                        "given again here",
                    )
                    .with_payload(Payload::Duplicate {
                        namespace: "field".into(),
                        name: field_def.name.into(),
                        earlier_module: None,
                    })
                    .with_secondary(first, "first given here")
                    .with_help("keep one of the two"),
                );
                continue;
            }
            if let Some(value) = self.value(field_def, &field.value) {
                attrs.push(Attr { def: field_def, key_span: key.span, value_span: field.value.span(), value });
            }
        }
        attrs
    }

    fn unknown_field(&mut self, def: &SectionDef, key: &Name) {
        let d = Diagnostic::new(
            Code::E0203,
            format!("unknown field `{}` in `{}`", key.text, def.name),
            key.span,
            format!("`{}` has no such field", def.name),
        );
        let alias = schema::FIELD_ALIASES
            .iter()
            .find(|(from, to)| *from == key.text && def.field(to).is_some())
            .map(|(_, to)| *to);
        let (mut d, guessed) = match alias {
            // another notation's name for the field: certain
            Some(field) => (
                d.with_payload(Payload::Alias {
                    namespace: "field".into(),
                    written: key.text.clone(),
                    canonical: field.into(),
                })
                .with_help(format!("did you mean `{field}`?"))
                .with_fix(key.span, field, Applicability::MachineApplicable),
                true,
            ),
            None => suggest::unknown(d, "field", &key.text, key.span, def.fields.iter().map(|f| f.name)),
        };
        if !guessed {
            let owners: Vec<&str> = schema::SECTIONS
                .iter()
                .chain([&&schema::ACTOR])
                .filter(|s| s.field(&key.text).is_some())
                .map(|s| s.name)
                .collect();
            if def.name == "actor" && ["count", "number", "type", "kind"].contains(&key.text.as_str()) {
                d = d.with_help("the count and type of a group go in its header: `actor NAME: 3 sedan { ... }`");
            } else if !owners.is_empty() {
                d = d.with_help(format!(
                    "`{}` belongs in {}",
                    key.text,
                    owners.iter().map(|o| format!("`{o}`")).collect::<Vec<_>>().join(" or ")
                ));
            }
            let fields: Vec<String> = def.fields.iter().map(|f| format!("`{}`", f.name)).collect();
            d = d.with_note(format!("the fields of `{}` are {}", def.name, fields.join(", ")));
        }
        self.report(d);
    }

    /// Convert one value to what its field takes; `None` after reporting why not.
    fn value(&mut self, def: &'static FieldDef, value: &Value) -> Option<Known<Val>> {
        match value {
            Value::Unspecified(_) => return Some(Known::Unspecified),
            Value::Error(_) => return None,
            _ => {}
        }
        let val = match (def.ty, value) {
            (ValueType::Speed | ValueType::Duration | ValueType::Length, Value::Range { low, high, span })
                if def.param =>
            {
                self.quantity_range(def, *low, *high, *span)?
            }
            (ValueType::Symbol, Value::Choice { options, span }) if def.param => self.names_choice(def, options, *span),
            (
                ValueType::Speed | ValueType::Duration | ValueType::Length | ValueType::Integer,
                Value::Range { low, span, .. },
            ) => {
                let low_text = &self.src[low.span().start..low.span().end];
                self.report(
                    Diagnostic::new(
                        Code::E0205,
                        format!("`{}` takes a single value, not a range", def.name),
                        *span,
                        format!("expected {}", def.ty.describe()),
                    )
                    .with_payload(wrong(def.name, def.ty.describe(), "a range"))
                    .with_help(format!("write one value, for example `{}: {}`", def.name, def.example))
                    .with_fix(*span, low_text.to_string(), Applicability::MaybeIncorrect),
                );
                return None;
            }
            (ValueType::Symbol | ValueType::Choice(_), Value::Choice { options, span }) => {
                let first = join(options.first().map_or(&[][..], |o| o.as_slice()));
                self.report(
                    Diagnostic::new(
                        Code::E0205,
                        format!("`{}` takes one name, not a choice", def.name),
                        *span,
                        "expected a name",
                    )
                    .with_payload(wrong(def.name, "a name", "a choice of names"))
                    .with_help(format!("write one name, for example `{}: {first}`", def.name))
                    .with_fix(*span, first, Applicability::MaybeIncorrect),
                );
                return None;
            }
            (ValueType::Symbol, Value::Words(words)) => Val::Symbol(self.symbol_from_words(words)),
            (ValueType::SymbolList, Value::List { items, span }) => Val::Symbols(self.symbol_list(def, items, *span)?),
            (ValueType::SymbolList, Value::Words(words)) => {
                let symbol = self.symbol_from_words(words);
                let span = words_span(words);
                let none = symbol.name == "none";
                let (help, fix) = if none {
                    ("write `[]` for an empty list".to_string(), "[]".to_string())
                } else {
                    (format!("write a list: `[{}]`", symbol.name), format!("[{}]", symbol.name))
                };
                self.report(
                    Diagnostic::new(Code::E0208, format!("`{}` takes a list", def.name), span, "a single name")
                        .with_help(help)
                        .with_payload(wrong(def.name, "a list of names", &symbol.name))
                        .with_fix(span, fix, Applicability::MachineApplicable),
                );
                Val::Symbols(if none { Vec::new() } else { vec![symbol] })
            }
            (ValueType::Choice(words_of_set), Value::Words(words)) => {
                Val::Symbol(self.choice(def, words_of_set, words)?)
            }
            (ValueType::Flag, Value::Words(words))
                if words.len() == 1 && matches!(words[0].text.as_str(), "yes" | "no") =>
            {
                Val::Flag(words[0].text == "yes")
            }
            (ValueType::Integer, Value::Words(words))
                if def.name == "lane" && words.len() == 1 && LaneWord::parse(&words[0].text).is_some() =>
            {
                // leftmost is lane 1; rightmost waits for the road's lanes
                if LaneWord::parse(&words[0].text) == Some(LaneWord::Rightmost) {
                    self.rightmost.push(value.span());
                }
                Val::Integer(1)
            }
            (ValueType::Integer, Value::Number { number, unit, span }) => {
                if let Some(unit) = unit {
                    self.report(
                        Diagnostic::new(
                            Code::E0206,
                            format!("`{}` takes no unit", def.name),
                            *unit,
                            "remove this unit",
                        )
                        .with_payload(wrong(def.name, "a whole number", &self.src[unit.start..unit.end]))
                        .with_fix(
                            Span::new(number.end, span.end),
                            "",
                            Applicability::MachineApplicable,
                        ),
                    );
                }
                Val::Integer(self.integer(*number, def.name)?)
            }
            (ValueType::Speed | ValueType::Duration | ValueType::Length, Value::Number { number, unit, .. }) => {
                let q = self.quantity(def, *number, *unit)?;
                self.not_negative(def, q.value, *number)?;
                Val::Quantity(q)
            }
            (ValueType::Text, Value::String(span)) => {
                Val::Text(lexer::unescape(&self.src[span.start..span.end], span.start, &mut self.diagnostics))
            }
            (ValueType::Text, Value::TextBlock(span)) => {
                Val::Text(lexer::text_block_content(&self.src[span.start..span.end]))
            }
            (ValueType::Position, Value::Position { relation, reference, .. }) => Val::Position(Position {
                relation: self.symbol_from_words(relation),
                reference: self.symbol_from_words(reference),
            }),
            (ValueType::Position, Value::Words(words)) => {
                let span = words_span(words);
                self.report(
                    Diagnostic::new(Code::E0205, "a position needs a reference", span, "a relation alone")
                        .with_help(format!("say what it is relative to, e.g. `{} of ego`", join(words)))
                        .with_payload(wrong(def.name, "a position", &join(words)))
                        .with_fix(Span::new(span.end, span.end), " of ego", Applicability::MaybeIncorrect),
                );
                return None;
            }
            (expected, found) => {
                self.report(
                    Diagnostic::new(
                        Code::E0205,
                        format!("`{}` takes {}, found {}", def.name, expected.describe(), found.describe()),
                        found.span(),
                        format!("expected {}", expected.describe()),
                    )
                    .with_payload(wrong(def.name, expected.describe(), found.describe()))
                    .with_help(format!("for example `{}: {}`", def.name, def.example)),
                );
                return None;
            }
        };
        Some(Known::Given(val))
    }

    /// `LOW..HIGH UNIT` of a quantity field: one unit (written once after the range, or
    /// the same at both ends), `low <= high`, neither end negative where that means nothing.
    fn quantity_range(&mut self, def: &FieldDef, low: cst::Bound, high: cst::Bound, span: Span) -> Option<Val> {
        let text = |s: Span| self.src[s.start..s.end].to_string();
        let unit = match (low.unit, high.unit) {
            (None, Some(h)) => h,
            (Some(l), Some(h)) if text(l) == text(h) => h,
            (Some(l), Some(h)) => {
                self.report(
                    Diagnostic::new(
                        Code::E0206,
                        format!("the ends of a range are in one unit, not `{}` and `{}`", text(l), text(h)),
                        l,
                        "another unit than the upper end's",
                    )
                    .with_secondary(h, "the upper end's unit")
                    .with_payload(wrong(def.name, &format!("both ends in `{}`", text(h)), &text(l)))
                    .with_help(format!(
                        "convert the lower end to `{}` and write the unit once, after the range",
                        text(h)
                    )),
                );
                return None;
            }
            (Some(l), None) => {
                let canonical = format!("{}..{} {}", text(low.number), text(high.number), text(l));
                self.report(
                    Diagnostic::new(
                        Code::E0206,
                        format!("the unit of a range goes after it: `{canonical}`"),
                        l,
                        "the upper end has no unit",
                    )
                    .with_payload(wrong(def.name, &canonical, &text(span)))
                    .with_help(format!("write `{canonical}`"))
                    .with_fix(span, canonical, Applicability::MachineApplicable),
                );
                return None;
            }
            (None, None) => {
                // reported as a value without a unit, with the unit added after the range
                self.quantity(def, high.number, None);
                return None;
            }
        };
        let lo = self.quantity(def, low.number, Some(unit))?;
        let hi = self.quantity(def, high.number, Some(unit))?;
        self.not_negative(def, lo.value, low.number)?;
        if lo.value > hi.value {
            let swapped = format!("{}..{} {}", text(high.number), text(low.number), text(unit));
            self.reversed(def.name, span, (lo.value, hi.value), &swapped, Some(lo.unit.as_str()));
            return None;
        }
        Some(Val::Range(lo, hi))
    }

    /// E0215: a range whose lower end is above its upper end; the fix swaps them.
    fn reversed(&mut self, field: &str, span: Span, (low, high): (f64, f64), swapped: &str, unit: Option<&str>) {
        self.report(
            Diagnostic::new(
                Code::E0215,
                format!("the range of `{field}` is reversed: its lower end is above its upper end"),
                span,
                "empty: nothing lies between these ends",
            )
            .with_payload(Payload::OutOfRange {
                quantity: field.into(),
                value: low,
                min: None,
                max: Some(high),
                unit: unit.map(str::to_string),
            })
            .with_help(format!("write the lower end first: `{swapped}`"))
            .with_fix(span, swapped.to_string(), Applicability::MachineApplicable),
        );
    }

    /// E0216: a distance, delay or trigger distance below 0 (speeds are the checker's; a
    /// signed field such as `offset` may be negative).
    fn not_negative(&mut self, def: &FieldDef, value: f64, number: Span) -> Option<()> {
        if value >= 0.0 || !def.param || def.signed || def.ty == ValueType::Speed {
            return Some(());
        }
        let unit = if def.ty == ValueType::Duration { "s" } else { "m" };
        let text = &self.src[number.start..number.end];
        self.report(
            Diagnostic::new(Code::E0216, format!("`{}` is not negative, found `{text}`", def.name), number, "below 0")
                .with_payload(Payload::OutOfRange {
                    quantity: def.name.into(),
                    value,
                    min: Some(0.0),
                    max: None,
                    unit: Some(unit.into()),
                })
                .with_help(format!("`{}` is {}; write `{}`", def.name, def.doc, text.trim_start_matches('-')))
                .with_fix(number, text.trim_start_matches('-').to_string(), Applicability::MaybeIncorrect),
        );
        None
    }

    /// `a | b | c` for a name field that takes a choice; a name given twice is W0201.
    fn names_choice(&mut self, def: &FieldDef, options: &[Vec<Name>], span: Span) -> Val {
        let mut symbols: Vec<Symbol> = Vec::new();
        let mut duplicate = None;
        for words in options {
            let symbol = self.symbol_from_words(words);
            if symbols.iter().any(|s| s.name == symbol.name) {
                duplicate.get_or_insert(symbol);
            } else {
                symbols.push(symbol);
            }
        }
        if let Some(again) = duplicate {
            let deduped = symbols.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(" | ");
            self.report(
                Diagnostic::new(
                    Code::W0201,
                    format!("the choice of `{}` names `{}` twice", def.name, again.name),
                    again.span,
                    "already a choice",
                )
                .with_help(format!("write `{deduped}`"))
                .with_payload(Payload::Duplicate {
                    namespace: def.name.into(),
                    name: again.name.clone(),
                    earlier_module: None,
                })
                .with_fix(span, deduped, Applicability::MachineApplicable),
            );
        }
        if symbols.len() == 1 { Val::Symbol(symbols.remove(0)) } else { Val::Choice(symbols) }
    }

    fn symbol_from_words(&mut self, words: &[Name]) -> Symbol {
        let span = words_span(words);
        let name = join(words);
        if words.len() > 1 {
            self.report(
                Diagnostic::new(
                    Code::E0207,
                    format!(
                        "`{}` is several words",
                        words.iter().map(|w| w.text.as_str()).collect::<Vec<_>>().join(" ")
                    ),
                    span,
                    "a name is one word",
                )
                .with_help(format!("join the words with `_`: `{name}`"))
                .with_payload(wrong("name", "one word", &self.src[span.start..span.end]))
                .with_fix(span, name.clone(), Applicability::MachineApplicable),
            );
        }
        Symbol { name, span }
    }

    /// A word of a closed set; another word is reported with the closest of the set.
    fn choice(&mut self, def: &FieldDef, set: &'static [&'static str], words: &[Name]) -> Option<Symbol> {
        let symbol = self.symbol_from_words(words);
        if set.contains(&symbol.name.as_str()) {
            return Some(symbol);
        }
        let listed = set.iter().map(|w| format!("`{w}`")).collect::<Vec<_>>().join(", ");
        let d = Diagnostic::new(
            Code::E0205,
            format!("`{}` does not take `{}`", def.name, symbol.name),
            symbol.span,
            "not one of its words",
        )
        .with_note(format!("`{}` takes {listed}", def.name));
        let (d, _) = suggest::unknown(d, def.name, &symbol.name, symbol.span, set.iter().copied());
        self.report(d);
        None
    }

    fn symbol_list(&mut self, def: &FieldDef, items: &[Value], span: Span) -> Option<Vec<Symbol>> {
        let mut symbols: Vec<Symbol> = Vec::new();
        let mut duplicate = None;
        for item in items {
            match item {
                Value::Words(words) => {
                    let symbol = self.symbol_from_words(words);
                    if symbols.iter().any(|s| s.name == symbol.name) {
                        duplicate.get_or_insert(symbol.span);
                    } else {
                        symbols.push(symbol);
                    }
                }
                Value::Error(_) => {}
                other => self.report(
                    Diagnostic::new(
                        Code::E0205,
                        format!("`{}` lists names, found {}", def.name, other.describe()),
                        other.span(),
                        "expected a name",
                    )
                    .with_payload(wrong(def.name, "a name", other.describe()))
                    .with_help(format!("for example `{}: {}`", def.name, def.example)),
                ),
            }
        }
        if let Some(at) = duplicate {
            let deduped = format!("[{}]", symbols.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", "));
            self.report(
                Diagnostic::new(Code::W0201, format!("`{}` lists a name twice", def.name), at, "already listed")
                    .with_help(format!("write `{deduped}`"))
                    .with_payload(Payload::Duplicate {
                        namespace: def.name.into(),
                        name: self.src[at.start..at.end].to_string(),
                        earlier_module: None,
                    })
                    .with_fix(span, deduped, Applicability::MachineApplicable),
            );
        }
        Some(symbols)
    }

    fn integer(&mut self, number: Span, what: &str) -> Option<i64> {
        let text = &self.src[number.start..number.end];
        if let Some((whole, fraction)) = text.split_once('.') {
            let mut d = Diagnostic::new(
                Code::E0211,
                format!("`{what}` takes a whole number, found `{text}`"),
                number,
                "not a whole number",
            )
            .with_payload(wrong(what, "a whole number", text));
            if fraction.bytes().all(|b| b == b'0') {
                d = d.with_help(format!("write `{whole}`")).with_fix(number, whole, Applicability::MachineApplicable);
            }
            self.report(d);
            return None;
        }
        match text.parse::<i64>() {
            Ok(n) => Some(n),
            Err(_) => {
                self.report(
                    Diagnostic::new(Code::E0005, format!("number `{text}` is out of range"), number, "too large")
                        .with_payload(wrong(what, "a number that fits in 64 bits", text)),
                );
                None
            }
        }
    }

    fn quantity(&mut self, def: &FieldDef, number: Span, unit: Option<Span>) -> Option<Quantity> {
        let text = &self.src[number.start..number.end];
        let value: f64 = match text.parse() {
            Ok(v) if f64::is_finite(v) => v,
            _ => {
                self.report(
                    Diagnostic::new(Code::E0005, format!("number `{text}` is out of range"), number, "too large")
                        .with_payload(wrong(def.name, "a finite number", text)),
                );
                return None;
            }
        };
        let (default, units) = match def.ty {
            ValueType::Speed => ("km/h", "`km/h`, `mph` and `m/s`"),
            ValueType::Duration => ("s", "`s`"),
            _ => ("m", "`m`"),
        };
        let Some(unit_span) = unit else {
            self.report(
                Diagnostic::new(
                    Code::E0206,
                    format!("`{}` needs a unit", def.name),
                    number,
                    format!("{} without a unit", def.ty.describe()),
                )
                .with_help(format!("write `{text} {default}`; the units are {units}"))
                .with_payload(wrong(def.name, def.ty.describe(), text))
                .with_fix(
                    Span::new(number.end, number.end),
                    format!(" {default}"),
                    Applicability::MaybeIncorrect,
                ),
            );
            return None;
        };
        let unit_text = &self.src[unit_span.start..unit_span.end];
        let unit = Unit::parse(unit_text)?;
        if unit.measures() != def.ty {
            self.report(
                Diagnostic::new(
                    Code::E0206,
                    format!(
                        "`{}` takes {}, but `{unit_text}` measures {}",
                        def.name,
                        def.ty.describe(),
                        unit.measures().describe().trim_start_matches("a ")
                    ),
                    unit_span,
                    format!("not a unit of {}", def.ty.describe().trim_start_matches("a ")),
                )
                .with_payload(wrong(def.name, def.ty.describe(), unit_text))
                .with_help(format!("the units of {} are {units}", def.ty.describe().trim_start_matches("a "))),
            );
            return None;
        }
        Some(Quantity { value, unit })
    }
}

/// The scenario's `lane: rightmost` values (at the value spans `at`) become the road's
/// `lanes`: a word whose number depends on the whole scenario, so it is resolved after
/// the scenario is read (by this lowering and by the YAML importer). Without the road's
/// `lanes` it is E0217 and the lane is left unspecified.
pub fn rightmost_lanes(scenario: &mut Scenario, at: &[Span]) -> Vec<Diagnostic> {
    let mut diagnostics = Vec::new();
    if at.is_empty() {
        return diagnostics;
    }
    let lanes = scenario.attr("road", "lanes").and_then(Attr::integer).filter(|n| *n > 0);
    let attrs = scenario.sections.iter_mut().flat_map(|s| &mut s.attrs);
    let attrs = attrs.chain(scenario.actors.iter_mut().flat_map(|g| &mut g.attrs));
    for attr in attrs.filter(|a| a.def.name == "lane" && at.contains(&a.value_span)) {
        match lanes {
            Some(lanes) => attr.value = Known::Given(Val::Integer(lanes)),
            None => {
                attr.value = Known::Unspecified;
                diagnostics.push(
                    Diagnostic::new(
                        Code::E0217,
                        "`rightmost` needs the road's number of lanes",
                        attr.value_span,
                        "which lane this is depends on `road { lanes }`",
                    )
                    .with_payload(wrong("lane", "a whole number", "rightmost"))
                    .with_help("give the road's `lanes`, or write the lane's number"),
                );
            }
        }
    }
    diagnostics
}

fn wrong(field: &str, expected: &str, found: &str) -> Payload {
    Payload::WrongValue { field: field.into(), expected: expected.into(), found: found.into() }
}

/// A name's stem and number: `car_2` is `car` and 2, `car` is `car` and 1.
fn numbered(name: &str) -> (&str, u32) {
    match name.rsplit_once('_') {
        Some((stem, n)) if !stem.is_empty() && !n.starts_with('0') => match n.parse::<u32>() {
            Ok(n) if n < u32::MAX / 2 => (stem, n),
            _ => (name, 1),
        },
        _ => (name, 1),
    }
}

fn join(words: &[Name]) -> String {
    words.iter().map(|w| w.text.as_str()).collect::<Vec<_>>().join("_")
}

#[cfg(test)]
mod tests {
    use tad_diagnostics::Code;

    #[test]
    fn a_duplicate_group_is_renamed_to_a_name_no_group_has() {
        let src = "scenario demo {\n  actor parked: 2 car {\n  }\n  actor parked: 3 suv {\n  }\n  actor parked_2: 1 van {\n  }\n}\n";
        let (_, diagnostics) = crate::analyze(src);
        let duplicate = diagnostics.iter().find(|d| d.code == Code::E0209).expect("E0209");
        assert_eq!(duplicate.fixes[0].replacement, "parked_3");
        let (fixed, applied) = tad_diagnostics::apply_fixes(src, &diagnostics);
        assert_eq!(applied, 1);
        assert!(fixed.contains("actor parked_3: 3 suv"), "{fixed}");
        let (module, after) = crate::analyze(&fixed);
        assert!(after.iter().all(|d| d.code != Code::E0209), "{after:?}");
        assert_eq!(module.scenario.unwrap().actors.len(), 3);
    }

    #[test]
    fn a_name_declared_three_times_gets_two_different_renames() {
        let group = |n: u32| format!("  actor car_2: {n} car {{\n  }}\n");
        let src = format!("scenario demo {{\n{}{}{}  actor car_3: 1 van {{\n  }}\n}}\n", group(1), group(2), group(3));
        let (_, diagnostics) = crate::analyze(&src);
        let renames: Vec<_> =
            diagnostics.iter().filter(|d| d.code == Code::E0209).map(|d| d.fixes[0].replacement.as_str()).collect();
        assert_eq!(renames, ["car_4", "car_5"]);
        let (fixed, applied) = tad_diagnostics::apply_fixes(&src, &diagnostics);
        assert_eq!(applied, 2);
        let (module, after) = crate::analyze(&fixed);
        assert!(after.is_empty(), "{after:?}");
        assert_eq!(module.scenario.unwrap().actors.len(), 4);
    }

    #[test]
    fn a_rename_counts_on_from_the_names_number() {
        assert_eq!(super::numbered("car_2"), ("car", 2));
        assert_eq!(super::numbered("car"), ("car", 1));
        assert_eq!(super::numbered("bus_ahead"), ("bus_ahead", 1));
        // not a count: a leading zero, no stem, a number with no room above it
        assert_eq!(super::numbered("car_07"), ("car_07", 1));
        assert_eq!(super::numbered("_2"), ("_2", 1));
        assert_eq!(super::numbered("car_4294967295"), ("car_4294967295", 1));
    }
}
