//! The prediction path of a surrogate's calibrated per-point uncertainty sigma_s(p, U_B)
//! ([`ErrorModel`], issue 21): per row of a data set, along a curve with its derivatives, and
//! its fit on a calibration set.

use super::dataset::{DataInfo, DataSet};
use super::error_model::ErrorModel;
use super::surrogate::{Surrogate, Voltages};
use super::transform::physical_to_z;
use crate::error::Result;

impl Surrogate {
    /// The calibrated per-point uncertainty, when the model file has one.
    pub fn error_model(&self) -> Option<&ErrorModel> {
        self.info
            .error_model
            .as_ref()
            .filter(|m| m.inputs.len() == self.dims.len())
    }

    /// `per-point` (a calibrated error model: sigma_s(p, U_B)) or `constant` (sigma_p), as
    /// `evaluate --json` and `predict --json` name it.
    pub fn sigma_kind(&self) -> &'static str {
        if self.error_model().is_some() {
            "per-point"
        } else {
            "constant"
        }
    }

    /// The relative uncertainty of every row of a data set (read with this model's space):
    /// sigma_s(z) of the error model, or the constant sigma_p without one.
    pub fn sigma_set(&self, set: &DataSet) -> Vec<f64> {
        match self.error_model() {
            Some(m) => (0..set.len())
                .map(|i| m.sigma(&set.z_row(i), None))
                .collect(),
            None => vec![self.sigma_p(); set.len()],
        }
    }

    /// The squared relative uncertainty sigma_s(p, U_k)^2 of every point of a curve, and with
    /// `jac` d sigma_s^2/dp_j (row-major, voltages x n_params; chain rule through dz/dp of the
    /// input map). Without an error model: sigma_p^2 with zero derivatives.
    ///
    /// # Errors
    /// As [`Surrogate::curve_into`] (the domain guard).
    pub fn curve_variance_into(
        &self,
        params: &[f64],
        u: &Voltages,
        var: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> Result<()> {
        self.check_params(params)?;
        let Some(m) = self.error_model() else {
            var.fill(self.sigma_p().powi(2));
            if let Some(j) = jac {
                j.fill(0.0);
            }
            return Ok(());
        };
        let np = self.n_params();
        let mut z = Vec::with_capacity(np + 1);
        let mut dz = Vec::with_capacity(np);
        for (&x, d) in params.iter().zip(&self.dims) {
            let (zj, dzj) = physical_to_z(d, x);
            z.push(zj);
            dz.push(dzj);
        }
        z.push(0.0);
        let mut g = vec![0.0; np];
        match jac {
            Some(jac) => {
                for (k, &zu) in u.z.iter().enumerate() {
                    z[np] = zu;
                    let s = m.sigma(&z, Some(&mut g));
                    var[k] = s * s;
                    for j in 0..np {
                        jac[k * np + j] = g[j] * dz[j];
                    }
                }
            }
            None => {
                for (k, &zu) in u.z.iter().enumerate() {
                    z[np] = zu;
                    var[k] = m.sigma(&z, None).powi(2);
                }
            }
        }
        Ok(())
    }

    /// The absolute uncertainty (pF) of each point of a curve `c_pf` at `params`:
    /// sigma_s(p, U_k) c_k, or sigma_p c_k without an error model.
    ///
    /// # Errors
    /// As [`Surrogate::curve_into`] (the domain guard).
    pub fn curve_sigma_pf(&self, params: &[f64], u: &Voltages, c_pf: &[f64]) -> Result<Vec<f64>> {
        let mut var = vec![0.0; c_pf.len()];
        self.curve_variance_into(params, u, &mut var, None)?;
        Ok(var.iter().zip(c_pf).map(|(v, c)| v.sqrt() * c).collect())
    }

    /// Fits and calibrates an error model on a data set of this model's space (its rows with
    /// c12) and returns it; the model itself is unchanged (set `info.error_model` to keep it).
    ///
    /// # Errors
    /// As [`ErrorModel::fit`].
    pub fn fit_error_model(&self, set: &DataSet) -> Result<ErrorModel> {
        let pred = self.predict_set(set);
        let rel: Vec<f64> = pred
            .iter()
            .zip(&set.c12_pf)
            .map(|(p, t)| (p - t) / t)
            .collect();
        let z: Vec<f64> = (0..set.len()).flat_map(|i| set.z_row(i)).collect();
        let names = self.dims.iter().map(|d| d.name.clone()).collect();
        ErrorModel::fit(names, &z, &rel, DataInfo::of(set))
    }
}
