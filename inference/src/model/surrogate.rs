//! The trained surrogate as a [`CvModel`]. With a calibrated error model in its file
//! (`hpge-cv calibrate`, issue 21) its uncertainty is per point, sigma_s(p, U_k)
//! ([`CvModel::curve_variance`]); without one, or with [`SurrogateModel::constant_sigma`], the
//! constant sigma_p of the paper's eq. 13.

use hpge_surrogate::Surrogate;
use hpge_surrogate::model::Voltages;

use super::{CvModel, constant_variance};
use crate::{Error, Result};

/// A surrogate bound to the measured voltages (mapped once).
#[derive(Debug, Clone)]
pub struct SurrogateModel {
    /// The network (or polynomial) and its metadata.
    pub surrogate: Surrogate,
    voltages: Voltages,
    describe: String,
    constant: bool,
}

impl SurrogateModel {
    /// Binds `surrogate` to `volts` (V); each voltage must lie in its training range.
    pub fn new(surrogate: Surrogate, volts: &[f64], describe: impl Into<String>) -> Result<Self> {
        let voltages = surrogate.voltages(volts)?;
        Ok(Self {
            surrogate,
            voltages,
            describe: describe.into(),
            constant: false,
        })
    }

    /// Uses the constant sigma_p even where the model file has an error model (for comparison
    /// with the paper's likelihood).
    #[must_use]
    pub fn constant_sigma(mut self, constant: bool) -> Self {
        self.constant = constant;
        self
    }
}

impl CvModel for SurrogateModel {
    fn inputs(&self) -> Vec<String> {
        self.surrogate
            .parameter_names()
            .into_iter()
            .map(String::from)
            .collect()
    }

    fn domain(&self) -> Vec<[f64; 2]> {
        (0..self.surrogate.n_params())
            .map(|k| self.surrogate.range(k))
            .collect()
    }

    fn voltages(&self) -> &[f64] {
        &self.voltages.volts
    }

    fn sigma_rel(&self) -> f64 {
        self.surrogate.sigma_p()
    }

    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        self.surrogate
            .curve_into(x, &self.voltages, c_pf, None)
            .map_err(Error::from)
    }

    fn has_jacobian(&self) -> bool {
        true
    }

    fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.surrogate
            .curve_jacobian_into(x, &self.voltages, c_pf, jac)
            .map_err(Error::from)
    }

    fn describe(&self) -> String {
        self.describe.clone()
    }

    fn has_point_variance(&self) -> bool {
        !self.constant && self.surrogate.error_model().is_some()
    }

    fn curve_variance(
        &self,
        x: &[f64],
        var_rel: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> Result<()> {
        if !self.has_point_variance() {
            constant_variance(self.sigma_rel(), var_rel, jac);
            return Ok(());
        }
        self.surrogate
            .curve_variance_into(x, &self.voltages, var_rel, jac)
            .map_err(Error::from)
    }
}
