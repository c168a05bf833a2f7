//! A small case of each hostile shape (`bench --hostile` measures them at 1 MB): the check
//! and the formatter finish, find what is wrong, and report a bounded amount whatever the
//! file's size.

use tad_bench::hostile::{CAP, SHAPES, measure};

#[test]
fn each_hostile_shape_is_reported_within_bounds() {
    for shape in SHAPES {
        let small = measure(&(shape.make)(10_000), 1);
        let large = measure(&(shape.make)(40_000), 1);
        let clean = shape.name.starts_with("clean");
        if clean {
            assert_eq!(large.format_errors, 0, "{}: the clean file formats", shape.name);
        } else {
            assert!(large.diagnostics > 0, "{}: nothing found", shape.name);
            // a run of one mistake is one report (a field given again is one each)
            if shape.name != "100k fields" {
                assert!(large.diagnostics <= 10, "{}: {} diagnostics", shape.name, large.diagnostics);
            }
        }
        // the formatter reports what check reports, capped, never one error per character
        assert!(
            large.format_errors <= large.diagnostics.max(1) + CAP,
            "{}: {} format errors",
            shape.name,
            large.format_errors
        );
        // four times the file, at most about four times the diagnostics
        assert!(
            large.diagnostics <= 4 * small.diagnostics + 8,
            "{}: {} then {}",
            shape.name,
            small.diagnostics,
            large.diagnostics
        );
        // the report shows the first CAP diagnostics, each with a line of bounded width
        assert!(
            large.report_bytes <= small.report_bytes.max(1) * 2 + 20_000,
            "{}: report {} bytes at 10 KB, {} at 40 KB",
            shape.name,
            small.report_bytes,
            large.report_bytes
        );
    }
}
