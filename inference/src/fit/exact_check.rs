//! The exact-solver check of a surrogate posterior: importance re-weighting of a thinned sample
//! with the exact solver's likelihood. For draws theta_i of the surrogate posterior,
//!   ln w_i = ln L_exact(theta_i) - ln L_surrogate(theta_i)
//! (the prior cancels; the exact likelihood has no surrogate term sigma_p), Pareto-smoothed
//! (PSIS, Vehtari et al. 2024): k-hat < 0.7 means the re-weighted estimates are reliable, and
//! the shift of each mean, (E_w[theta] - E[theta]) / sd[theta], says how far the surrogate moved
//! the posterior.
//!
//! Where the exact curves are solved ([`ExactGrids`]): by default every draw is solved on the
//! global mode's final grids (`hpge_solver::field::cv_curves_near_each`: the mode's adaptive
//! curve first, then each draw once per voltage on those grids, carried along with the geometry,
//! seeded by the mode's potentials, without refinement). The draws of a posterior lie close to
//! each other, so one refined grid serves them all; their likelihoods then differ by the physics
//! alone, not by which refinement pass each draw's own grid happened to stop at (up to the
//! solver tolerance, 1% at the check's default, in c12), and the check costs one potential solve
//! and one weighting stage per point instead of the adaptive passes and the error estimate's
//! two coarsened grids. A few draws ([`ExactCheckSettings::grid_check`]) are also solved on
//! their own adaptive grids, and the difference is reported ([`GridCheck`]).

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::predictive::thin_indices;
use crate::model::CvModel;
use crate::posterior::Likelihood;
use crate::prior::Prior;
use crate::rejection::{unless_rejected, with_reason};
use crate::sampler::Samples;
use crate::summary::psis;
use crate::{Error, Result};

/// Where the check solves the exact curves of the draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExactGrids {
    /// On the global mode's final grids (see the module text): the default.
    #[default]
    Mode,
    /// Each draw on its own adaptive grids (a full `ExactModel::curve` per draw).
    Own,
}

impl ExactGrids {
    /// The name on the command line and in the summary.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mode => "mode",
            Self::Own => "own",
        }
    }

    /// Parses `mode` or `own`.
    ///
    /// # Errors
    /// [`Error::BadOption`] naming `--exact-grids` and the value.
    pub fn parse(name: &str) -> crate::Result<Self> {
        match name {
            "mode" => Ok(Self::Mode),
            "own" => Ok(Self::Own),
            other => Err(Error::BadOption {
                option: format!("--exact-grids {other}"),
                message: "expected mode (every draw on the mode's grids) or own (each draw on its own adaptive grids)".into(),
            }),
        }
    }
}

/// The check passes when the Pareto k-hat of its importance ratios is at most this: above it the
/// re-weighted estimates are unreliable (Vehtari et al. 2024, section 3.2.4). With S draws the
/// limit is the smaller [`k_hat_limit`]`(S) = min(0.7, 1 - 1/log10 S)`.
pub const K_HAT_LIMIT: f64 = 0.7;

/// ... unless the weights are near-equal: every log ratio within this of every other (every
/// weight within a factor 2 of every other). Why that suffices without k-hat (issue 60): with
/// normalised weights w_i and S w_i in [1/R, R], R = exp(range),
/// - the weights' ESS = 1 / sum w_i^2 >= S / R (sum w_i^2 <= max w_i <= R / S): at least half
///   the draws count, so the re-weighted estimates have at most R times the variance of the
///   plain ones and the central limit theorem holds at the usual rate;
/// - each re-weighted mean lies within (R - 1) sd of the plain one
///   (|sum (w_i - 1/S)(f_i - mean f)| <= max |S w_i - 1| mean |f_i - mean f|), and the shifts,
///   measured from these reliable weights, are held to [`SHIFT_LIMIT_SD`] as always.
///
/// k-hat estimates the shape of the largest ratios' tail whatever its scale: on near-equal
/// weights it measures noise (the PPC example of `docs/own-detector.md`: k-hat 0.8-1.2 on
/// log ratios of range 0.41). What no finite sample shows, a region the draws did not reach,
/// k-hat fitted to those same draws does not show either.
pub const NEAR_EQUAL_LOG_RANGE: f64 = std::f64::consts::LN_2;

/// The sample-size-dependent k-hat limit of Vehtari et al. (JMLR 2024, section 3.2.4),
/// min(0.7, 1 - 1/log10 S): 0.5 at S = 100, 0.57 at 200, 0.67 at 1000; 0 or below (no k-hat
/// passes) for S <= 10.
///
/// ```
/// use hpge_inference::fit::k_hat_limit;
/// assert!((k_hat_limit(100) - 0.5).abs() < 1e-12);
/// assert_eq!(k_hat_limit(1_000_000), 0.7);
/// assert!(k_hat_limit(10) <= 0.0);
/// ```
pub fn k_hat_limit(draws: usize) -> f64 {
    if draws < 2 {
        return f64::NEG_INFINITY;
    }
    (1.0 - 1.0 / (draws as f64).log10()).min(K_HAT_LIMIT)
}

/// Whether importance ratios with Pareto `k_hat` over `draws` draws, whose log ratios span
/// `log_ratio_range` (max - min; `failed` draws without an exact solve), are reliable:
/// near-equal weights ([`NEAR_EQUAL_LOG_RANGE`], no failed draw), or k-hat within
/// [`k_hat_limit`]. NaN fails.
pub fn weights_reliable(k_hat: f64, draws: usize, log_ratio_range: f64, failed: usize) -> bool {
    near_equal_weights(log_ratio_range, failed) || k_hat <= k_hat_limit(draws)
}

/// Whether the weights are near-equal: log ratios spanning at most [`NEAR_EQUAL_LOG_RANGE`] and
/// no draw without an exact solve (weight 0). NaN is not near-equal.
pub fn near_equal_weights(log_ratio_range: f64, failed: usize) -> bool {
    failed == 0 && log_ratio_range <= NEAR_EQUAL_LOG_RANGE
}

/// ... and every posterior mean lies within this many posterior sd of its exact re-weighted
/// value (issue 21's acceptance: the surrogate moves no mean by more than a quarter of its sd).
pub const SHIFT_LIMIT_SD: f64 = 0.25;

/// Draws of the check also solved on their own grids when the others share the mode's
/// ([`ExactGrids::Mode`]): four, enough to see the size of the grids' difference at a few
/// percent of the check's cost.
pub const DEFAULT_GRID_CHECK: usize = 4;

/// How the exact-solver check runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExactCheckSettings {
    /// Draws re-weighted (evenly thinned), at least 1.
    pub draws: usize,
    /// Where their exact curves are solved.
    pub grids: ExactGrids,
    /// With [`ExactGrids::Mode`]: how many of the draws (evenly spread) are solved on their own
    /// adaptive grids too, for [`GridCheck`] (0: none).
    pub grid_check: usize,
    /// After a passing check in a refined fit: ascents of the exact posterior from this many of
    /// the sampler's local modes in other basins ([`super::basin_ascents`]; 0: none).
    pub ascents: usize,
}

/// The draws solved both on the mode's grids and on their own: how much the choice of grid
/// moves the check's inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridCheck {
    /// Draws solved both ways (those whose both solves succeeded).
    pub draws: usize,
    /// Largest |c_own - c_mode| / c_own over those draws and the voltages.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub max_rel_diff: f64,
    /// Largest |ln L_own - ln L_mode| (exact likelihood) over those draws: what the choice
    /// changes in an importance log-ratio.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub max_abs_delta_ln_l: f64,
    /// Wall time of the own-grid solves, s.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub seconds: f64,
}

/// One parameter's shift.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParameterShift {
    /// Name.
    pub name: String,
    /// The re-weighted (exact-solver) mean.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub exact_mean: f64,
    /// (exact mean - surrogate mean) / surrogate posterior sd.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub shift_sd: f64,
}

/// The result of the check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExactCheck {
    /// Draws re-weighted.
    pub draws: usize,
    /// Exact solves that failed (weight 0).
    pub failed: usize,
    /// Pareto k-hat of the importance ratios.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub pareto_k: f64,
    /// Effective sample size of the smoothed weights, 1 / sum w^2.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub ess: f64,
    /// Standard deviation of the draws' log importance ratios ln(p_exact / p_surrogate) (the
    /// draws whose exact solve succeeded). k-hat is the shape of the ratios' tail whatever its
    /// scale: beside a large k-hat, a spread of a few hundredths means near-equal weights.
    #[serde(default = "nan", deserialize_with = "super::round::f64_or_nan")]
    pub log_ratio_sd: f64,
    /// max - min of those log ratios.
    #[serde(default = "nan", deserialize_with = "super::round::f64_or_nan")]
    pub log_ratio_range: f64,
    /// Per parameter.
    pub parameters: Vec<ParameterShift>,
    /// Largest |c_exact - c_surrogate| / c_exact over the voltages at the global mode.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub max_rel_diff_at_mode: f64,
    /// chi^2 of the exact curve at the global mode (no surrogate term in sigma).
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub chi2_exact_at_mode: f64,
    /// chi^2 of the exact curve at the global mode under the data's own errors alone (the
    /// measured covariance; the paper's 3% term without one): what the measurement says of the
    /// fitted model ([`crate::Likelihood::chi2_data`]; NaN in files made before it).
    #[serde(default = "nan", deserialize_with = "super::round::f64_or_nan")]
    pub chi2_data_at_mode: f64,
    /// P(X >= chi2_data_at_mode) for X ~ chi^2(voltages - parameters): the goodness of fit of
    /// the exact curve at the mode against the data's own errors.
    #[serde(default = "nan", deserialize_with = "super::round::f64_or_nan")]
    pub p_data_at_mode: f64,
    /// The exact solver's curve at the global mode, pF (empty where its solve failed, and in
    /// files made before it was recorded).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub c_exact_at_mode_pf: Vec<f64>,
    /// That curve against the data's own errors (issue 63: the pulls panel of the predictive
    /// figure, and the run's calibration factor given the exact curve at the mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub own_errors_at_mode: Option<crate::posterior::OwnErrors>,
    /// The largest |shift_sd|.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub max_abs_shift_sd: f64,
    /// Whether the weights are reliable ([`weights_reliable`]: near-equal, or k-hat within
    /// [`k_hat_limit`] of the draws), every |shift| <= [`SHIFT_LIMIT_SD`] and no ascent found a
    /// better basin ([`super::BasinAscent::better`]).
    pub pass: bool,
    /// The k-hat limit for these draws, [`k_hat_limit`] (NaN in files made before it: there
    /// the limit was [`K_HAT_LIMIT`]).
    #[serde(default = "nan", deserialize_with = "super::round::f64_or_nan")]
    pub k_hat_limit: f64,
    /// Whether the weights were near-equal ([`NEAR_EQUAL_LOG_RANGE`]), which passes whatever
    /// k-hat says.
    #[serde(default)]
    pub near_equal: bool,
    /// Wall time, s.
    #[serde(deserialize_with = "super::round::f64_or_nan")]
    pub seconds: f64,
    /// Where the draws' exact curves were solved.
    pub grids: ExactGrids,
    /// With [`ExactGrids::Mode`] and a grid check: the own-grid comparison.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_check: Option<GridCheck>,
    /// With [`ExactGrids::Mode`]: draws whose solve failed on the mode's grids and were solved
    /// again on their own (a grid made for the mode need not resolve a draw's thin depleted
    /// layer: the main job's one failed draw of round 0, d_Li 3.31 mm against the mode's 3.0,
    /// shorted at 25 V on the mode's grid and solves on its own, 670.67 pF).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub own_grid_retries: usize,
    /// Target relative error of c12 of the exact solves (the adaptive grid's tolerance), where
    /// the caller knows it (a fit records its exact solver's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solver_tolerance: Option<f64>,
    /// Ascents of the exact posterior from the sampler's local modes in other basins (after a
    /// passing check; one that found a better basin fails it).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ascents: Vec<super::BasinAscent>,
    /// The draws whose exact solve failed (weight 0; `failed` of them), with the reason.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<FailedSolve>,
    /// The model inputs x and the exact curve of every draw whose solve succeeded, the mode's
    /// last (what posterior-adaptive refinement learns from; not in the summary).
    #[serde(skip)]
    pub solved: Vec<(Vec<f64>, Vec<f64>)>,
}

/// A draw of the check whose exact curve the field solver could not give.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedSolve {
    /// The model inputs x (the surrogate's columns, e.g. d_li_mm, y1_bot, ...).
    pub inputs: Vec<f64>,
    /// The solver's message.
    pub reason: String,
}

/// Runs the check on at most `settings.draws` draws (evenly thinned) and at the global mode
/// `mode`, their exact curves solved where `settings.grids` says. A solve that fails
/// recoverably gives its draw weight 0 (a surrogate curve that fails, NaN); any other model
/// error is returned. With [`ExactGrids::Mode`], a mode whose own curve fails recoverably sends
/// every draw to its own grids.
#[allow(clippy::too_many_arguments)]
pub fn exact_check(
    surrogate: &dyn CvModel,
    exact: &dyn CvModel,
    prior: &Prior,
    likelihood: &Likelihood,
    samples: &Samples,
    mode: &[f64],
    settings: &ExactCheckSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<ExactCheck> {
    let start = Instant::now();
    let exact_like = likelihood.with_sigma_rel(exact.sigma_rel());
    let all = samples.all();
    let idx = thin_indices(all.len(), settings.draws);
    let nv = likelihood.len();
    let nx = prior.input_names.len();
    let expand = |theta: &[f64]| -> Vec<f64> {
        let mut x = vec![0.0; nx];
        prior.expand(theta, &mut x);
        x
    };
    let eval = |model: &dyn CvModel, theta: &[f64]| -> Result<Vec<f64>> {
        let mut c = vec![0.0; nv];
        model.curve(&expand(theta), &mut c)?;
        Ok(c)
    };
    let mut points: Vec<&[f64]> = idx.iter().map(|&i| all[i]).collect();
    points.push(mode);
    // The sampled model's curve and its own sigma_p,k^2 at each point (a corrected surrogate's
    // vary with x), for its likelihood.
    let surrogate_curves: Vec<(Vec<f64>, Vec<f64>)> = points
        .par_iter()
        .map(|theta| {
            let c = unless_rejected(eval(surrogate, theta))?.unwrap_or_else(|| vec![f64::NAN; nv]);
            let mut var = vec![0.0; nv];
            unless_rejected(surrogate.curve_variance(&expand(theta), &mut var, None))?;
            Ok((c, var))
        })
        .collect::<Result<_>>()?;
    let mut grids = settings.grids;
    let mut exact_curves = None;
    let mut own_grid_retries = 0;
    if grids == ExactGrids::Mode {
        let xs: Vec<Vec<f64>> = points[..points.len() - 1]
            .iter()
            .map(|t| expand(t))
            .collect();
        // The mode's curve first (progress 1 of n + 1), then the draws.
        match unless_rejected(exact.curves_near(&expand(mode), &xs, progress))? {
            Some((c_mode, near)) => {
                let mut v = near
                    .into_iter()
                    .map(with_reason)
                    .collect::<Result<Vec<_>>>()?;
                // A draw that failed on the mode's grids: once more on its own.
                own_grid_retries = v.iter().filter(|c| c.is_err()).count();
                v.par_iter_mut()
                    .enumerate()
                    .try_for_each(|(i, c)| -> Result<()> {
                        if let Err(mode) = c {
                            let mode = std::mem::take(mode);
                            *c = with_reason(eval(exact, points[i]))?.map_err(|own| {
                                format!("on the mode's grids: {mode}; on its own: {own}")
                            });
                        }
                        Ok(())
                    })?;
                v.push(Ok(c_mode));
                exact_curves = Some(v);
            }
            None => grids = ExactGrids::Own,
        }
    }
    let exact_curves = match exact_curves {
        Some(v) => v,
        None => {
            // Each point on its own adaptive grids.
            let done = std::sync::atomic::AtomicUsize::new(0);
            points
                .par_iter()
                .map(|theta| {
                    let c = with_reason(eval(exact, theta));
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    progress(k + 1, points.len());
                    c
                })
                .collect::<Result<_>>()?
        }
    };
    let solved: Vec<(Vec<f64>, Vec<f64>)> = points
        .iter()
        .zip(&exact_curves)
        .filter_map(|(theta, ce)| ce.as_ref().ok().map(|c| (expand(theta), c.clone())))
        .collect();
    let failures: Vec<FailedSolve> = points
        .iter()
        .zip(&exact_curves)
        .filter_map(|(theta, ce)| {
            ce.as_ref().err().map(|reason| FailedSolve {
                inputs: expand(theta),
                reason: reason.clone(),
            })
        })
        .collect();
    let results: Vec<(f64, Option<Vec<f64>>, Vec<f64>)> = exact_curves
        .into_iter()
        .zip(surrogate_curves)
        .map(|(ce, (cs, var))| {
            let ce = ce.ok();
            let lr = match &ce {
                Some(c) => {
                    exact_like.ln_likelihood(c, None)
                        - likelihood.ln_likelihood_var(&cs, &var, None, None)
                }
                None => f64::NEG_INFINITY,
            };
            (lr, ce, cs)
        })
        .collect();
    let (at_mode, draws) = results.split_last().expect("the mode is always there");
    let failed = draws.iter().filter(|r| r.1.is_none()).count();
    let log_ratios: Vec<f64> = draws
        .iter()
        .map(|r| if r.0.is_finite() { r.0 } else { -1e300 })
        .collect();
    let p = psis(&log_ratios);
    let (log_ratio_sd, log_ratio_range) = spread(draws.iter().map(|r| r.0));
    let names = prior.names();
    let mut parameters = Vec::new();
    for (j, name) in names.iter().enumerate() {
        let vals: Vec<f64> = idx.iter().map(|&i| all[i][j]).collect();
        let (m, sd) = mean_sd(&vals);
        let mw: f64 = vals.iter().zip(&p.weights).map(|(v, w)| v * w).sum();
        parameters.push(ParameterShift {
            name: name.clone(),
            exact_mean: mw,
            shift_sd: if sd > 0.0 { (mw - m) / sd } else { 0.0 },
        });
    }
    let (max_rel, chi2_exact, chi2_data) = match &at_mode.1 {
        Some(ce) => (
            ce.iter()
                .zip(&at_mode.2)
                .map(|(e, s)| ((e - s) / e).abs())
                .fold(0.0, f64::max),
            exact_like.chi2(ce),
            exact_like.chi2_data(ce),
        ),
        None => (f64::NAN, f64::NAN, f64::NAN),
    };
    let ndf = exact_like.len().saturating_sub(names.len());
    let max_abs_shift_sd = parameters
        .iter()
        .map(|p| p.shift_sd.abs())
        .fold(0.0, f64::max);
    Ok(ExactCheck {
        draws: draws.len(),
        failed,
        pareto_k: p.k_hat,
        ess: p.ess,
        log_ratio_sd,
        log_ratio_range,
        pass: weights_reliable(p.k_hat, draws.len(), log_ratio_range, failed)
            && max_abs_shift_sd <= SHIFT_LIMIT_SD,
        k_hat_limit: k_hat_limit(draws.len()),
        near_equal: near_equal_weights(log_ratio_range, failed),
        parameters,
        max_rel_diff_at_mode: max_rel,
        chi2_exact_at_mode: chi2_exact,
        chi2_data_at_mode: chi2_data,
        p_data_at_mode: hpge_foundation::chi_squared_sf(ndf, chi2_data),
        c_exact_at_mode_pf: at_mode.1.clone().unwrap_or_default(),
        own_errors_at_mode: at_mode.1.as_ref().map(|ce| exact_like.own_errors(ce)),
        max_abs_shift_sd,
        seconds: start.elapsed().as_secs_f64(),
        grids,
        grid_check: None,
        own_grid_retries,
        solver_tolerance: None,
        ascents: Vec::new(),
        failures,
        solved,
    })
    .and_then(|mut check| {
        if grids == ExactGrids::Mode && settings.grid_check > 0 {
            add_grid_check(&mut check, exact, likelihood, settings.grid_check)?;
        }
        Ok(check)
    })
}

/// Solves `count` of a check's draws (evenly spread over those whose solve succeeded) on their
/// own adaptive grids and records how far their curves and exact likelihoods lie from the ones
/// on the mode's grids (`check.grid_check`). A refined fit runs it once, on its last round.
///
/// # Errors
/// A non-recoverable failure of the own-grid solves.
pub fn add_grid_check(
    check: &mut ExactCheck,
    exact: &dyn CvModel,
    likelihood: &Likelihood,
    count: usize,
) -> Result<()> {
    let start = Instant::now();
    let exact_like = likelihood.with_sigma_rel(exact.sigma_rel());
    // The mode is the last entry of `solved`.
    let draws = &check.solved[..check.solved.len().saturating_sub(1)];
    let n = draws.len();
    if n == 0 || count == 0 {
        return Ok(());
    }
    let mut picks: Vec<usize> = (0..count.min(n)).map(|j| j * n / count.min(n)).collect();
    picks.dedup();
    let nv = likelihood.len();
    let own: Vec<Option<Vec<f64>>> = picks
        .par_iter()
        .map(|&k| {
            let mut c = vec![0.0; nv];
            unless_rejected(exact.curve(&draws[k].0, &mut c)).map(|o| o.map(|()| c))
        })
        .collect::<Result<_>>()?;
    let (mut solved, mut max_rel, mut max_dl) = (0, 0.0f64, 0.0f64);
    for (&k, o) in picks.iter().zip(&own) {
        let Some(o) = o else {
            continue;
        };
        let m = &draws[k].1;
        solved += 1;
        for (a, b) in o.iter().zip(m) {
            max_rel = max_rel.max(((a - b) / a).abs());
        }
        let dl = exact_like.ln_likelihood(o, None) - exact_like.ln_likelihood(m, None);
        max_dl = max_dl.max(dl.abs());
    }
    check.grid_check = Some(GridCheck {
        draws: solved,
        max_rel_diff: max_rel,
        max_abs_delta_ln_l: max_dl,
        seconds: start.elapsed().as_secs_f64(),
    });
    check.seconds += start.elapsed().as_secs_f64();
    Ok(())
}

/// serde's `skip_serializing_if` for counters.
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// NaN (the serde default of a figure an older file lacks).
fn nan() -> f64 {
    f64::NAN
}

/// Sample standard deviation and range (max - min) of the finite values of `v` (NaN for fewer
/// than two).
fn spread(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let x: Vec<f64> = v.filter(|x| x.is_finite()).collect();
    if x.len() < 2 {
        return (f64::NAN, f64::NAN);
    }
    let (_, sd) = mean_sd(&x);
    let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (sd, hi - lo)
}

/// Mean and sample standard deviation (n - 1) of `x`.
fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let sd = (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (m, sd)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_k_hat_limit_falls_with_fewer_draws_and_near_equal_weights_pass_whatever_k_hat() {
        // Vehtari et al. 2024: 1 - 1/log10(S), at most 0.7.
        assert!((k_hat_limit(100) - 0.5).abs() < 1e-12);
        assert!((k_hat_limit(200) - (1.0 - 1.0 / 200f64.log10())).abs() < 1e-12);
        assert_eq!(k_hat_limit(10_000), 0.7);
        assert!(k_hat_limit(10) <= 0.0 && k_hat_limit(1) == f64::NEG_INFINITY);
        // The main job's round 1 (2026-12-06): k-hat 0.78, log ratios spread over 4.5: fails;
        // its round 2, k-hat 0.43 over 100 draws: passes; 0.6 over 100 draws now fails.
        assert!(!weights_reliable(0.78, 100, 4.53, 0));
        assert!(weights_reliable(0.43, 100, 5.77, 0));
        assert!(!weights_reliable(0.6, 100, 3.0, 0));
        assert!(weights_reliable(0.6, 1000, 3.0, 0));
        // NaN k-hat (too few draws for a tail) fails unless the weights are near-equal.
        assert!(!weights_reliable(f64::NAN, 12, 2.0, 0));
        assert!(weights_reliable(f64::NAN, 12, 0.3, 0));
        // A draw without an exact solve has weight 0: never near-equal.
        assert!(!weights_reliable(f64::NAN, 12, 0.3, 1));
    }

    #[test]
    fn near_equal_weights_with_a_heavy_looking_tail_pass_and_a_real_heavy_tail_fails() {
        // The PPC example's shape: 100 log ratios within 0.41 of each other whose top few spread
        // out, so the tail's shape looks heavy: k-hat above 0.7, every weight within 1.5x.
        let mut lr: Vec<f64> = (0..100).map(|i| 0.002 * f64::from(i % 7)).collect();
        for (j, x) in lr.iter_mut().rev().take(6).enumerate() {
            *x = 0.41 * (1.0 - 0.15 * j as f64);
        }
        let p = crate::summary::psis(&lr);
        let (_, range) = spread(lr.iter().copied());
        assert!(p.k_hat > 0.7, "k-hat {}", p.k_hat);
        assert!(range <= 0.41 + 1e-12);
        assert!(weights_reliable(p.k_hat, lr.len(), range, 0));
        // Ratios with a Pareto tail of shape 1 (r = 1/u): neither near-equal nor a small k-hat.
        let heavy: Vec<f64> = (1..=100)
            .map(|i| -((f64::from(i) - 0.5) / 100.0).ln())
            .collect();
        let q = crate::summary::psis(&heavy);
        let (_, range) = spread(heavy.iter().copied());
        assert!(
            !weights_reliable(q.k_hat, heavy.len(), range, 0),
            "k-hat {}",
            q.k_hat
        );
    }
}
