//! The one error type of the foundation crate.

use std::path::PathBuf;

/// What can go wrong in the foundation's utilities.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
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
    /// An output folder another process is writing (the one-writer lock of `generate`, `fit`,
    /// `discover` and the coverage studies).
    #[error(
        "{}: another `{command}` process is writing this folder ({holder}); wait for it to finish or use another --out",
        folder.display()
    )]
    Locked {
        /// The folder.
        folder: PathBuf,
        /// The command whose lock it is (`generate`, `fit`).
        command: String,
        /// Who holds the lock (pid, host, start time), as it wrote itself into the lock file.
        holder: String,
    },
    /// A shard that is not `K/M` with 0 <= K < M.
    #[error("`{text}`: {message}")]
    Shard {
        /// The text as given.
        text: String,
        /// What is wrong.
        message: String,
    },
}

impl Error {
    /// Whether a sampler may treat this as a rejected proposal and go on: never, these are
    /// errors of the run's input or its folders.
    pub fn is_recoverable(&self) -> bool {
        false
    }
}

/// The foundation's result type.
pub type Result<T> = std::result::Result<T, Error>;
