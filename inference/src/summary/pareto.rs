//! Pareto smoothed importance sampling (Vehtari, Simpson, Gelman, Yao, Gabry 2024, "Pareto
//! smoothed importance sampling", JMLR 25(72)) with the generalised Pareto fit of Zhang and
//! Stephens (2009, "A new and efficient estimation method for the generalized Pareto
//! distribution", Technometrics 51(3)).

/// Result of [`psis`].
#[derive(Debug, Clone, PartialEq)]
pub struct Psis {
    /// Smoothed, truncated importance weights, normalised to sum 1 (same order as the input).
    pub weights: Vec<f64>,
    /// Estimated Pareto shape of the upper tail of the importance ratios. Below 0.5 the ratios
    /// have finite variance; above 0.7 the importance sampling estimate is unreliable.
    pub k_hat: f64,
    /// Effective sample size of the normalised weights, `1 / sum_s w_s^2`.
    pub ess: f64,
}

/// Number of grid points of the Zhang-Stephens estimator beyond `sqrt(n)`.
const MIN_GRID_POINTS: usize = 30;
/// Prior constant of the Zhang-Stephens grid.
const GRID_PRIOR: f64 = 3.0;
/// Pseudo-observations of the weakly informative prior pulling `k` toward 0.5.
const PRIOR_WEIGHT: f64 = 10.0;

/// Fit of a generalised Pareto distribution (location 0) to exceedances `x > 0`: returns
/// `(k, sigma)` for the density `(1/sigma) (1 + k x / sigma)^(-1/k - 1)`.
///
/// Zhang & Stephens (2009) empirical Bayes estimator, as implemented in the `loo` package:
/// with `theta = -k / sigma`, `n` sorted exceedances, `m = 30 + floor(sqrt(n))` and `x*` the
/// first quartile `x_(floor(n/4 + 1/2))`, the grid is
/// `theta_j = 1 / x_(n) + (1 - sqrt(m / (j - 1/2))) / (3 x*)`, `j = 1..m`. Each grid point gets
/// the profile log-likelihood `l(theta) = n (ln(-theta / k(theta)) - k(theta) - 1)` with
/// `k(theta) = mean_i ln(1 - theta x_i)`; the posterior mean
/// `theta_hat = sum_j theta_j exp(l_j) / sum_j exp(l_j)` gives `k = mean_i ln(1 - theta_hat x_i)`
/// and `sigma = -k / theta_hat`. Finally `k` is shrunk toward 0.5 by a weakly informative prior
/// worth 10 observations (Vehtari et al. 2024, appendix): `k <- (n k + 10 * 0.5) / (n + 10)`;
/// `sigma` is the unshrunk value.
///
/// Returns `(NaN, NaN)` for empty input or any exceedance that is not finite and positive.
pub fn gpd_fit(x: &[f64]) -> (f64, f64) {
    let n = x.len();
    if n == 0 || x.iter().any(|&v| !(v.is_finite() && v > 0.0)) {
        return (f64::NAN, f64::NAN);
    }
    let mut x = x.to_vec();
    x.sort_by(f64::total_cmp);
    let nf = n as f64;
    let m = MIN_GRID_POINTS + (nf.sqrt().floor() as usize);
    let quartile = x[((nf / 4.0 + 0.5).floor() as usize).clamp(1, n) - 1];
    let xmax = x[n - 1];
    let thetas: Vec<f64> = (1..=m)
        .map(|j| 1.0 / xmax + (1.0 - (m as f64 / (j as f64 - 0.5)).sqrt()) / GRID_PRIOR / quartile)
        .collect();
    // Every theta_j < 1 / x_(n), so 1 - theta x_i > 0 for all i.
    let profile: Vec<f64> = thetas
        .iter()
        .map(|&theta| {
            let k = x.iter().map(|&v| (-theta * v).ln_1p()).sum::<f64>() / nf;
            let l = nf * ((-theta / k).ln() - k - 1.0);
            if l.is_nan() { f64::NEG_INFINITY } else { l }
        })
        .collect();
    let lmax = profile.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lmax == f64::NEG_INFINITY {
        return (f64::NAN, f64::NAN);
    }
    let (mut num, mut den) = (0.0, 0.0);
    for (&theta, &l) in thetas.iter().zip(&profile) {
        let w = (l - lmax).exp();
        num += theta * w;
        den += w;
    }
    let theta_hat = num / den;
    let k = x.iter().map(|&v| (-theta_hat * v).ln_1p()).sum::<f64>() / nf;
    let sigma = -k / theta_hat;
    let k = (nf * k + PRIOR_WEIGHT * 0.5) / (nf + PRIOR_WEIGHT);
    (k, sigma)
}

/// Quantile of the generalised Pareto distribution (location 0, shape `k`, scale `sigma`) at
/// probability `p`: `sigma ((1 - p)^(-k) - 1) / k`, and `-sigma ln(1 - p)` for `k = 0`.
fn gpd_quantile(p: f64, k: f64, sigma: f64) -> f64 {
    let log_tail = (-p).ln_1p();
    if k.abs() < 1e-12 {
        -sigma * log_tail
    } else {
        sigma * (-k * log_tail).exp_m1() / k
    }
}

/// The fewest draws whose Pareto k-hat [`psis`] estimates (a tail of at least 5 draws);
/// with fewer, k-hat is NaN (an exact-solver check then passes only on near-equal weights).
pub const PSIS_MIN_DRAWS: usize = 21;

/// Pareto smoothed importance sampling of the log importance ratios `log_ratios` (one per draw).
///
/// Following Vehtari et al. (2024), with `S` draws:
/// 1. shift by the largest log ratio (`r_s = exp(lr_s - max lr)`, so no overflow);
/// 2. take the `M = min(ceil(0.2 S), ceil(3 sqrt(S)))` largest ratios as the tail and the
///    `(M+1)`-th largest `u` as the threshold, fit a generalised Pareto to the exceedances
///    `r - u` with [`gpd_fit`] (Zhang-Stephens with the prior toward 0.5); `k_hat` is its shape;
/// 3. replace the `z`-th smallest tail ratio by `u + F^{-1}((z - 1/2) / M)`, the fitted GPD
///    quantiles, `z = 1..M` (original positions are kept);
/// 4. truncate every weight at `S^{3/4}` times the mean of the smoothed weights and normalise
///    to sum 1.
///
/// Special cases: `S < 10` gives `k_hat = NaN` and the raw (truncated, normalised) weights; all
/// ratios equal gives uniform weights and `k_hat = 0`; a tail of fewer than 5 draws
/// (`S <= 20`) gives `k_hat = NaN` and no smoothing; a tail whose ratios are all equal (a point
/// mass, the lightest possible tail) is left unsmoothed with `k_hat = 0`; a non-finite GPD fit
/// leaves the tail unsmoothed with `k_hat = NaN`. Log ratios of `-inf` are zero weights; a NaN
/// or `+inf` log ratio, or all of them `-inf`, gives NaN weights, `k_hat` and `ess`. Empty
/// input gives no weights, `k_hat = NaN` and `ess = 0`.
///
/// ```
/// use hpge_inference::summary::psis;
/// // Equal ratios: uniform weights, k-hat 0, ESS = S.
/// let flat = psis(&[0.3; 100]);
/// assert_eq!(flat.k_hat, 0.0);
/// assert!((flat.ess - 100.0).abs() < 1e-9);
/// // Ratios with a Pareto tail of shape 1 (r = 1/u): k-hat far above 0.7, few effective draws.
/// let heavy: Vec<f64> = (1..=400).map(|i| -((i as f64 - 0.5) / 400.0).ln()).collect();
/// let p = psis(&heavy);
/// assert!(p.k_hat > 0.7, "{}", p.k_hat);
/// assert!(p.ess < 100.0);
/// assert!((p.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
/// ```
pub fn psis(log_ratios: &[f64]) -> Psis {
    let s = log_ratios.len();
    if s == 0 {
        return Psis {
            weights: Vec::new(),
            k_hat: f64::NAN,
            ess: 0.0,
        };
    }
    if log_ratios.iter().any(|&v| v.is_nan() || v == f64::INFINITY) {
        return Psis {
            weights: vec![f64::NAN; s],
            k_hat: f64::NAN,
            ess: f64::NAN,
        };
    }
    let max = log_ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        // Every ratio is zero: nothing to weight.
        return Psis {
            weights: vec![f64::NAN; s],
            k_hat: f64::NAN,
            ess: f64::NAN,
        };
    }
    let mut w: Vec<f64> = log_ratios.iter().map(|&v| (v - max).exp()).collect();
    let all_equal = log_ratios.iter().all(|&v| v == max);
    let k_hat = if s < 10 {
        f64::NAN
    } else if all_equal {
        0.0
    } else {
        smooth_tail(&mut w)
    };
    // Truncate at S^{3/4} times the mean weight.
    let mean = w.iter().sum::<f64>() / s as f64;
    let cap = (s as f64).powf(0.75) * mean;
    for v in &mut w {
        *v = v.min(cap);
    }
    let total: f64 = w.iter().sum();
    for v in &mut w {
        *v /= total;
    }
    let ess = 1.0 / w.iter().map(|v| v * v).sum::<f64>();
    Psis {
        weights: w,
        k_hat,
        ess,
    }
}

/// Replaces the `M` largest of the ratios `w` (all in `[0, 1]`) by GPD quantiles; returns `k_hat`.
fn smooth_tail(w: &mut [f64]) -> f64 {
    let s = w.len();
    let sf = s as f64;
    let m = ((0.2 * sf).ceil() as usize).min((3.0 * sf.sqrt()).ceil() as usize);
    if m < 5 {
        return f64::NAN;
    }
    let mut order: Vec<usize> = (0..s).collect();
    order.sort_by(|&a, &b| w[a].total_cmp(&w[b]));
    let tail = &order[s - m..];
    let threshold = w[order[s - m - 1]];
    let (lo, hi) = (w[tail[0]], w[tail[m - 1]]);
    if hi - lo <= f64::EPSILON * hi {
        return 0.0;
    }
    // Exceedances; ties with the threshold become a tiny positive exceedance.
    let tiny = f64::MIN_POSITIVE.max(hi * 1e-300);
    let exceed: Vec<f64> = tail.iter().map(|&i| (w[i] - threshold).max(tiny)).collect();
    let (k, sigma) = gpd_fit(&exceed);
    if !(k.is_finite() && sigma.is_finite()) {
        return f64::NAN;
    }
    let mf = m as f64;
    for (z, &i) in tail.iter().enumerate() {
        w[i] = threshold + gpd_quantile((z as f64 + 0.5) / mf, k, sigma);
    }
    k
}

#[cfg(test)]
mod tests {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};
    use rand_distr::{Distribution, Normal};

    use super::*;

    fn gpd_draws(n: usize, k: f64, sigma: f64, seed: u64) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let u: f64 = rng.random();
                gpd_quantile(u, k, sigma)
            })
            .filter(|&x| x > 0.0)
            .collect()
    }

    #[test]
    fn gpd_fit_recovers_shape() {
        for (k, sigma, seed) in [(0.3, 1.0, 1), (0.7, 2.5, 2), (-0.2, 0.5, 3), (0.0, 1.0, 4)] {
            let x = gpd_draws(20_000, k, sigma, seed);
            let (kh, sh) = gpd_fit(&x);
            assert!((kh - k).abs() < 0.05, "k {k}: fitted {kh}");
            assert!((sh / sigma - 1.0).abs() < 0.1, "sigma {sigma}: fitted {sh}");
        }
        assert!(gpd_fit(&[]).0.is_nan());
        assert!(gpd_fit(&[1.0, -1.0]).0.is_nan());
    }

    #[test]
    fn equal_log_ratios_give_uniform_weights() {
        let p = psis(&[3.7; 1000]);
        assert_eq!(p.k_hat, 0.0);
        assert!(p.weights.iter().all(|&w| (w - 1e-3).abs() < 1e-15));
        assert!((p.ess - 1000.0).abs() < 1e-6);
        assert!(psis(&[0.0; 5]).k_hat.is_nan());
        assert!(psis(&[]).weights.is_empty());
        assert!(psis(&[0.0, f64::NAN]).weights[0].is_nan());
    }

    /// Log ratios of the N(0, 1) target for `n` draws of the N(0, sd^2) proposal.
    fn normal_ratios(n: usize, sd: f64, seed: u64) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(seed);
        let g = Normal::new(0.0, sd).unwrap();
        (0..n)
            .map(|_| {
                let x: f64 = g.sample(&mut rng);
                -0.5 * x * x + 0.5 * (x / sd).powi(2) + sd.ln()
            })
            .collect()
    }

    fn median(mut v: Vec<f64>) -> f64 {
        v.sort_by(f64::total_cmp);
        0.5 * (v[(v.len() - 1) / 2] + v[v.len() / 2])
    }

    #[test]
    fn small_gaussian_log_ratios_are_not_flagged_an_upper_tail_is() {
        // The exact check's case (S = 100 draws, tail M = 20): near-equal weights with Gaussian
        // log ratios are not a heavy tail, whatever their small scale; several draws far up in
        // the tail are (docs/own-detector.md reads a point contact's k-hat with this).
        let khats = |sd: f64, outliers: usize| -> Vec<f64> {
            (0..400u64)
                .map(|seed| {
                    let mut rng = StdRng::seed_from_u64(1000 + seed);
                    let g = Normal::new(0.0, sd).unwrap();
                    let mut lr: Vec<f64> = (0..100).map(|_| g.sample(&mut rng)).collect();
                    for (k, v) in lr.iter_mut().take(outliers).enumerate() {
                        *v = sd * (4.0 + 1.5 * k as f64);
                    }
                    psis(&lr).k_hat
                })
                .collect()
        };
        for sd in [0.01, 0.039, 0.3] {
            let k = khats(sd, 0);
            let flagged = k.iter().filter(|&&v| v > 0.7).count();
            assert!(flagged <= 4, "sd {sd}: {flagged} of 400 above 0.7");
            assert!(median(k) < 0.25, "sd {sd}");
        }
        // Five draws 4-10 sd up: the tail reads heavy (one alone does not: median about 0.5).
        let k = median(khats(0.039, 5));
        assert!(k > 0.7, "five outliers: median {k}");
        let k = median(khats(0.039, 1));
        assert!(k < 0.7, "one outlier: median {k}");
    }

    #[test]
    fn narrow_proposal_is_flagged_wide_is_not() {
        // Proposal N(0, q^2) for the N(0, 1) target: r ~ exp((1 - q^2) z^2 / 2), whose tail has
        // k = 1 - q^2 (0.75 for q = 0.5, 0.91 for q = 0.3). At finite S the fitted tail
        // (z > ~2.2 for S = 10^4) is locally lighter, so k_hat of single runs scatters around
        // 0.55-0.77 for q = 0.5; the test uses the median over ten seeds.
        let khat = |q: f64| -> Vec<f64> {
            (0..10)
                .map(|seed| psis(&normal_ratios(10_000, q, 100 + seed)).k_hat)
                .collect()
        };
        let half = khat(0.5);
        assert!(half.iter().all(|&k| k > 0.5), "q = 0.5: {half:?}");
        assert!(median(half.clone()) > 0.65, "q = 0.5: {half:?}");
        let narrow = khat(0.3);
        assert!(median(narrow.clone()) > 0.7, "q = 0.3: {narrow:?}");
        let wide = khat(1.5);
        assert!(wide.iter().all(|&k| k < 0.5), "q = 1.5: {wide:?}");

        let narrow = psis(&normal_ratios(10_000, 0.5, 5));
        let wide = psis(&normal_ratios(10_000, 1.5, 6));
        for p in [&narrow, &wide] {
            assert!((p.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(p.weights.iter().all(|&w| w >= 0.0));
            assert!(p.ess > 1.0 && p.ess <= 10_000.0 + 1e-6);
        }
        assert!(wide.ess > narrow.ess);
        // Self-normalised estimate of E[x^2] = 1 under the target from the wide proposal.
        let mut rng = StdRng::seed_from_u64(6);
        let g = Normal::new(0.0, 1.5).unwrap();
        let x: Vec<f64> = (0..10_000).map(|_| g.sample(&mut rng)).collect();
        let m2: f64 = x.iter().zip(&wide.weights).map(|(x, w)| w * x * x).sum();
        assert!((m2 - 1.0).abs() < 0.05, "E[x^2] {m2}");
    }
}
