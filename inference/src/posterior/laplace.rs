//! A posterior's mode and its Laplace approximation (`discover`'s quick fit of a candidate, and
//! the exact check's ascent into another basin): the mode by Levenberg-Marquardt on the whitened
//! residuals, and the Laplace approximation around it (the evidence and a Gaussian posterior).
//!
//! Residuals: e_k = (c_p,k(theta) - c_m,k) / sigma_k, with sigma_k the likelihood's standard
//! deviation at the current curve (held fixed within a step, updated between steps), and for
//! each normal or truncated-normal prior the pseudo-residual (theta_j - mu_j) / sd_j. A step
//! solves (J^T J + lambda diag(J^T J)) delta = -J^T e and is kept when the exact log posterior
//! (the ln sigma term and every prior normalisation included) rises.
//!
//! Laplace (e.g. MacKay 2003, ch. 27): with H = J^T J at the mode (the Gauss-Newton Hessian of
//! -ln p, prior rows included),
//!   ln Z ~ ln p(theta*) + ln L(theta*) + (d/2) ln(2 pi) - (1/2) ln det H,
//! and the posterior ~ N(theta*, H^-1). Models without a Jacobian (the exact solver) get forward
//! differences from [`crate::CvModel::curves_near`]: the exact solver solves the steps on the
//! grids of theta's curve, so the differences are smooth in theta.

use serde::{Deserialize, Serialize};

use super::Posterior;
use crate::numerics::Cholesky;
use crate::prior::PriorDistribution;
use crate::rejection::unless_rejected;
use crate::{Error, Result};

/// Settings of the quick fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LaplaceSettings {
    /// Most Levenberg-Marquardt steps (accepted or not).
    pub max_steps: usize,
    /// Stop when a step raises ln p by less than this (1e-2: far below what changes a Bayes
    /// factor's reading, and each exact-solver step costs d + 1 solves).
    pub tolerance: f64,
    /// Stop after this many curve evaluations (an exact-solver curve costs ~1-2 s; a geometry
    /// parameter the grid resolves in steps can make the optimiser reject step after step).
    pub max_evaluations: usize,
    /// Forward-difference step of parameter j: this fraction of its support's width (1e-2).
    /// The exact models solve x + h on the grids of x ([`crate::CvModel::curves_near`]), so a
    /// grid that differs between the two (at 0.2% an adaptive pass can, a jump of ~0.1% of c12
    /// and a derivative off by its own size, `validation/examples/fd_noise.rs`) cannot show up
    /// as a derivative: on the base grids the impurity knots' differences agree between h and
    /// h/2 (`validation/tests/near_derivatives.rs`). Left: a geometry step can move a cell's
    /// centre across a slanted boundary (d_Li near Super-Siegfried's borehole cone: jumps of
    /// 1e-3 of c12 near full depletion; reports/solver-performance.md).
    pub fd_step: f64,
}

impl Default for LaplaceSettings {
    fn default() -> Self {
        Self {
            max_steps: 20,
            tolerance: 1e-2,
            max_evaluations: 80,
            fd_step: 1e-2,
        }
    }
}

/// A posterior mode with its Laplace approximation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LaplaceFit {
    /// theta at the mode.
    pub theta: Vec<f64>,
    /// ln p(theta*) + ln L(theta*).
    pub ln_posterior: f64,
    /// ln L(theta*).
    pub ln_likelihood: f64,
    /// chi^2 at the mode.
    pub chi2: f64,
    /// Laplace estimate of ln Z.
    pub ln_evidence: f64,
    /// Covariance H^-1 of theta (d x d, row-major).
    pub covariance: Vec<f64>,
    /// c_p at the mode, pF.
    pub c_p: Vec<f64>,
    /// dc_p / dtheta at the mode (voltages x parameters, row-major), pF per unit.
    pub jacobian: Vec<f64>,
    /// Curve evaluations used.
    pub evaluations: usize,
    /// Accepted steps.
    pub steps: usize,
}

/// The forward-difference steps at theta: h_j = `fd_step` times parameter j's support width,
/// backwards (-h_j) where theta_j + h_j would leave the support.
pub fn fd_steps(prior: &crate::prior::Prior, theta: &[f64], fd_step: f64) -> Vec<f64> {
    prior
        .parameters
        .iter()
        .zip(theta)
        .map(|(p, t)| {
            let [lo, hi] = p.support;
            let h = fd_step * (hi - lo);
            if t + h > hi { -h } else { h }
        })
        .collect()
}

/// c_p and dc_p/dtheta at theta (analytic where the model has a Jacobian).
fn curve_and_jacobian(
    posterior: &Posterior,
    theta: &[f64],
    fd_step: f64,
    evaluations: &mut usize,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let prior = posterior.prior;
    let d = prior.dim();
    let nv = posterior.likelihood.len();
    let nx = prior.input_names.len();
    let mut x = vec![0.0; nx];
    prior.expand(theta, &mut x);
    let mut c = vec![0.0; nv];
    let mut jt = vec![0.0; nv * d];
    if posterior.model.has_jacobian() {
        let mut jx = vec![0.0; nv * nx];
        posterior.model.curve_jacobian(&x, &mut c, &mut jx)?;
        *evaluations += 1;
        for k in 0..nv {
            prior.contract(&jx[k * nx..(k + 1) * nx], &mut jt[k * d..(k + 1) * d]);
        }
        return Ok((c, jt));
    }
    // Forward differences: the steps' curves from the model's nearby-curve method (the exact
    // solver solves them on x's grids, so a grid change cannot masquerade as a derivative).
    let steps = fd_steps(prior, theta, fd_step);
    let mut xs = Vec::with_capacity(d);
    for (j, h) in steps.iter().enumerate() {
        let mut t = theta.to_vec();
        t[j] += h;
        let mut xj = vec![0.0; nx];
        prior.expand(&t, &mut xj);
        xs.push(xj);
    }
    let (c0, near) = posterior.model.curves_near(&x, &xs, &|_, _| {})?;
    let near = near.into_iter().collect::<Result<Vec<_>>>()?;
    c.copy_from_slice(&c0);
    for (j, (h, cj)) in steps.iter().zip(&near).enumerate() {
        for k in 0..nv {
            jt[k * d + j] = (cj[k] - c[k]) / h;
        }
    }
    *evaluations += 1 + d;
    Ok((c, jt))
}

/// Whitened residuals e and their Jacobian (rows: voltages, then prior rows).
fn residuals(posterior: &Posterior, theta: &[f64], c: &[f64], jc: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let d = theta.len();
    let lik = posterior.likelihood;
    let sigma = lik.sigma(c);
    let mut e = Vec::new();
    let mut j = Vec::new();
    for k in 0..c.len() {
        e.push((c[k] - lik.c_m[k]) / sigma[k]);
        j.extend(jc[k * d..(k + 1) * d].iter().map(|v| v / sigma[k]));
    }
    for (i, p) in posterior.prior.parameters.iter().enumerate() {
        if let PriorDistribution::Normal { mean, sd }
        | PriorDistribution::TruncatedNormal { mean, sd, .. } = p.distribution
        {
            e.push((theta[i] - mean) / sd);
            let mut row = vec![0.0; d];
            row[i] = 1.0 / sd;
            j.extend(row);
        }
    }
    (e, j)
}

/// J^T J and J^T e.
fn normal_equations(e: &[f64], j: &[f64], d: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = vec![0.0; d * d];
    let mut g = vec![0.0; d];
    for (r, &er) in e.iter().enumerate() {
        let row = &j[r * d..(r + 1) * d];
        for p in 0..d {
            g[p] += row[p] * er;
            for q in 0..d {
                a[p * d + q] += row[p] * row[q];
            }
        }
    }
    (a, g)
}

/// theta moved inside its support by at least 1e-9 of the width.
fn clamp(posterior: &Posterior, theta: &mut [f64]) {
    for (t, p) in theta.iter_mut().zip(&posterior.prior.parameters) {
        let [lo, hi] = p.support;
        let m = 1e-9 * (hi - lo);
        *t = t.clamp(lo + m, hi - m);
    }
}

/// The mode from `start` and the Laplace approximation there (see the module docs).
pub fn laplace_fit(
    posterior: &Posterior,
    start: &[f64],
    settings: &LaplaceSettings,
) -> Result<LaplaceFit> {
    levenberg_marquardt(posterior, None, start, settings, &mut Vec::new())
}

/// Model inputs x and the model's curve there, pF.
pub type VisitedCurve = (Vec<f64>, Vec<f64>);

/// [`laplace_fit`] on `posterior` (e.g. the exact solver's) with the Jacobian of `guide` (e.g.
/// the corrected surrogate the sampler used): row k of the guide's dc/dtheta scaled by
/// c_p,k / c_guide,k, so that a multiplicative error of the guide cancels. One curve of
/// `posterior`'s model per step instead of d + 1. A step is kept only when `posterior`'s ln p
/// rises, so the end is a point of `posterior` at least as high as the start; where the guide's
/// derivatives are off, the end may stop short of `posterior`'s own mode (its ln p a lower
/// bound of that mode's). The Laplace part (covariance, evidence) uses the guide's Jacobian.
/// Returns also every curve of `posterior`'s model it solved, the start's first.
///
/// # Errors
/// As [`laplace_fit`]; also a failure of the guide's curve or Jacobian.
pub fn laplace_fit_guided(
    posterior: &Posterior,
    guide: &dyn crate::CvModel,
    start: &[f64],
    settings: &LaplaceSettings,
) -> Result<(LaplaceFit, Vec<VisitedCurve>)> {
    let guide = Posterior {
        model: guide,
        prior: posterior.prior,
        likelihood: posterior.likelihood,
    };
    let mut visited = Vec::new();
    let lf = levenberg_marquardt(posterior, Some(&guide), start, settings, &mut visited)?;
    Ok((lf, visited))
}

/// c_p at theta (the evaluation's) and the guide's Jacobian scaled to it (see
/// [`laplace_fit_guided`]); the guide's work is not counted in `evaluations`.
fn guided_jacobian(
    guide: &Posterior,
    theta: &[f64],
    c_p: &[f64],
    fd_step: f64,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let d = theta.len();
    let (cg, mut jg) = curve_and_jacobian(guide, theta, fd_step, &mut 0)?;
    for (k, (cp, cgk)) in c_p.iter().zip(&cg).enumerate() {
        let f = if *cgk != 0.0 { cp / cgk } else { 1.0 };
        for v in &mut jg[k * d..(k + 1) * d] {
            *v *= f;
        }
    }
    Ok((c_p.to_vec(), jg))
}

/// The Levenberg-Marquardt ascent of [`laplace_fit`], with the Jacobian of `guide` where given
/// (then each curve of `posterior`'s model it solves is pushed to `visited`).
fn levenberg_marquardt(
    posterior: &Posterior,
    guide: Option<&Posterior>,
    start: &[f64],
    settings: &LaplaceSettings,
    visited: &mut Vec<VisitedCurve>,
) -> Result<LaplaceFit> {
    let d = posterior.dim();
    let nx = posterior.prior.input_names.len();
    let inputs = |theta: &[f64]| {
        let mut x = vec![0.0; nx];
        posterior.prior.expand(theta, &mut x);
        x
    };
    let mut theta = start.to_vec();
    clamp(posterior, &mut theta);
    let mut evaluations = 0;
    let mut current = posterior.evaluate(&theta)?;
    evaluations += 1;
    if !current.ln_posterior.is_finite() {
        return Err(Error::Numerical {
            what: "quick fit".into(),
            message: format!("the start point {theta:?} has zero posterior density"),
        });
    }
    if guide.is_some() {
        visited.push((inputs(&theta), current.c_p.clone()));
    }
    let jacobian = |theta: &[f64], c_p: &[f64], evaluations: &mut usize| match guide {
        Some(g) => guided_jacobian(g, theta, c_p, settings.fd_step),
        None => curve_and_jacobian(posterior, theta, settings.fd_step, evaluations),
    };
    let (mut c, mut jc) = jacobian(&theta, &current.c_p, &mut evaluations)?;
    let mut lambda = 1e-3;
    let mut steps = 0;
    for _ in 0..settings.max_steps {
        if evaluations >= settings.max_evaluations {
            break;
        }
        let (e, j) = residuals(posterior, &theta, &c, &jc);
        let (a, g) = normal_equations(&e, &j, d);
        let mut m = a.clone();
        for p in 0..d {
            m[p * d + p] += lambda * a[p * d + p].max(1e-12) + 1e-12;
        }
        let Some(ch) = Cholesky::new(&m, d) else {
            lambda *= 10.0;
            continue;
        };
        let delta = ch.solve(&g.iter().map(|v| -v).collect::<Vec<_>>());
        let mut trial: Vec<f64> = theta.iter().zip(&delta).map(|(t, s)| t + s).collect();
        clamp(posterior, &mut trial);
        // A recoverable failure at the trial point rejects the step; any other error is returned.
        let ev = unless_rejected(posterior.evaluate(&trial))?;
        evaluations += 1;
        if let (Some(ev), Some(_)) = (&ev, guide) {
            visited.push((inputs(&trial), ev.c_p.clone()));
        }
        match ev {
            Some(ev) if ev.ln_posterior > current.ln_posterior => {
                let gain = ev.ln_posterior - current.ln_posterior;
                theta = trial;
                current = ev;
                (c, jc) = jacobian(&theta, &current.c_p, &mut evaluations)?;
                lambda = (lambda / 3.0).max(1e-9);
                steps += 1;
                if gain < settings.tolerance {
                    break;
                }
            }
            _ => {
                lambda *= 4.0;
                if lambda > 1e8 {
                    break;
                }
            }
        }
    }
    let (e, j) = residuals(posterior, &theta, &c, &jc);
    let (h, _) = normal_equations(&e, &j, d);
    let mut hr = h.clone();
    for p in 0..d {
        hr[p * d + p] += 1e-10 * h[p * d + p].abs().max(1e-12);
    }
    let ch = Cholesky::new(&hr, d).ok_or_else(|| Error::Numerical {
        what: "Laplace approximation".into(),
        message: "the Hessian at the mode is not positive definite".into(),
    })?;
    let covariance = ch.inverse();
    let ln_evidence = current.ln_posterior + 0.5 * d as f64 * (2.0 * std::f64::consts::PI).ln()
        - 0.5 * ch.ln_det();
    Ok(LaplaceFit {
        chi2: posterior.likelihood.chi2(&current.c_p),
        theta,
        ln_posterior: current.ln_posterior,
        ln_likelihood: current.ln_likelihood,
        ln_evidence,
        covariance,
        c_p: current.c_p,
        jacobian: jc,
        evaluations,
        steps,
    })
}
