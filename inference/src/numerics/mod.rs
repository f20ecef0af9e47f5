//! Small dense numerics shared by the likelihood, the samplers, the fit and model discovery:
//! one Cholesky factorisation and one Nelder-Mead maximiser.

mod cholesky;
mod nelder_mead;

pub use cholesky::Cholesky;
pub use nelder_mead::{nelder_mead, nelder_mead_until};
