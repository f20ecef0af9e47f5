//! # hpge-inference
//!
//! The statistics side of hpge-cv (paper, sections 4 and 8): priors, the likelihood with
//! parameter-dependent uncertainties, samplers and their diagnostics, posterior summaries and
//! predictive checks, and the model-discovery workflow. It sees a model only through one narrow
//! trait, implemented by both the exact solver and the surrogate, and the measured curve only as
//! a [`CvData`] (from the measurement crate, hpge-measurement, which turns raw pulser data into
//! a C-V curve with its covariance). Filled in by the measurement and inference issues.

mod diagnostics;
mod discover;
mod error;
pub mod fit;
mod model;
mod posterior;
mod prior;
mod sampler;
mod summary;

pub use diagnostics::{
    Diagnostics, ess, ess_bulk, ess_tail, fold, rank_normalise, rank_rhat, split_chains, split_rhat,
};
pub use discover::{
    Affine, AffineKind, Baseline, CalibrationScale, Candidate, CandidateScore, Disagreement,
    DiscoverInputs, DiscoverSettings, Discovery, DiscoverySummary, Elpd, ExactVariant, Extension,
    Gap, LaplaceFit, LaplaceSettings, LiSlope, ModelFit, NotApplicable, PredictiveDraws, Predictor,
    Progress, QuadraticZ, Radial, Region, ResidualCheck, Scaled, Shifted, StrayCapacitance, Window,
    catalogue, delta_elpd, discover, laplace_fit, leave_window_out, probed_region, residual_check,
};
pub use error::{Error, Result};
pub use fit::{
    ExactCheck, Fit, FitFiles, FitJob, FitSettings, FitSummary, LEVELS, ModeSummary,
    ParameterShift, ParameterSummary, Predictive, TruthRecord, ZetaAtMode, ZetaProfile, draw_range,
    exact_check, fit, nelder_mead, predictive,
};
pub use hpge_measurement::CvData;
pub use model::{CvModel, ExactModel, SurrogateModel};
pub use posterior::{Cholesky, Evaluation, Likelihood, NoiseKind, NoiseSettings, Posterior};
pub use prior::{ParameterSpec, Prior, PriorDistribution, PriorParameter, PriorSpec};
pub use sampler::{
    ChainDraws, GaussianTarget, LocalMode, LogDensity, Phase, SampleSettings, SamplerKind, Samples,
    Status, StopReason, sample,
};
pub use summary::{
    Component, Mixture, Psis, find_modes, fit_mixture, gpd_fit, interval_contains, marginal_mode,
    psis, smallest_intervals,
};
