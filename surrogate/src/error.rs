//! The one error type of the surrogate crate.

/// Errors of the surrogate crate.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A solver-side failure (bad detector, failed solve) while building a data set.
    #[error(transparent)]
    Solver(#[from] hpge_solver::Error),
}

/// Result alias of the surrogate crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
