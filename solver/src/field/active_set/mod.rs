//! The active-set family: the potential with depletion as a bound-constrained quadratic problem.
//!
//! - [`depletion`]: the solve as a whole, rounds of the active-set iteration with the
//!   trapped-carrier pockets' floods between them (`field::pockets`), and its entry points.
//! - [`round`]: one round, the primal-dual active-set (semismooth Newton) iteration with the
//!   pocket ties held fixed.
//! - [`band`]: front moves between factorisations, projected over-relaxation in a band of
//!   unknowns around the depletion front.

pub(crate) mod band;
pub(crate) mod depletion;
mod round;

pub(crate) use depletion::{FastSeed, POCKET_TOL, potential_dofs, solve_fast_seeded};
pub use depletion::{MAX_POCKET_ROUNDS, PotentialSolution, solve_fast, solve_fast_with};
