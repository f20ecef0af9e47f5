//! A prior bound to a model: supports, the unconstrained map, densities, draws.

use std::path::PathBuf;

use hpge_foundation::normal_cdf;
use rand::{Rng, RngExt};

use super::{PriorDistribution, PriorSpec};
use crate::{Error, Result};

/// Mass of an untruncated normal the domain may cut off (more needs `truncated-normal`).
const NORMAL_MASS_OUTSIDE: f64 = 1e-6;

/// One fit parameter, bound.
#[derive(Debug, Clone, PartialEq)]
pub struct PriorParameter {
    /// Name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// The distribution.
    pub distribution: PriorDistribution,
    /// Where the prior density is positive: [lo, hi].
    pub support: [f64; 2],
    /// Indices of the model inputs it sets.
    pub inputs: Vec<usize>,
}

/// A prior bound to a model's inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// Name (`b-z`, ...).
    pub name: String,
    /// The file.
    pub file: PathBuf,
    /// Fit parameters.
    pub parameters: Vec<PriorParameter>,
    /// Model input names.
    pub input_names: Vec<String>,
    /// Fixed inputs: (index, value).
    pub fixed: Vec<(usize, f64)>,
}

impl Prior {
    /// Binds `spec` to a model with inputs `names` valid on `domain`. Every input must be set by
    /// exactly one parameter or fixed; a parameter's domain is the intersection of its inputs'
    /// ranges, and its prior must live inside it: a uniform or truncation range reaching outside
    /// is an error naming the file, parameter and domain, as is a normal with more than 1e-6 of
    /// its mass outside.
    pub fn bind(spec: &PriorSpec, names: &[String], domain: &[[f64; 2]]) -> Result<Self> {
        let file = &spec.file;
        let mut owner: Vec<Option<String>> = vec![None; names.len()];
        let find = |input: &str, key: &str| {
            names.iter().position(|n| n == input).ok_or_else(|| {
                Error::invalid(
                    file,
                    key,
                    format!(
                        "the model has no input `{input}` (it has {})",
                        names.join(", ")
                    ),
                )
            })
        };
        let mut parameters = Vec::new();
        for p in &spec.parameters {
            let key = format!("parameters.{}", p.name);
            let mut idx = Vec::new();
            let mut dom = [f64::NEG_INFINITY, f64::INFINITY];
            for input in PriorSpec::inputs_of(p) {
                let k = find(&input, &key)?;
                if let Some(o) = &owner[k] {
                    return Err(Error::invalid(
                        file,
                        &key,
                        format!("input `{input}` is already set by `{o}`"),
                    ));
                }
                owner[k] = Some(p.name.clone());
                dom = [dom[0].max(domain[k][0]), dom[1].min(domain[k][1])];
                idx.push(k);
            }
            if dom[0].partial_cmp(&dom[1]) != Some(std::cmp::Ordering::Less) {
                return Err(Error::invalid(
                    file,
                    &key,
                    "its inputs' domains do not overlap",
                ));
            }
            let outside = |what: &str, a: f64, b: f64| {
                Error::invalid(
                    file,
                    &key,
                    format!(
                        "the prior {what} [{a}, {b}] reaches outside the model's domain [{}, {}] (where the model was trained)",
                        dom[0], dom[1]
                    ),
                )
            };
            let support = match p.prior {
                PriorDistribution::Uniform { lo, hi } => {
                    if lo < dom[0] || hi > dom[1] {
                        return Err(outside("range", lo, hi));
                    }
                    [lo, hi]
                }
                PriorDistribution::Normal { mean, sd } => {
                    let mass =
                        normal_cdf((dom[0] - mean) / sd) + 1.0 - normal_cdf((dom[1] - mean) / sd);
                    if mass > NORMAL_MASS_OUTSIDE {
                        return Err(Error::invalid(
                            file,
                            &key,
                            format!(
                                "normal({mean}, {sd}) puts {:.3}% of its mass outside the model's domain [{}, {}]; use distribution = \"truncated-normal\"",
                                100.0 * mass,
                                dom[0],
                                dom[1]
                            ),
                        ));
                    }
                    dom
                }
                PriorDistribution::TruncatedNormal { mean, sd, lo, hi } => {
                    let (a, b) = (lo.unwrap_or(dom[0]), hi.unwrap_or(dom[1]));
                    if a < dom[0] || b > dom[1] {
                        return Err(outside("truncation", a, b));
                    }
                    // A normal whose mass on [a, b] is nil has no density there: every draw
                    // from the prior would have zero posterior density (issue 66).
                    let x = PriorDistribution::TruncatedNormal { mean, sd, lo, hi };
                    if !x.ln_pdf(0.5 * (a + b), [a, b]).is_finite() {
                        return Err(Error::invalid(
                            file,
                            key.clone(),
                            format!(
                                "truncated-normal({mean}, {sd}) has no mass on [{a}, {b}] (the \
                                 mean is {:.0} sd away): no value there has a prior density",
                                ((mean - 0.5 * (a + b)).abs() - 0.5 * (b - a)) / sd
                            ),
                        ));
                    }
                    [a, b]
                }
            };
            parameters.push(PriorParameter {
                name: p.name.clone(),
                unit: p.unit.clone(),
                distribution: p.prior,
                support,
                inputs: idx,
            });
        }
        let mut fixed = Vec::new();
        for (input, &value) in &spec.fixed {
            let key = format!("fixed.{input}");
            let k = find(input, &key)?;
            if let Some(o) = &owner[k] {
                return Err(Error::invalid(
                    file,
                    &key,
                    format!("input `{input}` is also set by `{o}`"),
                ));
            }
            if !(value >= domain[k][0] && value <= domain[k][1]) {
                return Err(Error::invalid(
                    file,
                    &key,
                    format!(
                        "{value} is outside the model's domain [{}, {}]",
                        domain[k][0], domain[k][1]
                    ),
                ));
            }
            owner[k] = Some("fixed".into());
            fixed.push((k, value));
        }
        if let Some(k) = owner.iter().position(Option::is_none) {
            return Err(Error::invalid(
                file,
                "parameters",
                format!(
                    "model input `{}` is set by no parameter and not fixed",
                    names[k]
                ),
            ));
        }
        Ok(Self {
            name: spec.name.clone(),
            file: file.clone(),
            parameters,
            input_names: names.to_vec(),
            fixed,
        })
    }

    /// Number of fit parameters.
    pub fn dim(&self) -> usize {
        self.parameters.len()
    }

    /// Parameter names.
    pub fn names(&self) -> Vec<String> {
        self.parameters.iter().map(|p| p.name.clone()).collect()
    }

    /// The model inputs x for fit parameters theta (tied inputs share a value; fixed ones keep
    /// theirs).
    pub fn expand(&self, theta: &[f64], x: &mut [f64]) {
        for (p, &t) in self.parameters.iter().zip(theta) {
            for &k in &p.inputs {
                x[k] = t;
            }
        }
        for &(k, v) in &self.fixed {
            x[k] = v;
        }
    }

    /// dL/dtheta from dL/dx: the sum over each parameter's inputs.
    pub fn contract(&self, dx: &[f64], dtheta: &mut [f64]) {
        for (p, g) in self.parameters.iter().zip(dtheta.iter_mut()) {
            *g = p.inputs.iter().map(|&k| dx[k]).sum();
        }
    }

    /// ln pi(theta) = sum_j ln p_j(theta_j) (-inf outside the support).
    pub fn ln_density(&self, theta: &[f64]) -> f64 {
        self.parameters
            .iter()
            .zip(theta)
            .map(|(p, &t)| p.distribution.ln_pdf(t, p.support))
            .sum()
    }

    /// theta_j = a + (b - a) s(z_j), s the logistic function: the samplers' unconstrained map.
    pub fn from_unconstrained(&self, z: &[f64], theta: &mut [f64]) {
        for ((p, &zj), t) in self.parameters.iter().zip(z).zip(theta.iter_mut()) {
            let [a, b] = p.support;
            *t = (a + (b - a) * logistic(zj)).clamp(a, b);
        }
    }

    /// z_j = ln((theta_j - a) / (b - theta_j)).
    pub fn to_unconstrained(&self, theta: &[f64], z: &mut [f64]) {
        for ((p, &t), zj) in self.parameters.iter().zip(theta).zip(z.iter_mut()) {
            let [a, b] = p.support;
            *zj = ((t - a) / (b - t)).ln();
        }
    }

    /// ln pi(theta(z)) + ln |dtheta/dz| and its gradient in z, with
    /// ln |dtheta_j/dz_j| = ln(b - a) + ln s(z) + ln(1 - s(z)); `dlike_dtheta` (the
    /// likelihood's gradient in theta) is chained through dtheta/dz and added to `grad_z`.
    pub fn ln_density_unconstrained(
        &self,
        z: &[f64],
        theta: &[f64],
        dlike_dtheta: Option<&[f64]>,
        grad_z: Option<&mut [f64]>,
    ) -> f64 {
        let mut lp = 0.0;
        let mut g = grad_z;
        for (j, p) in self.parameters.iter().enumerate() {
            let [a, b] = p.support;
            let s = logistic(z[j]);
            let ln_s = -softplus(-z[j]);
            let ln_1s = -softplus(z[j]);
            lp += p.distribution.ln_pdf(theta[j], p.support) + (b - a).ln() + ln_s + ln_1s;
            if let Some(g) = g.as_deref_mut() {
                let dtheta_dz = (b - a) * s * (1.0 - s);
                let dl = dlike_dtheta.map_or(0.0, |d| d[j]);
                g[j] = (p.distribution.d_ln_pdf(theta[j]) + dl) * dtheta_dz + (1.0 - 2.0 * s);
            }
        }
        lp
    }

    /// A draw from the prior (inverse CDF per parameter).
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> Vec<f64> {
        self.parameters
            .iter()
            .map(|p| {
                let u: f64 = rng.random::<f64>().clamp(1e-12, 1.0 - 1e-12);
                p.distribution.quantile(u, p.support)
            })
            .collect()
    }
}

/// s(z) = 1 / (1 + e^-z).
fn logistic(z: f64) -> f64 {
    if z >= 0.0 {
        1.0 / (1.0 + (-z).exp())
    } else {
        let e = z.exp();
        e / (1.0 + e)
    }
}

/// ln(1 + e^x), without overflow.
fn softplus(x: f64) -> f64 {
    if x > 30.0 { x } else { x.exp().ln_1p() }
}
