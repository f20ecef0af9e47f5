//! Gaussian mixtures fitted to posterior draws by expectation-maximisation (Dempster, Laird,
//! Rubin 1977; Bishop 2006, "Pattern Recognition and Machine Learning", sec. 9.2), used to find
//! the separated modes of a posterior, with the number of components chosen by BIC (Schwarz 1978).

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

use super::component::Component;
use super::em::{Prepared, em, kmeans_pp, moments};

/// A Gaussian mixture `p(x) = sum_c w_c N(x | mu_c, Sigma_c)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mixture {
    /// Components, sorted by weight, largest first.
    pub components: Vec<Component>,
    /// Log-likelihood of the fitted points, `sum_i ln p(x_i)`.
    pub log_likelihood: f64,
    /// Bayesian information criterion `-2 ln L + p ln n`, with
    /// `p = (k - 1) + k d + k d (d + 1) / 2` free parameters for `k` components in `d` dimensions.
    pub bic: f64,
}

/// Number of EM restarts from different k-means++ seeds in [`fit_mixture`].
const RESTARTS: usize = 4;
/// Diagonal regularisation, relative to each dimension's sample variance.
const REGULARISATION: f64 = 1e-6;
/// Smallest weight a component of a multi-component solution may have in [`find_modes`].
const MIN_WEIGHT: f64 = 0.02;
/// Separation, in pooled standard deviations, required between the means in [`find_modes`].
const MIN_SEPARATION: f64 = 2.0;
/// EM iteration limit used by [`find_modes`].
const FIND_MODES_ITER: usize = 200;

/// Number of free parameters of a `k`-component, `d`-dimensional full-covariance mixture.
fn parameter_count(k: usize, d: usize) -> usize {
    k - 1 + k * d + k * d * (d + 1) / 2
}

/// Maximum-likelihood Gaussian mixture with `k` full-covariance components, fitted to `points`
/// (each of the same dimension `d >= 1`) by EM.
///
/// Every restart (4 of them, run in parallel, each seeded from an `StdRng` seeded with `seed`)
/// picks initial means by k-means++ and starts with equal weights and the sample covariance,
/// then alternates the E step (responsibilities `r_ic ∝ w_c N(x_i | mu_c, Sigma_c)`) and the
/// M step (`w_c = N_c / n`, `mu_c = sum_i r_ic x_i / N_c`,
/// `Sigma_c = sum_i r_ic (x_i - mu_c)(x_i - mu_c)^T / N_c + diag(1e-6 var_j)`, where `var_j` is
/// the sample variance of dimension `j`, or `max(1, mean_j^2)` for a constant dimension) until
/// the mean log-likelihood per point changes by at most 1e-6 or `max_iter` iterations have run.
/// The restart with the highest log-likelihood is kept; its components are sorted by weight,
/// largest first, and `bic = -2 ln L + p ln n` with `p = (k-1) + k d + k d (d+1)/2`.
///
/// `None` when `k == 0`, `n < 5 k`, the points have unequal or zero dimension or non-finite
/// coordinates, or every restart degenerates (a component with fewer than one point's worth of
/// responsibility, or a covariance that is not positive definite).
pub fn fit_mixture(points: &[Vec<f64>], k: usize, seed: u64, max_iter: usize) -> Option<Mixture> {
    let n = points.len();
    if k == 0 || n < 5 * k {
        return None;
    }
    let d = points[0].len();
    if d == 0
        || points
            .iter()
            .any(|p| p.len() != d || p.iter().any(|v| !v.is_finite()))
    {
        return None;
    }
    let (mean, global_cov) = moments(points, d);
    let reg: Vec<f64> = (0..d)
        .map(|j| {
            let var = global_cov[j * d + j];
            REGULARISATION
                * if var > 0.0 {
                    var
                } else {
                    mean[j].powi(2).max(1.0)
                }
        })
        .collect();
    let mut start_cov = global_cov;
    for j in 0..d {
        start_cov[j * d + j] += reg[j];
    }
    let mut rng = StdRng::seed_from_u64(seed);
    let seeds: Vec<u64> = (0..RESTARTS).map(|_| rng.random()).collect();
    // Restarts run in parallel; each has its own seed, so the result does not depend on threads.
    let runs: Vec<Option<(Vec<Component>, f64)>> = seeds
        .par_iter()
        .map(|&s| {
            let init = kmeans_pp(points, k, &mut StdRng::seed_from_u64(s));
            em(points, init, &start_cov, &reg, max_iter.max(1))
        })
        .collect();
    let mut best: Option<(Vec<Component>, f64)> = None;
    for (comps, ll) in runs.into_iter().flatten() {
        if best.as_ref().is_none_or(|b| ll > b.1) {
            best = Some((comps, ll));
        }
    }
    let (mut components, log_likelihood) = best?;
    components.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    let bic = -2.0 * log_likelihood + parameter_count(k, d) as f64 * (n as f64).ln();
    Some(Mixture {
        components,
        log_likelihood,
        bic,
    })
}

/// Whether every pair of components is separated: with `u = mu_a - mu_b`, the pooled variance
/// along `u` is `s^2 = (u^T Sigma_a u + u^T Sigma_b u) / (2 |u|^2)`, and the pair is separated
/// when `|u| > 2 s` (for two equal-weight Gaussians of equal variance, `|u| > 2 s` is exactly
/// when their mixture density along `u` is bimodal).
fn separated(components: &[Component]) -> bool {
    let d = components.first().map_or(0, |c| c.mean.len());
    let along = |cov: &[f64], u: &[f64]| -> f64 {
        (0..d)
            .map(|a| (0..d).map(|b| u[a] * cov[a * d + b] * u[b]).sum::<f64>())
            .sum()
    };
    components.iter().enumerate().all(|(i, a)| {
        components[i + 1..].iter().all(|b| {
            let u: Vec<f64> = a.mean.iter().zip(&b.mean).map(|(x, y)| x - y).collect();
            let u2: f64 = u.iter().map(|v| v * v).sum();
            let s2 = (along(&a.cov, &u) + along(&b.cov, &u)) / (2.0 * u2);
            u2 > MIN_SEPARATION * MIN_SEPARATION * s2
        })
    })
}

/// The separated modes of a cloud of posterior draws, as a Gaussian mixture in the original units.
///
/// Each dimension is standardised (`z_j = (x_j - mean_j) / sd_j`; a constant dimension keeps
/// `sd_j = 1`), [`fit_mixture`] is run for `k = 1..=max_k` (seed `seed + k`, at most 200 EM
/// iterations), and the admissible fit with the lowest BIC is returned. `k = 1` is always
/// admissible; `k > 1` only when every component has weight `>= 0.02` and every pair of
/// components is separated: their means lie more than 2 pooled standard deviations apart along
/// the line joining them (with `u = mu_a - mu_b`, `|u|^2 > 4 (u^T Sigma_a u + u^T Sigma_b u) /
/// (2 |u|^2)`). So one skewed or curved mode, which BIC alone may split into overlapping
/// Gaussians, stays one component.
///
/// The result is de-standardised: `mu = mean + sd * mu_z`, `Sigma_ab = sd_a sd_b Sigma_z,ab`,
/// and the log-likelihood and BIC refer to the original units (`ln L = ln L_z - n sum_j ln sd_j`).
/// When no fit succeeds (fewer than 5 points, non-finite coordinates), the single component is
/// the sample mean and covariance, with the Gaussian log-likelihood when that covariance is
/// positive definite (NaN otherwise); no points at all give no components and NaN log-likelihood
/// and BIC.
pub fn find_modes(points: &[Vec<f64>], max_k: usize, seed: u64) -> Mixture {
    let n = points.len();
    let d = points.first().map_or(0, Vec::len);
    if n == 0 || d == 0 || points.iter().any(|p| p.len() != d) {
        return Mixture {
            components: Vec::new(),
            log_likelihood: f64::NAN,
            bic: f64::NAN,
        };
    }
    let (mean, cov) = moments(points, d);
    let sd: Vec<f64> = (0..d)
        .map(|j| {
            let s = cov[j * d + j].sqrt();
            if s > 0.0 && s.is_finite() { s } else { 1.0 }
        })
        .collect();
    let z: Vec<Vec<f64>> = points
        .iter()
        .map(|p| (0..d).map(|j| (p[j] - mean[j]) / sd[j]).collect())
        .collect();
    let mut best: Option<Mixture> = None;
    for k in 1..=max_k.max(1) {
        let Some(m) = fit_mixture(&z, k, seed.wrapping_add(k as u64), FIND_MODES_ITER) else {
            continue;
        };
        let admissible = k == 1
            || (m.components.iter().all(|c| c.weight >= MIN_WEIGHT) && separated(&m.components));
        if admissible && best.as_ref().is_none_or(|b| m.bic < b.bic) {
            best = Some(m);
        }
    }
    let log_jacobian: f64 = sd.iter().map(|s| s.ln()).sum::<f64>() * n as f64;
    match best {
        Some(m) => Mixture {
            components: m
                .components
                .into_iter()
                .map(|c| Component {
                    weight: c.weight,
                    mean: (0..d).map(|j| mean[j] + sd[j] * c.mean[j]).collect(),
                    cov: (0..d * d)
                        .map(|ab| sd[ab / d] * sd[ab % d] * c.cov[ab])
                        .collect(),
                })
                .collect(),
            log_likelihood: m.log_likelihood - log_jacobian,
            bic: m.bic + 2.0 * log_jacobian,
        },
        None => {
            let single = Component {
                weight: 1.0,
                mean,
                cov,
            };
            let log_likelihood = match Prepared::new(&single, d) {
                Some(p) => {
                    let mut y = vec![0.0; d];
                    points.iter().map(|x| p.log_density(x, &mut y)).sum()
                }
                None => f64::NAN,
            };
            Mixture {
                components: vec![single],
                log_likelihood,
                bic: -2.0 * log_likelihood + parameter_count(1, d) as f64 * (n as f64).ln(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use rand_distr::{Distribution, Normal};

    use super::*;

    /// Draws of N(mu, L L^T) for a lower-triangular `l` (row-major 3 x 3).
    fn gaussian(n: usize, mu: [f64; 3], l: [f64; 9], rng: &mut StdRng) -> Vec<Vec<f64>> {
        let g = Normal::new(0.0, 1.0).unwrap();
        (0..n)
            .map(|_| {
                let e: Vec<f64> = (0..3).map(|_| g.sample(rng)).collect();
                (0..3)
                    .map(|i| mu[i] + (0..3).map(|j| l[i * 3 + j] * e[j]).sum::<f64>())
                    .collect()
            })
            .collect()
    }

    #[test]
    fn bimodal_draws_give_two_modes() {
        let mut rng = StdRng::seed_from_u64(21);
        let sd = [1.0, 2.0, 0.5];
        let l = [sd[0], 0.0, 0.0, 0.0, sd[1], 0.0, 0.0, 0.0, sd[2]];
        // Means 8 sd apart (in dimension 0).
        let mu_a = [0.0, 0.0, 0.0];
        let mu_b = [8.0 * sd[0], 0.0, 0.0];
        let mut points = Vec::new();
        for _ in 0..4000 {
            let which = rng.random::<f64>() < 0.7;
            let mu = if which { mu_a } else { mu_b };
            points.extend(gaussian(1, mu, l, &mut rng));
        }
        let m = find_modes(&points, 4, 7);
        assert_eq!(m.components.len(), 2, "{m:?}");
        let (a, b) = (&m.components[0], &m.components[1]);
        assert!(
            (a.weight - 0.7).abs() < 0.03 && (b.weight - 0.3).abs() < 0.03,
            "{m:?}"
        );
        for j in 0..3 {
            assert!((a.mean[j] - mu_a[j]).abs() < 0.1 * sd[j], "{m:?}");
            assert!((b.mean[j] - mu_b[j]).abs() < 0.1 * sd[j], "{m:?}");
            let var = sd[j] * sd[j];
            assert!((a.cov[j * 3 + j] / var - 1.0).abs() < 0.15, "{m:?}");
            assert!((b.cov[j * 3 + j] / var - 1.0).abs() < 0.15, "{m:?}");
        }
        assert!((a.weight + b.weight - 1.0).abs() < 1e-12);
        // The one-component fit of the same draws has a larger BIC.
        let one = fit_mixture(&points, 1, 1, 10).unwrap();
        assert!(one.bic > m.bic);
    }

    #[test]
    fn correlated_gaussian_gives_one_mode() {
        let mut rng = StdRng::seed_from_u64(22);
        // Strongly correlated, very different scales.
        let l = [
            3.0,
            0.0,
            0.0,
            0.9 * 0.01,
            0.01 * 0.19f64.sqrt(),
            0.0,
            -50.0,
            20.0,
            30.0,
        ];
        let points = gaussian(4000, [10.0, -0.5, 1e3], l, &mut rng);
        let m = find_modes(&points, 4, 3);
        assert_eq!(m.components.len(), 1, "{m:?}");
        let c = &m.components[0];
        assert_eq!(c.weight, 1.0);
        assert!((c.mean[0] - 10.0).abs() < 0.1 * 3.0);
        assert!((c.mean[2] - 1e3).abs() < 0.1 * 62.0);
        // Covariance L L^T recovered in the original units.
        let exact = |a: usize, b: usize| (0..3).map(|m| l[a * 3 + m] * l[b * 3 + m]).sum::<f64>();
        for a in 0..3 {
            for b in 0..3 {
                let tol = 0.1 * (exact(a, a) * exact(b, b)).sqrt();
                assert!(
                    (c.cov[a * 3 + b] - exact(a, b)).abs() < tol,
                    "{a}{b}: {m:?}"
                );
            }
        }
    }

    #[test]
    fn degenerate_inputs() {
        let pts: Vec<Vec<f64>> = (0..8).map(|i| vec![i as f64, 1.0]).collect();
        assert!(fit_mixture(&pts, 2, 0, 50).is_none());
        assert!(fit_mixture(&pts, 0, 0, 50).is_none());
        // A constant dimension is regularised, not fatal.
        let m = fit_mixture(&pts, 1, 0, 50).unwrap();
        assert_eq!(m.components.len(), 1);
        assert!(m.log_likelihood.is_finite());
        let m = find_modes(&pts[..3], 3, 0);
        assert_eq!(m.components.len(), 1);
        assert!((m.components[0].mean[0] - 1.0).abs() < 1e-12);
        assert!(find_modes(&[], 3, 0).components.is_empty());
    }
}
