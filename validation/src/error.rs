//! The one error type of the validation crate.

/// Errors of the validation crate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
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
    /// A shipped file whose content a study cannot use.
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong with it.
        message: String,
    },
}

/// Result alias of the validation crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// [`Error::File`]: `path` could not be written, for `reason`.
    pub(crate) fn cannot_write(path: &std::path::Path, reason: &dyn std::fmt::Display) -> Self {
        Error::File {
            path: path.to_path_buf(),
            message: format!("cannot write the file: {reason}"),
        }
    }

    /// Whether a sampler may treat this error as a rejected proposal (zero posterior density):
    /// a closed form asked outside its domain, or a recoverable error of the crate below.
    pub fn is_recoverable(&self) -> bool {
        match self {
            Error::Domain { .. } => true,
            Error::Solver(e) => e.is_recoverable(),
            Error::Inference(e) => e.is_recoverable(),
            Error::File { .. } => false,
        }
    }
}
