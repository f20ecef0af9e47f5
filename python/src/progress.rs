//! How a long call reports its progress: lines on stderr or a Python callable.

use hpge_inference::fit::{FitJob, FitOptions};
use pyo3::prelude::*;

/// Where a long call reports how far it is.
pub(crate) enum Progress {
    /// Nothing.
    Off,
    /// One line on stderr per step.
    Stderr(&'static str),
    /// A Python callable called with (done, total).
    Callback(Py<PyAny>),
}

impl Progress {
    /// `progress=True|False|callable`.
    pub(crate) fn from_arg(arg: &Bound<'_, PyAny>, what: &'static str) -> PyResult<Self> {
        if arg.is_callable() {
            Ok(Progress::Callback(arg.clone().unbind()))
        } else if arg.is_truthy()? {
            Ok(Progress::Stderr(what))
        } else {
            Ok(Progress::Off)
        }
    }

    /// Reports `done` of `total` steps (any thread; takes the GIL only for a callback).
    pub(crate) fn report(&self, done: usize, total: usize) {
        match self {
            Progress::Off => {}
            Progress::Stderr(what) => eprintln!("hpge_cv: {what} {done}/{total}"),
            Progress::Callback(f) => Python::attach(|py| {
                if let Err(e) = f.call1(py, (done, total)) {
                    e.print(py);
                }
            }),
        }
    }
}

/// `progress=None` (the default) prints lines on stderr.
pub(crate) fn progress_arg(
    arg: Option<Bound<'_, PyAny>>,
    what: &'static str,
) -> PyResult<Progress> {
    match arg {
        Some(a) => Progress::from_arg(&a, what),
        None => Ok(Progress::Stderr(what)),
    }
}

/// Discovery's stages and sampling progress.
pub(crate) struct DiscoverProgress(pub(crate) Progress);

impl hpge_inference::Progress for DiscoverProgress {
    fn stage(&self, message: &str) {
        if let Progress::Stderr(_) = self.0 {
            eprintln!("hpge_cv: discover: {message}");
        }
    }
    fn sampling(&self, s: &hpge_inference::Status) {
        if let Progress::Callback(_) = self.0 {
            self.0.report(s.draws, 0);
        }
    }
}

/// A fit's progress for `run_fit` (lines on stderr or the callback).
pub(crate) struct FitProgress(pub(crate) Progress);

impl hpge_reports::fit::FitObserver for FitProgress {
    fn setup_done(&self, _: &FitJob, _: &FitOptions, _: &hpge_inference::FitSettings) {}
    fn sampling(&self, s: &hpge_inference::Status) {
        if let Progress::Stderr(_) = self.0 {
            eprintln!(
                "hpge_cv: fit [{:6.1} s] {:?}: R-hat {:.4}, min ESS {:.0}, acceptance {:.2}",
                s.seconds, s.phase, s.rhat_max, s.ess_min, s.acceptance
            );
        } else {
            self.0.report(s.draws, 0);
        }
    }
    fn sampling_done(&self) {}
    fn exact_start(&self, _: usize) {}
    fn exact_progress(&self, done: usize, total: usize) {
        self.0.report(done, total);
    }
    fn exact_done(&self) {}
    fn finished(&self, _: &hpge_reports::fit::FitRun) {}
}
