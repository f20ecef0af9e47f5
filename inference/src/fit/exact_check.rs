//! The exact-solver check of a surrogate posterior: importance re-weighting of a thinned sample
//! with the exact solver's likelihood. For draws theta_i of the surrogate posterior,
//!   ln w_i = ln L_exact(theta_i) - ln L_surrogate(theta_i)
//! (the prior cancels; the exact likelihood has no surrogate term sigma_p), Pareto-smoothed
//! (PSIS, Vehtari et al. 2024): k-hat < 0.7 means the re-weighted estimates are reliable, and
//! the shift of each mean, (E_w[theta] - E[theta]) / sd[theta], says how far the surrogate moved
//! the posterior.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::predictive::thin_indices;
use crate::Result;
use crate::model::CvModel;
use crate::posterior::Likelihood;
use crate::prior::Prior;
use crate::rejection::unless_rejected;
use crate::sampler::Samples;
use crate::summary::psis;

/// One parameter's shift.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterShift {
    /// Name.
    pub name: String,
    /// The re-weighted (exact-solver) mean.
    pub exact_mean: f64,
    /// (exact mean - surrogate mean) / surrogate posterior sd.
    pub shift_sd: f64,
}

/// The result of the check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExactCheck {
    /// Draws re-weighted.
    pub draws: usize,
    /// Exact solves that failed (weight 0).
    pub failed: usize,
    /// Pareto k-hat of the importance ratios.
    pub pareto_k: f64,
    /// Effective sample size of the smoothed weights, 1 / sum w^2.
    pub ess: f64,
    /// Per parameter.
    pub parameters: Vec<ParameterShift>,
    /// Largest |c_exact - c_surrogate| / c_exact over the voltages at the global mode.
    pub max_rel_diff_at_mode: f64,
    /// chi^2 of the exact curve at the global mode (no surrogate term in sigma).
    pub chi2_exact_at_mode: f64,
    /// The largest |shift_sd|.
    pub max_abs_shift_sd: f64,
    /// Whether k-hat < 0.7 and every |shift| < 0.5 sd.
    pub pass: bool,
    /// Wall time, s.
    pub seconds: f64,
    /// Target relative error of c12 of the exact solves (the adaptive grid's tolerance), where
    /// the caller knows it (a fit records its exact solver's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solver_tolerance: Option<f64>,
}

/// Runs the check on at most `n` draws (evenly thinned) and at the global mode `mode`. A solve
/// that fails recoverably gives its draw weight 0 (a surrogate curve that fails, NaN); any
/// other model error is returned.
#[allow(clippy::too_many_arguments)]
pub fn exact_check(
    surrogate: &dyn CvModel,
    exact: &dyn CvModel,
    prior: &Prior,
    likelihood: &Likelihood,
    samples: &Samples,
    mode: &[f64],
    n: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<ExactCheck> {
    let start = Instant::now();
    let exact_like = likelihood.with_sigma_rel(exact.sigma_rel());
    let all = samples.all();
    let idx = thin_indices(all.len(), n);
    let nv = likelihood.len();
    let nx = prior.input_names.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = idx.len() + 1;
    let eval = |model: &dyn CvModel, theta: &[f64]| -> Result<Vec<f64>> {
        let mut x = vec![0.0; nx];
        prior.expand(theta, &mut x);
        let mut c = vec![0.0; nv];
        model.curve(&x, &mut c)?;
        Ok(c)
    };
    let mut points: Vec<&[f64]> = idx.iter().map(|&i| all[i]).collect();
    points.push(mode);
    let results: Vec<(f64, Option<Vec<f64>>, Vec<f64>)> = points
        .par_iter()
        .map(|theta| -> Result<_> {
            let cs = unless_rejected(eval(surrogate, theta))?.unwrap_or_else(|| vec![f64::NAN; nv]);
            let ce = unless_rejected(eval(exact, theta))?;
            let lr = match &ce {
                Some(c) => exact_like.ln_likelihood(c, None) - likelihood.ln_likelihood(&cs, None),
                None => f64::NEG_INFINITY,
            };
            progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                total,
            );
            Ok((lr, ce, cs))
        })
        .collect::<Result<_>>()?;
    let (at_mode, draws) = results.split_last().expect("the mode is always there");
    let failed = draws.iter().filter(|r| r.1.is_none()).count();
    let log_ratios: Vec<f64> = draws
        .iter()
        .map(|r| if r.0.is_finite() { r.0 } else { -1e300 })
        .collect();
    let p = psis(&log_ratios);
    let names = prior.names();
    let mut parameters = Vec::new();
    for (j, name) in names.iter().enumerate() {
        let vals: Vec<f64> = idx.iter().map(|&i| all[i][j]).collect();
        let m = vals.iter().sum::<f64>() / vals.len() as f64;
        let sd =
            (vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (vals.len() as f64 - 1.0)).sqrt();
        let mw: f64 = vals.iter().zip(&p.weights).map(|(v, w)| v * w).sum();
        parameters.push(ParameterShift {
            name: name.clone(),
            exact_mean: mw,
            shift_sd: if sd > 0.0 { (mw - m) / sd } else { 0.0 },
        });
    }
    let (max_rel, chi2_exact) = match &at_mode.1 {
        Some(ce) => (
            ce.iter()
                .zip(&at_mode.2)
                .map(|(e, s)| ((e - s) / e).abs())
                .fold(0.0, f64::max),
            exact_like.chi2(ce),
        ),
        None => (f64::NAN, f64::NAN),
    };
    let max_abs_shift_sd = parameters
        .iter()
        .map(|p| p.shift_sd.abs())
        .fold(0.0, f64::max);
    Ok(ExactCheck {
        draws: draws.len(),
        failed,
        pareto_k: p.k_hat,
        ess: p.ess,
        pass: p.k_hat < 0.7 && max_abs_shift_sd < 0.5,
        parameters,
        max_rel_diff_at_mode: max_rel,
        chi2_exact_at_mode: chi2_exact,
        max_abs_shift_sd,
        seconds: start.elapsed().as_secs_f64(),
        solver_tolerance: None,
    })
}
