//! Traces of emitted programs in the real Scenic 3.1.1 (`tad-scenic-run`'s, re-exported),
//! and the test suites' tracer: a skip where Scenic is missing, a failure with
//! `TAD_REQUIRE_SCENIC=1`.

use std::path::Path;

pub use tad_scenic_run::trace::*;

use crate::scenic;

/// The tracer; `None` (after saying so where a user sees it) when Scenic is not installed,
/// a panic when `TAD_REQUIRE_SCENIC=1`.
pub fn tracer(base: &Path) -> Option<Tracer> {
    let found = (|| Some(Tracer { python: scenic::python()?, script: script()?, maps: scenic::map_dir(base)? }))();
    if found.is_none() {
        scenic::unavailable(
            "Scenic is not available for tracing (set TADSL_SCENIC_PYTHON to a python with scenic 3.1.1, \
             or run `bash ../shared/scenic/setup.sh .venv-scenic`; ../shared/maps/CARLA must exist)",
        );
    }
    found
}
