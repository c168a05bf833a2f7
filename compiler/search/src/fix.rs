//! A scenario's source with its parameters fixed: each slot's value written back into the
//! field it came from, in the unit the field was written in, then formatted.
//!
//! Slots are named by the bytecode's lowering (`spec/bytecode.md` §5.4): `GROUP.speed`,
//! `GROUP.delay`, `GROUP.trigger` and `ego.speed` replace the written range.
//! `GROUP.shift`, `GROUP.spread` (the layout's free room) and `GROUP.offset` are where the
//! group stands; they become the group's `offset` field, which moves it along its lane after
//! the layout and takes the slot's place. Because the layout of the rewritten scenario
//! may place a group elsewhere (a fixed speed is laid out as itself, a range as its upper
//! end), the rewritten source is compiled once and every group's `offset` set so that its
//! first actor stands exactly where it stood in the searched scene.

use std::collections::BTreeMap;
use std::fmt;

use tad_bytecode::{Instr, ParamSlot, Program};
use tad_syntax::model::{Attr, Scenario, Val};
use tad_syntax::schema::Unit;

/// Why a source could not be rewritten.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FixError {
    /// The source holds no scenario, or does not parse.
    NoScenario,
    /// A slot names a group or field the source does not have (the source changed since
    /// it was compiled).
    UnknownSlot { slot: String },
    /// Slots and values differ in number.
    Mismatch { slots: usize, values: usize },
    /// The rewritten source does not compile.
    Recompile,
}

impl fmt::Display for FixError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FixError::NoScenario => f.write_str("the source holds no scenario that parses"),
            FixError::UnknownSlot { slot } => {
                write!(f, "parameter `{slot}` has no field in the source (was the file changed since it ran?)")
            }
            FixError::Mismatch { slots, values } => write!(f, "{values} values for {slots} parameters"),
            FixError::Recompile => f.write_str("the scenario with fixed parameters does not compile"),
        }
    }
}

impl std::error::Error for FixError {}

/// `src`, whose program is `searched`, with every slot fixed to its value (SI: m/s, m, s)
/// and every group where the searched scene had it; `compile` turns a source into its
/// program as the caller does (the same vocabulary and modules).
pub fn fix(
    src: &str,
    searched: &Program,
    values: &[f64],
    compile: &dyn Fn(&str) -> Option<Program>,
) -> Result<String, FixError> {
    let slots = &searched.params;
    if slots.len() != values.len() {
        return Err(FixError::Mismatch { slots: slots.len(), values: values.len() });
    }
    let (module, _) = tad_syntax::analyze(src);
    let scenario = module.scenario.as_ref().ok_or(FixError::NoScenario)?;
    // the written offsets: fixed ones as written, searched ones at their values
    let mut offsets: BTreeMap<String, f64> = BTreeMap::new();
    for a in &scenario.actors {
        if let Some(Val::Quantity(q)) = a.attr("offset").and_then(|x| x.value.given()) {
            offsets.insert(a.name.text.clone(), q.si());
        }
    }
    for (slot, &value) in slots.iter().zip(values) {
        if let Some((group, "shift" | "spread" | "offset")) = slot.name.rsplit_once('.') {
            offsets.insert(group.to_string(), value);
        }
    }
    let first = rewrite(src, scenario, slots, values, &offsets)?;
    let program = compile(&first).ok_or(FixError::Recompile)?;
    // where each group's first actor stood, and where it stands now
    let stands = |p: &Program, params: &[f64]| -> BTreeMap<String, f64> {
        p.code
            .iter()
            .filter_map(|i| match i {
                Instr::Spawn { group, index: 0, along, .. } => Some((group.clone(), along.eval(params))),
                _ => None,
            })
            .collect()
    };
    let now = stands(&program, &[]);
    let mut moved = false;
    for (group, along) in stands(searched, values) {
        let Some(&at) = now.get(&group) else { continue };
        if (along - at).abs() > 1e-4 {
            *offsets.entry(group).or_insert(0.0) += along - at;
            moved = true;
        }
    }
    if moved { rewrite(src, scenario, slots, values, &offsets) } else { Ok(first) }
}

/// The source with the non-placement slots fixed and each group's `offset` as given.
fn rewrite(
    src: &str,
    scenario: &Scenario,
    slots: &[ParamSlot],
    values: &[f64],
    offsets: &BTreeMap<String, f64>,
) -> Result<String, FixError> {
    // (start, end, text): replacements, or insertions where start == end
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    let replace = |attr: &Attr, value: f64, default: Unit| {
        let unit = written_unit(attr).unwrap_or(default);
        (attr.value_span.start, attr.value_span.end, quantity(value, unit))
    };
    for (slot, &value) in slots.iter().zip(values) {
        let unknown = || FixError::UnknownSlot { slot: slot.name.clone() };
        let (owner, what) = slot.name.rsplit_once('.').ok_or_else(unknown)?;
        if owner == "ego" {
            let attr = scenario.attr("ego", what).filter(|_| what == "speed").ok_or_else(unknown)?;
            edits.push(replace(attr, value, Unit::KilometresPerHour));
            continue;
        }
        let group = scenario.actor(owner).ok_or_else(unknown)?;
        let (field, unit) = match what {
            "speed" => ("speed", Unit::KilometresPerHour),
            "delay" => ("delay", Unit::Seconds),
            "trigger" => ("trigger", Unit::Metres),
            "shift" | "spread" | "offset" => continue,
            _ => return Err(unknown()),
        };
        edits.push(replace(group.attr(field).ok_or_else(unknown)?, value, unit));
    }
    for (name, &value) in offsets {
        let Some(group) = scenario.actor(name) else { continue };
        match group.attr("offset") {
            Some(attr) => edits.push(replace(attr, value, Unit::Metres)),
            None => {
                let line = format!("offset: {}", quantity(value, Unit::Metres));
                match group.attrs.iter().map(|a| a.value_span.end).max() {
                    Some(end) => edits.push((end, end, format!("\n{line}"))),
                    None => {
                        let Some(close) = src[..group.span.end].rfind('}') else { continue };
                        edits.push((close, close, format!("{line}\n")));
                    }
                }
            }
        }
    }
    edits.sort_by(|a, b| b.0.cmp(&a.0).then(b.1.cmp(&a.1)));
    let mut text = src.to_string();
    for (start, end, with) in edits {
        text.replace_range(start..end, &with);
    }
    tad_syntax::format::format(&text).map_err(|_| FixError::NoScenario)
}

/// The unit a quantity or range was written in.
fn written_unit(attr: &Attr) -> Option<Unit> {
    match attr.value.given()? {
        Val::Quantity(q) | Val::Range(q, _) => Some(q.unit),
        _ => None,
    }
}

/// `value` (SI) in `unit`, to a thousandth, without trailing zeros: `27.5 km/h`.
fn quantity(value: f64, unit: Unit) -> String {
    let v = value / unit.to_si();
    let mut text = format!("{v:.3}");
    while text.ends_with('0') {
        text.pop();
    }
    if text.ends_with('.') {
        text.pop();
    }
    if text == "-0" {
        text = "0".into();
    }
    format!("{text} {}", unit.as_str())
}
