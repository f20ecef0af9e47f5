//! A surrogate that knows its error (issue 21, item 2): a per-point relative uncertainty
//! sigma_s(p, U_B) in place of the one constant sigma_p of the paper's eq. 13.
//!
//! The model is heteroscedastic Gaussian in the network's own coordinates z = Phi^-1(u) of every
//! input (the parameters and the bias, network order):
//!
//!   ln sigma_s^2(z) = 2 ln kappa + w_0 + sum_j (a_j z_j + b_j z_j^2),
//!
//! so the uncertainty may grow towards either end of every range (the edges of the training set,
//! where the networks extrapolate: the models README, issue 24) and with the bias. The weights w
//! minimise the Gaussian negative log-likelihood of the relative errors
//! r_i = (c_p - c_s)/c_s of a calibration set (a proper scoring rule; convex in w, solved by
//! Newton's method with a line search), and the one factor kappa then makes exactly 95.45% of
//! the calibration rows lie within 2 sigma_s (the errors have heavier tails than a Gaussian, so
//! the maximum-likelihood scale alone covers too few at 2 sigma and too many at 1 sigma).
//! sigma_s is capped at [`SIGMA_MAX`]: beyond it a surrogate says nothing and the cap keeps the
//! quadratic terms from running away at |z| = 4.75.
//!
//! Chosen over an ensemble spread because it needs no retraining and is calibrated on data the
//! networks never saw; measured against the constant sigma_p in `models/README.md`.

use faer::Mat;
use faer::linalg::solvers::Solve;
use serde::{Deserialize, Serialize};

use super::dataset::DataInfo;
use super::metrics::quantile;
use crate::error::{Error, Result};

/// The largest relative uncertainty the model gives (100%).
pub const SIGMA_MAX: f64 = 1.0;
/// The smallest (1e-5: below the exact solver's own accuracy).
pub const SIGMA_MIN: f64 = 1e-5;
/// Ridge penalty on every weight but the constant, per calibration row (keeps the fit defined
/// where one z_j^2 barely varies).
pub const RIDGE_PER_ROW: f64 = 1e-4;
/// The fraction of calibration rows kappa puts within 2 sigma_s (the Gaussian 2-sigma content).
pub const TARGET_COVERAGE_2SIGMA: f64 = 0.9545;

/// The calibrated per-point uncertainty of a surrogate, stored in its model file
/// (`error_model` in the metadata).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorModel {
    /// Input names (network order: the parameters, then the bias).
    pub inputs: Vec<String>,
    /// w_0, then (a_j, b_j) for every input j: ln sigma^2 = 2 ln kappa + w_0 + sum a_j z_j + b_j z_j^2.
    pub weights: Vec<f64>,
    /// kappa (dimensionless), from the 2-sigma coverage of the calibration set.
    pub kappa: f64,
    /// The calibration set.
    pub calibration: DataInfo,
    /// Fractions of the calibration rows within 1 and 2 sigma_s.
    pub coverage_1sigma: f64,
    /// See `coverage_1sigma`.
    pub coverage_2sigma: f64,
    /// Newton iterations of the fit.
    pub iterations: usize,
}

fn features(z: &[f64], phi: &mut Vec<f64>) {
    phi.clear();
    phi.push(1.0);
    for &zj in z {
        phi.push(zj);
        phi.push(zj * zj);
    }
}

/// The Gaussian negative log-likelihood (without constants) of the relative errors `r2` (squared)
/// for the log-variances s: sum 0.5 (s_i + r_i^2 e^-s_i) + 0.5 ridge |w_1..|^2.
fn objective(phi: &[Vec<f64>], r2: &[f64], w: &[f64], ridge: f64) -> f64 {
    let data: f64 = phi
        .iter()
        .zip(r2)
        .map(|(f, &r)| {
            let s: f64 = f.iter().zip(w).map(|(a, b)| a * b).sum();
            0.5 * (s + r * (-s).exp())
        })
        .sum();
    data + 0.5 * ridge * w[1..].iter().map(|x| x * x).sum::<f64>()
}

impl ErrorModel {
    /// Fits the model to relative errors `rel` at network coordinates `z` (row-major,
    /// rows x inputs) and calibrates kappa on the same rows.
    ///
    /// # Errors
    /// [`Error::Training`] with fewer rows than twice the weights, non-finite values, or a fit
    /// that does not converge.
    pub fn fit(inputs: Vec<String>, z: &[f64], rel: &[f64], calibration: DataInfo) -> Result<Self> {
        let d = inputs.len();
        let k = 1 + 2 * d;
        let n = rel.len();
        if d == 0 || z.len() != n * d {
            return Err(Error::Training {
                message: format!("error model: {} values for {n} rows of {d} inputs", z.len()),
            });
        }
        if n < 2 * k {
            return Err(Error::Training {
                message: format!(
                    "error model: {n} calibration rows, at least {} needed",
                    2 * k
                ),
            });
        }
        if let Some(i) = rel.iter().position(|r| !r.is_finite()) {
            return Err(Error::Training {
                message: format!("error model: calibration row {i} has a non-finite error"),
            });
        }
        let floor = SIGMA_MIN * SIGMA_MIN;
        let r2: Vec<f64> = rel.iter().map(|r| (r * r).max(floor)).collect();
        let phi: Vec<Vec<f64>> = z
            .chunks(d)
            .map(|row| {
                let mut f = Vec::with_capacity(k);
                features(row, &mut f);
                f
            })
            .collect();
        let ridge = RIDGE_PER_ROW * n as f64;
        let mut w = vec![0.0; k];
        w[0] = (r2.iter().sum::<f64>() / n as f64).ln();
        let mut value = objective(&phi, &r2, &w, ridge);
        let mut iterations = 0;
        let mut converged = false;
        while iterations < 100 {
            iterations += 1;
            let mut h = Mat::<f64>::zeros(k, k);
            let mut g = Mat::<f64>::zeros(k, 1);
            for (f, &r) in phi.iter().zip(&r2) {
                let s: f64 = f.iter().zip(&w).map(|(a, b)| a * b).sum();
                let e = r * (-s).exp();
                for i in 0..k {
                    g[(i, 0)] += 0.5 * f[i] * (1.0 - e);
                    for j in 0..=i {
                        h[(i, j)] += 0.5 * e * f[i] * f[j];
                    }
                }
            }
            for i in 0..k {
                if i > 0 {
                    g[(i, 0)] += ridge * w[i];
                    h[(i, i)] += ridge;
                }
                for j in 0..i {
                    h[(j, i)] = h[(i, j)];
                }
            }
            let llt = h.llt(faer::Side::Lower).map_err(|e| Error::Training {
                message: format!("error model: singular Hessian: {e:?}"),
            })?;
            let step = llt.solve(&g);
            let decrement: f64 = (0..k).map(|i| step[(i, 0)] * g[(i, 0)]).sum();
            if decrement < 1e-10 * n as f64 {
                converged = true;
                break;
            }
            let mut t = 1.0;
            loop {
                let trial: Vec<f64> = (0..k).map(|i| w[i] - t * step[(i, 0)]).collect();
                let v = objective(&phi, &r2, &trial, ridge);
                if v <= value - 0.25 * t * decrement {
                    w = trial;
                    value = v;
                    break;
                }
                t *= 0.5;
                if t < 1e-10 {
                    return Err(Error::Training {
                        message: "error model: the line search failed".into(),
                    });
                }
            }
        }
        if !converged {
            return Err(Error::Training {
                message: "error model: Newton's method did not converge in 100 steps".into(),
            });
        }
        let mut model = ErrorModel {
            inputs,
            weights: w,
            kappa: 1.0,
            calibration,
            coverage_1sigma: f64::NAN,
            coverage_2sigma: f64::NAN,
            iterations,
        };
        let mut t: Vec<f64> = z
            .chunks(d)
            .zip(rel)
            .map(|(row, r)| r.abs() / model.sigma(row, None))
            .collect();
        t.sort_by(f64::total_cmp);
        model.kappa = (quantile(&t, TARGET_COVERAGE_2SIGMA) / 2.0).max(1e-3);
        let (c1, c2) = model.coverage(z, rel);
        model.coverage_1sigma = c1;
        model.coverage_2sigma = c2;
        Ok(model)
    }

    /// sigma_s at network coordinates z (every input, network order), and with `grad`
    /// d sigma_s^2 / dz_j for the first `grad.len()` inputs (zero where the cap holds).
    ///
    /// sigma_s = clamp(kappa exp(s/2), SIGMA_MIN, SIGMA_MAX), s = w . phi(z).
    pub fn sigma(&self, z: &[f64], grad: Option<&mut [f64]>) -> f64 {
        let mut s = self.weights[0];
        for (j, &zj) in z.iter().enumerate() {
            s += self.weights[1 + 2 * j] * zj + self.weights[2 + 2 * j] * zj * zj;
        }
        let raw = self.kappa * (0.5 * s).exp();
        let sigma = raw.clamp(SIGMA_MIN, SIGMA_MAX);
        if let Some(g) = grad {
            let free = sigma == raw;
            for (j, gj) in g.iter_mut().enumerate() {
                // d sigma^2/dz_j = sigma^2 ds/dz_j.
                *gj = if free {
                    sigma * sigma * (self.weights[1 + 2 * j] + 2.0 * self.weights[2 + 2 * j] * z[j])
                } else {
                    0.0
                };
            }
        }
        sigma
    }

    /// Fractions of rows (z row-major, relative errors `rel`) with |r| <= sigma_s and
    /// |r| <= 2 sigma_s.
    pub fn coverage(&self, z: &[f64], rel: &[f64]) -> (f64, f64) {
        coverage_of(
            rel,
            z.chunks(self.inputs.len()).map(|row| self.sigma(row, None)),
        )
    }
}

/// Fractions of `rel` within 1 and 2 of their `sigma`s (NaN for no rows).
pub fn coverage_of(rel: &[f64], sigma: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut one, mut two) = (0usize, 0usize);
    for (r, s) in rel.iter().zip(sigma) {
        one += usize::from(r.abs() <= s);
        two += usize::from(r.abs() <= 2.0 * s);
    }
    let n = rel.len() as f64;
    (one as f64 / n, two as f64 / n)
}
