//! The exact check's look beyond the sampled basin (issue 21): importance weights only re-weight
//! draws the sampler made, so a check can pass while the exact posterior is higher in a basin the
//! (corrected) surrogate barely visits. Seen on the shipped B_Z fit: the check passed (k-hat
//! 0.44) with the posterior at d_Li = 1.5 mm, y_top > y_bot, while the exact solver's best point
//! (model discovery's, d_Li = 2.67 mm, y_bot > y_top) has an exact chi^2 lower by 3.7; the
//! sampler's local mode in that basin sat at d_Li = 1.2 mm, where the exact density is lower.
//!
//! So a passing check also climbs the exact posterior (Levenberg-Marquardt on the exact solver
//! with the sampled model's Jacobian, [`laplace_fit_guided`]: one exact curve a step) from the
//! sampler's local modes in other basins (weight at least
//! [`MIN_ASCENT_WEIGHT`], away from the global mode by more than 1% of a parameter's support and
//! more than [`AWAY_SD`] posterior sd, best first). It fails when an ascent ends at an exact
//! ln p above the exact ln p at the global mode by more than [`ASCENT_MARGIN`]: the exact
//! posterior is e^margin times denser there than at the fit's best point. (An ascent that climbs
//! back into the fitted basin cannot do that while the check passes: its exact peak then lies
//! within a quarter sd of the fitted mode in every parameter, which is 0.03 d below it in ln p
//! for a Gaussian.) Every exact curve the ascent solved then teaches the error model, so the
//! next round's corrected surrogate knows that basin.
//!
//! The Jacobian: with exact forward differences a step cost d + 1 exact curves (the shipped B_RZ
//! fit's two ascents 99 curves, about 130 s of its 5 min). The sampled model's derivatives,
//! scaled to the exact curve point by point, cost nothing and point the same way wherever the
//! model's error varies slowly; a step is still kept only when the exact ln p rises, so an
//! ascent's end is an exact point at least as high as its start, and a better basin it reports
//! is there. It may stop short of the exact peak where the model's derivatives are off, which
//! can only hide a basin, never invent one.

use serde::{Deserialize, Serialize};

use super::round::f64_or_nan;
use super::run::Fit;
use crate::model::CvModel;
use crate::posterior::{LaplaceSettings, Likelihood, Posterior, laplace_fit_guided};
use crate::prior::Prior;
use crate::rejection::unless_rejected;
use crate::{Error, Result};

/// An ascent fails the check when it ends higher than the exact ln p at the global mode by more
/// than this (e^1 = 2.7 times the density).
pub const ASCENT_MARGIN: f64 = 1.0;

/// A local mode within this many posterior sd of the global mode in every parameter lies in the
/// fitted basin, which the check's draws cover: no ascent from there (the shipped B_RZ fit has
/// one at 0.23 sd; its other basin lies 4.3 sd away, B_Z's at 3.5 and 4.4 sd).
pub const AWAY_SD: f64 = 1.0;

/// Local modes of less weight than this (Laplace, under the sampled model) get no ascent.
pub const MIN_ASCENT_WEIGHT: f64 = 0.01;

/// Ascents from the sampler's local modes after a passing check (0: none).
pub const DEFAULT_ASCENTS: usize = 2;

/// Levenberg-Marquardt steps of one ascent at most (one exact curve each, kept or not).
const ASCENT_STEPS: usize = 16;

/// Model inputs x and the exact curve there, pF.
pub type SolvedCurve = (Vec<f64>, Vec<f64>);

/// One ascent of the exact posterior.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BasinAscent {
    /// Where it started: a local mode of the sampled model (parameters).
    pub start: Vec<f64>,
    /// Where it ended.
    pub theta: Vec<f64>,
    /// The exact ln p (prior + exact likelihood) at its end.
    #[serde(deserialize_with = "f64_or_nan")]
    pub ln_posterior_exact: f64,
    /// The exact ln p at the fit's global mode.
    #[serde(deserialize_with = "f64_or_nan")]
    pub ln_posterior_exact_at_mode: f64,
    /// Exact curves it solved.
    pub evaluations: usize,
    /// Whether it found a better basin (fails the check).
    pub better: bool,
}

/// Whether `theta` lies farther than 1% of its support from `mode` in some parameter (a local
/// mode of its own, not the global mode found twice).
pub fn away_from_mode(prior: &Prior, mode: &[f64], theta: &[f64]) -> bool {
    theta
        .iter()
        .zip(mode)
        .zip(&prior.parameters)
        .any(|((a, b), p)| (a - b).abs() > 0.01 * (p.support[1] - p.support[0]))
}

/// Ascents of the exact posterior from up to `n` of `result`'s local modes in other basins,
/// each guided by the Jacobian of `sampled` (the model the sampler used); every exact curve
/// they solved (inputs x, c) for the error model. An ascent whose start fails to solve, or whose
/// Hessian is singular, is left out. `mode_curve`: the exact curve at `result.mode` when the
/// caller has it (the exact check's last solved curve), else it is solved here.
///
/// # Errors
/// A model error other than a recoverable failed solve.
pub fn basin_ascents(
    exact: &dyn CvModel,
    sampled: &dyn CvModel,
    prior: &Prior,
    likelihood: &Likelihood,
    result: &Fit,
    mode_curve: Option<&[f64]>,
    n: usize,
) -> Result<(Vec<BasinAscent>, Vec<SolvedCurve>)> {
    let sd: Vec<f64> = result.summary.parameters.iter().map(|p| p.std).collect();
    let beyond_sd = |theta: &[f64]| {
        theta
            .iter()
            .zip(&result.mode)
            .zip(&sd)
            .any(|((a, b), s)| (a - b).abs() > AWAY_SD * s)
    };
    let starts: Vec<Vec<f64>> = result
        .samples
        .local_modes
        .iter()
        .filter(|l| {
            l.weight >= MIN_ASCENT_WEIGHT
                && away_from_mode(prior, &result.mode, &l.theta)
                && beyond_sd(&l.theta)
        })
        .take(n)
        .map(|l| l.theta.clone())
        .collect();
    if starts.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let exact_like = likelihood.with_sigma_rel(exact.sigma_rel());
    let posterior = Posterior::new(exact, prior, &exact_like)?;
    let at_mode = match mode_curve {
        Some(c) => Some(posterior.evaluate_curve(&result.mode, c.to_vec())?),
        None => unless_rejected(posterior.evaluate(&result.mode))?,
    };
    let Some(at_mode) = at_mode else {
        return Ok((Vec::new(), Vec::new()));
    };
    let settings = LaplaceSettings {
        max_steps: ASCENT_STEPS,
        max_evaluations: 1 + ASCENT_STEPS,
        ..LaplaceSettings::default()
    };
    let mut ascents = Vec::new();
    let mut curves = Vec::new();
    for start in starts {
        // A failed solve or a singular Hessian at the end: no ascent from here.
        let (lf, visited) = match laplace_fit_guided(&posterior, sampled, &start, &settings) {
            Ok(r) => r,
            Err(e) if e.is_recoverable() || matches!(e, Error::Numerical { .. }) => continue,
            Err(e) => return Err(e),
        };
        let better = lf.ln_posterior > at_mode.ln_posterior + ASCENT_MARGIN;
        curves.extend(visited);
        ascents.push(BasinAscent {
            start,
            theta: lf.theta,
            ln_posterior_exact: lf.ln_posterior,
            ln_posterior_exact_at_mode: at_mode.ln_posterior,
            evaluations: lf.evaluations,
            better,
        });
    }
    Ok((ascents, curves))
}
