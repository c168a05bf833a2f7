//! Document symbols and folding ranges.
//!
//! For TAD both come from the concrete tree (it keeps every block's braces, even in a
//! document with errors) with the model's facts for details (`4 pedestrian · cross`); a
//! YAML answer's outline comes from the model, whose spans point into the YAML. Folds are
//! the blocks that span lines, runs of `//` comment lines, and text blocks.

use tad_syntax::cst::{self, Entry, Item, Member};
use tad_syntax::lexer::Token;
use tad_syntax::model::{Known, Module};

use crate::{Database, Language, SourceFile, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SymbolKind {
    Scenario,
    Section,
    Group,
    Field,
    Declaration,
    Module,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Symbol {
    pub name: String,
    pub detail: Option<String>,
    pub kind: SymbolKind,
    /// The whole construct.
    pub span: Span,
    /// Its name.
    pub selection: Span,
    pub children: Vec<Symbol>,
}

fn leaf(name: &str, detail: Option<String>, kind: SymbolKind, span: Span, selection: Span) -> Symbol {
    Symbol { name: name.to_string(), detail, kind, span, selection, children: Vec::new() }
}

fn fields(text: &str, entries: &[Entry]) -> Vec<Symbol> {
    entries
        .iter()
        .filter_map(|e| match e {
            Entry::Field(f) => {
                let value = text.get(f.value.span().start..f.value.span().end).unwrap_or("");
                let value = value.lines().next().unwrap_or("").trim();
                Some(leaf(&f.key.text, Some(value.to_string()), SymbolKind::Field, f.span, f.key.span))
            }
            Entry::Error(_) => None,
        })
        .collect()
}

/// `4 pedestrian · cross`: a group's count, type and behavior.
fn group_detail(module: &Module, name: &str) -> Option<String> {
    let group = module.scenario.as_ref()?.actor(name)?;
    let count = group.count.as_ref().map_or("1".to_string(), |c| match &c.value {
        Known::Given(c) => c.to_string(),
        Known::Unspecified => "unspecified".into(),
    });
    let kind = group.kind.value.given().map_or("unspecified", |k| k.name.as_str());
    let behavior =
        group.attr("behavior").and_then(|a| a.symbol()).map(|b| format!(" · {}", b.name)).unwrap_or_default();
    Some(format!("{count} {kind}{behavior}"))
}

pub fn symbols(db: &Database, file: SourceFile) -> Vec<Symbol> {
    let module = &tad_db::analyze(db, file).module;
    if file.language(db) == Language::Yaml {
        return from_model(module);
    }
    let text = file.text(db);
    let parsed = tad_syntax::parse(text);
    let mut out = Vec::new();
    for item in &parsed.file.items {
        match item {
            Item::Use(u) => {
                let name = u.path.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(".");
                let selection = u.path.first().map_or(u.span, |f| f.span.to(u.path.last().map_or(f.span, |l| l.span)));
                out.push(leaf(&name, Some("use".into()), SymbolKind::Module, u.span, selection));
            }
            Item::Declaration(d) => {
                let mut symbol =
                    leaf(&d.name.text, Some(d.kind.text.clone()), SymbolKind::Declaration, d.span, d.name.span);
                symbol.children = d.body.as_ref().map(|b| fields(text, &b.items)).unwrap_or_default();
                out.push(symbol);
            }
            Item::Scenario(s) => {
                let name = s.name.as_ref().map_or("scenario", |n| n.text.as_str());
                let selection = s.name.as_ref().map_or(s.keyword, |n| n.span);
                let mut symbol = leaf(name, Some("scenario".into()), SymbolKind::Scenario, s.span, selection);
                for member in &s.body.items {
                    match member {
                        Member::Section(section) => {
                            let mut child =
                                leaf(&section.name.text, None, SymbolKind::Section, section.span, section.name.span);
                            child.children = fields(text, &section.body.items);
                            symbol.children.push(child);
                        }
                        Member::Actor(actor) => {
                            let detail = group_detail(module, &actor.name.text);
                            let mut child =
                                leaf(&actor.name.text, detail, SymbolKind::Group, actor.span, actor.name.span);
                            child.children = fields(text, &actor.body.items);
                            symbol.children.push(child);
                        }
                        Member::Error(_) => {}
                    }
                }
                out.push(symbol);
            }
            Item::Error(_) => {}
        }
    }
    out
}

fn from_model(module: &Module) -> Vec<Symbol> {
    let Some(scenario) = &module.scenario else { return Vec::new() };
    let attrs = |attrs: &[tad_syntax::model::Attr]| -> Vec<Symbol> {
        attrs
            .iter()
            .map(|a| leaf(a.def.name, None, SymbolKind::Field, a.key_span.to(a.value_span), a.key_span))
            .collect()
    };
    let mut children: Vec<Symbol> = scenario
        .sections
        .iter()
        .map(|s| Symbol {
            children: attrs(&s.attrs),
            ..leaf(s.def.name, None, SymbolKind::Section, s.span, s.name_span)
        })
        .collect();
    children.extend(scenario.actors.iter().map(|g| Symbol {
        children: attrs(&g.attrs),
        ..leaf(&g.name.text, group_detail(module, &g.name.text), SymbolKind::Group, g.span, g.name.span)
    }));
    let name = scenario.name.as_ref().map_or("scenario", |n| n.text.as_str());
    let selection = scenario.name.as_ref().map_or(scenario.span, |n| n.span);
    vec![Symbol { children, ..leaf(name, Some("scenario".into()), SymbolKind::Scenario, scenario.span, selection) }]
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FoldKind {
    Block,
    Comment,
    Text,
}

/// A foldable region, from the line of `span.start` to the line of `span.end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Fold {
    pub span: Span,
    pub kind: FoldKind,
}

pub fn folding(db: &Database, file: SourceFile) -> Vec<Fold> {
    if file.language(db) != Language::Tad {
        return Vec::new();
    }
    let text = file.text(db);
    let multiline = |span: Span| text.get(span.start..span.end).is_some_and(|t| t.contains('\n'));
    let mut out = Vec::new();
    let parsed = tad_syntax::parse(text);
    let block = |body: Span, out: &mut Vec<Fold>| {
        if multiline(body) {
            out.push(Fold { span: body, kind: FoldKind::Block });
        }
    };
    for item in &parsed.file.items {
        match item {
            Item::Declaration(cst::Declaration { body: Some(b), .. }) => block(b.span(), &mut out),
            Item::Scenario(s) => {
                block(s.body.span(), &mut out);
                for member in &s.body.items {
                    match member {
                        Member::Section(section) => block(section.body.span(), &mut out),
                        Member::Actor(actor) => block(actor.body.span(), &mut out),
                        Member::Error(_) => {}
                    }
                }
            }
            _ => {}
        }
    }
    // runs of comment lines
    let mut run: Option<Span> = None;
    for comment in &parsed.comments {
        let follows = run.is_some_and(|r| {
            text.get(r.end..comment.start).is_some_and(|gap| gap.trim().is_empty() && gap.matches('\n').count() == 1)
        });
        run = match run {
            Some(r) if follows => Some(r.to(*comment)),
            Some(r) => {
                if multiline(r) {
                    out.push(Fold { span: r, kind: FoldKind::Comment });
                }
                Some(*comment)
            }
            None => Some(*comment),
        };
    }
    if let Some(r) = run.filter(|r| multiline(*r)) {
        out.push(Fold { span: r, kind: FoldKind::Comment });
    }
    for (s, token, e) in &tad_syntax::lexer::lex(text).tokens {
        if *token == Token::TextBlock && multiline(Span::new(*s, *e)) {
            out.push(Fold { span: Span::new(*s, *e), kind: FoldKind::Text });
        }
    }
    out.sort_by_key(|f| (f.span.start, f.span.end));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    const EXAMPLE: &str = include_str!("../../../examples/safety/right_turn.tad");

    #[test]
    fn the_outline_of_an_example() {
        let (db, file) = testing::file(EXAMPLE);
        let found = symbols(&db, file);
        assert_eq!(found.len(), 1);
        let scenario = &found[0];
        assert_eq!(scenario.name, "right_turn");
        let names: Vec<&str> = scenario.children.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            ["source", "environment", "road", "ego", "left_turning_taxi", "crossing_pedestrians", "through_cars"]
        );
        let walkers = &scenario.children[5];
        assert_eq!(walkers.detail.as_deref(), Some("4 pedestrian · cross"));
        assert_eq!(walkers.children.len(), 4);
        assert!(walkers.span.contains(walkers.selection));
    }

    #[test]
    fn folds_blocks_comments_and_text() {
        let (db, file) = testing::file(EXAMPLE);
        let folds = folding(&db, file);
        let kinds = |k| folds.iter().filter(|f| f.kind == k).count();
        assert_eq!(kinds(FoldKind::Block), 8, "the scenario, 4 sections, 3 groups: {folds:?}");
        assert_eq!(kinds(FoldKind::Comment), 1);
        assert_eq!(kinds(FoldKind::Text), 1);
    }

    #[test]
    fn broken_documents_and_yaml() {
        let (db, file) = testing::file("// é\nscenario demo {\n  road {\n    lanes: 2\n  actor a: car {\n");
        assert_eq!(symbols(&db, file).len(), 1);
        let _ = folding(&db, file);
        let yaml = "Scenario:\n  Environment:\n    Weather: sunny\n    Time: day\n";
        let (db, file) = testing::with_language(yaml, Language::Yaml);
        let found = symbols(&db, file);
        assert_eq!(found[0].children[0].name, "environment");
    }
}
