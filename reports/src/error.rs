//! The one error type of the reports crate.
//!
//! Each variant names the file (and what was attempted) where there is one. The texts are those
//! the command line prints: `hpge-cv` shows an error with its sources joined by ": ".

/// Returns `Err(Error::Invalid)` with a formatted message from the enclosing function.
macro_rules! invalid {
    ($($arg:tt)*) => {
        return Err($crate::error::Error::invalid(format!($($arg)*)))
    };
}

use std::path::PathBuf;

/// Errors of the reports crate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A figure could not be drawn or written; `message` is the drawing failure with its causes.
    #[error("cannot write the plot {}: {message}", file.display())]
    Draw {
        /// The figure file.
        file: PathBuf,
        /// What failed (e.g. "drawing failed: ...").
        message: String,
    },
    /// One plotters call failed while a figure was drawn (`render!` turns it into `Draw`, which
    /// names the file).
    #[error("drawing failed: {message}")]
    Drawing {
        /// The plotters error.
        message: String,
    },
    /// A figure file whose extension names no format this crate writes.
    #[error("{}: {message}", file.display())]
    UnknownFormat {
        /// The file.
        file: PathBuf,
        /// The hint, e.g. "unknown file type; use .svg or .png".
        message: &'static str,
    },
    /// An output path given on the command line is unusable (checked before any work).
    #[error("{flag} {}: {message}", file.display())]
    Output {
        /// The option that named it, e.g. `--plot`.
        flag: String,
        /// The path as given.
        file: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// The output folder already holds a results file of another run (other inputs, settings
    /// or truths), which a run replaces only with `--force` ([`crate::replace`]).
    #[error("{}: {message}", file.display())]
    OtherRun {
        /// The results file there.
        file: PathBuf,
        /// Both runs and what differs.
        message: String,
    },
    /// A file or folder could not be created, written or copied.
    #[error("{action} {}", file.display())]
    Io {
        /// The file or folder.
        file: PathBuf,
        /// What was attempted, e.g. "cannot create the folder".
        action: &'static str,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// A file could not be copied.
    #[error("cannot copy {} to {}", from.display(), to.display())]
    Copy {
        /// The source file.
        from: PathBuf,
        /// The destination.
        to: PathBuf,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// An input file could not be read.
    #[error("{}: cannot read {what}", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// What it should hold, e.g. "the learning curves".
        what: &'static str,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// An input file is not the JSON it should be.
    #[error("{}: {what}", file.display())]
    Json {
        /// The file.
        file: PathBuf,
        /// What is wrong, e.g. "not a JSON fit summary".
        what: &'static str,
        /// The parser's message.
        #[source]
        source: serde_json::Error,
    },
    /// An input file is readable but its content is not what a report needs.
    #[error("{}: {message}", file.display())]
    Content {
        /// The file.
        file: PathBuf,
        /// What is wrong (the line, key or parameter at fault).
        message: String,
    },
    /// A parameter space could not be loaded.
    #[error("the space {}", file.display())]
    Space {
        /// The space file.
        file: PathBuf,
        /// Why.
        #[source]
        source: hpge_surrogate::Error,
    },
    /// Values handed to a figure or report that it cannot use (no parameters, mismatched
    /// lengths, an empty curve).
    #[error("{message}")]
    Invalid {
        /// What is wrong.
        message: String,
    },
    /// An error with what was being done when it happened (e.g. the step of `report paper`).
    #[error("{context}: {inner}")]
    Context {
        /// What was being done.
        context: String,
        /// The error itself.
        inner: Box<Error>,
    },
    /// A table of an earlier step could not be read.
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// A solver-side failure (a bad detector, a failed solve).
    #[error(transparent)]
    Solver(#[from] hpge_solver::Error),
    /// A surrogate-side failure (a model or data set that does not load).
    #[error(transparent)]
    Surrogate(#[from] hpge_surrogate::Error),
    /// An inference-side failure (data, priors, the exact model).
    #[error(transparent)]
    Inference(#[from] hpge_inference::Error),
    /// A measured curve could not be read.
    #[error(transparent)]
    Measurement(#[from] hpge_measurement::Error),
    /// JSON serialisation of a report failed.
    #[error(transparent)]
    Serialize(#[from] serde_json::Error),
    /// Formatting a report's text failed.
    #[error(transparent)]
    Format(#[from] std::fmt::Error),
}

/// Result alias of the reports crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// A plotters error as `Drawing` (its debug form, as plotters gives no better text).
    pub(crate) fn drawing<E: std::fmt::Debug>(e: E) -> Self {
        Error::Drawing {
            message: format!("{e:?}"),
        }
    }

    /// A closure that turns an I/O error on `file` into `Io` with `action`.
    pub(crate) fn io(
        file: &std::path::Path,
        action: &'static str,
    ) -> impl FnOnce(std::io::Error) -> Self {
        let file = file.to_path_buf();
        move |source| Error::Io {
            file,
            action,
            source,
        }
    }

    /// This error with what was being done when it happened.
    pub fn context(self, context: impl Into<String>) -> Self {
        Error::Context {
            context: context.into(),
            inner: Box::new(self),
        }
    }

    /// `Invalid` with `message`.
    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        Error::Invalid {
            message: message.into(),
        }
    }

    /// The error and its causes joined by ": " (how the command line prints an error).
    pub fn chain_text(&self) -> String {
        let mut text = self.to_string();
        let mut source = std::error::Error::source(self);
        while let Some(s) = source {
            text.push_str(": ");
            text.push_str(&s.to_string());
            source = s.source();
        }
        text
    }
}
