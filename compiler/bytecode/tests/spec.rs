//! `spec/bytecode.md` against the code: the opcode table, the tag tables, the version and
//! the listing excerpt are what the crate does.

mod common;

use tad_bytecode::format::{self, Op, Tag};
use tad_bytecode::{FORMAT_VERSION, Light};
use tad_road::{Arm, Body, Place, Turn};

fn spec() -> String {
    std::fs::read_to_string(tad_test_support::repo().join("spec/bytecode.md")).expect("spec/bytecode.md")
}

fn cells(line: &str) -> Vec<String> {
    line.trim().trim_matches('|').split('|').map(|c| c.trim().to_string()).collect()
}

#[test]
fn the_opcode_table_is_the_crates() {
    let spec = spec();
    let rows: Vec<Vec<String>> = spec.lines().filter(|l| l.starts_with("| `0x")).map(cells).collect();
    assert_eq!(rows.len(), Op::ALL.len(), "one row per opcode");
    for (row, op) in rows.iter().zip(Op::ALL) {
        assert_eq!(row[0], format!("`{:#04x}`", *op as u8), "{row:?}");
        assert_eq!(row[1], format!("`{}`", op.mnemonic()), "{row:?}");
        assert_eq!(row[3], if op.blocks() { "yes" } else { "no" }, "{row:?}");
    }
}

/// `0 `ego`, 1 `left`, ...` from the tag table's row for `set`.
fn tags(spec: &str, set: &str) -> Vec<(u8, String)> {
    let row = spec.lines().find(|l| l.starts_with(&format!("| {set} |"))).unwrap_or_else(|| panic!("no row {set}"));
    cells(row)[1]
        .split(", ")
        .map(|t| {
            let (n, name) = t.split_once(' ').unwrap();
            (n.parse().unwrap(), name.trim_matches('`').to_string())
        })
        .collect()
}

fn check<T: Tag>(spec: &str, set: &str, all: &[T], name: fn(T) -> &'static str) {
    let rows = tags(spec, set);
    assert_eq!(rows.len(), all.len(), "{set}");
    for (n, written) in rows {
        let t = T::from_tag(n).unwrap_or_else(|| panic!("{set}: no tag {n}"));
        assert_eq!(name(t), written, "{set} {n}");
        assert_eq!(t.tag(), n);
    }
}

#[test]
fn the_tag_tables_are_the_crates() {
    let spec = spec();
    check(&spec, "arm", &Arm::ALL, format::arm_name);
    check(&spec, "turn", &[Turn::Straight, Turn::Left, Turn::Right, Turn::UTurn], format::turn_name);
    check(&spec, "body", &[Body::Vehicle, Body::Walker, Body::Object], format::body_name);
    check(&spec, "place", &[Place::Lane, Place::Curb, Place::Shoulder, Place::Sidewalk], format::place_name);
    check(&spec, "light (a phase)", &[Light::Off, Light::Red, Light::Yellow, Light::Green], format::light_name);
}

#[test]
fn the_version_and_the_listing_excerpt_are_the_crates() {
    let spec = spec();
    assert!(spec.contains(&format!("| 4 | 2 | `u16` format version: {FORMAT_VERSION} (§7) |")));
    assert!(spec.contains(&format!("The format version is {FORMAT_VERSION} (`tad_bytecode::FORMAT_VERSION`)")));
    let start = spec.find("```text\n; TADSL bytecode").expect("the listing excerpt");
    let block = &spec[start + 8..];
    let block = &block[..block.find("```").unwrap()];
    let listing = tad_bytecode::disasm(&common::program(&common::example("red_light_running")));
    let listing = listing.replace(&tad_test_support::repo().display().to_string(), "");
    for line in block.lines() {
        assert!(listing.lines().any(|l| l == line), "`{line}` is not in the listing:\n{listing}");
    }
}
