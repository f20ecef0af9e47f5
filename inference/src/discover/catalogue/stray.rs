//! An additive stray capacitance in parallel with c12 (cables, the holding structure, a
//! capacitance the circuit's calibration did not remove): c = c12 + c_s.

use std::sync::Arc;

use super::{Affine, Baseline, Candidate, Extension, one_more};
use crate::Result;
use crate::prior::PriorDistribution;

/// Domain of c_s, pF.
pub const STRAY_RANGE_PF: [f64; 2] = [-50.0, 100.0];
/// Prior sd of c_s, pF: a few pF are typical of cables and fixtures; 10 pF is generous.
pub const STRAY_PRIOR_SD_PF: f64 = 10.0;

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

    fn build(&self, base: &Baseline) -> Result<Candidate> {
        let model = Affine::shift(base.model.clone(), "c_stray_pf", STRAY_RANGE_PF);
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
