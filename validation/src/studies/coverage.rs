//! Simulation-based calibration of the fit (Talts, Betancourt, Simpson, Vehtari, Gelman 2018):
//! truths theta_i drawn from the prior, data simulated through a model plus the noise model,
//! fitted; if sampler, likelihood and model agree, the rank of theta_i among L posterior draws
//! is uniform on 0..=L, and the smallest intervals cover theta_i at their nominal rate.
//!
//! Data from the surrogate itself test the sampler and the summary; data from the exact solver
//! (noise without the surrogate term) measure what the surrogate's error does to coverage.

use std::time::Instant;

use hpge_inference::fit::draw_range;
use hpge_inference::summary::{interval_contains, smallest_intervals};
use hpge_inference::{CvModel, FitSettings, Likelihood, Posterior, Prior, fit};
use rand::RngExt;
use rand::SeedableRng;
use rand::rngs::StdRng;
use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;

/// Nominal levels of the coverage curve (the 0.683 and 0.955 of the pass test among them).
pub const COVERAGE_LEVELS: [f64; 11] = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.683, 0.8, 0.9, 0.955, 0.99];

/// Settings of a study.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CoverageSettings {
    /// Number of truths.
    pub n_truths: usize,
    /// Seed of the truths and the noise (fit i uses seed + i).
    pub seed: u64,
    /// The fit (sampling targets lower than a real fit's: ranks need ~L independent draws).
    pub fit: FitSettings,
    /// L: posterior draws each truth is ranked among (evenly thinned).
    pub ranks: usize,
}

/// One parameter's calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterCoverage {
    /// Name.
    pub name: String,
    /// KS p-value of the (jittered) normalised ranks against uniform.
    pub ks_p: f64,
    /// Fraction of truths inside the 68.3% smallest interval.
    pub coverage_683: f64,
    /// Fraction inside the 95.5% smallest interval.
    pub coverage_955: f64,
    /// 99% interval of coverage_683 for a calibrated fit (binomial quantiles / n).
    pub expected_683: [f64; 2],
    /// The same for 95.5%.
    pub expected_955: [f64; 2],
    /// Coverage at each of COVERAGE_LEVELS.
    pub coverage_curve: Vec<f64>,
    /// Rank of each truth among L draws (0..=L).
    pub ranks: Vec<usize>,
}

/// A study's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoverageReport {
    /// Truths fitted.
    pub n_truths: usize,
    /// Per parameter.
    pub parameters: Vec<ParameterCoverage>,
    /// Every KS p > 0.01 / n_parameters and every coverage inside its 99% interval.
    pub pass: bool,
    /// L.
    pub ranks: usize,
    /// Fits that did not reach their R-hat/ESS targets (kept in the study).
    pub unconverged: usize,
    /// Truths dropped because the data model failed there (exact solver: no c12).
    pub skipped: usize,
    /// Nominal levels of `coverage_curve`.
    pub levels: Vec<f64>,
    /// Wall time, s.
    pub seconds: f64,
}

/// One-sample Kolmogorov-Smirnov test of `u` (in [0, 1]) against uniform: the asymptotic p-value
/// Q_KS((sqrt(n) + 0.12 + 0.11/sqrt(n)) D) with Q_KS(x) = 2 sum_k (-1)^(k-1) exp(-2 k^2 x^2)
/// (Stephens 1970; Numerical Recipes' form).
pub fn ks_uniform(u: &[f64]) -> f64 {
    let n = u.len();
    if n == 0 {
        return f64::NAN;
    }
    let mut s = u.to_vec();
    s.sort_by(f64::total_cmp);
    let nf = n as f64;
    let d = s
        .iter()
        .enumerate()
        .map(|(i, &x)| (x - i as f64 / nf).max((i + 1) as f64 / nf - x))
        .fold(0.0, f64::max);
    let en = nf.sqrt();
    let x = (en + 0.12 + 0.11 / en) * d;
    if x < 0.2 {
        return 1.0;
    }
    let mut q = 0.0;
    for k in 1..=100 {
        let t = 2.0 * if k % 2 == 1 { 1.0 } else { -1.0 } * (-2.0 * (k * k) as f64 * x * x).exp();
        q += t;
        if t.abs() < 1e-12 {
            break;
        }
    }
    q.clamp(0.0, 1.0)
}

/// The central 99% interval of k/n for k ~ Binomial(n, p): the 0.005 and 0.995 quantiles.
pub fn binomial_interval(n: usize, p: f64, mass: f64) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    // pmf by recursion from the mode in log space.
    let ln_pmf = |k: usize| -> f64 {
        let (nf, kf) = (n as f64, k as f64);
        ln_gamma(nf + 1.0) - ln_gamma(kf + 1.0) - ln_gamma(nf - kf + 1.0)
            + kf * p.ln()
            + (nf - kf) * (1.0 - p).ln()
    };
    let tail = (1.0 - mass) / 2.0;
    let mut cdf = 0.0;
    let mut lo = 0;
    let mut hi = n;
    let mut found_lo = false;
    for k in 0..=n {
        cdf += ln_pmf(k).exp();
        if !found_lo && cdf >= tail {
            lo = k;
            found_lo = true;
        }
        if cdf >= 1.0 - tail {
            hi = k;
            break;
        }
    }
    [lo as f64 / n as f64, hi as f64 / n as f64]
}

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, 9 terms; relative error ~1e-15).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// What one truth contributed.
struct TruthResult {
    ranks: Vec<usize>,
    jitter: Vec<f64>,
    inside: Vec<Vec<bool>>,
    converged: bool,
}

/// Runs the study: `data_model` simulates the data (with `template`'s noise; pass
/// `data_sigma_rel` = 0 for exact-solver data, the surrogate's sigma_p for surrogate data; a
/// `data_model` with a per-point uncertainty then draws its model error with that instead),
/// `fit_model` is fitted. `progress(done, total)` after each truth.
#[allow(clippy::too_many_arguments)]
pub fn coverage(
    fit_model: &dyn CvModel,
    data_model: &dyn CvModel,
    data_sigma_rel: f64,
    prior: &Prior,
    template: &Likelihood,
    settings: &CoverageSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<CoverageReport> {
    let start = Instant::now();
    let d = prior.dim();
    let nv = template.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let n = settings.n_truths;
    let results: Vec<Result<Option<TruthResult>>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut rng =
                StdRng::seed_from_u64(settings.seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ i as u64);
            let truth = prior.sample(&mut rng);
            let mut x = vec![0.0; prior.input_names.len()];
            prior.expand(&truth, &mut x);
            let mut c = vec![0.0; nv];
            let tick = || {
                progress(
                    done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                    n,
                )
            };
            // A truth whose curve fails recoverably is skipped; any other error ends the study.
            match data_model.curve(&x, &mut c) {
                Ok(()) => {}
                Err(e) if e.is_recoverable() => {
                    tick();
                    return Ok(None);
                }
                Err(e) => return Err(e.into()),
            }
            // Surrogate data with a calibrated per-point uncertainty draws its model error
            // with sigma_s at the truth, as the likelihood assumes it.
            let c_m = if data_sigma_rel > 0.0 && data_model.has_point_variance() {
                let mut var = vec![0.0; nv];
                data_model.curve_variance(&x, &mut var, None)?;
                template.simulate_var(&c, &var, &mut rng)
            } else {
                template
                    .with_sigma_rel(data_sigma_rel)
                    .simulate(&c, &mut rng)
            };
            let like = template.with_data(c_m);
            let posterior = Posterior::new(fit_model, prior, &like)?;
            let mut fs = settings.fit;
            fs.sample.seed = settings.seed.wrapping_add(i as u64 + 1);
            fs.predictive_draws = 10;
            fs.mode_draws = 200;
            let f = fit(&posterior, &fs, Default::default(), &|_| {})?;
            let all = f.samples.all();
            let l = settings.ranks;
            let idx: Vec<usize> = (0..l).map(|k| k * all.len() / l).collect();
            let mut ranks = Vec::with_capacity(d);
            let mut jitter = Vec::with_capacity(d);
            let mut inside = Vec::with_capacity(d);
            for (j, p) in prior.parameters.iter().enumerate() {
                ranks.push(idx.iter().filter(|&&k| all[k][j] < truth[j]).count());
                jitter.push(rng.random::<f64>());
                let draws: Vec<f64> = all.iter().map(|t| t[j]).collect();
                let range = draw_range(&draws, p.support);
                let si = smallest_intervals(&draws, None, range, fs.bins, &COVERAGE_LEVELS);
                inside.push(
                    si.iter()
                        .map(|iv| interval_contains(iv, truth[j]))
                        .collect(),
                );
            }
            tick();
            Ok(Some(TruthResult {
                ranks,
                jitter,
                inside,
                converged: f.summary.converged,
            }))
        })
        .collect();
    let mut kept = Vec::new();
    let mut skipped = 0;
    for r in results {
        match r? {
            Some(t) => kept.push(t),
            None => skipped += 1,
        }
    }
    let m = kept.len();
    let l = settings.ranks;
    let k683 = COVERAGE_LEVELS
        .iter()
        .position(|&x| x == 0.683)
        .expect("0.683 is a level");
    let k955 = COVERAGE_LEVELS
        .iter()
        .position(|&x| x == 0.955)
        .expect("0.955 is a level");
    let e683 = binomial_interval(m, 0.683, 0.99);
    let e955 = binomial_interval(m, 0.955, 0.99);
    let mut parameters = Vec::with_capacity(d);
    let mut pass = m > 0;
    for (j, p) in prior.parameters.iter().enumerate() {
        let u: Vec<f64> = kept
            .iter()
            .map(|t| (t.ranks[j] as f64 + t.jitter[j]) / (l + 1) as f64)
            .collect();
        let ks_p = ks_uniform(&u);
        let curve: Vec<f64> = (0..COVERAGE_LEVELS.len())
            .map(|k| kept.iter().filter(|t| t.inside[j][k]).count() as f64 / m.max(1) as f64)
            .collect();
        let (c683, c955) = (curve[k683], curve[k955]);
        pass &= ks_p > 0.01 / d as f64
            && c683 >= e683[0]
            && c683 <= e683[1]
            && c955 >= e955[0]
            && c955 <= e955[1];
        parameters.push(ParameterCoverage {
            name: p.name.clone(),
            ks_p,
            coverage_683: c683,
            coverage_955: c955,
            expected_683: e683,
            expected_955: e955,
            coverage_curve: curve,
            ranks: kept.iter().map(|t| t.ranks[j]).collect(),
        });
    }
    Ok(CoverageReport {
        n_truths: m,
        parameters,
        pass,
        ranks: l,
        unconverged: kept.iter().filter(|t| !t.converged).count(),
        skipped,
        levels: COVERAGE_LEVELS.to_vec(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ks_of_uniform_grid_is_high_and_of_skewed_values_low() {
        let u: Vec<f64> = (0..500).map(|i| (i as f64 + 0.5) / 500.0).collect();
        assert!(ks_uniform(&u) > 0.99);
        let v: Vec<f64> = u.iter().map(|x| x * x).collect();
        assert!(ks_uniform(&v) < 1e-6);
    }

    #[test]
    fn binomial_interval_brackets_the_mean() {
        let [lo, hi] = binomial_interval(200, 0.683, 0.99);
        assert!(lo < 0.683 && hi > 0.683);
        // Normal approximation: 0.683 -+ 2.576 sqrt(p q / n) = [0.598, 0.768].
        assert!(
            (lo - 0.598).abs() < 0.01 && (hi - 0.768).abs() < 0.01,
            "{lo} {hi}"
        );
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }
}
