//! The paper's two YAML in-context examples (TrafficAlign's NL→DSL prompt) lower to the
//! scenarios of `examples/paper/nl_to_dsl_example_{1,2}.tad`, in everything the YAML says.

mod common;
use common::*;
use tad_syntax::model::*;

/// The YAML says `move forward`, the TAD example `move_forward`: the paper's word is the
/// canonical name, so the two agree as written.
fn canonical(name: &str) -> &str {
    name
}

fn same_value(a: &Known<Val>, b: &Known<Val>) -> bool {
    match (a, b) {
        (Known::Unspecified, Known::Unspecified) => true,
        (Known::Given(a), Known::Given(b)) => match (a, b) {
            (Val::Symbol(a), Val::Symbol(b)) => canonical(&a.name) == canonical(&b.name),
            (Val::Symbols(a), Val::Symbols(b)) => {
                a.iter().map(|s| &s.name).collect::<Vec<_>>() == b.iter().map(|s| &s.name).collect::<Vec<_>>()
            }
            (Val::Integer(a), Val::Integer(b)) => a == b,
            (Val::Quantity(a), Val::Quantity(b)) => a == b,
            (Val::Text(a), Val::Text(b)) => a == b,
            (Val::Position(a), Val::Position(b)) => {
                a.relation.name == b.relation.name && a.reference.name == b.reference.name
            }
            _ => false,
        },
        _ => false,
    }
}

fn fields(attrs: &[Attr]) -> Vec<&str> {
    attrs.iter().map(|a| a.def.name).collect()
}

/// The text a value span covers reads as the value.
fn span_reads_as(text: &str, attr: &Attr) {
    let written = &text[attr.value_span.start..attr.value_span.end];
    let ok = match &attr.value {
        Known::Unspecified => written == "unspecified",
        Known::Given(Val::Symbol(s)) => tad_yaml::norm::normalize(written) == s.name,
        Known::Given(Val::Symbols(list)) => list.is_empty() && written == "none",
        Known::Given(Val::Integer(n)) => written == n.to_string(),
        Known::Given(Val::Quantity(q)) => written == format!("{} {}", q.value, q.unit.as_str()),
        Known::Given(Val::Position(_)) => written.starts_with(&attr_relation(attr)),
        _ => true,
    };
    assert!(ok, "`{}` has value span `{written}` for {:?}", attr.def.name, attr.value);
    let key = &text[attr.key_span.start..attr.key_span.end];
    assert!(!key.is_empty() && !key.contains(':'), "key span `{key}`");
}

fn attr_relation(attr: &Attr) -> String {
    match &attr.value {
        Known::Given(Val::Position(p)) => p.relation.name.replace('_', " "),
        _ => String::new(),
    }
}

fn compare(answer_file: &str, tad_file: &str, expect: &[(&str, &[&str])], actors: &[&str]) {
    let answer = read(&repo().join(answer_file));
    let (model, diagnostics) = tad_yaml::lower(&answer);
    assert!(diagnostics.is_empty(), "{answer_file}: {diagnostics:?}");
    let (reference, tad_diagnostics) = tad_syntax::analyze(&read(&repo().join(tad_file)));
    assert!(errors(&tad_diagnostics).is_empty());
    let y = model.scenario.as_ref().unwrap();
    let t = reference.scenario.as_ref().unwrap();

    for (section, expected) in expect {
        let ys = y.section(section).unwrap_or_else(|| panic!("no `{section}`"));
        assert_eq!(fields(&ys.attrs), *expected, "fields of `{section}`");
        for attr in &ys.attrs {
            let theirs = t.attr(section, attr.def.name).unwrap_or_else(|| panic!("{section}.{}", attr.def.name));
            assert!(
                same_value(&attr.value, &theirs.value),
                "{section}.{}: {:?} vs {:?}",
                attr.def.name,
                attr.value,
                theirs.value
            );
            span_reads_as(&answer, attr);
        }
        // the section's span covers its YAML block
        assert!(answer[ys.name_span.start..ys.name_span.end].ends_with(if *section == "road" {
            "road_network"
        } else if *section == "ego" {
            "ego_vehicle"
        } else {
            section
        }));
    }
    assert_eq!(y.sections.len(), expect.len());

    let names: Vec<&str> = y.actors.iter().map(|a| a.name.text.as_str()).collect();
    assert_eq!(names, actors);
    for actor in &y.actors {
        let theirs = t.actor(&actor.name.text).unwrap();
        assert_eq!(actor.count(), theirs.count(), "{}: count", actor.name.text);
        assert_eq!(actor.kind.value.given().map(|k| &k.name), theirs.kind.value.given().map(|k| &k.name));
        assert_eq!(fields(&actor.attrs), ["behavior", "speed", "position", "lane"]);
        for attr in &actor.attrs {
            let other = theirs.attr(attr.def.name).unwrap();
            assert!(same_value(&attr.value, &other.value), "{}.{}", actor.name.text, attr.def.name);
            span_reads_as(&answer, attr);
        }
        assert_eq!(&answer[actor.name.span.start..actor.name.span.end], actor.name.text);
        let kind = &answer[actor.kind.span.start..actor.kind.span.end];
        assert_eq!(tad_yaml::norm::normalize(kind), actor.kind.value.given().unwrap().name);
    }
}

const ROAD: &[&str] = &["type", "context", "lanes", "direction", "signs", "light"];

#[test]
fn example_1_lowers_to_nl_to_dsl_example_1() {
    compare(
        "tests/yaml/paper/nl_to_dsl_example_1.yaml",
        "examples/paper/nl_to_dsl_example_1.tad",
        &[("environment", &["weather", "time"]), ("road", ROAD), ("ego", &["behavior", "speed", "lane"])],
        &["vehicle_in_front_1", "vehicle_in_front_2", "vehicles_opposite_direction"],
    );
}

#[test]
fn example_2_lowers_to_nl_to_dsl_example_2() {
    compare(
        "tests/yaml/paper/nl_to_dsl_example_2.yaml",
        "examples/paper/nl_to_dsl_example_2.tad",
        &[("environment", &["weather", "time"]), ("road", ROAD), ("ego", &["behavior", "speed", "lane"])],
        &["construction_vehicles", "traffic_worker"],
    );
}

#[test]
fn the_paper_examples_are_trafficalign() {
    let answer = read(&repo().join("tests/yaml/paper/nl_to_dsl_example_1.yaml"));
    assert_eq!(tad_yaml::dialect(&answer), Some(tad_yaml::Dialect::TrafficAlign));
}
