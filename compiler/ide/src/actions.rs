//! Code actions and formatting.
//!
//! Code actions are the checker's own fixes (`Diagnostic::fixes`), never a second set of
//! rules: every machine-applicable and maybe-incorrect fix of a diagnostic that touches
//! the requested range becomes a quick fix, titled from the edit itself; a fix with
//! placeholders is left out (a person must write part of it). "Fix all" applies every
//! machine-applicable fix of the file, skipping overlapping ones as `tadslc check --fix`
//! does.
//!
//! Formatting runs the formatter of `tadslc fmt` and returns the difference as line edits
//! (so a client keeps its cursor and folds); range formatting keeps the hunks that touch
//! the range. A document with syntax errors is not formatted (the answer is `None`).

use std::time::Duration;

use tad_diagnostics::{Applicability, Diagnostic, Fix};

use crate::{Database, Edit, Language, SourceFile, Span};

/// A quick fix: the diagnostic it fixes (an index into `tad_db::check(db, file)`'s
/// diagnostics) and its edits to the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Action {
    pub title: String,
    pub diagnostic: usize,
    pub edits: Vec<Edit>,
    pub applicability: Applicability,
    /// The fix to apply when a client applies "the" fix (machine-applicable).
    pub preferred: bool,
}

/// Quick fixes for the diagnostics of `file` whose primary span touches `range`.
pub fn code_actions(db: &Database, file: SourceFile, range: Span) -> Vec<Action> {
    let text = file.text(db);
    let id = file.id(db);
    let mut out = Vec::new();
    for (index, diagnostic) in tad_db::check(db, file).diagnostics.iter().enumerate() {
        let span = diagnostic.primary.span;
        if diagnostic.file != id || span.end < range.start || span.start > range.end {
            continue;
        }
        for fix in usable(diagnostic) {
            if fix.span.end > text.len()
                || !text.is_char_boundary(fix.span.start)
                || !text.is_char_boundary(fix.span.end)
            {
                continue;
            }
            out.push(Action {
                title: title(text, fix),
                diagnostic: index,
                edits: vec![Edit { span: fix.span, text: fix.replacement.clone() }],
                applicability: fix.applicability,
                preferred: fix.applicability == Applicability::MachineApplicable,
            });
        }
    }
    out
}

/// Every machine-applicable fix of `file`, without overlaps; empty when there is none.
pub fn fix_all(db: &Database, file: SourceFile) -> Vec<Edit> {
    let text = file.text(db);
    let id = file.id(db);
    let checked = tad_db::check(db, file);
    let mine = checked.diagnostics.iter().filter(|d| d.file == id);
    tad_diagnostics::machine_fixes(mine, text.len())
        .into_iter()
        .map(|fix| Edit { span: fix.span, text: fix.replacement.clone() })
        .collect()
}

fn usable(diagnostic: &Diagnostic) -> impl Iterator<Item = &Fix> {
    diagnostic.fixes.iter().filter(|f| f.applicability != Applicability::HasPlaceholders)
}

fn title(text: &str, fix: &Fix) -> String {
    let old = text.get(fix.span.start..fix.span.end).unwrap_or("");
    let short = |s: &str| {
        let s = s.trim();
        if s.chars().count() > 40 { format!("{}…", s.chars().take(40).collect::<String>()) } else { s.to_string() }
    };
    match (old.trim().is_empty(), fix.replacement.trim().is_empty()) {
        (true, false) => format!("Insert `{}`", short(&fix.replacement)),
        (false, true) => format!("Remove `{}`", short(old)),
        _ => format!("Replace `{}` with `{}`", short(old), short(&fix.replacement)),
    }
}

/// The edits that format `file`, or `None` when it cannot be formatted (YAML, syntax
/// errors). Empty when it is formatted already.
pub fn format(db: &Database, file: SourceFile) -> Option<Vec<Edit>> {
    format_lines(db, file, None)
}

/// The formatting edits that touch `range`.
pub fn format_range(db: &Database, file: SourceFile, range: Span) -> Option<Vec<Edit>> {
    format_lines(db, file, Some(range))
}

fn format_lines(db: &Database, file: SourceFile, range: Option<Span>) -> Option<Vec<Edit>> {
    if file.language(db) != Language::Tad {
        return None;
    }
    let old = file.text(db);
    let new = tad_syntax::format::format(old).ok()?;
    Some(line_edits(old, &new, range))
}

/// The line hunks turning `old` into `new` (those touching `range`, if given).
pub fn line_edits(old: &str, new: &str, range: Option<Span>) -> Vec<Edit> {
    if old == new {
        return Vec::new();
    }
    let diff = similar::TextDiff::configure().timeout(Duration::from_millis(500)).diff_lines(old, new);
    let starts = |text: &str| -> Vec<usize> {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        if starts.last() == Some(&text.len()) && !text.is_empty() {
            starts.pop();
        }
        starts.push(text.len());
        starts
    };
    let (old_starts, new_starts) = (starts(old), starts(new));
    let at = |starts: &[usize], line: usize| starts[line.min(starts.len() - 1)];
    let mut edits = Vec::new();
    for op in diff.ops() {
        let (tag, old_lines, new_lines) = op.as_tag_tuple();
        if tag == similar::DiffTag::Equal {
            continue;
        }
        let span = Span::new(at(&old_starts, old_lines.start), at(&old_starts, old_lines.end));
        if let Some(range) = range
            && (span.end < range.start || span.start > range.end)
        {
            continue;
        }
        let text = new[at(&new_starts, new_lines.start)..at(&new_starts, new_lines.end)].to_string();
        edits.push(Edit { span, text });
    }
    edits
}

/// `text` with `edits` applied (sorted, not overlapping).
pub fn apply(text: &str, edits: &[Edit]) -> String {
    let mut edits: Vec<&Edit> = edits.iter().collect();
    edits.sort_by_key(|e| (e.span.start, e.span.end));
    let mut out = String::with_capacity(text.len());
    let mut cursor = 0;
    for edit in edits {
        let start = edit.span.start.clamp(cursor, text.len());
        out.push_str(&text[cursor..start]);
        out.push_str(&edit.text);
        cursor = edit.span.end.clamp(start, text.len());
    }
    out.push_str(&text[cursor..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    const ALIAS: &str = "scenario demo {\n  environment {\n    weather: sunny\n    time: daytime\n  }\n}\n";

    #[test]
    fn an_alias_has_a_preferred_quick_fix() {
        let (db, file) = testing::file(ALIAS);
        let at = ALIAS.find("sunny").unwrap();
        let actions = code_actions(&db, file, Span::new(at, at));
        let fix = actions.iter().find(|a| a.title == "Replace `sunny` with `clear`").expect("the alias fix");
        assert!(fix.preferred);
        let diagnostic = &tad_db::check(&db, file).diagnostics[fix.diagnostic];
        assert_eq!(diagnostic.code.as_str(), "W0401");
        assert!(apply(ALIAS, &fix.edits).contains("weather: clear"));
        // nothing for a range elsewhere
        assert!(code_actions(&db, file, Span::new(0, 5)).iter().all(|a| a.title != fix.title));
    }

    #[test]
    fn a_misspelt_name_is_a_maybe_incorrect_fix() {
        let text = ALIAS.replace("sunny", "cloudyy");
        let (db, file) = testing::file(&text);
        let at = text.find("cloudyy").unwrap();
        let actions = code_actions(&db, file, Span::new(at, at + 3));
        let fix = actions.iter().find(|a| a.title.contains("`cloudy`")).expect("a did-you-mean fix");
        assert_eq!(fix.applicability, Applicability::MaybeIncorrect);
        assert!(!fix.preferred);
        // fix-all leaves guesses alone
        assert!(fix_all(&db, file).iter().all(|e| e.text != "cloudy"));
    }

    /// A name another standard module declares gets a `use` line as its fix, once for
    /// several such names, and the fixed file knows them.
    #[test]
    fn a_name_of_another_module_is_fixed_by_one_use_line() {
        let text = "scenario demo {\n  actor a: 1 deer {\n    behavior: cross\n  }\n  actor b: 2 cow {\n    behavior: stopped\n  }\n}\n";
        let (db, file) = testing::file(text);
        let at = text.find("deer").unwrap();
        let actions = code_actions(&db, file, Span::new(at, at));
        let fix = actions.iter().find(|a| a.title == "Insert `use rural`").expect("the use fix");
        assert_eq!(fix.applicability, Applicability::MachineApplicable);
        let all = fix_all(&db, file);
        assert_eq!(all.iter().filter(|e| e.text == "use rural\n").count(), 1, "{all:?}");
        let fixed = apply(text, &all);
        assert!(fixed.starts_with("use rural\nscenario demo {"), "{fixed}");
        let (db, file) = testing::file(&fixed);
        assert!(tad_db::check(&db, file).diagnostics.iter().all(|d| d.code.as_str() != "E0400"));
    }

    #[test]
    fn formatting_is_line_edits_and_ranges_keep_their_hunks() {
        let text = "scenario demo {\n  environment {\n      weather: clear\n    time: daytime\n  }\n  road {\n    lanes:   2\n  }\n}\n";
        let (db, file) = testing::file(text);
        let edits = format(&db, file).expect("formattable");
        let formatted = apply(text, &edits);
        assert_eq!(formatted, tad_syntax::format::format(text).unwrap());
        // only the hunk on the `lanes` line
        let at = text.find("lanes:").unwrap();
        let partial = apply(text, &format_range(&db, file, Span::new(at, at)).unwrap());
        assert!(partial.contains("\n    lanes: 2\n"), "{partial}");
        assert!(partial.contains("\n      weather: clear\n"), "{partial}");
        // formatted text needs no edit; a broken one is not formatted
        let (db, file) = testing::file(&formatted);
        assert_eq!(format(&db, file), Some(Vec::new()));
        let (db, file) = testing::file("scenario demo { road { lanes: 2 ");
        assert_eq!(format(&db, file), None);
    }

    #[test]
    fn line_edits_handle_a_missing_final_newline_and_non_ascii() {
        let old = "// é\na\nb";
        let new = "// é\na\nc\n";
        assert_eq!(apply(old, &line_edits(old, new, None)), new);
        assert_eq!(apply("", &line_edits("", "x\n", None)), "x\n");
    }
}
