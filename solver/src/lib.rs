//! # hpge-solver
//!
//! The physics of hpge-cv: detector descriptions (geometry, materials, contacts, passives, world),
//! impurity-density models with their parameter transforms, and the potential with depletion,
//! weighting potentials and the capacitance matrix, on the CPU or (the `sor` method) on a GPU
//! through wgpu; the electric field, charge drift (ADL model) and pulses by Shockley-Ramo.
//!
//! Units at the interfaces: lengths in mm, potentials in V, impurity densities in cm^-3 (signed:
//! positive is n-type), capacitances in pF. SI inside the numerics.
//!
//! # Modules
//!
//! - [`detector`]: the detector file format, its evaluation and checks, and the [`Detector`].
//! - [`impurity`]: impurity-density models zeta(r, z) and the paper's parameter transform.
//! - [`geometry`]: axisymmetric (r, z) primitives and constructive solid geometry.
//! - [`grid`]: the non-uniform tensor grid and its settings ([`GridSettings`]).
//! - [`field`]: field solves: potential with depletion, weighting potentials, capacitances,
//!   C-V curves, depletion and pinch-off voltages.
//! - [`drift`]: the electric field of a solved point, charge drift and pulses.
//! - [`jobs`]: one library call per solver command (`simulate`, `capacitance`, `field`,
//!   `pulse`, `sensitivity`, `convergence`) with its options, record and table: the pipeline
//!   the command line and the Python module both run.
//! - [`gpu`]: the wgpu backend's adapter and precision.
//! - [`options`]: the options of the commands that load a detector and solve fields
//!   ([`options::DetectorInput`], [`options::SolverOptions`], [`GridOverrides`]), declared once
//!   for the command line.
//! - [`expr`]: named parameters ([`Parameters`]) and the expressions detector files may use.
//! - [`material`], [`constants`]: material properties and physical constants.
//!
//! The names most users need first are re-exported here; everything else lives at its module
//! path (e.g. [`field::solve_fast`], [`detector::Region`], [`drift::ElectricField`]).
//!
//! # Example
//!
//! The capacitance between the two contacts of the planar p-n detector at 100 V on the default
//! grid (1 mm spacing) without adaptive refinement:
//!
//! ```
//! use std::path::Path;
//!
//! use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
//!
//! let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/planar-pn.toml");
//! let det = Detector::from_file(&file, &Parameters::new())?;
//! let mut settings = FieldSettings::default().for_detector(&det);
//! settings.grid.adaptive = false;
//! let point = solve_point(&det, 100.0, &settings, None)?;
//! assert!(point.c12_pf > 0.0);
//! # Ok::<(), hpge_solver::Error>(())
//! ```

#![warn(missing_docs)]
mod carrier;
mod error;
mod relaxation;

pub mod constants;
pub mod detector;
pub mod drift;
pub mod expr;
pub mod field;
pub mod geometry;
pub mod gpu;
pub mod grid;
pub mod impurity;
pub mod jobs;
pub mod material;
pub mod options;
pub mod scan;

/// Solver internals for measurements outside the product (`hpge-benches`: the multigrid
/// solver measured against the sparse Cholesky, `reports/solver-performance.md`): the assembled
/// field systems, their factorisation and the weighting problem's unknowns. Not a stable API.
#[cfg(feature = "internals")]
#[doc(hidden)]
pub mod internals {
    pub use crate::field::cholesky::{Factor, Symbolic};
    pub use crate::field::system::{Dof, System};
    pub use crate::field::weighting::{Owner, owners, weighting_dofs};
}

pub use detector::Detector;
pub use drift::{Pulse, pulse};
pub use error::{DetectorPart, Error, Result};
pub use expr::{MAX_EXPRESSION_DEPTH, Parameters, Quantity};
pub use field::{
    Backend, CvCurve, CvPoint, FieldSettings, Method, PointResult, WeightingMode, cv_curve,
    full_depletion_voltage, pinch_off_voltage, solve_point, solve_potential,
};
pub use gpu::Precision;
pub use grid::{GridOverrides, GridSettings};
pub use impurity::ImpuritySpec;

/// What made a results file whose numbers come from this solver: the program, its version,
/// today's UTC date and [`field::PHYSICS_REVISION`] (issue 63), written under
/// [`hpge_foundation::MADE_KEY`].
///
/// ```
/// let made = hpge_solver::made();
/// assert_eq!(made.solver_revision.as_deref(), Some(hpge_solver::field::PHYSICS_REVISION));
/// ```
pub fn made() -> hpge_foundation::Made {
    hpge_foundation::Made::now(Some(field::PHYSICS_REVISION))
}
