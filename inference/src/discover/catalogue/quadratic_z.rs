//! A quadratic z term in the impurity density: y(r, z) gains 4 y_quad t (1 - t), t the relative
//! height (zero at both faces, y_quad at mid-height), so zeta can bulge or sag between the faces
//! instead of following the rz model's straight line in y (paper Eq. (21)). Outside the
//! surrogate's space: computed with the exact solver.

use std::path::Path;

use hpge_solver::Detector;

use super::{Baseline, Candidate, ExactParameter, Extension, one_more_exact};
use crate::{Error, Result};

/// Domain of y_quad.
pub const QUAD_RANGE: [f64; 2] = [-0.5, 0.5];
/// Prior sd of y_quad: 0.15 in y is a factor of ~3 in density at mid-height.
pub const QUAD_PRIOR_SD: f64 = 0.15;
/// The effect, in words (names it in errors and descriptions).
const LABEL: &str = "a quadratic z term y_quad";

/// Sets y_quad on the detector's rz impurity model.
fn set_quadratic(det: &mut Detector, extra: &[f64]) -> Result<()> {
    let cannot = |message: String| Error::Extension {
        extension: LABEL.into(),
        message,
    };
    let mut spec = det.semiconductor.impurity_spec().clone();
    let hpge_solver::impurity::ModelSpec::Rz(rz) = &mut spec.model else {
        return Err(cannot(format!(
            "the quadratic z term needs the rz impurity model, the detector has `{}`",
            spec.model.name()
        )));
    };
    rz.y_quad = Some(extra[0].into());
    det.set_impurity(&spec, Path::new("(quadratic-z extension)"))
        .map_err(|e| cannot(e.to_string()))
}

/// The catalogue entry.
pub struct QuadraticZ;

impl Extension for QuadraticZ {
    fn name(&self) -> &'static str {
        "quadratic-z"
    }

    fn description(&self) -> &'static str {
        "a quadratic z term in the impurity density (zeta bulges or sags between the faces)"
    }

    fn signature(&self) -> &'static str {
        "residuals at intermediate voltages, where the depletion front sweeps the crystal's \
         middle height; faces and full depletion fit"
    }

    fn build(&self, base: &Baseline) -> Result<Candidate> {
        one_more_exact(
            self,
            base,
            ExactParameter {
                name: "y_quad",
                unit: "1",
                description: "quadratic z term of y (its value at mid-height)",
                range: QUAD_RANGE,
                prior_sd: QUAD_PRIOR_SD,
                dry_run: 0.0,
            },
            set_quadratic,
            LABEL,
        )
    }
}
