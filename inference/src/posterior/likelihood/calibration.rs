//! The run's calibration scale (issue 63: "the calibration scale the covariance lets float,
//! whose posterior is reported nowhere").
//!
//! A measured covariance V_m = u u^T + diag(d) is one scale shared by every point (u, `measure`'s
//! charge-calibration term) plus each point's own statistics (d). Written with a latent
//! a ~ N(0, 1), the residual r = c_m - c_p is a u + e, e ~ N(0, D) with D = diag(d + the
//! likelihood's model-side variance). Given c_p the posterior of a is normal,
//!   precision s = 1 + u^T D^-1 u,  mean a = u^T D^-1 r / s,
//! and the likelihood's chi^2 splits into the pulls left once that scale is taken out and the
//! scale's own term:
//!   r^T Sigma^-1 r = sum_k ((r_k - a u_k) / sqrt(D_k))^2 + a^2.
//! With u_k = f c_m,k (f the relative calibration uncertainty), c_m - a u = c_p reads
//! c_m = kappa c_p with kappa = 1 / (1 - a f): the data are kappa times the model
//! ([`CalibrationScale`]; its sd by the linearisation, f / sqrt(s) / (1 - a f)^2).

use serde::{Deserialize, Serialize};

use super::{Likelihood, ModelVar};

/// The calibration factor kappa (c_m = kappa c_p, up to the points' own errors) given a model
/// curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CalibrationScale {
    /// Posterior mean of kappa.
    pub factor: f64,
    /// Its posterior standard deviation.
    pub factor_sd: f64,
    /// Its prior standard deviation f: the measured covariance's shared term relative to c_m
    /// (the mean of u_k / c_m,k).
    pub prior_sd: f64,
}

/// The scale at one curve, with what the figures need.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleFit {
    /// kappa's posterior.
    pub scale: CalibrationScale,
    /// (r_k - a u_k) / sqrt(D_k): the residuals, the shared scale taken out, over each point's
    /// own standard deviation.
    pub pulls: Vec<f64>,
    /// a, the scale in units of its prior standard deviation (its chi^2 term is a^2).
    pub a: f64,
}

/// A model curve against the data's own errors: what a pulls panel shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OwnErrors {
    /// Each point's own standard deviation, pF: sqrt(d_k) of a measured covariance
    /// u u^T + diag(d) (the shared scale taken out), sqrt(V_kk) of any other covariance, the
    /// paper's f_m c_p without one.
    pub sigma_pf: Vec<f64>,
    /// Each point's whole standard deviation under the data's errors, pF: sqrt(V_kk) of a
    /// measured covariance (the shared scale included), the paper's f_m c_p without one.
    #[serde(default)]
    pub sigma_total_pf: Vec<f64>,
    /// (c_m - c_p - a u) / sigma per point (data minus model; a = 0 without the scale).
    pub pulls: Vec<f64>,
    /// The calibration scale, with a measured covariance u u^T + diag(d).
    pub calibration: Option<CalibrationScale>,
    /// The scale's own chi^2 term a^2 (0 without it): chi^2_data = sum pulls^2 + this, exactly
    /// for the paper's likelihood and a rank-one covariance.
    pub scale_chi2: f64,
}

impl Likelihood {
    /// `c_p` against the data's own errors ([`OwnErrors`]); the solver's eq. 7 terms and the
    /// model's sigma_p are left out, as in [`Likelihood::chi2_data`].
    pub fn own_errors(&self, c_p: &[f64]) -> OwnErrors {
        if let (Some(ro), Some(fit)) = (self.rank_one.as_ref(), self.calibration_data(c_p)) {
            return OwnErrors {
                sigma_pf: ro.d.iter().map(|d| d.sqrt()).collect(),
                sigma_total_pf: ro
                    .d
                    .iter()
                    .zip(&ro.u)
                    .map(|(d, u)| (d + u * u).sqrt())
                    .collect(),
                pulls: fit.pulls,
                calibration: Some(fit.scale),
                scale_chi2: fit.a * fit.a,
            };
        }
        let n = self.len();
        let sigma_pf: Vec<f64> = match &self.covariance {
            Some(vm) => (0..n).map(|k| vm[k * n + k].sqrt()).collect(),
            None => c_p.iter().map(|c| self.noise.measurement_rel * c).collect(),
        };
        let pulls = (0..n)
            .map(|k| (self.c_m[k] - c_p[k]) / sigma_pf[k])
            .collect();
        OwnErrors {
            sigma_total_pf: sigma_pf.clone(),
            sigma_pf,
            pulls,
            calibration: None,
            scale_chi2: 0.0,
        }
    }

    /// The calibration scale at `c_p` under the data's own errors alone (D = d: the solver's
    /// eq. 7 terms and the model's sigma_p left out, as [`Likelihood::chi2_data`]); None
    /// without a measured covariance of the form u u^T + diag(d).
    pub fn calibration_data(&self, c_p: &[f64]) -> Option<ScaleFit> {
        let ro = self.rank_one.as_ref()?;
        self.scale_fit(c_p, &ro.d)
    }

    /// The calibration scale at `c_p` under the likelihood the fit samples (D = d plus the
    /// model-side variance with sigma_p,k^2 = `var_rel`); None as for
    /// [`Likelihood::calibration_data`].
    pub fn calibration_var(&self, c_p: &[f64], var_rel: &[f64]) -> Option<ScaleFit> {
        let ro = self.rank_one.as_ref()?;
        let v = ModelVar::PerPoint(var_rel);
        let dd: Vec<f64> = (0..self.len())
            .map(|k| ro.d[k] + self.variance(c_p[k], v.at(k)))
            .collect();
        self.scale_fit(c_p, &dd)
    }

    fn scale_fit(&self, c_p: &[f64], dd: &[f64]) -> Option<ScaleFit> {
        let u = &self.rank_one.as_ref()?.u;
        if dd.iter().any(|&x| !(x > 0.0 && x.is_finite())) || c_p.len() != u.len() {
            return None;
        }
        let r: Vec<f64> = self.c_m.iter().zip(c_p).map(|(m, p)| m - p).collect();
        let s = 1.0 + (0..u.len()).map(|k| u[k] * u[k] / dd[k]).sum::<f64>();
        let a = (0..u.len()).map(|k| u[k] * r[k] / dd[k]).sum::<f64>() / s;
        let f = (0..u.len()).map(|k| u[k] / self.c_m[k]).sum::<f64>() / u.len() as f64;
        let pulls = (0..u.len())
            .map(|k| (r[k] - a * u[k]) / dd[k].sqrt())
            .collect();
        let shrink = 1.0 - a * f;
        Some(ScaleFit {
            scale: CalibrationScale {
                factor: 1.0 / shrink,
                factor_sd: f / s.sqrt() / (shrink * shrink),
                prior_sd: f,
            },
            pulls,
            a,
        })
    }
}

/// The posterior of kappa over posterior draws: the mixture of each draw's normal, by its mean
/// and the law of total variance; None without draws.
pub fn mixture(scales: &[CalibrationScale]) -> Option<CalibrationScale> {
    let n = scales.len() as f64;
    let first = scales.first()?;
    let mean = scales.iter().map(|s| s.factor).sum::<f64>() / n;
    let var = scales
        .iter()
        .map(|s| s.factor_sd.powi(2) + (s.factor - mean).powi(2))
        .sum::<f64>()
        / n;
    Some(CalibrationScale {
        factor: mean,
        factor_sd: var.sqrt(),
        prior_sd: first.prior_sd,
    })
}

#[cfg(test)]
mod tests {
    use crate::posterior::{Likelihood, NoiseKind, NoiseSettings};

    fn likelihood(c_m: &[f64], f: f64, d: f64) -> Likelihood {
        let n = c_m.len();
        let cov: Vec<Vec<f64>> = (0..n)
            .map(|j| {
                (0..n)
                    .map(|k| f * c_m[j] * f * c_m[k] + if j == k { d * d } else { 0.0 })
                    .collect()
            })
            .collect();
        let data = crate::CvData {
            voltage_v: (0..n).map(|k| 100.0 * (k + 1) as f64).collect(),
            c12_pf: c_m.to_vec(),
            sigma_pf: (0..n).map(|k| cov[k][k].sqrt()).collect(),
            covariance_pf2: Some(cov),
            source: "test".into(),
        };
        let noise = NoiseSettings {
            kind: NoiseKind::Covariance,
            ..NoiseSettings::default()
        };
        Likelihood::new(&data, noise, 0.0).unwrap()
    }

    #[test]
    fn a_curve_off_by_a_common_factor_is_the_scale_and_no_pull() {
        // The data are 1.03 times the model, the calibration's prior sd 3%, the points' own
        // errors 0.01 pF: the scale takes it all and leaves no pull.
        let c_p = [400.0, 300.0, 200.0, 120.0, 100.0];
        let c_m: Vec<f64> = c_p.iter().map(|c| 1.03 * c).collect();
        let l = likelihood(&c_m, 0.03, 0.01);
        let fit = l.calibration_data(&c_p).unwrap();
        // kappa = 1.03 up to the prior's pull towards 1 (tiny next to the points' precision).
        assert!((fit.scale.factor - 1.03).abs() < 1e-6, "{:?}", fit.scale);
        assert!(fit.pulls.iter().all(|p| p.abs() < 1e-3), "{:?}", fit.pulls);
        assert!((fit.scale.prior_sd - 0.03).abs() < 1e-12);
        // chi^2 = sum pulls^2 + a^2.
        let chi2 = fit.pulls.iter().map(|p| p * p).sum::<f64>() + fit.a * fit.a;
        assert!(
            (chi2 - l.chi2_data(&c_p)).abs() < 1e-9 * chi2.max(1.0),
            "{chi2}"
        );
    }

    #[test]
    fn own_errors_split_the_data_chi2() {
        let c_p = [410.0, 290.0, 205.0, 118.0, 101.0, 99.0];
        let c_m = [400.0, 300.0, 200.0, 120.0, 100.0, 100.5];
        let l = likelihood(&c_m, 0.03, 0.5);
        let own = l.own_errors(&c_p);
        let chi2 = own.pulls.iter().map(|p| p * p).sum::<f64>() + own.scale_chi2;
        assert!((chi2 - l.chi2_data(&c_p)).abs() < 1e-9 * chi2);
        assert!(
            own.sigma_pf.iter().all(|s| (s - 0.5).abs() < 1e-9),
            "{:?}",
            own.sigma_pf
        );
        // The paper's likelihood: 3% of c_p, no scale.
        let paper = Likelihood::new(
            &crate::CvData {
                covariance_pf2: None,
                ..crate::CvData {
                    voltage_v: (1..=6).map(|k| 100.0 * k as f64).collect(),
                    c12_pf: c_m.to_vec(),
                    sigma_pf: vec![1.0; 6],
                    covariance_pf2: None,
                    source: "test".into(),
                }
            },
            NoiseSettings::default(),
            0.0,
        )
        .unwrap();
        let own = paper.own_errors(&c_p);
        assert!(own.calibration.is_none());
        assert!((own.pulls[0] - (400.0 - 410.0) / (0.03 * 410.0)).abs() < 1e-12);
        let chi2: f64 = own.pulls.iter().map(|p| p * p).sum();
        assert!((chi2 - paper.chi2_data(&c_p)).abs() < 1e-9 * chi2);
    }

    #[test]
    fn the_split_of_chi2_holds_for_any_residual() {
        let c_p = [410.0, 290.0, 205.0, 118.0, 101.0, 99.0];
        let c_m = [400.0, 300.0, 200.0, 120.0, 100.0, 100.5];
        let l = likelihood(&c_m, 0.03, 0.5);
        let fit = l.calibration_data(&c_p).unwrap();
        let chi2 = fit.pulls.iter().map(|p| p * p).sum::<f64>() + fit.a * fit.a;
        assert!(
            (chi2 - l.chi2_data(&c_p)).abs() < 1e-9 * chi2,
            "{chi2} {}",
            l.chi2_data(&c_p)
        );
        let zero = vec![0.0; c_p.len()];
        let full = l.calibration_var(&c_p, &zero).unwrap();
        // The solver's terms widen D: the points pull less, the scale's sd grows.
        assert!(full.scale.factor_sd > fit.scale.factor_sd);
    }

    #[test]
    fn without_a_rank_one_covariance_there_is_no_scale() {
        let data = crate::CvData {
            voltage_v: vec![100.0, 200.0, 300.0],
            c12_pf: vec![3.0, 2.0, 1.0],
            sigma_pf: vec![0.1; 3],
            covariance_pf2: None,
            source: "test".into(),
        };
        let l = Likelihood::new(&data, NoiseSettings::default(), 0.0).unwrap();
        assert!(l.calibration_data(&[3.0, 2.0, 1.0]).is_none());
        assert!(super::mixture(&[]).is_none());
    }
}
