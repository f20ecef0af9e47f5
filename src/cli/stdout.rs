//! What the commands print on stdout goes through [`outln!`] and [`out!`] (declared in
//! `main.rs`): a write that fails (stdout on a full disk, `/dev/full`, or a pipe whose reader
//! has gone, as in `| head`) is an error, never a panic (issue 66). `main` ends a broken pipe
//! quietly with the command's usual status; any other failure is an error naming stdout.

use std::io::Write;

/// Writing stdout failed.
#[derive(Debug, thiserror::Error)]
#[error("stdout: cannot write: {source}")]
pub struct StdoutError {
    /// The operating system's reason.
    #[source]
    pub source: std::io::Error,
}

impl StdoutError {
    /// Whether the reader of a pipe has gone (`| head`): not a failure of the command.
    pub fn broken_pipe(&self) -> bool {
        self.source.kind() == std::io::ErrorKind::BrokenPipe
    }
}

/// Writes `args` to stdout and flushes it.
///
/// # Errors
/// [`StdoutError`] when stdout cannot be written.
pub fn write_fmt(args: std::fmt::Arguments<'_>) -> Result<(), StdoutError> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.flush())
        .map_err(|source| StdoutError { source })
}
