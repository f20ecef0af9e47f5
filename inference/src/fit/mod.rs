//! A whole fit: sampling, the posterior summary (means, modes, smallest intervals, diagnostics),
//! the posterior predictive, the modes of a multimodal posterior, and the exact-solver check.

mod ascent;
mod checkpoint;
mod exact_check;
mod job;
mod options;
pub mod outputs;
mod predictive;
mod refine;
mod refine_settings;
mod reproduce;
mod round;
mod run;
mod summary;
mod truth;
mod zeta;

pub use ascent::{
    ASCENT_MARGIN, AWAY_SD, BasinAscent, DEFAULT_ASCENTS, MIN_ASCENT_WEIGHT, away_from_mode,
    basin_ascents,
};
pub use checkpoint::{
    Checkpoint, FIT_LOCK, ROUNDS_DIR, SavedRound, fingerprint, folder_files, lock_output,
    remove_stale, write_whole,
};
pub use exact_check::{
    DEFAULT_GRID_CHECK, ExactCheck, ExactCheckSettings, ExactGrids, FailedSolve, GridCheck,
    K_HAT_LIMIT, NEAR_EQUAL_LOG_RANGE, ParameterShift, SHIFT_LIMIT_SD, add_grid_check, exact_check,
    k_hat_limit, near_equal_weights, weights_reliable,
};
pub use job::{EXACT_CHECK_TOLERANCE, FitFiles, FitJob, file_hash};
pub use options::{
    DEFAULT_DATA, DEFAULT_DETECTOR, DEFAULT_EXACT_DRAWS, DEFAULT_MODEL, DEFAULT_PRIOR,
    FIT_LIKELIHOOD, FIT_MAX_SECONDS, FitOptions, check_positive, noise_settings, sampler_kind,
};
pub use predictive::thin_indices;
pub use predictive::{Predictive, predictive};
pub use refine::{
    DEFAULT_HYPER_EVALS, DEFAULT_REFINE_ROUNDS, MAX_LOCAL_MODE_CURVES, RefineInputs,
    RefineProgress, RefineSettings, RefineVariance, RefinedFit, Resume, refine_fit,
};
pub use round::{RefineRound, f64_or_nan};
pub use run::{Fit, FitSettings, draw_range, fit};
pub use summary::{FitSummary, LEVELS, ModeSummary, ParameterSummary, mode_physics};
pub use truth::{TruthRecord, read_truth, truth_records};
pub use zeta::{ZETA_BAND_DRAWS, ZetaAtMode, ZetaProfile, zeta_profiles};
