//! The one error type of the validation crate.

/// Errors of the validation crate.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A closed form asked outside its domain.
    #[error("{quantity} = {value} is outside the closed form's domain: {why}")]
    Domain {
        /// Name of the argument.
        quantity: &'static str,
        /// Its value.
        value: f64,
        /// Why it is invalid.
        why: String,
    },
    /// A solver-side failure.
    #[error(transparent)]
    Solver(#[from] hpge_solver::Error),
    /// An inference-side failure (a fit in a coverage study).
    #[error(transparent)]
    Inference(#[from] hpge_inference::Error),
}

/// Result alias of the validation crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
