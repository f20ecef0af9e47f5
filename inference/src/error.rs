//! The one error type of the inference crate.

/// Errors of the inference crate.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A failure in the surrogate layer (or, through it, the solver).
    #[error(transparent)]
    Surrogate(#[from] hpge_surrogate::Error),
}

/// Result alias of the inference crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
