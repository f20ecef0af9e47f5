//! The posterior predictive of c_p - c_m per voltage (the paper's figures of the predictive):
//! the predicted curve of thinned posterior draws minus the measurement, with central bands.

use rayon::prelude::*;
use serde::Serialize;

use crate::Result;
use crate::posterior::{Posterior, PosteriorEvaluation};
use crate::rejection::unless_rejected;
use crate::sampler::Samples;

/// Per voltage: the median and the central 68.3/95.5/99.7% bands of c_p - c_m (pF), the
/// measurement and the prediction at the global mode with its sigma.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Predictive {
    /// Bias, V.
    pub voltage_v: Vec<f64>,
    /// c_m, pF.
    pub c_m_pf: Vec<f64>,
    /// c_p at the global mode, pF.
    pub c_mode_pf: Vec<f64>,
    /// sigma_c at the global mode, pF (the likelihood's per-point standard deviation).
    pub sigma_pf: Vec<f64>,
    /// Median of c_p - c_m over the draws, pF.
    pub median_pf: Vec<f64>,
    /// [lo, hi] of c_p - c_m per level (LEVELS order), per voltage.
    pub bands_pf: Vec<Vec<[f64; 2]>>,
    /// Draws used.
    pub draws: usize,
    /// The posterior-predictive p-value of the likelihood's chi^2 (Gelman, Meng and Stern
    /// 1996): P(T(y_rep, theta) >= T(y, theta)) over the posterior and replicated data, with
    /// T = chi^2 under the likelihood at theta. At fixed theta the replicated T is chi^2(N)
    /// (N voltages: a Gaussian quadratic form in its own covariance), so the p-value is the
    /// draws' mean of P(chi^2(N) >= T(y, theta_s)), without sampling y_rep (Rao-Blackwellised).
    /// Near 0: the data lie further from every posterior curve than the likelihood's errors
    /// allow; near 1: closer (errors too large, or a stand-in made by the fitted model).
    pub ppp: f64,
    /// The posterior of the run's calibration factor kappa (c_m = kappa c_p) that a measured
    /// covariance u u^T + diag(d) lets float: per draw the normal posterior of the shared scale
    /// under the likelihood the fit samples, mixed over the draws
    /// ([`crate::posterior::calibration_mixture`]); None without such a covariance.
    pub calibration: Option<crate::posterior::CalibrationScale>,
}

/// Quantile q of sorted values (linear interpolation).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let h = q * (sorted.len() - 1) as f64;
    let i = h.floor() as usize;
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + (h - i as f64) * (sorted[j] - sorted[i])
}

/// Evenly spaced indices of at most `n` of `total` draws (the draws the exact-solver check, the
/// posterior predictive and discover's fits use).
pub fn thin_indices(total: usize, n: usize) -> Vec<usize> {
    let n = n.min(total).max(1);
    (0..n).map(|i| i * total / n).collect()
}

/// The predictive from at most `n` draws, with the evaluation at the mode `mode` (its curve, and
/// its model variance for sigma_c). A draw whose curve
/// fails recoverably is left out; any other model error is returned.
pub fn predictive(
    posterior: &Posterior,
    samples: &Samples,
    n: usize,
    mode: &PosteriorEvaluation,
    levels: &[f64],
) -> Result<Predictive> {
    let c_mode = &mode.c_p;
    let all = samples.all();
    let idx = thin_indices(all.len(), n);
    let evaluations: Vec<PosteriorEvaluation> = idx
        .par_iter()
        .map(|&i| unless_rejected(posterior.evaluate(all[i])))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let c_m = &posterior.likelihood.c_m;
    let nv = c_m.len();
    let ppp = evaluations
        .iter()
        .map(|e| {
            let chi2 = posterior.likelihood.chi2_var(&e.c_p, &e.var_rel);
            hpge_foundation::chi_squared_sf(nv, chi2)
        })
        .sum::<f64>()
        / evaluations.len() as f64;
    let scales: Vec<crate::posterior::CalibrationScale> = evaluations
        .iter()
        .filter_map(|e| posterior.likelihood.calibration_var(&e.c_p, &e.var_rel))
        .map(|f| f.scale)
        .collect();
    let calibration = crate::posterior::calibration_mixture(&scales);
    let curves: Vec<Vec<f64>> = evaluations.into_iter().map(|e| e.c_p).collect();
    let mut median = vec![0.0; nv];
    let mut bands = vec![Vec::new(); nv];
    for k in 0..nv {
        let mut d: Vec<f64> = curves.iter().map(|c| c[k] - c_m[k]).collect();
        d.sort_by(f64::total_cmp);
        if d.is_empty() {
            continue;
        }
        median[k] = quantile(&d, 0.5);
        bands[k] = levels
            .iter()
            .map(|l| [quantile(&d, 0.5 - l / 2.0), quantile(&d, 0.5 + l / 2.0)])
            .collect();
    }
    Ok(Predictive {
        voltage_v: posterior.model.voltages().to_vec(),
        c_m_pf: c_m.clone(),
        c_mode_pf: c_mode.to_vec(),
        sigma_pf: posterior.likelihood.sigma_var(c_mode, &mode.var_rel),
        median_pf: median,
        bands_pf: bands,
        draws: curves.len(),
        ppp,
        calibration,
    })
}
