//! The one error type of the measurement crate.

use std::path::{Path, PathBuf};

/// Errors of the measurement crate. Every variant names the file (and key) or the step at fault,
/// so the command line can print a message a user can act on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {action}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What was attempted ("cannot read the file", "cannot write the file", ...).
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
    /// A setting out of its range, before any file is involved (the `validate` methods of the
    /// settings; [`crate::MeasureSettings::from_file`] turns it into [`Error::Invalid`] naming
    /// the file).
    #[error("{key} {message}")]
    Setting {
        /// The key, as written in `measurement.toml` (e.g. `circuit.r_pg_ohm`, `tail.delay_ns`).
        key: String,
        /// What is wrong with it ("must be positive, got -1").
        message: String,
    },
    /// A file that the HDF5 reader cannot open as HDF5 (not HDF5, truncated, unreadable): an
    /// `.lh5` pulse file.
    #[error("{}: cannot open as an HDF5 (LH5) file: {reason}", file.display())]
    Hdf5Open {
        /// The file.
        file: PathBuf,
        /// The HDF5 reader's reason.
        reason: String,
    },
    /// An HDF5 file that opens but does not hold the expected LH5 waveform table: a missing
    /// table or dataset, a wrong rank or element type, units that disagree with the sidecar.
    #[error("{}: `{dataset}`: {reason}", file.display())]
    Lh5 {
        /// The file.
        file: PathBuf,
        /// The table or dataset at fault (an HDF5 path, e.g. `/ch000/raw/waveform/values`).
        dataset: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A numerical step failed (a fit that did not converge, too few events in a peak).
    #[error("{what}: {message}")]
    Numerical {
        /// Which step, e.g. "pulser peak at 25 V".
        what: String,
        /// Why.
        message: String,
    },
    /// A value given through the API or the command line is invalid.
    #[error("`{name}`: {message}")]
    Argument {
        /// Name of the argument.
        name: String,
        /// What is wrong with it.
        message: String,
    },
}

/// Result alias of the measurement crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// [`Error::Io`] of `file` and `action` as a `map_err` argument:
    /// `std::fs::write(f, b).map_err(Error::io(f, "cannot write the file"))`.
    pub fn io(file: &Path, action: &'static str) -> impl FnOnce(std::io::Error) -> Self {
        let file = file.to_path_buf();
        move |source| Error::Io {
            file,
            action,
            source,
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

    /// Shorthand for [`Error::Setting`].
    pub fn setting(key: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Setting {
            key: key.into(),
            message: message.into(),
        }
    }
}
