//! What `hpge-cv discover --json` prints and `discovery.json` holds: the fields first,
//! in its order, then the details a reader needs to check them.

use std::collections::BTreeMap;

use serde::Serialize;

use super::DiscoverSettings;
use super::checks::Window;
use super::region::ProbedRegion;

/// A window of structured disagreement and the detector region it probes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Disagreement {
    /// [lo, hi] bias of the window, V.
    #[serde(rename = "voltages_V")]
    pub voltages_v: [f64; 2],
    /// The region the depletion front sweeps across the window (start model's best fit).
    pub region: Option<ProbedRegion>,
    /// Look-elsewhere-corrected posterior-predictive p-value of the window.
    pub p_value: f64,
    /// The run of residuals: voltage indices, sign (+1: data above the model), sum of r^2.
    pub window: Window,
    /// Why the region could not be computed, if it could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub region_error: Option<String>,
}

/// One catalogue entry's quick score.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateScore {
    /// The entry's name.
    pub name: String,
    /// Laplace ln Bayes factor against the start model (same predictor): ln Z_c - ln Z_0; null
    /// (NaN) where the candidate's optimum lies at a prior bound (`at_prior_bound`): the Laplace
    /// approximation does not hold there, and the candidate is not chosen.
    pub score: f64,
    /// The candidate's parameters whose optimum lies within 1% of the support's width of a
    /// prior bound (`summary::near_bound`), worded; empty where none does.
    pub at_prior_bound: Vec<String>,
    /// What computed its curves (`surrogate`, `exact`).
    pub predictor: String,
    /// chi^2 drop at the optimum (start model's chi^2 minus the candidate's).
    pub delta_chi2: f64,
    /// chi^2 at the candidate's optimum.
    pub chi2: f64,
    /// Its parameters at the optimum (name -> value).
    pub optimum: BTreeMap<String, f64>,
    /// The parameters it adds.
    pub added: Vec<String>,
    /// What it is.
    pub description: String,
    /// The residual signature it explains.
    pub signature: String,
    /// Curve evaluations of its quick fit.
    pub evaluations: usize,
    /// Wall time of its quick fit, s.
    pub seconds: f64,
}

/// Goodness of fit of one model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gap {
    /// chi^2 / ndf at the global mode.
    pub chi2_ndf: f64,
    /// Largest |pull| at the global mode.
    pub max_pull: f64,
    /// Posterior-predictive p-value of the chi^2 discrepancy.
    pub ppc_p: f64,
    /// chi^2 at the global mode.
    pub chi2: f64,
    /// Degrees of freedom (voltages minus parameters).
    pub ndf: usize,
    /// The model (`b-z`, `b-z+radial`, ...).
    pub model: String,
    /// How it was fitted: `mcmc` (converged or not, see the fit) or `laplace`.
    pub method: String,
    /// Whether the sampler converged (`laplace`: true when the optimiser did).
    pub converged: bool,
    /// Parameters at the global mode (name -> value).
    pub mode: BTreeMap<String, f64>,
}

/// An entry that does not apply here.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotApplicable {
    /// The entry.
    pub name: String,
    /// Why.
    pub reason: String,
}

/// The whole result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DiscoverySummary {
    /// The start model's prior name.
    pub start_model: String,
    /// Windows of structured disagreement of the start model.
    pub disagreement: Vec<Disagreement>,
    /// Every applicable entry with its quick score, best first.
    pub candidates: Vec<CandidateScore>,
    /// The extension added, or null when the start model describes the data.
    pub chosen: Option<String>,
    /// The start model.
    pub before: Gap,
    /// The extended model (the start model again when nothing was chosen).
    pub after: Gap,
    /// elpd(after) - elpd(before), leave-window-out (0 when nothing was chosen).
    pub delta_elpd: f64,
    /// Its standard error.
    pub delta_elpd_se: f64,
    /// Wall time, s.
    pub seconds: f64,
    /// ln Bayes factor of the chosen extension (its Laplace score), null when none was chosen.
    pub ln_bayes_factor: Option<f64>,
    /// How the elpd was estimated: `psis` (Pareto-smoothed importance sampling over MCMC
    /// draws), or `laplace-linear` (closed form for the Laplace approximation with a
    /// linearised curve: the exact-solver fits).
    pub elpd_method: String,
    /// Blocks of the leave-window-out elpd.
    pub elpd_blocks: usize,
    /// Largest Pareto k-hat of the elpd's importance weights (before, after); NaN (null in
    /// the JSON) for `laplace-linear`, which samples nothing.
    pub elpd_max_k_hat: [f64; 2],
    /// Every run of same-sign residuals of the start model (the flagged ones are in
    /// `disagreement`).
    pub runs: Vec<Window>,
    /// What computed the start model and the candidates (`exact`, or `surrogate` with the
    /// exact solver only for entries outside its space).
    pub predictor: String,
    /// The start model's MCMC fit on the surrogate (it seeds the exact quick fit).
    pub surrogate_start: Gap,
    /// Entries that do not apply to this start model or detector.
    pub not_applicable: Vec<NotApplicable>,
    /// The decision in words.
    pub verdict: String,
    /// What made this file: program, version, date and the solver's physics revision (issue
    /// 63); absent from files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub made: Option<hpge_foundation::Made>,
    /// Program version.
    pub program_version: String,
    /// Input files and hashes.
    pub inputs: BTreeMap<String, String>,
    /// Settings and seed.
    pub settings: DiscoverSettings,
    /// The stages taken back from an interrupted run of the same arguments (`OUT/stages`), in
    /// order; empty for a run that solved everything itself.
    pub resumed_stages: Vec<String>,
}
