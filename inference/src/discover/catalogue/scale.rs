//! A multiplicative calibration scale: the circuit's constants (pulser voltage, resistors, the
//! charge calibration) off by a common factor, c = s c12.

use std::sync::Arc;

use super::{Affine, Baseline, Candidate, Extension, one_more};
use crate::Result;
use crate::prior::PriorDistribution;

/// Domain of s.
pub const SCALE_RANGE: [f64; 2] = [0.5, 2.0];
/// Prior sd of s: the circuit constants' combined 6% (3% on each of Q, R_PG, R1, R2, U_PG, the
/// shipped measurement's uncertainty budget), doubled to be generous.
pub const SCALE_PRIOR_SD: f64 = 0.12;

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

    fn build(&self, base: &Baseline) -> Result<Candidate> {
        let model = Affine::scale(base.model.clone(), "cal_scale", SCALE_RANGE);
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
