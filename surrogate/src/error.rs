//! The one error type of the surrogate crate.

use std::path::PathBuf;

/// Errors of the surrogate crate (each names the file and key at fault where there is one).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A solver-side failure (bad detector, failed solve) while building a data set.
    #[error(transparent)]
    Solver(#[from] hpge_solver::Error),
    /// A file could not be read or written.
    #[error("{}: {action}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What was attempted.
        action: &'static str,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// A file does not parse or fit its schema.
    #[error("{}: {message}", file.display())]
    Parse {
        /// The file.
        file: PathBuf,
        /// The parser's message with line, column and key.
        message: String,
    },
    /// A well-formed value that is invalid.
    #[error("{}: `{key}`: {message}", file.display())]
    Invalid {
        /// The file.
        file: PathBuf,
        /// Key path, e.g. `dimensions[3].range`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A value given through the API or the command line is invalid.
    #[error("`{name}`: {message}")]
    Argument {
        /// Name of the argument.
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// Result alias of the surrogate crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
