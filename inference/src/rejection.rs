//! How samplers and optimisers treat a failed model evaluation: a recoverable error
//! ([`Error::is_recoverable`]: a failed solve, a point outside the model's domain) is a rejected
//! point of zero posterior density; any other error (I/O, invalid settings, a GPU failure) ends
//! the run and is returned.

use std::sync::Mutex;

use crate::{Error, Result};

/// The log density of an evaluation: its value, -inf for a recoverable error, or the error.
pub(crate) fn density_or_rejected(evaluation: Result<f64>) -> Result<f64> {
    Ok(unless_rejected(evaluation)?.unwrap_or(f64::NEG_INFINITY))
}

/// An evaluation's value, `None` for a recoverable error, or the error.
pub(crate) fn unless_rejected<T>(evaluation: Result<T>) -> Result<Option<T>> {
    match evaluation {
        Ok(v) => Ok(Some(v)),
        Err(e) if e.is_recoverable() => Ok(None),
        Err(e) => Err(e),
    }
}

/// [`unless_rejected`] that keeps the reason: a recoverable failure is `Ok(Err(message))`.
pub(crate) fn with_reason<T>(evaluation: Result<T>) -> Result<std::result::Result<T, String>> {
    match evaluation {
        Ok(v) => Ok(Ok(v)),
        Err(e) if e.is_recoverable() => Ok(Err(e.to_string())),
        Err(e) => Err(e),
    }
}

/// Log densities for an optimiser that takes a plain `Fn(&[f64]) -> f64` (Nelder-Mead, finite
/// differences): a recoverable error gives -inf; the first other error is kept, every later
/// call returns NaN without evaluating (so the optimiser winds down cheaply), and
/// [`Latch::check`] returns the error.
#[derive(Debug, Default)]
pub(crate) struct Latch {
    failure: Mutex<Option<Error>>,
}

impl Latch {
    /// The value of `evaluate()`, unless an error ended the run already (NaN, not evaluated).
    pub(crate) fn value(&self, evaluate: impl FnOnce() -> Result<f64>) -> f64 {
        if self.failed() {
            return f64::NAN;
        }
        match density_or_rejected(evaluate()) {
            Ok(v) => v,
            Err(e) => {
                if let Ok(mut f) = self.failure.lock() {
                    f.get_or_insert(e);
                }
                f64::NAN
            }
        }
    }

    /// Whether a non-recoverable error was seen.
    pub(crate) fn failed(&self) -> bool {
        self.failure.lock().map_or(true, |f| f.is_some())
    }

    /// The first non-recoverable error seen, if any (taken out of the latch).
    pub(crate) fn check(&self) -> Result<()> {
        match self.failure.lock().ok().and_then(|mut f| f.take()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}
