//! Model discovery (issue 9): the paper's reasoning from a misfit to a missing effect, as a
//! workflow. Fit a start model; find the voltage windows where it disagrees with the data and
//! the detector region each probes; score every entry of a catalogue of physical extensions by
//! a quick Laplace fit; give the best a full fit; show how much of the gap it closes
//! (chi^2/ndf, pulls, posterior-predictive p, leave-window-out elpd, Bayes factor).

mod catalogue;
mod checks;
mod elpd_linear;
mod fits;
mod options;
mod region;
mod resume;
mod run;
mod settings;
mod summary;

pub use crate::posterior::{LaplaceFit, LaplaceSettings, laplace_fit};
pub use catalogue::{
    Affine, AffineKind, Baseline, CalibrationScale, Candidate, ExactVariant, Extension,
    ExtensionPredictor, LiSlope, Modifier, QuadraticZ, Radial, Scaled, Shifted, StrayCapacitance,
    catalogue,
};
pub use checks::{
    Elpd, PredictiveDraws, ResidualCheck, Window, delta_elpd, leave_window_out, residual_check,
};
pub use options::{DEFAULT_START_MODEL, DiscoverOptions, WorkflowOptions};
pub use region::{ProbedRegion, probed_region};
pub use resume::{DISCOVER_LOCK, STAGES_DIR, Stages, lock_output, run_fingerprint};
pub use run::discover;
pub use settings::{
    DEFAULT_MIN_LN_BAYES, DiscoverInputs, DiscoverSettings, Discovery, ModelFit, Progress,
};
pub use summary::{CandidateScore, Disagreement, DiscoverySummary, Gap, NotApplicable};
