//! The one error type of the inference crate.

use std::path::PathBuf;

/// Errors of the inference crate. Every variant names the file (and key) at fault, so the
/// command line can print a message a user can act on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A failure in the surrogate layer (or, through it, the solver).
    #[error(transparent)]
    Surrogate(#[from] hpge_surrogate::Error),
    /// A lock, shard or file error of the shared utilities (`hpge_foundation`).
    #[error(transparent)]
    Foundation(#[from] hpge_foundation::Error),
    /// A file could not be read or written.
    #[error("{}: {action}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What was attempted ("cannot read the file", "cannot create the file", ...).
        action: &'static str,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// A file is malformed: not an .npy array, truncated, a CSV with a wrong header or a
    /// non-numeric cell, TOML that does not parse or fit the schema.
    #[error("{}: {message}", file.display())]
    Format {
        /// The file.
        file: PathBuf,
        /// What is wrong, with line/column/key where known.
        message: String,
    },
    /// A well-formed value that is invalid (NaN sample, negative period, shape disagreeing with
    /// the sidecar, asymmetric covariance, ...).
    #[error("{}: `{key}`: {message}", file.display())]
    Invalid {
        /// The file the value came from.
        file: PathBuf,
        /// The key, column or array element at fault.
        key: String,
        /// What is wrong with it.
        message: String,
    },
    /// A numerical step failed (a fit that did not converge, too few events in a peak).
    #[error("{what}: {message}")]
    Numerical {
        /// Which step, e.g. "pulser peak at 25 V".
        what: String,
        /// Why.
        message: String,
    },
    /// A model extension cannot build its detector at this point (e.g. a Li thickness slope
    /// that leaves less than the thinnest layer allowed, an impurity model the extension cannot
    /// modify): the point lies outside the extended model's domain.
    #[error("`{extension}`: {message}")]
    Extension {
        /// The extension, in words (e.g. "a Li thickness slope").
        extension: String,
        /// Why the detector cannot be built.
        message: String,
    },
    /// A catalogue entry does not apply to the start model or detector (model discovery).
    #[error("{reason}")]
    NotApplicable {
        /// The entry's name (e.g. `radial`).
        extension: String,
        /// Why, in words.
        reason: String,
    },
    /// A value given through the API or the command line is invalid.
    #[error("`{name}`: {message}")]
    Argument {
        /// Name of the argument.
        name: String,
        /// What is wrong with it.
        message: String,
    },
    /// Reading a measured curve failed.
    #[error(transparent)]
    Measurement(#[from] hpge_measurement::Error),
    /// The solver failed outside a model evaluation (reading a detector, the profiles at a mode).
    #[error(transparent)]
    Solver(#[from] hpge_solver::Error),
    /// An error with what was being read or done when it happened (e.g. `--detector D.toml`).
    #[error("{context}: {inner}")]
    Context {
        /// What was being read or done.
        context: String,
        /// The error itself.
        inner: Box<Error>,
    },
    /// A command-line style option whose value is not one of the accepted ones.
    #[error("{option}: {message}")]
    BadOption {
        /// The option with its value, e.g. `--sampler gibbs`.
        option: String,
        /// What is accepted.
        message: String,
    },
    /// A surrogate trained for another detector than the one a fit is given.
    #[error(
        "{}: the model was trained for the detector {trained_file} (hash {trained_hash}), not for {} (hash {hash}); fit with the detector the training rows were generated for, or train a model for this one",
        model.display(),
        detector.display()
    )]
    DetectorMismatch {
        /// The model file.
        model: PathBuf,
        /// The detector file recorded in the model.
        trained_file: String,
        /// Its hash as recorded.
        trained_hash: String,
        /// The detector file given.
        detector: PathBuf,
        /// Its hash.
        hash: String,
    },
}

/// Result alias of the inference crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Whether a sampler (or an optimiser) may treat this error of a model evaluation as a
    /// rejected proposal, zero posterior density: a failed solve, a point outside the model's
    /// domain, a numerical failure of a curve. I/O, malformed files, invalid values and
    /// arguments, and GPU failures are not: they end the run.
    pub fn is_recoverable(&self) -> bool {
        match self {
            Error::Surrogate(e) => e.is_recoverable(),
            Error::Foundation(e) => e.is_recoverable(),
            Error::Numerical { .. } | Error::Extension { .. } => true,
            Error::Io { .. }
            | Error::Format { .. }
            | Error::Invalid { .. }
            | Error::NotApplicable { .. }
            | Error::Argument { .. }
            | Error::BadOption { .. }
            | Error::DetectorMismatch { .. } => false,
            Error::Solver(e) => e.is_recoverable(),
            Error::Measurement(_) => false,
            Error::Context { inner, .. } => inner.is_recoverable(),
        }
    }

    /// This error with what was being read or done when it happened.
    pub fn context(self, context: impl Into<String>) -> Self {
        Error::Context {
            context: context.into(),
            inner: Box::new(self),
        }
    }

    /// Shorthand for [`Error::Format`].
    pub fn format(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Format {
            file: file.into(),
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(
        file: impl Into<PathBuf>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            file: file.into(),
            key: key.into(),
            message: message.into(),
        }
    }
}
