//! The prediction path of a surrogate's calibrated per-point uncertainty sigma_s(p, U_B)
//! ([`ErrorModel`], issue 21): per row of a data set, along a curve with its derivatives, and
//! its fit on a calibration set.

use super::dataset::{DataInfo, DataSet};
use super::error_model::ErrorModel;
use super::surrogate::{Predictor, Surrogate, Voltages};
use super::transform::physical_to_z;
use crate::error::Result;

/// The name of the error model's extra input on a surrogate with the pinch-off gate: the gate's
/// proximity e(p, U_B) in [0, 1] ([`super::StepsHead::gate_proximity`]), so that sigma_s can grow
/// where the network switches regime (issue 59).
pub const GATE_INPUT: &str = "gate_proximity";

impl Surrogate {
    /// The calibrated per-point uncertainty, when the model file has one: inputs the space's
    /// dimensions (network order), and on a gated surrogate also the gate input (`GATE_INPUT`).
    pub fn error_model(&self) -> Option<&ErrorModel> {
        let d = self.dims.len();
        self.info.error_model.as_ref().filter(|m| {
            m.inputs.len() == d
                || (m.inputs.len() == d + 1 && m.inputs[d] == GATE_INPUT && self.has_gate())
        })
    }

    /// Whether every network of the surrogate has the pinch-off gate.
    pub fn has_gate(&self) -> bool {
        match &self.predictor {
            Predictor::Networks(nets) => !nets.is_empty() && nets.iter().all(|n| n.has_gate()),
            Predictor::Polynomial(_) => false,
        }
    }

    /// The members' mean gate proximity at z_p along z_U (and its de/dz_p, voltages x
    /// n_params); false without a gate.
    fn gate_feature(&self, zp: &[f64], zu: &[f64], e: &mut [f64], jac: Option<&mut [f64]>) -> bool {
        let Predictor::Networks(nets) = &self.predictor else {
            return false;
        };
        if !self.has_gate() {
            return false;
        }
        let m = nets.len() as f64;
        let np = self.n_params();
        let mut ek = vec![0.0; zu.len()];
        let mut jk = vec![0.0; if jac.is_some() { zu.len() * np } else { 0 }];
        e.fill(0.0);
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.fill(0.0);
        }
        for net in nets {
            let with_jac = jac.is_some().then_some(&mut jk[..]);
            net.gate_proximity(zp, zu, &mut ek, with_jac);
            for (a, b) in e.iter_mut().zip(&ek) {
                *a += b / m;
            }
            if let Some(j) = jac.as_deref_mut() {
                for (a, b) in j.iter_mut().zip(&jk) {
                    *a += b / m;
                }
            }
        }
        true
    }

    /// The error model's input row of data-set row i: its z (network order), and the gate's
    /// proximity there when the model has [`GATE_INPUT`].
    fn error_inputs(&self, set: &DataSet, i: usize, gated: bool) -> Vec<f64> {
        let mut z = set.z_row(i);
        if gated {
            let np = self.n_params();
            let mut e = [0.0];
            self.gate_feature(&z[..np], &z[np..np + 1], &mut e, None);
            z.push(e[0]);
        }
        z
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
    /// sigma_s(z) of the error model (with the gate's proximity on a gated surrogate), or the
    /// constant sigma_p without one.
    pub fn sigma_set(&self, set: &DataSet) -> Vec<f64> {
        match self.error_model() {
            Some(m) => {
                let gated = m.inputs.len() > self.dims.len();
                (0..set.len())
                    .map(|i| m.sigma(&self.error_inputs(set, i, gated), None))
                    .collect()
            }
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
        // On a gated surrogate the gate's proximity e_k is the last input, with de_k/dz_p.
        let gated = m.inputs.len() > self.dims.len();
        let nv = u.z.len();
        let mut e = vec![0.0; if gated { nv } else { 0 }];
        let mut je = vec![0.0; if gated && jac.is_some() { nv * np } else { 0 }];
        if gated {
            let want = jac.is_some().then_some(&mut je[..]);
            self.gate_feature(&z[..np], &u.z, &mut e, want);
            z.push(0.0);
        }
        let mut g = vec![0.0; z.len()];
        match jac {
            Some(jac) => {
                for (k, &zu) in u.z.iter().enumerate() {
                    z[np] = zu;
                    if gated {
                        z[np + 1] = e[k];
                    }
                    let s = m.sigma(&z, Some(&mut g));
                    var[k] = s * s;
                    for j in 0..np {
                        // d sigma^2/dz_j through z_j itself and through e_k(z_p).
                        let via_gate = if gated {
                            g[np + 1] * je[k * np + j]
                        } else {
                            0.0
                        };
                        jac[k * np + j] = (g[j] + via_gate) * dz[j];
                    }
                }
            }
            None => {
                for (k, &zu) in u.z.iter().enumerate() {
                    z[np] = zu;
                    if gated {
                        z[np + 1] = e[k];
                    }
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
        self.fit_error_model_with(set, true)
    }

    /// [`Surrogate::fit_error_model`], with the gate's proximity among the inputs only when
    /// `gate_input` (and the surrogate has the gate).
    ///
    /// # Errors
    /// As [`ErrorModel::fit`].
    pub fn fit_error_model_with(&self, set: &DataSet, gate_input: bool) -> Result<ErrorModel> {
        let pred = self.predict_set(set);
        let rel: Vec<f64> = pred
            .iter()
            .zip(&set.c12_pf)
            .map(|(p, t)| (p - t) / t)
            .collect();
        let gated = gate_input && self.has_gate();
        let z: Vec<f64> = (0..set.len())
            .flat_map(|i| self.error_inputs(set, i, gated))
            .collect();
        let mut names: Vec<String> = self.dims.iter().map(|d| d.name.clone()).collect();
        if gated {
            names.push(GATE_INPUT.to_string());
        }
        ErrorModel::fit(names, &z, &rel, DataInfo::of(set))
    }
}
