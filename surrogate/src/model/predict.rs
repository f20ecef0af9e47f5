//! One prediction of a C-V curve with everything a caller shows: c12, the ensemble's spread,
//! the per-point uncertainty and optionally the Jacobian (the `predict` command and the Python
//! binding make the same call).

use super::Surrogate;
use crate::Result;

/// A curve predicted by [`Surrogate::predict`], one entry per voltage.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// c12 (pF): the ensemble mean `c_p(U_k)`.
    pub c12_pf: Vec<f64>,
    /// The members' standard deviation of c12 (pF); zeros for one member.
    pub spread_pf: Vec<f64>,
    /// The surrogate's uncertainty (pF): `sigma_s(p, U_k) c_k` with a calibrated error model,
    /// `sigma_p c_k` without.
    pub sigma_pf: Vec<f64>,
    /// `dc_k / dp_j` (pF per parameter unit), one row per voltage, when asked for.
    pub jacobian_pf: Option<Vec<Vec<f64>>>,
}

impl Surrogate {
    /// c12 (pF) at `params` (physical units, network order) and `volts` (V), with the ensemble
    /// spread, the per-point uncertainty sigma_s(p, U) c12 and, when `jacobian`, dc12/dp.
    ///
    /// Only the domain guard applies (every input inside the training space); whether to
    /// refuse inputs where the training rows thin out is the caller's ([`Self::check_support`]).
    ///
    /// # Errors
    /// [`crate::Error::OutsideDomain`] or [`crate::Error::Argument`] from the domain guard.
    pub fn predict(&self, params: &[f64], volts: &[f64], jacobian: bool) -> Result<Prediction> {
        let u = self.voltages(volts)?;
        let n = volts.len();
        let mut c12_pf = vec![0.0; n];
        let mut spread_pf = vec![0.0; n];
        self.curve_into(params, &u, &mut c12_pf, Some(&mut spread_pf))?;
        let jacobian_pf = if jacobian {
            let np = self.n_params();
            let mut j = vec![0.0; n * np];
            let mut c = vec![0.0; n];
            self.curve_jacobian_into(params, &u, &mut c, &mut j)?;
            Some(j.chunks(np).map(<[f64]>::to_vec).collect())
        } else {
            None
        };
        let sigma_pf = self.curve_sigma_pf(params, &u, &c12_pf)?;
        Ok(Prediction {
            c12_pf,
            spread_pf,
            sigma_pf,
            jacobian_pf,
        })
    }
}
