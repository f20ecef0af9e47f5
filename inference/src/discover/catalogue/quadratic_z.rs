//! A quadratic z term in the impurity density: y(r, z) gains 4 y_quad t (1 - t), t the relative
//! height (zero at both faces, y_quad at mid-height), so zeta can bulge or sag between the faces
//! instead of following the rz model's straight line in y (paper Eq. (21)). Outside the
//! surrogate's space: computed with the exact solver.

use std::path::Path;
use std::sync::Arc;

use hpge_solver::Detector;

use super::{Baseline, Candidate, ExactVariant, Extension, ExtensionPredictor, one_more};
use crate::prior::{Prior, PriorDistribution};
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
    if spec.model.as_str() != "rz" {
        return Err(cannot(format!(
            "the quadratic z term needs the rz impurity model, the detector has `{}`",
            spec.model.as_str()
        )));
    }
    spec.y_quad = Some(extra[0]);
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
        let volts = base.model.voltages();
        let model = ExactVariant::new(
            base.exact,
            volts,
            &[("y_quad", QUAD_RANGE)],
            set_quadratic,
            LABEL,
        )?;
        let mut x = base_inputs(base)?;
        x.push(0.0);
        model.detector(&x)?;
        Ok(one_more(
            self,
            base,
            ExtensionPredictor::Exact,
            Arc::new(model),
            (
                "y_quad",
                "1",
                "quadratic z term of y (its value at mid-height)",
                PriorDistribution::TruncatedNormal {
                    mean: 0.0,
                    sd: QUAD_PRIOR_SD,
                    lo: None,
                    hi: None,
                },
            ),
            0.0,
        ))
    }
}

/// The start mode as model inputs of the surrogate's space (for a dry run of a modifier).
pub(super) fn base_inputs(base: &Baseline) -> Result<Vec<f64>> {
    let names = base.model.inputs();
    let prior = Prior::bind(base.spec, &names, &base.model.domain())?;
    let mut x = vec![0.0; names.len()];
    prior.expand(base.mode, &mut x);
    Ok(x)
}
