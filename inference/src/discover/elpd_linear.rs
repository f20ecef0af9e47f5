//! Leave-window-out elpd of a Laplace fit, exact for its linearised Gaussian model.
//!
//! Importance sampling (PSIS) from the full posterior fails when one voltage block pins a
//! direction of a narrow Laplace posterior (Pareto k-hat > 0.7: the data are noiseless or very
//! informative). For the linearised model c(theta) ~ c* + J (theta - theta*), with the whitened
//! Gauss-Newton precision H = sum_k w_k w_k^T + (prior rows), w_k = J_k / sigma_k, leaving
//! out block b is closed form:
//!
//! - H_-b = H - sum_{k in b} w_k w_k^T;
//! - theta_-b = theta* - H_-b^-1 g_b, with g_b = sum_{k in b} w_k (y_k - c*_k) / sigma_k the
//!   block's pull on the mode (the full posterior's gradient is zero at theta*);
//! - p(y_b | y_-b) = N(y_b; c*_b + J_b (theta_-b - theta*), diag(sigma_b^2) + J_b H_-b^-1 J_b^T).
//!
//! sigma is held at its value at the mode (its dependence on c is second order here).

use super::checks::{Elpd, block_partition};
use crate::numerics::Cholesky;
use crate::posterior::LaplaceFit;

/// H = covariance^-1 (d x d, row-major); None when the covariance is not positive definite.
fn precision(cov: &[f64], d: usize) -> Option<Vec<f64>> {
    Some(Cholesky::new(cov, d)?.inverse())
}

/// ln N(y; m, S) for a small dense S; None when S is not positive definite.
fn ln_mvn(y: &[f64], m: &[f64], s: &[f64]) -> Option<f64> {
    let n = y.len();
    let ch = Cholesky::new(s, n)?;
    let r: Vec<f64> = y.iter().zip(m).map(|(a, b)| a - b).collect();
    let x = ch.solve(&r);
    let quad: f64 = r.iter().zip(&x).map(|(a, b)| a * b).sum();
    Some(-0.5 * (quad + ch.ln_det() + n as f64 * (2.0 * std::f64::consts::PI).ln()))
}

/// `ln p(y_b | y_-b)` for every block of `n_blocks` contiguous voltage blocks, under the
/// linearised Gaussian model of `lf` (see the module docs); `c_m` measured (pF), `sigma` the
/// noise sd at the mode (pF). A block whose reduced precision is not positive definite (it
/// alone fixed a direction the prior leaves free) gets NaN. `max_k_hat` is NaN: no importance
/// sampling is involved.
pub fn leave_window_out_linear(
    c_m: &[f64],
    lf: &LaplaceFit,
    sigma: &[f64],
    n_blocks: usize,
) -> Elpd {
    let n = c_m.len();
    let d = lf.theta.len();
    let blocks = block_partition(n, n_blocks);
    let h = precision(&lf.covariance, d);
    let jac = |k: usize| &lf.jacobian[k * d..(k + 1) * d];
    let per_block: Vec<f64> = blocks
        .iter()
        .map(|&[first, last]| {
            let Some(h) = h.as_ref() else {
                return f64::NAN;
            };
            let mut hb = h.clone();
            let mut g = vec![0.0; d];
            for k in first..=last {
                let (jk, s) = (jac(k), sigma[k]);
                let r = (c_m[k] - lf.c_p[k]) / (s * s);
                for p in 0..d {
                    g[p] += jk[p] * r;
                    for q in 0..d {
                        hb[p * d + q] -= jk[p] * jk[q] / (s * s);
                    }
                }
            }
            let Some(chb) = Cholesky::new(&hb, d) else {
                return f64::NAN;
            };
            let shift: Vec<f64> = chb.solve(&g).into_iter().map(|v| -v).collect();
            let idx: Vec<usize> = (first..=last).collect();
            let mean: Vec<f64> = idx
                .iter()
                .map(|&k| lf.c_p[k] + jac(k).iter().zip(&shift).map(|(a, b)| a * b).sum::<f64>())
                .collect();
            // J_b H_-b^-1 J_b^T + diag(sigma^2).
            let u: Vec<Vec<f64>> = idx.iter().map(|&k| chb.solve(jac(k))).collect();
            let m = idx.len();
            let mut s = vec![0.0; m * m];
            for a in 0..m {
                for b in 0..m {
                    s[a * m + b] = jac(idx[a]).iter().zip(&u[b]).map(|(x, y)| x * y).sum();
                }
                s[a * m + a] += sigma[idx[a]].powi(2);
            }
            let y: Vec<f64> = idx.iter().map(|&k| c_m[k]).collect();
            ln_mvn(&y, &mean, &s).unwrap_or(f64::NAN)
        })
        .collect();
    Elpd {
        total: per_block.iter().sum(),
        blocks,
        per_block,
        max_k_hat: f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear model c = A theta + a0 with a Gaussian prior: the Laplace fit is exact, and so
    /// must be the closed-form leave-block-out predictive; compare with refitting on y_-b.
    #[test]
    fn matches_refitting_a_linear_gaussian_model() {
        let n = 12;
        let d = 2;
        let a: Vec<[f64; 2]> = (0..n).map(|k| [1.0, k as f64 / 4.0]).collect();
        let sigma: Vec<f64> = (0..n).map(|k| 0.5 + 0.05 * k as f64).collect();
        let prior_mean: [f64; 2] = [1.0, -0.5];
        let prior_sd: [f64; 2] = [2.0, 1.5];
        let y: Vec<f64> = (0..n)
            .map(|k| 0.3 + 0.8 * a[k][1] + 0.4 * ((k * 7 % 5) as f64 - 2.0))
            .collect();
        // Posterior of theta given the points in `keep`: precision and mean.
        let posterior = |keep: &dyn Fn(usize) -> bool| {
            let mut h = [0.0; 4];
            let mut rhs = [0.0; 2];
            for p in 0..d {
                h[p * d + p] += 1.0 / prior_sd[p].powi(2);
                rhs[p] += prior_mean[p] / prior_sd[p].powi(2);
            }
            for k in (0..n).filter(|&k| keep(k)) {
                let w = 1.0 / sigma[k].powi(2);
                for p in 0..d {
                    rhs[p] += a[k][p] * y[k] * w;
                    for q in 0..d {
                        h[p * d + q] += a[k][p] * a[k][q] * w;
                    }
                }
            }
            let ch = Cholesky::new(&h, d).unwrap();
            let mean = ch.solve(&rhs);
            let mut cov = vec![0.0; 4];
            for q in 0..d {
                let mut e = vec![0.0; d];
                e[q] = 1.0;
                for (p, v) in ch.solve(&e).into_iter().enumerate() {
                    cov[p * d + q] = v;
                }
            }
            (mean, cov)
        };
        let (theta, covariance) = posterior(&|_| true);
        let c_p: Vec<f64> = a
            .iter()
            .map(|r| r[0] * theta[0] + r[1] * theta[1])
            .collect();
        let lf = LaplaceFit {
            theta: theta.clone(),
            ln_posterior: 0.0,
            ln_likelihood: 0.0,
            chi2: 0.0,
            ln_evidence: 0.0,
            covariance,
            c_p,
            jacobian: a.iter().flat_map(|r| r.to_vec()).collect(),
            evaluations: 0,
            steps: 0,
        };
        let elpd = leave_window_out_linear(&y, &lf, &sigma, 4);
        assert_eq!(elpd.blocks.len(), 4);
        for (b, &[first, last]) in elpd.blocks.iter().enumerate() {
            let (m, cov) = posterior(&|k| k < first || k > last);
            let idx: Vec<usize> = (first..=last).collect();
            let mean: Vec<f64> = idx
                .iter()
                .map(|&k| a[k][0] * m[0] + a[k][1] * m[1])
                .collect();
            let q = idx.len();
            let mut s = vec![0.0; q * q];
            for i in 0..q {
                for j in 0..q {
                    let (ri, rj) = (a[idx[i]], a[idx[j]]);
                    for p in 0..d {
                        for r in 0..d {
                            s[i * q + j] += ri[p] * cov[p * d + r] * rj[r];
                        }
                    }
                }
                s[i * q + i] += sigma[idx[i]].powi(2);
            }
            let ys: Vec<f64> = idx.iter().map(|&k| y[k]).collect();
            let want = ln_mvn(&ys, &mean, &s).unwrap();
            assert!(
                (elpd.per_block[b] - want).abs() < 1e-10,
                "block {b}: {} vs {want}",
                elpd.per_block[b]
            );
        }
        assert!((elpd.total - elpd.per_block.iter().sum::<f64>()).abs() < 1e-12);
        assert!(elpd.max_k_hat.is_nan());
    }

    #[test]
    fn a_block_that_alone_fixes_a_free_direction_gives_nan() {
        // One parameter, flat prior (no prior row), all information in the first block.
        let lf = LaplaceFit {
            theta: vec![1.0],
            ln_posterior: 0.0,
            ln_likelihood: 0.0,
            chi2: 0.0,
            ln_evidence: 0.0,
            covariance: vec![0.5],
            c_p: vec![1.0, 1.0, 0.0, 0.0],
            jacobian: vec![1.0, 1.0, 0.0, 0.0],
            evaluations: 0,
            steps: 0,
        };
        let e = leave_window_out_linear(&[1.1, 0.9, 0.1, -0.1], &lf, &[1.0; 4], 2);
        assert!(e.per_block[0].is_nan());
        assert!(e.per_block[1].is_finite());
    }
}
