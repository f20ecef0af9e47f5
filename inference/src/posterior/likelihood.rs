//! The likelihood of a measured curve c_m given a predicted one c_p.
//!
//! Paper (section 8, eqs. 12-15): independent normals with a standard deviation that depends on
//! the prediction,
//!   sigma_c(c_p)^2 = (f_m c_p)^2 + (f_s c_p + a_s)^2 + (sigma_p c_p)^2,
//! f_m = 3% (measurement), f_s = 1% and a_s = 1 pF (the field solver, eq. 7), sigma_p the
//! surrogate's relative error (from the model file), and
//!   ln L = sum_k [ -(c_m,k - c_p,k)^2 / (2 sigma_k^2) - ln sigma_k - ln sqrt(2 pi) ].
//! sigma depends on the parameters, so the ln sigma term stays.
//!
//! Covariance variant: the measured covariance V_m (with its correlated calibration scale)
//! replaces the diagonal 3% term,
//!   Sigma(c_p) = V_m + diag((f_s c_p + a_s)^2 + (sigma_p c_p)^2),
//!   ln L = -r^T Sigma^-1 r / 2 - ln det Sigma / 2 - N ln sqrt(2 pi),  r = c_m - c_p.
//! A measured covariance is one calibration scale shared by every point plus each point's
//! statistics, V_m = u u^T + diag(d) (`measure`'s, exactly); then Sigma = D + u u^T with D
//! diagonal, and Sherman-Morrison gives, with w = D^-1 u and s = 1 + u^T w,
//!   Sigma^-1 r = D^-1 r - w (w^T r) / s,  ln det Sigma = sum_k ln D_k + ln s,
//!   (Sigma^-1)_kk = 1 / D_k - w_k^2 / s,
//! in O(N) instead of a Cholesky factorisation's O(N^3) per evaluation ([`RankOne`]; any other
//! covariance takes the Cholesky path). Both give the same numbers (unit tests).
//!
//! `auto` ([`NoiseKind::Auto`]): the covariance variant where the curve comes with its covariance,
//! else the paper's; [`Likelihood::new`] resolves it, so a likelihood's kind is never `auto`.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::numerics::Cholesky;
use crate::{CvData, Error, Result};

mod calibration;
pub use calibration::{CalibrationScale, OwnErrors, ScaleFit, mixture as calibration_mixture};

const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// Which noise model (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseKind {
    /// The paper's: independent, 3% of c_p for the measurement.
    #[default]
    Paper,
    /// The measured covariance instead of the 3% term.
    Covariance,
    /// `covariance` where the curve has a covariance file, else `paper` (resolved when the data
    /// are bound: [`Likelihood::new`]).
    Auto,
}

impl NoiseKind {
    /// Parses `paper`, `covariance` or `auto`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "paper" => Some(NoiseKind::Paper),
            "covariance" => Some(NoiseKind::Covariance),
            "auto" => Some(NoiseKind::Auto),
            _ => None,
        }
    }

    /// The name.
    pub fn as_str(&self) -> &'static str {
        match self {
            NoiseKind::Paper => "paper",
            NoiseKind::Covariance => "covariance",
            NoiseKind::Auto => "auto",
        }
    }
}

/// The noise model's constants (defaults: the paper's, section 8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSettings {
    /// Which model.
    pub kind: NoiseKind,
    /// f_m: relative measurement uncertainty (paper eq. 14: 3%).
    pub measurement_rel: f64,
    /// f_s: relative field-solver uncertainty (paper eq. 7: 1%).
    pub solver_rel: f64,
    /// a_s: absolute field-solver uncertainty, pF (paper eq. 7: 1 pF).
    pub solver_abs_pf: f64,
    /// Use the surrogate's constant sigma_p (the paper's eq. 13) even where its model file has a
    /// calibrated per-point sigma_s(p, U_B) (`--constant-sigma`; default false).
    #[serde(default)]
    pub constant_sigma: bool,
}

impl Default for NoiseSettings {
    fn default() -> Self {
        Self {
            kind: NoiseKind::Paper,
            measurement_rel: 0.03,
            solver_rel: 0.01,
            solver_abs_pf: 1.0,
            constant_sigma: false,
        }
    }
}

/// The model's squared relative uncertainty sigma_p^2: one constant, or one per point.
#[derive(Clone, Copy)]
enum ModelVar<'a> {
    Constant(f64),
    PerPoint(&'a [f64]),
}

impl ModelVar<'_> {
    fn at(self, k: usize) -> f64 {
        match self {
            ModelVar::Constant(v) => v,
            ModelVar::PerPoint(v) => v[k],
        }
    }
}

/// The likelihood of one measured curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Likelihood {
    /// Measured c12, pF.
    pub c_m: Vec<f64>,
    /// Constants.
    pub noise: NoiseSettings,
    /// The model's relative uncertainty sigma_p.
    pub sigma_rel_model: f64,
    /// V_m (row-major), for the covariance variant.
    covariance: Option<Vec<f64>>,
    /// V_m as u u^T + diag(d) where it has that form (the fast path).
    rank_one: Option<RankOne>,
}

/// A covariance u u^T + diag(d): one fully correlated scale plus independent parts.
#[derive(Debug, Clone, PartialEq)]
struct RankOne {
    u: Vec<f64>,
    d: Vec<f64>,
}

impl RankOne {
    /// u and d of `v` (N x N, row-major) when every off-diagonal element is u_j u_k to 1e-12
    /// of sqrt(V_jj V_kk) and d = diag(V) - u^2 >= 0; None otherwise (or for N < 3, where
    /// u is not determined by the off-diagonal elements).
    fn detect(v: &[f64], n: usize) -> Option<Self> {
        if n < 3 {
            return None;
        }
        let at = |j: usize, k: usize| v[j * n + k];
        let u = (0..n)
            .map(|k| {
                let (j, l) = ((k + 1) % n, (k + 2) % n);
                let u2 = at(k, j) * at(k, l) / at(j, l);
                // Signs relative to u_0 > 0.
                let sign = if k == 0 { 1.0 } else { at(k, 0).signum() };
                (u2.is_finite() && u2 > 0.0).then(|| sign * u2.sqrt())
            })
            .collect::<Option<Vec<f64>>>()?;
        let tol = 1e-12;
        for j in 0..n {
            for k in 0..n {
                if j != k && (at(j, k) - u[j] * u[k]).abs() > tol * (at(j, j) * at(k, k)).sqrt() {
                    return None;
                }
            }
        }
        let d: Vec<f64> = (0..n).map(|k| (at(k, k) - u[k] * u[k]).max(0.0)).collect();
        if (0..n).any(|k| at(k, k) - u[k] * u[k] < -tol * at(k, k)) {
            return None;
        }
        Some(Self { u, d })
    }

    /// (Sigma^-1 r, ln det Sigma, diag Sigma^-1) for Sigma = diag(d + extra) + u u^T, or None
    /// where a diagonal element is not positive.
    fn solve(&self, extra: impl Fn(usize) -> f64, r: &[f64]) -> Option<(Vec<f64>, f64, Vec<f64>)> {
        let n = self.u.len();
        let dd: Vec<f64> = (0..n).map(|k| self.d[k] + extra(k)).collect();
        if dd.iter().any(|&x| !(x > 0.0 && x.is_finite())) {
            return None;
        }
        let w: Vec<f64> = (0..n).map(|k| self.u[k] / dd[k]).collect();
        let s = 1.0 + self.u.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>();
        let wr: f64 = w.iter().zip(r).map(|(a, b)| a * b).sum();
        let alpha = (0..n).map(|k| r[k] / dd[k] - w[k] * wr / s).collect();
        let ln_det = dd.iter().map(|x| x.ln()).sum::<f64>() + s.ln();
        let inv_diag = (0..n).map(|k| 1.0 / dd[k] - w[k] * w[k] / s).collect();
        Some((alpha, ln_det, inv_diag))
    }
}

impl Likelihood {
    /// The likelihood of `data` under `noise`, with the model's sigma_p. The covariance variant
    /// needs the data's covariance; `auto` becomes `covariance` where the data have one, else
    /// `paper`.
    pub fn new(data: &CvData, noise: NoiseSettings, sigma_rel_model: f64) -> Result<Self> {
        let mut noise = noise;
        if noise.kind == NoiseKind::Auto {
            noise.kind = if data.covariance_pf2.is_some() {
                NoiseKind::Covariance
            } else {
                NoiseKind::Paper
            };
        }
        let covariance = match noise.kind {
            NoiseKind::Paper | NoiseKind::Auto => None,
            NoiseKind::Covariance => {
                let cov = data.covariance_pf2.as_ref().ok_or_else(|| {
                    Error::invalid(
                        &data.source,
                        "covariance",
                        "the covariance likelihood needs the curve's covariance file (<stem>.covariance.csv)",
                    )
                })?;
                Some(cov.iter().flatten().copied().collect::<Vec<f64>>())
            }
        };
        let n = data.c12_pf.len();
        let rank_one = covariance
            .as_deref()
            .and_then(|v: &[f64]| RankOne::detect(v, n));
        Ok(Self {
            c_m: data.c12_pf.clone(),
            noise,
            sigma_rel_model,
            covariance,
            rank_one,
        })
    }

    /// Whether Sigma takes the rank-one fast path; [`Likelihood::dense`] is a copy that
    /// factorises Sigma by Cholesky even where the fast path applies (tests compare the two).
    #[cfg(test)]
    pub(crate) fn has_rank_one(&self) -> bool {
        self.rank_one.is_some()
    }

    /// See [`Likelihood::has_rank_one`].
    #[cfg(test)]
    pub(crate) fn dense(&self) -> Self {
        Self {
            rank_one: None,
            ..self.clone()
        }
    }

    /// (Sigma^-1 r, ln det Sigma, diag Sigma^-1 when `want_diag`) of the covariance variant,
    /// by the rank-one fast path where V_m has that form, else by Cholesky; None where Sigma is
    /// not positive definite.
    fn solve_sigma(
        &self,
        vm: &[f64],
        c_p: &[f64],
        v: ModelVar,
        r: &[f64],
        want_diag: bool,
    ) -> Option<(Vec<f64>, f64, Vec<f64>)> {
        if let Some(ro) = &self.rank_one {
            return ro.solve(|k| self.variance(c_p[k], v.at(k)), r);
        }
        let chol = Cholesky::new(&self.covariance_at(vm, c_p, v), self.len())?;
        let inv_diag = if want_diag {
            chol.inverse_diagonal()
        } else {
            Vec::new()
        };
        Some((chol.solve(r), chol.ln_det(), inv_diag))
    }

    /// The number of points N.
    pub fn len(&self) -> usize {
        self.c_m.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.c_m.is_empty()
    }

    /// The model-side variance at c_p (pF^2): (f_s c + a_s)^2 + (sigma_p c)^2, plus (f_m c)^2
    /// for the paper's model; `s2` is sigma_p^2 (the model's squared relative uncertainty).
    fn variance(&self, c: f64, s2: f64) -> f64 {
        let n = &self.noise;
        let s = n.solver_rel * c + n.solver_abs_pf;
        // The 3% term unless the measured covariance replaces it.
        let m = if self.covariance.is_none() {
            n.measurement_rel * c
        } else {
            0.0
        };
        s * s + s2 * c * c + m * m
    }

    /// d variance / dc at sigma_p^2 = `s2`.
    fn d_variance(&self, c: f64, s2: f64) -> f64 {
        let n = &self.noise;
        let s = n.solver_rel * c + n.solver_abs_pf;
        let mut d = 2.0 * s * n.solver_rel + 2.0 * s2 * c;
        if self.covariance.is_none() {
            d += 2.0 * n.measurement_rel.powi(2) * c;
        }
        d
    }

    /// Sigma(c_p) = V_m + diag(model-side variance) (row-major), for the covariance variant.
    fn covariance_at(&self, vm: &[f64], c_p: &[f64], v: ModelVar) -> Vec<f64> {
        let n = self.len();
        let mut a = vm.to_vec();
        for k in 0..n {
            a[k * n + k] += self.variance(c_p[k], v.at(k));
        }
        a
    }

    /// The standard deviation of each point (pF) at c_p: sqrt of the diagonal of Sigma.
    pub fn sigma(&self, c_p: &[f64]) -> Vec<f64> {
        self.sigma_with(c_p, self.constant())
    }

    /// [`Likelihood::sigma`] with the model's own sigma_p,k^2 at each point (`var_rel`, a model
    /// whose uncertainty varies: `CvModel::curve_variance`) in place of the constant.
    pub fn sigma_var(&self, c_p: &[f64], var_rel: &[f64]) -> Vec<f64> {
        self.sigma_with(c_p, ModelVar::PerPoint(var_rel))
    }

    fn sigma_with(&self, c_p: &[f64], v: ModelVar) -> Vec<f64> {
        let n = self.len();
        c_p.iter()
            .enumerate()
            .map(|(k, &c)| {
                let m = self.covariance.as_ref().map_or(0.0, |m| m[k * n + k]);
                (self.variance(c, v.at(k)) + m).sqrt()
            })
            .collect()
    }

    /// The model's constant sigma_p^2.
    fn constant(&self) -> ModelVar<'static> {
        ModelVar::Constant(self.sigma_rel_model * self.sigma_rel_model)
    }

    /// ln L(c_p) (see the module docs); with `grad`, also d ln L / d c_p.
    pub fn ln_likelihood(&self, c_p: &[f64], grad: Option<&mut [f64]>) -> f64 {
        self.ln_likelihood_with(c_p, self.constant(), grad, None)
    }

    /// ln L(c_p) with the model's sigma_p,k^2 at each point (`var_rel`) in place of the
    /// constant; with `grad_c`, d ln L / d c_p, with `grad_var`, d ln L / d sigma_p,k^2.
    pub fn ln_likelihood_var(
        &self,
        c_p: &[f64],
        var_rel: &[f64],
        grad_c: Option<&mut [f64]>,
        grad_var: Option<&mut [f64]>,
    ) -> f64 {
        self.ln_likelihood_with(c_p, ModelVar::PerPoint(var_rel), grad_c, grad_var)
    }

    fn ln_likelihood_with(
        &self,
        c_p: &[f64],
        v: ModelVar,
        grad_c: Option<&mut [f64]>,
        grad_var: Option<&mut [f64]>,
    ) -> f64 {
        let n = self.len();
        let mut gc = grad_c;
        let mut gv = grad_var;
        match &self.covariance {
            None => {
                let mut ll = 0.0;
                for k in 0..n {
                    let var = self.variance(c_p[k], v.at(k));
                    let r = self.c_m[k] - c_p[k];
                    ll -= 0.5 * r * r / var + 0.5 * var.ln() + LN_SQRT_2PI;
                    // d/dvar of -r^2/(2v) - ln v / 2.
                    let dl_dv = 0.5 * (r * r / var - 1.0) / var;
                    if let Some(g) = gc.as_deref_mut() {
                        // d/dc, with dr/dc = -1.
                        g[k] = r / var + dl_dv * self.d_variance(c_p[k], v.at(k));
                    }
                    if let Some(g) = gv.as_deref_mut() {
                        g[k] = dl_dv * c_p[k] * c_p[k];
                    }
                }
                ll
            }
            Some(vm) => {
                let r: Vec<f64> = (0..n).map(|k| self.c_m[k] - c_p[k]).collect();
                let grads = gc.is_some() || gv.is_some();
                let Some((alpha, ln_det, inv_diag)) = self.solve_sigma(vm, c_p, v, &r, grads)
                else {
                    return f64::NEG_INFINITY;
                };
                let quad: f64 = r.iter().zip(&alpha).map(|(x, y)| x * y).sum();
                if grads {
                    for k in 0..n {
                        let dl_dv = 0.5 * (alpha[k] * alpha[k] - inv_diag[k]);
                        if let Some(g) = gc.as_deref_mut() {
                            g[k] = alpha[k] + dl_dv * self.d_variance(c_p[k], v.at(k));
                        }
                        if let Some(g) = gv.as_deref_mut() {
                            g[k] = dl_dv * c_p[k] * c_p[k];
                        }
                    }
                }
                -0.5 * quad - 0.5 * ln_det - n as f64 * LN_SQRT_2PI
            }
        }
    }

    /// chi^2 = r^T Sigma(c_p)^-1 r with r = c_m - c_p (the sum of squared pulls for the paper's
    /// independent model).
    pub fn chi2(&self, c_p: &[f64]) -> f64 {
        self.chi2_with(c_p, self.constant())
    }

    /// [`Likelihood::chi2`] with the model's sigma_p,k^2 at each point (`var_rel`).
    pub fn chi2_var(&self, c_p: &[f64], var_rel: &[f64]) -> f64 {
        self.chi2_with(c_p, ModelVar::PerPoint(var_rel))
    }

    /// chi^2 of `c_p` under the data's own errors alone, what the measurement says of a model
    /// curve: r^T V_m^-1 r with the measured covariance V_m (the covariance variant), else
    /// sum_k (r_k / (f_m c_p,k))^2 with the paper's 3% term; the solver's eq. 7 terms and the
    /// model's sigma_p are left out. r = c_m - c_p.
    pub fn chi2_data(&self, c_p: &[f64]) -> f64 {
        let mut data_only = self.clone();
        data_only.noise.solver_rel = 0.0;
        data_only.noise.solver_abs_pf = 0.0;
        data_only.chi2_with(c_p, ModelVar::Constant(0.0))
    }

    fn chi2_with(&self, c_p: &[f64], v: ModelVar) -> f64 {
        let n = self.len();
        match &self.covariance {
            None => (0..n)
                .map(|k| (self.c_m[k] - c_p[k]).powi(2) / self.variance(c_p[k], v.at(k)))
                .sum(),
            Some(vm) => {
                let r: Vec<f64> = (0..n).map(|k| self.c_m[k] - c_p[k]).collect();
                let Some((alpha, _, _)) = self.solve_sigma(vm, c_p, v, &r, false) else {
                    return f64::INFINITY;
                };
                r.iter().zip(&alpha).map(|(x, y)| x * y).sum()
            }
        }
    }

    /// Pulls (c_p - c_m) / sigma per point, sigma the square root of Sigma's diagonal.
    pub fn pulls(&self, c_p: &[f64]) -> Vec<f64> {
        self.pulls_with(c_p, self.constant())
    }

    /// [`Likelihood::pulls`] with the model's sigma_p,k^2 at each point (`var_rel`).
    pub fn pulls_var(&self, c_p: &[f64], var_rel: &[f64]) -> Vec<f64> {
        self.pulls_with(c_p, ModelVar::PerPoint(var_rel))
    }

    fn pulls_with(&self, c_p: &[f64], v: ModelVar) -> Vec<f64> {
        let s = self.sigma_with(c_p, v);
        (0..self.len())
            .map(|k| (c_p[k] - self.c_m[k]) / s[k])
            .collect()
    }

    /// A copy for another model's relative uncertainty (the exact solver: 0).
    pub fn with_sigma_rel(&self, sigma_rel_model: f64) -> Self {
        Self {
            sigma_rel_model,
            ..self.clone()
        }
    }

    /// A simulated measurement: c_p plus noise from this noise model (N(0, Sigma(c_p))).
    pub fn simulate<R: Rng + ?Sized>(&self, c_p: &[f64], rng: &mut R) -> Vec<f64> {
        self.simulate_with(c_p, self.constant(), rng)
    }

    /// A simulated measurement whose model term has a squared relative uncertainty per point,
    /// `var_rel` (a calibrated surrogate's sigma_s(p, U_k)^2).
    pub fn simulate_var<R: Rng + ?Sized>(
        &self,
        c_p: &[f64],
        var_rel: &[f64],
        rng: &mut R,
    ) -> Vec<f64> {
        self.simulate_with(c_p, ModelVar::PerPoint(var_rel), rng)
    }

    fn simulate_with<R: Rng + ?Sized>(&self, c_p: &[f64], v: ModelVar, rng: &mut R) -> Vec<f64> {
        let n = self.len();
        let z: Vec<f64> = (0..n).map(|_| StandardNormal.sample(rng)).collect();
        match &self.covariance {
            None => c_p
                .iter()
                .zip(&z)
                .enumerate()
                .map(|(k, (&c, &e))| c + self.variance(c, v.at(k)).sqrt() * e)
                .collect(),
            Some(vm) => {
                let a = self.covariance_at(vm, c_p, v);
                let chol = Cholesky::new(&a, n).expect("a covariance plus a positive diagonal");
                let e = chol.mul_lower(&z);
                c_p.iter().zip(e).map(|(&c, e)| c + e).collect()
            }
        }
    }

    /// A copy with other measured values (simulated data for coverage studies).
    pub fn with_data(&self, c_m: Vec<f64>) -> Self {
        Self {
            c_m,
            ..self.clone()
        }
    }
}
