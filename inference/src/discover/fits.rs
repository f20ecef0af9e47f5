//! The workflow's fits: MCMC or Laplace, their predictive draws and the gap they leave.

use std::collections::BTreeMap;

use rand::{SeedableRng, rngs::StdRng};
use rand_distr::{Distribution, StandardNormal};

use super::catalogue::Candidate;
use super::checks::{PredictiveDraws, leave_window_out, residual_check};
use super::elpd_linear::leave_window_out_linear;
use super::settings::{DiscoverSettings, ModelFit, Progress};
use super::summary::Gap;
use crate::fit::thin_indices;
use crate::fit::{Fit, fit};
use crate::model::CvModel;
use crate::numerics::Cholesky;
use crate::posterior::{LaplaceFit, laplace_fit};
use crate::posterior::{Likelihood, Posterior};
use crate::prior::Prior;
use crate::prior::PriorDistribution;
use crate::rejection::unless_rejected;
use crate::{Error, Result};

/// Predictive draws of an MCMC fit: at most `n` thinned draws (a draw whose curve fails
/// recoverably is left out; any other model error is returned).
pub(super) fn mcmc_draws(posterior: &Posterior, fit: &Fit, n: usize) -> Result<PredictiveDraws> {
    let all = fit.samples.all();
    let mut draws = PredictiveDraws {
        curves: Vec::new(),
        sigmas: Vec::new(),
    };
    for i in thin_indices(all.len(), n) {
        if let Some(ev) = unless_rejected(posterior.evaluate(all[i]))? {
            draws.sigmas.push(posterior.likelihood.sigma(&ev.c_p));
            draws.curves.push(ev.c_p);
        }
    }
    Ok(draws)
}

/// Draws of the Laplace approximation N(theta*, H^-1) (inside the prior's support) with the
/// curve linearised at the mode: c = c* + J (theta - theta*).
pub(super) fn laplace_draws(
    posterior: &Posterior,
    lf: &LaplaceFit,
    n: usize,
    seed: u64,
) -> PredictiveDraws {
    let d = lf.theta.len();
    let nv = lf.c_p.len();
    let mut rng = StdRng::seed_from_u64(seed);
    let mut draws = PredictiveDraws {
        curves: Vec::new(),
        sigmas: Vec::new(),
    };
    let Some(ch) = Cholesky::new(&lf.covariance, d) else {
        return draws;
    };
    let mut tries = 0;
    while draws.curves.len() < n && tries < 100 * n {
        tries += 1;
        let e: Vec<f64> = (0..d).map(|_| StandardNormal.sample(&mut rng)).collect();
        let dt = ch.mul_lower(&e);
        let theta: Vec<f64> = lf.theta.iter().zip(&dt).map(|(t, s)| t + s).collect();
        if !posterior.prior.ln_density(&theta).is_finite() {
            continue;
        }
        let c: Vec<f64> = (0..nv)
            .map(|k| lf.c_p[k] + (0..d).map(|j| lf.jacobian[k * d + j] * dt[j]).sum::<f64>())
            .collect();
        draws.sigmas.push(posterior.likelihood.sigma(&c));
        draws.curves.push(c);
    }
    draws
}

/// Goodness of fit at a mode.
pub(super) fn gap(
    model: &ModelFit,
    lik: &Likelihood,
    converged: bool,
    mode: &[f64],
    method: &str,
) -> Gap {
    let chi2 = lik.chi2(&model.c_mode);
    let ndf = lik.len().saturating_sub(model.names.len());
    Gap {
        chi2_ndf: chi2 / ndf.max(1) as f64,
        max_pull: lik
            .pulls(&model.c_mode)
            .iter()
            .fold(0.0f64, |m, p| m.max(p.abs())),
        ppc_p: model.check.ppc_p,
        chi2,
        ndf,
        model: model.model.clone(),
        method: method.into(),
        converged,
        mode: model
            .names
            .iter()
            .cloned()
            .zip(mode.iter().copied())
            .collect(),
    }
}

/// An MCMC fit of `prior` on `model` with its checks.
pub(super) fn mcmc_fit(
    model: &dyn CvModel,
    prior: &Prior,
    lik: &Likelihood,
    settings: &DiscoverSettings,
    inputs: &BTreeMap<String, String>,
    progress: &dyn Progress,
) -> Result<ModelFit> {
    let posterior = Posterior::new(model, prior, lik)?;
    let f = fit(&posterior, &settings.fit, inputs.clone(), &|s| {
        progress.sampling(s)
    })?;
    let draws = mcmc_draws(&posterior, &f, settings.draws)?;
    let c_mode = f.predictive.c_mode_pf.clone();
    Ok(ModelFit {
        model: prior.name.clone(),
        names: prior.names(),
        check: residual_check(&lik.c_m, &draws, settings.min_run, settings.seed),
        elpd: leave_window_out(&lik.c_m, &draws, settings.elpd_blocks),
        sigma_mode: lik.sigma(&c_mode),
        c_mode,
        mcmc: Some(f),
        laplace: None,
    })
}

/// A Laplace fit's checks: the residual check on draws of the linearised Gaussian, the elpd
/// in closed form for it ([`leave_window_out_linear`]).
pub(super) fn laplace_model_fit(
    posterior: &Posterior,
    lf: LaplaceFit,
    settings: &DiscoverSettings,
) -> ModelFit {
    let lik = posterior.likelihood;
    let draws = laplace_draws(posterior, &lf, settings.draws, settings.seed ^ 0x1a9);
    ModelFit {
        model: posterior.prior.name.clone(),
        names: posterior.prior.names(),
        check: residual_check(&lik.c_m, &draws, settings.min_run, settings.seed),
        elpd: leave_window_out_linear(&lik.c_m, &lf, &lik.sigma(&lf.c_p), settings.elpd_blocks),
        sigma_mode: lik.sigma(&lf.c_p),
        c_mode: lf.c_p.clone(),
        mcmc: None,
        laplace: Some(lf),
    }
}

/// Start points of the start model's quick fit: the surrogate MCMC mode and, on the exact
/// solver, the prior's centre too (the surrogate's mode may sit at the wrong one of two
/// near-symmetric modes; seen on z-only truths, where B_Z swapped top and bottom).
pub(super) fn start_points(prior: &Prior, sur_mode: &[f64], centre: bool) -> Vec<Vec<f64>> {
    let mut v = vec![sur_mode.to_vec()];
    if centre {
        v.push(
            prior
                .parameters
                .iter()
                .map(|p| {
                    let m = match p.distribution {
                        PriorDistribution::Uniform { lo, hi } => 0.5 * (lo + hi),
                        PriorDistribution::Normal { mean, .. }
                        | PriorDistribution::TruncatedNormal { mean, .. } => mean,
                    };
                    m.clamp(p.support[0], p.support[1])
                })
                .collect(),
        );
    }
    v
}

/// The best (highest ln p) of the quick fits from `starts`; the first error if all fail.
pub(super) fn best_laplace(
    posterior: &Posterior,
    starts: &[Vec<f64>],
    settings: &DiscoverSettings,
) -> Result<LaplaceFit> {
    let mut best: Option<LaplaceFit> = None;
    let mut first_err = None;
    for s in starts {
        match laplace_fit(posterior, s, &settings.laplace) {
            Ok(f) => {
                if best
                    .as_ref()
                    .is_none_or(|b| f.ln_posterior > b.ln_posterior)
                {
                    best = Some(f);
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    match (best, first_err) {
        (Some(b), _) => Ok(b),
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::Argument {
            name: "start points".into(),
            message: "none given".into(),
        }),
    }
}

/// A candidate's prior bound to its model.
pub(super) fn bind(c: &Candidate) -> Result<Prior> {
    Prior::bind(&c.spec, &c.model.inputs(), &c.model.domain())
}
