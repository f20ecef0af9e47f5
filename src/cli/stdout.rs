//! What the commands print on stdout goes through [`outln!`] and [`out!`] (declared in
//! `main.rs`): a write that fails (stdout on a full disk, `/dev/full`, or a pipe whose reader
//! has gone, as in `| head`) is an error, never a panic (issue 66). A broken pipe is not the
//! command's failure: the rest of stdout is dropped and the command goes on to its usual status
//! (a fit that did not converge still exits with 3); any other failure is an error naming
//! stdout.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// The reader of stdout has gone: what is left to print is dropped.
static READER_GONE: AtomicBool = AtomicBool::new(false);

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
/// A broken pipe is not an error: it is noted, and this and every later write are dropped.
pub fn write_fmt(args: std::fmt::Arguments<'_>) -> Result<(), StdoutError> {
    if READER_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out
        .write_fmt(args)
        .and_then(|()| out.flush())
        .map_err(|source| StdoutError { source })
    {
        Err(e) if e.broken_pipe() => {
            READER_GONE.store(true, Ordering::Relaxed);
            Ok(())
        }
        r => r,
    }
}
