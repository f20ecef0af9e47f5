//! Mode search before sampling, and the mode-jump proposal of the adaptive Metropolis.
//!
//! A random walk tuned in one mode rarely crosses to another, and R-hat cannot see a mode no
//! chain visits. So before tuning, Nelder-Mead runs from `starts` dispersed points (prior draws)
//! find the local maxima of ln p(z); maxima within 5 standard deviations (Mahalanobis, with the
//! Laplace covariance Sigma_k = (-H_k)^-1) of a higher one are the same mode. Each mode gets the
//! Laplace weight w_k ∝ p(z_k) sqrt(det Sigma_k). When more than one mode carries weight, the
//! sampler mixes random-walk steps with independence proposals from the mixture
//!   q(z) = sum_k w_k N(z; z_k, s^2 Sigma_k)   (s = 1.5),
//! accepted with min(1, p(z') q(z) / (p(z) q(z'))), which keeps detailed balance (Tierney 1994:
//! a mixture of valid kernels is valid) and moves chains between modes.

use rand::RngExt;
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use std::time::Instant;

use super::samples::LocalMode;
use super::start::chain_rng;
use super::target::LogDensity;
use crate::Result;
use crate::numerics::{Cholesky, nelder_mead_until};
use crate::rejection::Latch;

/// Width factor of the mixture components over the Laplace covariance.
const INFLATE: f64 = 1.5;
/// Modes this much below the best (in ln p) are ignored.
const LN_P_WINDOW: f64 = 30.0;

/// One local maximum.
#[derive(Debug, Clone)]
pub(super) struct Mode {
    /// Location (z).
    pub z: Vec<f64>,
    /// ln p(z).
    pub ln_p: f64,
    /// Laplace covariance, row-major.
    pub cov: Vec<f64>,
    /// Laplace weight (normalised over the modes).
    pub weight: f64,
    chol: Cholesky,
}

/// The modes found, best first.
#[derive(Debug, Clone)]
pub(super) struct Modes {
    pub modes: Vec<Mode>,
    /// Evaluations spent.
    pub evaluations: u64,
}

/// -H by central differences (step h), symmetrised.
fn neg_hessian(f: &dyn Fn(&[f64]) -> f64, z: &[f64], h: f64) -> Vec<f64> {
    let d = z.len();
    let f0 = f(z);
    let mut h2 = vec![0.0; d * d];
    let at = |i: usize, a: f64, j: usize, b: f64| {
        let mut x = z.to_vec();
        x[i] += a;
        x[j] += b;
        f(&x)
    };
    for i in 0..d {
        h2[i * d + i] = -(at(i, h, i, 0.0) - 2.0 * f0 + at(i, -h, i, 0.0)) / (h * h);
        for j in 0..i {
            let v = -(at(i, h, j, h) - at(i, h, j, -h) - at(i, -h, j, h) + at(i, -h, j, -h))
                / (4.0 * h * h);
            h2[i * d + j] = v;
            h2[j * d + i] = v;
        }
    }
    h2
}

/// Inverse of a symmetric matrix made positive definite (diagonal loading until Cholesky works).
fn laplace_cov(neg_h: &[f64], d: usize) -> Vec<f64> {
    let mut a = neg_h.to_vec();
    let scale = (0..d).map(|i| a[i * d + i].abs()).fold(1e-6, f64::max);
    let mut load = 0.0;
    loop {
        if !a.iter().any(|v| !v.is_finite())
            && let Some(c) = Cholesky::new(&a, d)
        {
            let mut inv = c.inverse();
            // Never much wider than the prior's unit scale in z: variances above 4 are scaled
            // down to 4 by D Sigma D with D diagonal (a congruence, so it stays positive
            // definite).
            let scale: Vec<f64> = (0..d)
                .map(|i| (4.0 / inv[i * d + i]).sqrt().min(1.0))
                .collect();
            for i in 0..d {
                for j in 0..d {
                    inv[i * d + j] *= scale[i] * scale[j];
                }
            }
            return inv;
        }
        load = if load == 0.0 {
            1e-6 * scale
        } else {
            load * 10.0
        };
        a = neg_h.to_vec();
        for i in 0..d {
            if !a[i * d + i].is_finite() {
                a[i * d + i] = scale;
            }
            a[i * d + i] += load;
        }
        for v in a.iter_mut() {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
    }
}

/// Searches for modes from `starts` dispersed points. A recoverable model error is a point of
/// zero density; any other error ends the search and is returned. At `deadline` (the sampling
/// run's time budget) the search stops with what it has: starts not begun are skipped, the
/// simplexes stop where they are, and only the best point found becomes a mode.
pub(super) fn search(
    target: &dyn LogDensity,
    starts: usize,
    seed: u64,
    deadline: Instant,
) -> Result<Modes> {
    let d = target.dim();
    let latch = Latch::default();
    let f = |z: &[f64]| latch.value(|| target.ln_density(z, None));
    let past = || Instant::now() >= deadline;
    let runs: Vec<(Vec<f64>, f64, u64)> = (0..starts)
        .into_par_iter()
        .filter_map(|s| {
            // The first start always runs: the chains need a point to start from.
            if s > 0 && past() {
                return None;
            }
            let mut rng = chain_rng(seed ^ 0x6d6f_6465, s);
            let mut z0 = None;
            for _ in 0..100 {
                let z = target.initial(&mut rng);
                if f(&z).is_finite() {
                    z0 = Some(z);
                    break;
                }
            }
            let z0 = z0?;
            let max_evals = 250 * d + 500;
            // Two restarts of the simplex: Nelder-Mead stalls in curved valleys.
            let (z1, _) = nelder_mead_until(&f, &z0, 0.5, max_evals, 1e-9, &past);
            let (z2, l2) = nelder_mead_until(&f, &z1, 0.1, max_evals, 1e-10, &past);
            Some((z2, l2, 2 * max_evals as u64))
        })
        .collect();
    latch.check()?;
    let mut evaluations: u64 = runs.iter().map(|r| r.2).sum();
    let mut found: Vec<(Vec<f64>, f64)> = runs
        .into_iter()
        .map(|r| (r.0, r.1))
        .filter(|r| r.1.is_finite())
        .collect();
    found.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut modes: Vec<Mode> = Vec::new();
    let best = found.first().map_or(f64::NEG_INFINITY, |r| r.1);
    for (z, lp) in found {
        // Past the budget: the best point alone (its Laplace covariance starts the tuning).
        if lp < best - LN_P_WINDOW || (!modes.is_empty() && past()) {
            break;
        }
        let same = modes.iter().any(|m| {
            let r: Vec<f64> = z.iter().zip(&m.z).map(|(a, b)| a - b).collect();
            let a = m.chol.solve(&r);
            r.iter().zip(&a).map(|(x, y)| x * y).sum::<f64>() < 25.0
        });
        if same {
            continue;
        }
        let nh = neg_hessian(&f, &z, 1e-3);
        evaluations += (2 * d * d + 1) as u64;
        let cov = laplace_cov(&nh, d);
        // The inverse of a positive-definite matrix, congruence-scaled: positive definite up to
        // rounding; a diagonal fallback otherwise.
        let (cov, chol) = match Cholesky::new(&cov, d) {
            Some(c) => (cov, c),
            None => {
                let diag: Vec<f64> = (0..d * d)
                    .map(|k| {
                        if k % (d + 1) == 0 {
                            cov[k].abs().clamp(1e-12, 4.0)
                        } else {
                            0.0
                        }
                    })
                    .collect();
                let c = Cholesky::new(&diag, d).expect("a positive diagonal");
                (diag, c)
            }
        };
        modes.push(Mode {
            z,
            ln_p: lp,
            cov,
            weight: 0.0,
            chol,
        });
    }
    // Laplace weights: ln w = ln p + ln det(Sigma) / 2.
    let lw: Vec<f64> = modes
        .iter()
        .map(|m| m.ln_p + 0.5 * m.chol.ln_det())
        .collect();
    let mx = lw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let total: f64 = lw.iter().map(|l| (l - mx).exp()).sum();
    for (m, l) in modes.iter_mut().zip(&lw) {
        m.weight = (l - mx).exp() / total;
    }
    modes.retain(|m| m.weight >= 1e-3);
    let total: f64 = modes.iter().map(|m| m.weight).sum();
    for m in modes.iter_mut() {
        m.weight /= total;
    }
    modes.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    latch.check()?;
    Ok(Modes { modes, evaluations })
}

impl Modes {
    /// The modes as reported: parameters, ln p(theta | data) and Laplace weight.
    pub fn local_modes(&self, target: &dyn LogDensity) -> Vec<LocalMode> {
        self.modes
            .iter()
            .map(|m| {
                let (theta, ln_posterior) = target.output(&m.z, m.ln_p);
                LocalMode {
                    weight: m.weight,
                    theta,
                    ln_posterior,
                }
            })
            .collect()
    }

    /// A draw from the mixture q.
    pub fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        let u: f64 = rng.random();
        let mut acc = 0.0;
        let mut k = self.modes.len() - 1;
        for (i, m) in self.modes.iter().enumerate() {
            acc += m.weight;
            if u < acc {
                k = i;
                break;
            }
        }
        let m = &self.modes[k];
        let e: Vec<f64> = (0..m.z.len())
            .map(|_| {
                let x: f64 = StandardNormal.sample(rng);
                INFLATE * x
            })
            .collect();
        let l = m.chol.mul_lower(&e);
        m.z.iter().zip(l).map(|(a, b)| a + b).collect()
    }

    /// ln q(z).
    pub fn ln_q(&self, z: &[f64]) -> f64 {
        let d = z.len() as f64;
        let terms: Vec<f64> = self
            .modes
            .iter()
            .map(|m| {
                let r: Vec<f64> = z.iter().zip(&m.z).map(|(a, b)| a - b).collect();
                let a = m.chol.solve(&r);
                let q: f64 =
                    r.iter().zip(&a).map(|(x, y)| x * y).sum::<f64>() / (INFLATE * INFLATE);
                m.weight.ln()
                    - 0.5 * q
                    - 0.5 * m.chol.ln_det()
                    - d * INFLATE.ln()
                    - 0.5 * d * (2.0 * std::f64::consts::PI).ln()
            })
            .collect();
        let mx = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        mx + terms.iter().map(|t| (t - mx).exp()).sum::<f64>().ln()
    }
}
