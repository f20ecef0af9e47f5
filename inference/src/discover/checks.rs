//! Posterior-predictive checks that point at where a fitted model misses the measurement, and
//! the leave-window-out expected log predictive density (elpd) that scores a model extension.
//!
//! Notation: `k = 0..N` indexes the bias voltages, `s = 0..S` the posterior draws, c_m,k (pF)
//! is the measured capacitance c12, c_s,k (pF) the curve predicted by draw s and sigma_s,k (pF)
//! the standard deviation of the independent Gaussian noise of draw s at voltage k.
//!
//! * [`residual_check`]: standardised residuals
//!   `r_k = (c_m,k - mean_s c_s,k) / sqrt(mean_s sigma_s,k^2 + var_s c_s,k)`, the runs of
//!   same-sign residuals ("windows") with a look-elsewhere corrected p-value, and the global
//!   posterior-predictive p-value of the chi^2 discrepancy.
//! * [`leave_window_out`]: `elpd_b = ln p(y_b | y_-b)` for contiguous blocks b of voltages, by
//!   Pareto smoothed importance sampling (PSIS) of the posterior draws.
//! * [`delta_elpd`]: the paired difference of two such scores and its standard error.

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

use crate::summary::psis;

/// `ln sqrt(2 pi)`.
const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// Most replicates [`residual_check`] draws.
pub const MAX_REPLICATES: usize = 4000;

/// Posterior-predictive draws of one fit: for draw s and voltage k the predicted c12 c_s,k (pF)
/// and the noise standard deviation sigma_s,k (pF), so that the predictive of the measurement
/// given draw s is `y_k ~ N(c_s,k, sigma_s,k^2)`, independent over k.
///
/// Every row of `curves` and `sigmas` has one entry per voltage; both have one row per draw.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictiveDraws {
    /// Predicted c12 (pF) per draw, per voltage: `curves[s][k] = c_s,k`.
    pub curves: Vec<Vec<f64>>,
    /// Noise standard deviation (pF) per draw, per voltage: `sigmas[s][k] = sigma_s,k`.
    pub sigmas: Vec<Vec<f64>>,
}

impl PredictiveDraws {
    /// Number of draws S.
    fn len(&self) -> usize {
        self.curves.len()
    }

    /// Panics unless there are as many sigma rows as curve rows and every row has `n` entries.
    fn check_shape(&self, n: usize) {
        assert_eq!(
            self.curves.len(),
            self.sigmas.len(),
            "PredictiveDraws: {} curves but {} sigma rows",
            self.curves.len(),
            self.sigmas.len()
        );
        for (s, (c, sd)) in self.curves.iter().zip(&self.sigmas).enumerate() {
            assert!(
                c.len() == n && sd.len() == n,
                "PredictiveDraws: draw {s} has {} curve and {} sigma values, the measurement {n}",
                c.len(),
                sd.len()
            );
        }
    }
}

/// A run of same-sign standardised residuals (voltage indices first..=last).
///
/// `statistic` is `T_w = sum_{k=first..=last} r_k^2` (dimensionless); `p_value` is its
/// look-elsewhere corrected p-value `(1 + #{j : M_j >= T_w}) / (1 + R)`, M_j the largest run
/// statistic of posterior-predictive replicate j (see [`residual_check`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Window {
    /// First voltage index of the run.
    pub first: usize,
    /// Last voltage index of the run (inclusive).
    pub last: usize,
    /// Sign of the residuals in the run: +1 (measurement above the prediction) or -1.
    pub sign: i8,
    /// `T_w = sum_{k in w} r_k^2`.
    pub statistic: f64,
    /// `(1 + #{j : M_j >= T_w}) / (1 + R)`.
    pub p_value: f64,
}

/// Result of [`residual_check`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualCheck {
    /// Standardised residual per voltage:
    /// `r_k = (c_m,k - mean_s c_s,k) / sqrt(mean_s sigma_s,k^2 + var_s c_s,k)` (dimensionless;
    /// `var_s` with the 1/S denominator, so the scale is the standard deviation of the
    /// posterior predictive mixture).
    pub residuals: Vec<f64>,
    /// Every run of >= min_run consecutive residuals of the same sign, in voltage order.
    pub windows: Vec<Window>,
    /// Global posterior-predictive p-value of the chi^2 discrepancy:
    /// `(1/R) #{j : chi2(y_rep,j; c_s, sigma_s) >= chi2(c_m; c_s, sigma_s)}`, s = j mod S,
    /// `chi2(y; c, sigma) = sum_k ((y_k - c_k) / sigma_k)^2`. NaN without replicates.
    pub ppc_p: f64,
    /// Replicates used: `R = min(S, 4000)`.
    pub replicates: usize,
}

/// Sign of a residual: +1, -1, or 0 for zero or NaN (which belongs to no run).
fn sign_of(r: f64) -> i8 {
    if r > 0.0 {
        1
    } else if r < 0.0 {
        -1
    } else {
        0
    }
}

/// Calls `f(first, last, sign, T)` for every maximal run `first..=last` of equal nonzero sign of
/// `r` that has at least `min_run` elements, with `T = sum_{k=first..=last} r_k^2`, in order.
fn for_each_run(r: &[f64], min_run: usize, mut f: impl FnMut(usize, usize, i8, f64)) {
    let mut start = 0;
    let mut sign = 0i8;
    let mut stat = 0.0;
    for (k, &v) in r.iter().enumerate() {
        let sk = sign_of(v);
        if sk != sign {
            if sign != 0 && k - start >= min_run {
                f(start, k - 1, sign, stat);
            }
            start = k;
            sign = sk;
            stat = 0.0;
        }
        stat += v * v;
    }
    if sign != 0 && r.len() - start >= min_run {
        f(start, r.len() - 1, sign, stat);
    }
}

/// `chi2(y; c, sigma) = sum_k ((y_k - c_k) / sigma_k)^2`.
fn chi2(y: &[f64], c: &[f64], sigma: &[f64]) -> f64 {
    y.iter()
        .zip(c)
        .zip(sigma)
        .map(|((y, c), s)| ((y - c) / s).powi(2))
        .sum()
}

/// Standardised residuals, runs of same-sign residuals and the posterior-predictive chi^2
/// p-value of the measurement `c_m` (pF, one per voltage) under the predictive `draws`.
///
/// * Residuals: with `mu_k = mean_s c_s,k` and
///   `scale_k = sqrt(mean_s sigma_s,k^2 + var_s c_s,k)` (1/S variance),
///   `r_k = (c_m,k - mu_k) / scale_k`.
/// * Windows: the maximal runs of equal sign of r_k (a zero or NaN residual ends a run and
///   belongs to none) with at least `min_run` elements; statistic `T_w = sum_{k in w} r_k^2`.
/// * Look-elsewhere correction: `R = min(S, 4000)` replicates; replicate j uses draw
///   `s = j mod S` and `y_rep,k = c_s,k + sigma_s,k e_k`, `e_k ~ N(0, 1)` drawn in voltage order
///   from `StdRng::seed_from_u64(seed)`. It is standardised with the observed `mu_k` and
///   `scale_k`, its runs found by the same rule, and `M_j` is its largest run statistic (0 if
///   it has no run). `p_w = (1 + #{j : M_j >= T_w}) / (1 + R)`.
/// * `ppc_p = (1/R) #{j : chi2(y_rep,j; c_s, sigma_s) >= chi2(c_m; c_s, sigma_s)}` with the
///   same draw s on both sides.
///
/// Without draws the residuals are NaN, there are no windows, `ppc_p` is NaN and
/// `replicates` is 0.
///
/// # Panics
/// If the rows of `draws` do not all have `c_m.len()` entries or the numbers of curve and sigma
/// rows differ.
pub fn residual_check(
    c_m: &[f64],
    draws: &PredictiveDraws,
    min_run: usize,
    seed: u64,
) -> ResidualCheck {
    let n = c_m.len();
    draws.check_shape(n);
    let n_draws = draws.len();
    if n_draws == 0 {
        return ResidualCheck {
            residuals: vec![f64::NAN; n],
            windows: Vec::new(),
            ppc_p: f64::NAN,
            replicates: 0,
        };
    }
    let sf = n_draws as f64;
    // Predictive mean and scale per voltage.
    let mut mu = vec![0.0; n];
    let mut mean_var = vec![0.0; n];
    for (c, sd) in draws.curves.iter().zip(&draws.sigmas) {
        for ((m, v), (&ck, &sk)) in mu.iter_mut().zip(&mut mean_var).zip(c.iter().zip(sd)) {
            *m += ck / sf;
            *v += sk * sk / sf;
        }
    }
    let mut var_c = vec![0.0; n];
    for c in &draws.curves {
        for ((v, &ck), &m) in var_c.iter_mut().zip(c).zip(&mu) {
            *v += (ck - m).powi(2) / sf;
        }
    }
    let scale: Vec<f64> = mean_var
        .iter()
        .zip(&var_c)
        .map(|(a, b)| (a + b).sqrt())
        .collect();
    let standardise = |y: &[f64], out: &mut [f64]| {
        for (((o, &yk), &m), &sc) in out.iter_mut().zip(y).zip(&mu).zip(&scale) {
            *o = (yk - m) / sc;
        }
    };
    let mut residuals = vec![0.0; n];
    standardise(c_m, &mut residuals);
    let mut windows = Vec::new();
    for_each_run(&residuals, min_run, |first, last, sign, statistic| {
        windows.push(Window {
            first,
            last,
            sign,
            statistic,
            p_value: f64::NAN,
        });
    });

    let replicates = n_draws.min(MAX_REPLICATES);
    let mut rng = StdRng::seed_from_u64(seed);
    let mut y_rep = vec![0.0; n];
    let mut r_rep = vec![0.0; n];
    let mut max_stats = Vec::with_capacity(replicates);
    let mut exceed = 0usize;
    for j in 0..replicates {
        let s = j % n_draws;
        let (c, sd) = (&draws.curves[s], &draws.sigmas[s]);
        for ((y, &ck), &sk) in y_rep.iter_mut().zip(c).zip(sd) {
            let e: f64 = StandardNormal.sample(&mut rng);
            *y = ck + sk * e;
        }
        standardise(&y_rep, &mut r_rep);
        let mut m_j = 0.0f64;
        for_each_run(&r_rep, min_run, |_, _, _, t| m_j = m_j.max(t));
        max_stats.push(m_j);
        if chi2(&y_rep, c, sd) >= chi2(c_m, c, sd) {
            exceed += 1;
        }
    }
    for w in &mut windows {
        let count = max_stats.iter().filter(|&&m| m >= w.statistic).count();
        w.p_value = (1 + count) as f64 / (1 + replicates) as f64;
    }
    ResidualCheck {
        residuals,
        windows,
        ppc_p: exceed as f64 / replicates as f64,
        replicates,
    }
}

/// Result of [`leave_window_out`]: the leave-block-out expected log predictive density
/// `elpd = sum_b ln p(y_b | y_-b)` (natural log of a density in pF^-n_b).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Elpd {
    /// [first, last] voltage indices of each block (contiguous, covering all voltages).
    pub blocks: Vec<[usize; 2]>,
    /// elpd of each block left out: `elpd_b = ln p(y_b | y_-b)`.
    pub per_block: Vec<f64>,
    /// Sum over blocks: `sum_b elpd_b`.
    pub total: f64,
    /// Largest Pareto k-hat over blocks (NaN if any block's k-hat is NaN, e.g. fewer than 10
    /// draws); above 0.7 the importance sampling estimate is unreliable.
    pub max_k_hat: f64,
}

/// `n_blocks` (clamped to `[1, n]`) contiguous blocks `[first, last]` covering `0..n`, sizes
/// `floor(n / B)` or one more (the first `n mod B` blocks are the longer ones). Empty if n = 0.
pub(super) fn block_partition(n: usize, n_blocks: usize) -> Vec<[usize; 2]> {
    if n == 0 {
        return Vec::new();
    }
    let b = n_blocks.clamp(1, n);
    let (size, extra) = (n / b, n % b);
    let mut first = 0;
    (0..b)
        .map(|i| {
            let len = size + usize::from(i < extra);
            let block = [first, first + len - 1];
            first += len;
            block
        })
        .collect()
}

/// `ln N(y; c, sigma) = -((y - c) / sigma)^2 / 2 - ln sigma - ln sqrt(2 pi)`.
fn ln_normal(y: f64, c: f64, sigma: f64) -> f64 {
    let z = (y - c) / sigma;
    -0.5 * z * z - sigma.ln() - LN_SQRT_2PI
}

/// Leave-window-out elpd of the measurement `c_m` (pF) under the posterior `draws`.
///
/// The N voltages are split into `n_blocks` (clamped to `[1, N]`) contiguous blocks of sizes
/// differing by at most one. For block b and draw s,
/// `ll_s,b = sum_{k in b} ln N(c_m,k; c_s,k, sigma_s,k)`. By the importance sampling
/// leave-one-out identity `p(y_b | y_-b) = 1 / E_post[1 / p(y_b | theta)]`; with `w_s` the
/// normalised PSIS weights ([`psis`]) of the log ratios `-ll_s,b`,
/// `elpd_b = ln sum_s w_s exp(ll_s,b)`, evaluated by log-sum-exp. `total = sum_b elpd_b`,
/// `max_k_hat = max_b k_hat_b`.
///
/// With N = 0 there are no blocks, `total = 0` and `max_k_hat` is NaN; without draws every
/// `elpd_b` is NaN.
///
/// # Panics
/// If the rows of `draws` do not all have `c_m.len()` entries or the numbers of curve and sigma
/// rows differ.
pub fn leave_window_out(c_m: &[f64], draws: &PredictiveDraws, n_blocks: usize) -> Elpd {
    let n = c_m.len();
    draws.check_shape(n);
    let blocks = block_partition(n, n_blocks);
    let mut per_block = Vec::with_capacity(blocks.len());
    let mut max_k_hat = if blocks.is_empty() {
        f64::NAN
    } else {
        f64::NEG_INFINITY
    };
    for &[first, last] in &blocks {
        let ll: Vec<f64> = draws
            .curves
            .iter()
            .zip(&draws.sigmas)
            .map(|(c, sd)| {
                (first..=last)
                    .map(|k| ln_normal(c_m[k], c[k], sd[k]))
                    .sum::<f64>()
            })
            .collect();
        if ll.is_empty() {
            per_block.push(f64::NAN);
            max_k_hat = f64::NAN;
            continue;
        }
        let neg: Vec<f64> = ll.iter().map(|v| -v).collect();
        let p = psis(&neg);
        // ln sum_s w_s exp(ll_s), by log-sum-exp over the terms with w_s > 0.
        let terms: Vec<f64> = p
            .weights
            .iter()
            .zip(&ll)
            .map(|(&w, &l)| {
                if w > 0.0 {
                    w.ln() + l
                } else {
                    f64::NEG_INFINITY
                }
            })
            .collect();
        let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let elpd = if p.weights.iter().any(|w| w.is_nan()) {
            f64::NAN
        } else if top == f64::NEG_INFINITY {
            f64::NEG_INFINITY
        } else {
            top + terms.iter().map(|t| (t - top).exp()).sum::<f64>().ln()
        };
        per_block.push(elpd);
        max_k_hat = if p.k_hat.is_nan() || max_k_hat.is_nan() {
            f64::NAN
        } else {
            max_k_hat.max(p.k_hat)
        };
    }
    Elpd {
        total: per_block.iter().sum(),
        blocks,
        per_block,
        max_k_hat,
    }
}

/// Paired difference of two leave-window-out scores over the same blocks: with
/// `d_b = after.per_block[b] - before.per_block[b]`, `b = 1..B`, returns
/// `(sum_b d_b, sqrt(B var_b(d_b)))`, `var_b` the sample variance (denominator B - 1). The
/// standard error is NaN for B < 2. Positive means `after` predicts the held-out blocks better.
///
/// # Panics
/// If the two scores were computed on different blocks.
pub fn delta_elpd(before: &Elpd, after: &Elpd) -> (f64, f64) {
    assert_eq!(
        before.blocks, after.blocks,
        "delta_elpd: the two scores use different blocks"
    );
    let d: Vec<f64> = after
        .per_block
        .iter()
        .zip(&before.per_block)
        .map(|(a, b)| a - b)
        .collect();
    let sum: f64 = d.iter().sum();
    let nb = d.len();
    if nb < 2 {
        return (sum, f64::NAN);
    }
    let bf = nb as f64;
    let mean = sum / bf;
    let var = d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (bf - 1.0);
    (sum, (bf * var).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: usize = 60;

    /// A smooth C-V-like truth curve (pF) over N voltages and its noise sd (pF).
    fn truth() -> (Vec<f64>, Vec<f64>) {
        let c: Vec<f64> = (0..N)
            .map(|k| {
                let v = 50.0 * k as f64;
                20.0 + 80.0 / (1.0 + (v / 600.0).powi(2))
            })
            .collect();
        let sd = c.iter().map(|c| 0.03 * c + 1.0).collect();
        (c, sd)
    }

    fn normals(n: usize, rng: &mut StdRng) -> Vec<f64> {
        (0..n).map(|_| StandardNormal.sample(&mut *rng)).collect()
    }

    fn point_mass(c: &[f64], sd: &[f64], s: usize) -> PredictiveDraws {
        PredictiveDraws {
            curves: vec![c.to_vec(); s],
            sigmas: vec![sd.to_vec(); s],
        }
    }

    #[test]
    fn runs_are_maximal_same_sign_and_long_enough() {
        let r = [
            1.0, 2.0, 0.5, -1.0, -1.0, 3.0, 1.0, 1.0, 1.0, 0.0, 2.0, 2.0, 2.0,
        ];
        let mut got = Vec::new();
        for_each_run(&r, 3, |a, b, s, t| got.push((a, b, s, t)));
        assert_eq!(
            got,
            vec![(0, 2, 1, 5.25), (5, 8, 1, 12.0), (10, 12, 1, 12.0)]
        );
        let mut got = Vec::new();
        for_each_run(&r, 2, |a, b, s, _| got.push((a, b, s)));
        assert_eq!(got, vec![(0, 2, 1), (3, 4, -1), (5, 8, 1), (10, 12, 1)]);
    }

    #[test]
    fn residuals_use_predictive_mean_and_mixture_scale() {
        // Two draws at one voltage: c = 1, 3 (mean 2, var 1), sigma = 1, 2 (mean sq 2.5).
        let draws = PredictiveDraws {
            curves: vec![vec![1.0], vec![3.0]],
            sigmas: vec![vec![1.0], vec![2.0]],
        };
        let check = residual_check(&[5.5], &draws, 1, 1);
        assert!((check.residuals[0] - 3.5 / 3.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(check.replicates, 2);
        assert_eq!(check.windows.len(), 1);
        assert_eq!((check.windows[0].first, check.windows[0].last), (0, 0));
        assert_eq!(check.windows[0].sign, 1);
    }

    #[test]
    fn null_data_gives_calibrated_ppc_and_no_windows() {
        let (c, sd) = truth();
        let draws = point_mass(&c, &sd, 1000);
        let (mut ppc_ok, mut windows_ok) = (0, 0);
        for seed in 0..20u64 {
            let mut rng = StdRng::seed_from_u64(1000 + seed);
            let e = normals(N, &mut rng);
            let y: Vec<f64> = c
                .iter()
                .zip(&sd)
                .zip(&e)
                .map(|((c, s), e)| c + s * e)
                .collect();
            let check = residual_check(&y, &draws, 3, seed);
            assert_eq!(check.replicates, 1000);
            if check.ppc_p > 0.01 && check.ppc_p < 0.99 {
                ppc_ok += 1;
            }
            if check.windows.iter().all(|w| w.p_value >= 0.01) {
                windows_ok += 1;
            }
        }
        assert!(ppc_ok >= 16, "ppc_p in (0.01, 0.99) for {ppc_ok} of 20");
        assert!(
            windows_ok >= 18,
            "no significant window for {windows_ok} of 20"
        );
    }

    #[test]
    fn bump_on_eight_voltages_is_found() {
        let (c, sd) = truth();
        let mut rng = StdRng::seed_from_u64(7);
        // A posterior with some spread around the truth.
        let s_draws = 2000;
        let mut draws = PredictiveDraws {
            curves: Vec::with_capacity(s_draws),
            sigmas: Vec::with_capacity(s_draws),
        };
        for _ in 0..s_draws {
            let shift: f64 = StandardNormal.sample(&mut rng);
            draws.curves.push(
                c.iter()
                    .zip(&sd)
                    .map(|(c, s)| c + 0.1 * s * shift)
                    .collect(),
            );
            draws.sigmas.push(sd.clone());
        }
        let e = normals(N, &mut rng);
        let (lo, hi) = (30, 37);
        let y: Vec<f64> = (0..N)
            .map(|k| {
                let bump = if (lo..=hi).contains(&k) {
                    4.0 * sd[k]
                } else {
                    0.0
                };
                c[k] + sd[k] * e[k] + bump
            })
            .collect();
        let check = residual_check(&y, &draws, 3, 11);
        let hit = check
            .windows
            .iter()
            .find(|w| w.first <= lo && w.last >= hi)
            .expect("a window covers the bump");
        assert_eq!(hit.sign, 1);
        assert!(hit.p_value < 0.01, "p = {}", hit.p_value);
        assert!(check.ppc_p < 0.01, "ppc_p = {}", check.ppc_p);
        // Without the bump the same noise gives no significant window.
        let y0: Vec<f64> = (0..N).map(|k| c[k] + sd[k] * e[k]).collect();
        let check0 = residual_check(&y0, &draws, 3, 11);
        assert!(check0.windows.iter().all(|w| w.p_value >= 0.01));
    }

    #[test]
    fn point_mass_elpd_is_exact_log_density() {
        let (c, sd) = truth();
        let mut rng = StdRng::seed_from_u64(3);
        let e = normals(N, &mut rng);
        let y: Vec<f64> = c
            .iter()
            .zip(&sd)
            .zip(&e)
            .map(|((c, s), e)| c + s * e)
            .collect();
        let elpd = leave_window_out(&y, &point_mass(&c, &sd, 50), 7);
        assert_eq!(elpd.blocks.len(), 7);
        let mut total = 0.0;
        for (&[a, b], &got) in elpd.blocks.iter().zip(&elpd.per_block) {
            let want: f64 = (a..=b)
                .map(|k| {
                    let z = (y[k] - c[k]) / sd[k];
                    -0.5 * z * z - sd[k].ln() - 0.5 * (2.0 * std::f64::consts::PI).ln()
                })
                .sum();
            assert!(
                (got - want).abs() < 1e-10,
                "block [{a}, {b}]: {got} vs {want}"
            );
            total += want;
        }
        assert!((elpd.total - total).abs() < 1e-9);
        assert_eq!(elpd.max_k_hat, 0.0);
    }

    /// Exact `ln N(y_b; m 1, I + a 11^T)`, `a = 1 / (N - n_b)`, via the matrix determinant lemma
    /// and Sherman-Morrison: `det = 1 + a n`, `Sigma^-1 = I - a / (1 + a n) 11^T`.
    fn exact_block_predictive(y_b: &[f64], m: f64, a: f64) -> f64 {
        let n = y_b.len() as f64;
        let d: Vec<f64> = y_b.iter().map(|y| y - m).collect();
        let dd: f64 = d.iter().map(|v| v * v).sum();
        let sd: f64 = d.iter().sum();
        let quad = dd - a * sd * sd / (1.0 + a * n);
        -n * LN_SQRT_2PI - 0.5 * (1.0 + a * n).ln() - 0.5 * quad
    }

    #[test]
    fn conjugate_gaussian_elpd_matches_closed_form() {
        let mut rng = StdRng::seed_from_u64(42);
        let y: Vec<f64> = normals(N, &mut rng).iter().map(|e| 5.0 + e).collect();
        let ybar = y.iter().sum::<f64>() / N as f64;
        let s_draws = 20_000;
        let thetas: Vec<f64> = normals(s_draws, &mut rng)
            .iter()
            .map(|e| ybar + e / (N as f64).sqrt())
            .collect();
        let draws = PredictiveDraws {
            curves: thetas.iter().map(|&t| vec![t; N]).collect(),
            sigmas: vec![vec![1.0; N]; s_draws],
        };
        for n_blocks in [6, 7] {
            let elpd = leave_window_out(&y, &draws, n_blocks);
            assert!(elpd.max_k_hat < 0.7, "k_hat = {}", elpd.max_k_hat);
            for (&[a, b], &got) in elpd.blocks.iter().zip(&elpd.per_block) {
                let n_b = b - a + 1;
                let rest: f64 = y[..a].iter().chain(&y[b + 1..]).sum();
                let m = rest / (N - n_b) as f64;
                let want = exact_block_predictive(&y[a..=b], m, 1.0 / (N - n_b) as f64);
                assert!(
                    (got - want).abs() < 0.05,
                    "block [{a}, {b}]: {got} vs {want}"
                );
            }
        }
    }

    fn elpd_of(per_block: Vec<f64>) -> Elpd {
        Elpd {
            blocks: (0..per_block.len()).map(|b| [b, b]).collect(),
            total: per_block.iter().sum(),
            per_block,
            max_k_hat: 0.0,
        }
    }

    #[test]
    fn delta_elpd_sums_paired_differences() {
        let before = elpd_of(vec![-10.0, -20.0, -5.0, 0.0]);
        // Differences 1, 2, 3, 4: sum 10, sample variance 5/3, se sqrt(4 * 5/3).
        let after = elpd_of(vec![-9.0, -18.0, -2.0, 4.0]);
        let (d, se) = delta_elpd(&before, &after);
        assert!((d - 10.0).abs() < 1e-12);
        assert!((se - (4.0 * 5.0 / 3.0f64).sqrt()).abs() < 1e-12);
        let (d1, se1) = delta_elpd(&elpd_of(vec![1.0]), &elpd_of(vec![3.5]));
        assert_eq!(d1, 2.5);
        assert!(se1.is_nan());
    }

    #[test]
    #[should_panic(expected = "different blocks")]
    fn delta_elpd_rejects_different_blocks() {
        delta_elpd(&elpd_of(vec![1.0, 2.0]), &elpd_of(vec![1.0, 2.0, 3.0]));
    }

    #[test]
    fn blocks_partition_voltages_evenly() {
        for n in 1..=70 {
            for n_blocks in 0..=(n + 3) {
                let blocks = block_partition(n, n_blocks);
                assert_eq!(blocks.len(), n_blocks.clamp(1, n));
                let mut next = 0;
                for &[a, b] in &blocks {
                    assert_eq!(a, next, "n = {n}, B = {n_blocks}");
                    assert!(b >= a);
                    next = b + 1;
                }
                assert_eq!(next, n);
                let sizes: Vec<usize> = blocks.iter().map(|[a, b]| b - a + 1).collect();
                let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                assert!(hi - lo <= 1, "n = {n}, B = {n_blocks}: {sizes:?}");
            }
        }
        assert!(block_partition(0, 4).is_empty());
        // leave_window_out uses the same partition.
        let (c, sd) = truth();
        let elpd = leave_window_out(&c, &point_mass(&c, &sd, 20), 8);
        assert_eq!(elpd.blocks, block_partition(N, 8));
        assert_eq!(elpd.per_block.len(), 8);
    }
}
