//! The posterior a sampler sees: ln p(theta | c_m) = ln pi(theta) + ln L(c_p(x(theta))), in the
//! parameters theta or in the unconstrained z (theta = a + (b - a) s(z), Jacobian included).

use super::Likelihood;
use crate::model::CvModel;
use crate::prior::Prior;
use crate::{Error, Result};

/// The posterior of one fit.
#[derive(Clone, Copy)]
pub struct Posterior<'a> {
    /// The model.
    pub model: &'a dyn CvModel,
    /// The prior (bound to the model's inputs).
    pub prior: &'a Prior,
    /// The likelihood.
    pub likelihood: &'a Likelihood,
}

/// One evaluation at theta.
#[derive(Debug, Clone, PartialEq)]
pub struct PosteriorEvaluation {
    /// ln pi(theta) + ln L.
    pub ln_posterior: f64,
    /// ln L.
    pub ln_likelihood: f64,
    /// The predicted curve, pF.
    pub c_p: Vec<f64>,
    /// The model's squared relative uncertainty at each point, sigma_p,k^2
    /// (`CvModel::curve_variance`).
    pub var_rel: Vec<f64>,
}

impl std::fmt::Debug for Posterior<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Posterior")
            .field("model", &self.model.describe())
            .field("prior", &self.prior.name)
            .finish()
    }
}

impl<'a> Posterior<'a> {
    /// Checks that model, prior and data fit together: the same voltages, at least as many
    /// points as parameters.
    pub fn new(
        model: &'a dyn CvModel,
        prior: &'a Prior,
        likelihood: &'a Likelihood,
    ) -> Result<Self> {
        if model.voltages().len() != likelihood.len() {
            return Err(Error::Argument {
                name: "data".into(),
                message: format!(
                    "the model predicts {} voltages, the data have {}",
                    model.voltages().len(),
                    likelihood.len()
                ),
            });
        }
        if likelihood.len() < prior.dim() {
            return Err(Error::Argument {
                name: "data".into(),
                message: format!(
                    "{} voltages cannot constrain {} parameters ({}): the curve needs at least as many points as the fit has parameters",
                    likelihood.len(),
                    prior.dim(),
                    prior.names().join(", ")
                ),
            });
        }
        Ok(Self {
            model,
            prior,
            likelihood,
        })
    }

    /// Number of fit parameters.
    pub fn dim(&self) -> usize {
        self.prior.dim()
    }

    /// ln pi(theta) + ln L(theta) and the predicted curve. Outside the prior's support the
    /// posterior is -inf (no model call); a model error (outside its domain, a failed solve) is
    /// returned for the caller to treat as a rejection.
    pub fn evaluate(&self, theta: &[f64]) -> Result<PosteriorEvaluation> {
        self.evaluate_with(theta, None)
    }

    /// [`Posterior::evaluate`] with the model's curve at `theta` already solved (`c_p`, pF):
    /// ln pi(theta) + ln L(c_p) with the model's per-point variance at theta; no curve solve.
    ///
    /// # Errors
    /// The model's variance fails (as [`CvModel::curve_variance`]).
    pub fn evaluate_curve(&self, theta: &[f64], c_p: Vec<f64>) -> Result<PosteriorEvaluation> {
        self.evaluate_with(theta, Some(c_p))
    }

    /// ln pi + ln L at `theta`, the curve solved by the model unless given.
    fn evaluate_with(&self, theta: &[f64], given: Option<Vec<f64>>) -> Result<PosteriorEvaluation> {
        let lp = self.prior.ln_density(theta);
        let nv = self.likelihood.len();
        let mut var_rel = vec![self.model.sigma_rel().powi(2); nv];
        if !lp.is_finite() {
            return Ok(PosteriorEvaluation {
                ln_posterior: f64::NEG_INFINITY,
                ln_likelihood: f64::NEG_INFINITY,
                c_p: given.unwrap_or_else(|| vec![0.0; nv]),
                var_rel,
            });
        }
        let mut x = vec![0.0; self.prior.input_names.len()];
        self.prior.expand(theta, &mut x);
        let c_p = match given {
            Some(c) => c,
            None => {
                let mut c = vec![0.0; nv];
                self.model.curve(&x, &mut c)?;
                c
            }
        };
        self.model.curve_variance(&x, &mut var_rel, None)?;
        let ll = self
            .likelihood
            .ln_likelihood_var(&c_p, &var_rel, None, None);
        Ok(PosteriorEvaluation {
            ln_posterior: lp + ll,
            ln_likelihood: ll,
            c_p,
            var_rel,
        })
    }

    /// ln p(z) = ln pi(theta(z)) + ln |dtheta/dz| + ln L(theta(z)), the density the samplers
    /// draw z from; with `grad`, d ln p / dz (needs the model's Jacobian). Also returns theta.
    pub fn ln_density_z(&self, z: &[f64], grad: Option<&mut [f64]>) -> Result<(f64, Vec<f64>)> {
        let d = self.dim();
        let mut theta = vec![0.0; d];
        self.prior.from_unconstrained(z, &mut theta);
        let mut x = vec![0.0; self.prior.input_names.len()];
        self.prior.expand(&theta, &mut x);
        let nv = self.likelihood.len();
        let mut c_p = vec![0.0; nv];
        match grad {
            None => {
                self.model.curve(&x, &mut c_p)?;
                let ll = if self.model.has_point_variance() {
                    let mut var_rel = vec![0.0; nv];
                    self.model.curve_variance(&x, &mut var_rel, None)?;
                    self.likelihood
                        .ln_likelihood_var(&c_p, &var_rel, None, None)
                } else {
                    self.likelihood.ln_likelihood(&c_p, None)
                };
                let lp = self.prior.ln_density_unconstrained(z, &theta, None, None);
                Ok((lp + ll, theta))
            }
            Some(g) => {
                let nx = x.len();
                let mut jac = vec![0.0; nv * nx];
                self.model.curve_jacobian(&x, &mut c_p, &mut jac)?;
                let mut dl_dc = vec![0.0; nv];
                let mut dl_dx = vec![0.0; nx];
                let ll = if self.model.has_point_variance() {
                    let mut var_rel = vec![0.0; nv];
                    let mut jac_var = vec![0.0; nv * nx];
                    self.model
                        .curve_variance(&x, &mut var_rel, Some(&mut jac_var))?;
                    let mut dl_dv = vec![0.0; nv];
                    let ll = self.likelihood.ln_likelihood_var(
                        &c_p,
                        &var_rel,
                        Some(&mut dl_dc),
                        Some(&mut dl_dv),
                    );
                    for k in 0..nv {
                        for j in 0..nx {
                            dl_dx[j] += dl_dv[k] * jac_var[k * nx + j];
                        }
                    }
                    ll
                } else {
                    self.likelihood.ln_likelihood(&c_p, Some(&mut dl_dc))
                };
                for k in 0..nv {
                    for j in 0..nx {
                        dl_dx[j] += dl_dc[k] * jac[k * nx + j];
                    }
                }
                let mut dl_dtheta = vec![0.0; d];
                self.prior.contract(&dl_dx, &mut dl_dtheta);
                let lp = self
                    .prior
                    .ln_density_unconstrained(z, &theta, Some(&dl_dtheta), Some(g));
                Ok((lp + ll, theta))
            }
        }
    }
}
