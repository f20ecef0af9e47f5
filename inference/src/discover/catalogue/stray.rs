//! An additive stray capacitance in parallel with c12 (cables, the holding structure, a
//! capacitance the circuit's calibration did not remove): c = c12 + c_s.

use std::sync::Arc;

use super::{Baseline, Candidate, Extension, one_more};
use crate::Result;
use crate::model::CvModel;
use crate::prior::PriorDistribution;

/// Domain of c_s, pF.
pub const STRAY_RANGE_PF: [f64; 2] = [-50.0, 100.0];
/// Prior sd of c_s, pF: a few pF are typical of cables and fixtures; 10 pF is generous.
pub const STRAY_PRIOR_SD_PF: f64 = 10.0;

/// `inner` plus a constant: c_k(x, c_s) = c_inner,k(x) + c_s (pF).
pub struct Shifted {
    inner: Arc<dyn CvModel>,
    name: String,
    range: [f64; 2],
}

impl Shifted {
    /// `inner` with one more input `name` (pF) valid on `range`.
    pub fn new(inner: Arc<dyn CvModel>, name: &str, range: [f64; 2]) -> Self {
        Self {
            inner,
            name: name.into(),
            range,
        }
    }
}

impl CvModel for Shifted {
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
        c_pf.iter_mut().for_each(|c| *c += x[n]);
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        self.inner.has_jacobian()
    }

    /// dc_k/dx_j of the inner model; dc_k/dc_s = 1.
    fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], jac: &mut [f64]) -> Result<()> {
        let n = x.len() - 1;
        let nv = c_pf.len();
        let mut inner = vec![0.0; nv * n];
        self.inner.curve_jacobian(&x[..n], c_pf, &mut inner)?;
        for k in 0..nv {
            jac[k * (n + 1)..k * (n + 1) + n].copy_from_slice(&inner[k * n..(k + 1) * n]);
            jac[k * (n + 1) + n] = 1.0;
            c_pf[k] += x[n];
        }
        Ok(())
    }

    fn describe(&self) -> String {
        format!("{} + {}", self.inner.describe(), self.name)
    }
}

/// The catalogue entry.
pub struct StrayCapacitance;

impl Extension for StrayCapacitance {
    fn name(&self) -> &'static str {
        "stray-capacitance"
    }

    fn description(&self) -> &'static str {
        "an additive stray capacitance c_s (pF) in parallel with c12"
    }

    fn signature(&self) -> &'static str {
        "a constant offset in pF: small relative residuals at low voltage (large c12), growing \
         towards full depletion where c12 is smallest, flat beyond it"
    }

    fn build(&self, base: &Baseline) -> std::result::Result<Candidate, String> {
        let model = Shifted::new(base.model.clone(), "c_stray_pf", STRAY_RANGE_PF);
        Ok(one_more(
            self,
            base,
            base.predictor,
            Arc::new(model),
            (
                "c_stray_pf",
                "pF",
                "stray capacitance in parallel with c12",
                PriorDistribution::TruncatedNormal {
                    mean: 0.0,
                    sd: STRAY_PRIOR_SD_PF,
                    lo: None,
                    hi: None,
                },
            ),
            0.0,
        ))
    }
}
