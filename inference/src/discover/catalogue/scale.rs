//! A multiplicative calibration scale: the circuit's constants (pulser voltage, resistors, the
//! charge calibration) off by a common factor, c = s c12.

use std::sync::Arc;

use super::{Baseline, Candidate, Extension, one_more};
use crate::Result;
use crate::model::CvModel;
use crate::prior::PriorDistribution;

/// Domain of s.
pub const SCALE_RANGE: [f64; 2] = [0.5, 2.0];
/// Prior sd of s: the circuit constants' combined 6% (3% on each of Q, R_PG, R1, R2, U_PG, the
/// shipped measurement's uncertainty budget), doubled to be generous.
pub const SCALE_PRIOR_SD: f64 = 0.12;

/// `inner` times a factor: c_k(x, s) = s c_inner,k(x).
pub struct Scaled {
    inner: Arc<dyn CvModel>,
    name: String,
    range: [f64; 2],
}

impl Scaled {
    /// `inner` with one more input `name` (dimensionless) valid on `range`.
    pub fn new(inner: Arc<dyn CvModel>, name: &str, range: [f64; 2]) -> Self {
        Self {
            inner,
            name: name.into(),
            range,
        }
    }
}

impl CvModel for Scaled {
    fn inputs(&self) -> Vec<String> {
        let mut v = self.inner.inputs();
        v.push(self.name.clone());
        v
    }

    fn domain(&self) -> Vec<[f64; 2]> {
        let mut v = self.inner.domain();
        v.push(self.range);
        v
    }

    fn voltages(&self) -> &[f64] {
        self.inner.voltages()
    }

    fn sigma_rel(&self) -> f64 {
        self.inner.sigma_rel()
    }

    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        let n = x.len() - 1;
        self.inner.curve(&x[..n], c_pf)?;
        c_pf.iter_mut().for_each(|c| *c *= x[n]);
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        self.inner.has_jacobian()
    }

    /// dc_k/dx_j = s dc_inner,k/dx_j; dc_k/ds = c_inner,k.
    fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], jac: &mut [f64]) -> Result<()> {
        let n = x.len() - 1;
        let s = x[n];
        let nv = c_pf.len();
        let mut inner = vec![0.0; nv * n];
        self.inner.curve_jacobian(&x[..n], c_pf, &mut inner)?;
        for k in 0..nv {
            for j in 0..n {
                jac[k * (n + 1) + j] = s * inner[k * n + j];
            }
            jac[k * (n + 1) + n] = c_pf[k];
            c_pf[k] *= s;
        }
        Ok(())
    }

    fn describe(&self) -> String {
        format!("{} x {}", self.inner.describe(), self.name)
    }
}

/// The catalogue entry.
pub struct CalibrationScale;

impl Extension for CalibrationScale {
    fn name(&self) -> &'static str {
        "calibration-scale"
    }

    fn description(&self) -> &'static str {
        "a multiplicative calibration scale s on the measured capacitance (the circuit constants)"
    }

    fn signature(&self) -> &'static str {
        "the same relative residual at every voltage, below and above full depletion"
    }

    fn build(&self, base: &Baseline) -> std::result::Result<Candidate, String> {
        let model = Scaled::new(base.model.clone(), "cal_scale", SCALE_RANGE);
        Ok(one_more(
            self,
            base,
            base.predictor,
            Arc::new(model),
            (
                "cal_scale",
                "1",
                "calibration scale of the measured c12",
                PriorDistribution::TruncatedNormal {
                    mean: 1.0,
                    sd: SCALE_PRIOR_SD,
                    lo: None,
                    hi: None,
                },
            ),
            1.0,
        ))
    }
}
