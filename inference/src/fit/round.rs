//! One round of posterior-adaptive refinement as a fit reports it (`summary.json`'s
//! `refinement`) and writes it (`OUT/rounds/`).

use serde::{Deserialize, Serialize};

/// Reads a number written by serde_json, where NaN (a k-hat of too few draws, a mode without an
/// exact curve) is written as `null`: null reads back as NaN.
///
/// # Errors
/// Neither a number nor null.
pub fn f64_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// One round of refinement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefineRound {
    /// 0 for the plain surrogate.
    pub round: usize,
    /// Exact curves the sampled model was corrected with (0 in round 0).
    pub training_curves: usize,
    /// Pareto k-hat of the round's exact check.
    #[serde(deserialize_with = "f64_or_nan")]
    pub pareto_k: f64,
    /// Its largest |mean shift| in posterior sd.
    #[serde(deserialize_with = "f64_or_nan")]
    pub max_abs_shift_sd: f64,
    /// Its largest |c_exact - c_model| / c_exact at the round's global mode.
    #[serde(deserialize_with = "f64_or_nan")]
    pub max_rel_diff_at_mode: f64,
    /// Whether the check passed.
    pub pass: bool,
    /// Sampling and summary, s.
    #[serde(deserialize_with = "f64_or_nan")]
    pub sampling_seconds: f64,
    /// The exact check, s.
    #[serde(deserialize_with = "f64_or_nan")]
    pub exact_seconds: f64,
    /// Fitting the error model before this round, s (0 in round 0).
    #[serde(deserialize_with = "f64_or_nan")]
    pub error_model_seconds: f64,
    /// Whether this round was taken back from a previous, interrupted run of the same fit
    /// (`OUT/rounds/`) instead of being solved again.
    #[serde(default)]
    pub resumed: bool,
    /// Why the refinement ended at this failed round (the round limit, too few exact curves for
    /// the error model); absent on a passing or intermediate round.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// Exact curves solved at the sampler's other local modes after this round's check (they
    /// teach the error model with the check's, see [`crate::fit::MAX_LOCAL_MODE_CURVES`]).
    #[serde(default)]
    pub local_mode_curves: usize,
    /// The best ascent of this round's check that found a better basin than the fit's
    /// ([`crate::fit::basin_ascents`]); absent when none did or none ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub better_basin: Option<super::BasinAscent>,
    /// The model inputs of the exact curve whose error-model variance was this round's point
    /// variance at every input (`--refine-variance best`, rounds after the first); absent
    /// otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variance_at: Option<Vec<f64>>,
}
