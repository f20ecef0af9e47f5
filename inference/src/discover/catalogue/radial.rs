//! Radial dependence of the impurity density: the start model ties the rz model's y knots of a
//! face together (zeta depends on z only, the paper's B_Z); freeing them gives each knot its own y
//! (B_Z -> B_RZ, the paper's section 8.2). The surrogate's space already holds every knot, so the
//! start model is the candidate with all knots of a face equal.

use super::{Baseline, Candidate, Extension};
use crate::prior::{ParameterSpec, PriorDistribution, PriorSpec};
use crate::{Error, Result};

/// Prior sd of each freed knot's y around the start model's shared value: 0.5 in y is a factor
/// of ~10^1.5 in density near 1e10 cm^-3, and reaches a p-type mantle layer (the paper's mantle
/// knots moved by ~1 in y, table 4).
pub const RADIAL_PRIOR_SD: f64 = 0.5;

/// The catalogue entry.
pub struct Radial;

/// Whether `input` is a y knot of the rz model (`y<k>_bot`, `y<k>_top`).
fn is_knot(input: &str) -> bool {
    (input.ends_with("_bot") || input.ends_with("_top")) && input.starts_with('y')
}

impl Extension for Radial {
    fn name(&self) -> &'static str {
        "radial"
    }

    fn description(&self) -> &'static str {
        "radial dependence of the impurity density: each y knot of the rz model free (B_Z -> B_RZ)"
    }

    fn signature(&self) -> &'static str {
        "structured residuals at low voltage, where the depletion front moves in from the mantle \
         and c12 probes the outer radii; a good fit near full depletion"
    }

    fn build(&self, base: &Baseline) -> Result<Candidate> {
        let mut parameters = Vec::new();
        let mut start = Vec::new();
        let mut added = Vec::new();
        for (p, &value) in base.spec.parameters.iter().zip(base.mode) {
            let inputs = PriorSpec::inputs_of(p);
            if inputs.len() > 1 && inputs.iter().all(|i| is_knot(i)) {
                for input in inputs {
                    parameters.push(ParameterSpec {
                        name: input.clone(),
                        unit: p.unit.clone(),
                        description: format!("y of knot {input}, freed from {}", p.name),
                        inputs: vec![],
                        prior: PriorDistribution::TruncatedNormal {
                            mean: value,
                            sd: RADIAL_PRIOR_SD,
                            lo: None,
                            hi: None,
                        },
                    });
                    start.push(value);
                    added.push(input);
                }
            } else {
                parameters.push(p.clone());
                start.push(value);
            }
        }
        if added.is_empty() {
            return Err(Error::NotApplicable {
                extension: self.name().into(),
                reason: format!(
                    "the start model {} ties no y knots together: zeta already depends on r",
                    base.spec.name
                ),
            });
        }
        let mut spec = base.spec.clone();
        spec.name = format!("{}+radial", base.spec.name);
        spec.parameters = parameters;
        Ok(Candidate {
            name: self.name().into(),
            description: self.description().into(),
            signature: self.signature().into(),
            predictor: base.predictor,
            model: base.model.clone(),
            spec,
            start,
            added,
        })
    }
}
