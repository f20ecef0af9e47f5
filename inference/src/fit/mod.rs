//! A whole fit: sampling, the posterior summary (means, modes, smallest intervals, diagnostics),
//! the posterior predictive, the modes of a multimodal posterior, and the exact-solver check.

mod exact_check;
mod predictive;
mod run;
mod summary;

pub use exact_check::{ExactCheck, ParameterShift, exact_check};
pub(crate) use predictive::thin_indices;
pub use predictive::{Predictive, predictive};
pub use run::{Fit, FitSettings, draw_range, fit};
pub use summary::{FitSummary, LEVELS, ModeSummary, ParameterSummary};
