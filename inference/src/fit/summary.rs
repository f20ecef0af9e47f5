//! What a fit reports (`summary.json`): the issue's fields first, then provenance and
//! diagnostics.

use std::collections::BTreeMap;

use serde::Serialize;

use super::{ExactCheck, RefineRound};
use crate::posterior::NoiseSettings;
use crate::prior::PriorDistribution;
use crate::sampler::{LocalMode, SampleSettings, SamplerStop};

/// Probability contents of the smallest intervals (1, 2 and 3 sigma of a normal).
pub const LEVELS: [f64; 3] = [0.683, 0.955, 0.997];

/// One parameter's marginal posterior.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterSummary {
    /// Name.
    pub name: String,
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
    /// The parameter's value at the global mode (the maximum of the joint posterior).
    pub global_mode: f64,
    /// The maximum of the 1D marginal (fullest histogram bin).
    pub marginal_mode: f64,
    /// Smallest intervals per level ("0.683", "0.955", "0.997"), each a list of disjoint
    /// [lo, hi] (several for a multimodal marginal).
    pub smallest_intervals: BTreeMap<String, Vec<[f64; 2]>>,
    /// Rank-normalised split R-hat.
    pub rhat: f64,
    /// Bulk ESS.
    pub ess_bulk: f64,
    /// Tail ESS.
    pub ess_tail: f64,
    /// Unit.
    pub unit: String,
    /// The prior.
    pub prior: PriorDistribution,
    /// Where the prior is positive.
    pub support: [f64; 2],
    /// The modes and 68.3% interval ends within 1% of the support's width of a finite bound
    /// (`summary::bound_flags`, issue 63), worded; empty where none is. A mode at a bound is the
    /// bound, not a maximum: the posterior presses against the prior there.
    pub at_prior_bound: Vec<String>,
}

/// One mode of the posterior (a component of a Gaussian mixture over the draws).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeSummary {
    /// Probability mass.
    pub weight: f64,
    /// Location (the component's mean), in parameter order.
    pub location: Vec<f64>,
    /// The component's standard deviations.
    pub std: Vec<f64>,
    /// What the mode is, by physics rather than rank (issue 63): for each pair of parameters
    /// `X_bot` / `X_top`, whether the bottom or the top level is the higher at its location
    /// (`y: bottom > top`), joined by "; " ([`mode_physics`]); empty where no pair exists.
    #[serde(default)]
    pub physics: String,
}

/// The physics label of a mode at `location` of parameters `names` ([`ModeSummary::physics`]):
/// B_Z's two modes, the bottom and top levels swapped, are "y: bottom > top" and
/// "y: top > bottom" whatever their weights.
///
/// ```
/// use hpge_inference::fit::mode_physics;
/// let names = ["d_li_mm", "y_bot", "y_top"].map(String::from);
/// assert_eq!(mode_physics(&names, &[1.0, 0.68, 0.50]), "y: bottom > top");
/// assert_eq!(mode_physics(&names, &[1.0, 0.50, 0.68]), "y: top > bottom");
/// assert_eq!(mode_physics(&names[..1], &[1.0]), "");
/// ```
pub fn mode_physics(names: &[String], location: &[f64]) -> String {
    let mut out = Vec::new();
    for (j, name) in names.iter().enumerate() {
        let Some(stem) = name.strip_suffix("_bot") else {
            continue;
        };
        let top = format!("{stem}_top");
        let Some(k) = names.iter().position(|n| *n == top) else {
            continue;
        };
        let (b, t) = (location[j], location[k]);
        let word = if b > t {
            "bottom > top"
        } else if t > b {
            "top > bottom"
        } else {
            "bottom = top"
        };
        out.push(format!("{stem}: {word}"));
    }
    out.join("; ")
}

/// The summary of a fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitSummary {
    /// R-hat and ESS targets reached.
    pub converged: bool,
    /// Wall time of sampling and summary (the exact check's time is in its own record), s.
    pub seconds: f64,
    /// The likelihood's chi^2 at the global mode: sigma with every term of the noise model
    /// (the data's, the solver's eq. 7 and the model's sigma_p; see `likelihood`). The data's
    /// own chi^2 at the exact-checked mode is `exact_check.chi2_data_at_mode`.
    pub chi2: f64,
    /// Degrees of freedom: voltages minus parameters.
    pub ndf: usize,
    /// The posterior-predictive p-value of the likelihood's chi^2
    /// ([`super::Predictive::ppp`]).
    pub posterior_predictive_p: f64,
    /// The posterior of the run's calibration factor kappa (c_m = kappa c_p) that the measured
    /// covariance lets float ([`super::Predictive::calibration`]); absent without a measured
    /// covariance of one shared scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration_factor: Option<crate::posterior::CalibrationScale>,
    /// Per parameter.
    pub parameters: Vec<ParameterSummary>,
    /// The modes found (one for a unimodal posterior).
    pub modes: Vec<ModeSummary>,
    /// The local maxima found before sampling (Metropolis' mode search), best weight first.
    pub local_modes: Vec<LocalMode>,
    /// The exact-solver check (absent with --no-exact-check); after refinement, the last
    /// round's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_check: Option<ExactCheck>,
    /// Why the exact-solver check was not run although asked for (the time budget,
    /// `--max-seconds`, ran out while sampling: issue 66).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_check_skipped: Option<String>,
    /// The rounds of posterior-adaptive refinement, the plain surrogate's first (absent with
    /// --no-exact-check).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refinement: Option<Vec<RefineRound>>,
    /// Share of the posterior draws with an input where the surrogate's training rows thin out
    /// (outside its support, issue 24: there it extrapolates); absent where not computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior_outside_support: Option<f64>,
    /// What made this file: program, version, date and the solver's physics revision (issue
    /// 63); absent from files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub made: Option<hpge_foundation::Made>,
    /// hpge-cv version.
    pub program_version: String,
    /// Inputs: the data, model and prior files (with hashes where known).
    pub inputs: BTreeMap<String, String>,
    /// The noise model.
    pub likelihood: NoiseSettings,
    /// Sampler settings (sampler, chains, seed, targets).
    pub settings: SampleSettings,
    /// Why sampling stopped.
    pub stop: SamplerStop,
    /// Whether the tuning met its criterion.
    pub tuned: bool,
    /// Tuning cycles (Metropolis).
    pub tuning_cycles: usize,
    /// Tuning wall time, s.
    pub tuning_seconds: f64,
    /// Kept draws per chain.
    pub draws_per_chain: usize,
    /// Acceptance per chain (NUTS: fraction of non-divergent transitions).
    pub acceptance: Vec<f64>,
    /// Divergent transitions (NUTS).
    pub divergences: usize,
    /// Log-density evaluations.
    pub evaluations: u64,
    /// Smallest bulk ESS per second of sampling.
    pub ess_bulk_per_second: f64,
    /// ln p(theta | data) at the global mode (up to the evidence).
    pub ln_posterior_at_mode: f64,
    /// Largest |pull| at the global mode.
    pub max_abs_pull: f64,
}
