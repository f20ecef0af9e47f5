//! # hpge-validation
//!
//! Problems with known answers, shared by tests, benches and reports: the long coax in closed form
//! (DESIGN.md, "Analytic and reference checks"), and (with the solver issue) 1D high-precision
//! references, planar cases and synthetic truths. The integration tests in `tests/` check the
//! solver crate against them.

mod accuracy;
mod coax;
mod coverage;
mod error;
mod hidden;
mod planar;
mod radial1d;

pub use accuracy::{AccuracyCase, AccuracyRow, accuracy_cases, accuracy_row};
pub use coax::{COAX_REFERENCE_TABLE, LongCoax};
pub use coverage::{
    COVERAGE_LEVELS, CoverageReport, CoverageSettings, ParameterCoverage, binomial_interval,
    coverage, ks_uniform,
};
pub use error::{Error, Result};
pub use hidden::{
    BASE_TRUTH, HiddenEffect, HiddenOutcome, RADIAL_TRUTH, hidden_curve, hidden_effects,
    run_hidden, simulate_hidden,
};
pub use planar::PlanarPn;
pub use radial1d::{DEFAULT_NODES, MIN_NODES, RadialReference, RadialSolution};

/// Absolute path of a file shipped in the repository (e.g. `detectors/coax-analytic.toml`).
pub fn repo_path(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}
