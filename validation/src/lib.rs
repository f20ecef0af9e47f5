//! # hpge-validation
//!
//! Problems with known answers, shared by tests, benches and reports, and the studies built on
//! them. The integration tests in `tests/` check the solver crate against these answers.
//!
//! - [`problems`]: closed forms and 1D references: the planar p-n detector
//!   ([`problems::planar`]), the long true coax (DESIGN.md, "Analytic and reference checks";
//!   [`problems::coax`]) and the high-precision radial 1D reference ([`problems::radial1d`]).
//! - [`studies`]: c12 accuracy against a 4x finer grid ([`studies::accuracy`]), simulation-based
//!   calibration of the fit ([`studies::coverage`]) and hidden-effect tests of model discovery
//!   ([`studies::hidden`]), with the options a user gives them ([`studies::options`]).
//!
//! The names most users need first are re-exported here; the rest live at their module paths
//! (e.g. [`studies::coverage::ks_uniform`], [`problems::radial1d::DEFAULT_NODES`]).
//!
//! # Example
//!
//! The long coax's closed form: the bias that depletes it fully, and its capacitance per
//! length there.
//!
//! ```
//! use hpge_validation::LongCoax;
//!
//! let coax = LongCoax::validation();
//! let u_fd_v = coax.full_depletion_v();
//! let c_pf_per_mm = coax.c12_per_mm_pf(u_fd_v)?;
//! assert!(u_fd_v > 0.0 && c_pf_per_mm > 0.0);
//! # Ok::<(), hpge_validation::Error>(())
//! ```

#![warn(missing_docs)]
mod error;
mod repo;

pub mod problems;
pub mod studies;

pub use error::{Error, Result};
pub use problems::coax::{COAX_REFERENCE_TABLE, LongCoax};
pub use problems::planar::PlanarPn;
pub use problems::radial1d::{RadialReference, RadialSolution};
pub use repo::{legend_detector, repo_path, shipped_fit_files};
pub use studies::accuracy::{AccuracyCase, AccuracyRow, accuracy_cases, accuracy_row};
pub use studies::coverage::{
    CoverageModels, CoverageOutcome, CoverageReport, CoverageRun, CoverageSettings, coverage,
};
pub use studies::hidden::{HiddenEffect, HiddenOutcome, hidden_effects, run_hidden};
pub use studies::hidden_summary::HiddenStudy;
pub use studies::options::{CoverageOptions, HiddenOptions};
