//! The catalogue of model extensions model discovery tries (issue 9): each entry names a
//! physical effect the start model lacks, its parameters and priors, and the signature it leaves
//! in the C-V residuals. Adding an entry is one file here implementing [`Extension`] and one line
//! in [`catalogue`].
//!
//! An entry builds a [`Candidate`]: a [`CvModel`] whose inputs are the start model's plus the
//! effect's, and a prior spec that contains the start model's parameters (the start model is the
//! candidate at the effect's null value, so the two nest). Entries that need predictions the
//! surrogate was not trained for run on the exact field solver ([`ExtensionPredictor::Exact`]).

mod affine;
mod exact_variant;
mod li_slope;
mod quadratic_z;
mod radial;
mod scale;
mod stray;

use std::sync::Arc;

use hpge_surrogate::ExactSolver;
use serde::Serialize;

pub use affine::{Affine, AffineKind, Scaled, Shifted};
pub use exact_variant::{ExactVariant, Modifier};
pub use li_slope::LiSlope;
pub use quadratic_z::QuadraticZ;
pub use radial::Radial;
pub use scale::CalibrationScale;
pub use stray::StrayCapacitance;

use crate::Result;
use crate::model::CvModel;
use crate::prior::{ParameterSpec, Prior, PriorDistribution, PriorSpec};

/// What computes a candidate's curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExtensionPredictor {
    /// The trained surrogate (the effect is in its space, or acts on its output).
    Surrogate,
    /// The exact field solver (the effect is outside the surrogate's space).
    Exact,
}

impl ExtensionPredictor {
    /// `surrogate` or `exact`.
    pub fn as_str(&self) -> &'static str {
        match self {
            ExtensionPredictor::Surrogate => "surrogate",
            ExtensionPredictor::Exact => "exact",
        }
    }
}

/// What an extension builds on: the start model and its fit.
#[derive(Clone)]
pub struct Baseline<'a> {
    /// The start model's prior (its parameters and ties).
    pub spec: &'a PriorSpec,
    /// The start fit's global mode, in `spec`'s parameter order.
    pub mode: &'a [f64],
    /// The start model's predictor: the surrogate, or the exact solver (then every entry
    /// runs on the exact solver).
    pub model: Arc<dyn CvModel>,
    /// Which of the two `model` is.
    pub predictor: ExtensionPredictor,
    /// The exact solver on the surrogate's space and detector.
    pub exact: &'a ExactSolver,
}

/// A start model extended by one effect, ready to be scored and fitted.
#[derive(Clone)]
pub struct Candidate {
    /// The extension's name (e.g. `radial`).
    pub name: String,
    /// What it adds, in words.
    pub description: String,
    /// The residual signature it explains.
    pub signature: String,
    /// What computes its curves.
    pub predictor: ExtensionPredictor,
    /// The extended model.
    pub model: Arc<dyn CvModel>,
    /// Its prior: the start model's parameters (possibly split) and the added ones.
    pub spec: PriorSpec,
    /// Where an optimiser starts: the start mode with the effect at its null value.
    pub start: Vec<f64>,
    /// The parameters it adds (for a split, the new per-input parameters).
    pub added: Vec<String>,
}

/// One entry of the catalogue.
pub trait Extension: Send + Sync {
    /// Short name used in outputs and on the command line (`radial`, `stray-capacitance`, ...).
    fn name(&self) -> &'static str;
    /// What the effect is, physically.
    fn description(&self) -> &'static str;
    /// The residual pattern the effect leaves when the start model lacks it.
    fn signature(&self) -> &'static str;
    /// The extended model, or why the entry does not apply to this start model or detector
    /// (its text is the report's reason).
    fn build(&self, base: &Baseline) -> Result<Candidate>;
}

/// Every entry, in a fixed order (the report lists them this way).
pub fn catalogue() -> Vec<Box<dyn Extension>> {
    vec![
        Box::new(Radial),
        Box::new(StrayCapacitance),
        Box::new(CalibrationScale),
        Box::new(QuadraticZ),
        Box::new(LiSlope),
    ]
}

/// `spec` with one more parameter `name` (a model input of the same name) and its prior.
pub(crate) fn with_parameter(
    spec: &PriorSpec,
    name: &str,
    unit: &str,
    description: &str,
    prior: PriorDistribution,
) -> PriorSpec {
    let mut s = spec.clone();
    s.parameters.push(ParameterSpec {
        name: name.into(),
        unit: unit.into(),
        description: description.into(),
        inputs: vec![],
        prior,
    });
    s.name = format!("{}+{name}", spec.name);
    s
}

/// A candidate that adds one parameter with null value `null` to the start model.
pub(crate) fn one_more(
    ext: &dyn Extension,
    base: &Baseline,
    predictor: ExtensionPredictor,
    model: Arc<dyn CvModel>,
    parameter: (&str, &str, &str, PriorDistribution),
    null: f64,
) -> Candidate {
    let (name, unit, description, prior) = parameter;
    let mut start = base.mode.to_vec();
    start.push(null);
    Candidate {
        name: ext.name().into(),
        description: ext.description().into(),
        signature: ext.signature().into(),
        predictor,
        model,
        spec: with_parameter(base.spec, name, unit, description, prior),
        start,
        added: vec![name.into()],
    }
}

/// One parameter of an effect outside the surrogate's space (computed with the exact solver):
/// its name, unit and description, its domain, and its prior, a normal of sd `prior_sd` around
/// zero.
pub(crate) struct ExactParameter {
    /// The parameter's (and the model input's) name.
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// What it is, in words.
    pub description: &'static str,
    /// Its domain, [lo, hi].
    pub range: [f64; 2],
    /// The sd of its prior (a normal around zero, unbounded).
    pub prior_sd: f64,
    /// The value the modifier is tried at once before the candidate is returned (so an entry
    /// that cannot apply to this detector says so now).
    pub dry_run: f64,
}

/// A candidate that adds one exact-solver parameter (null value zero) to the start model: the
/// exact model with `modify` applying it ([`ExactVariant`]), checked once at the start mode with
/// the parameter at `dry_run`.
pub(crate) fn one_more_exact(
    ext: &dyn Extension,
    base: &Baseline,
    parameter: ExactParameter,
    modify: Modifier,
    label: &str,
) -> Result<Candidate> {
    let volts = base.model.voltages();
    let model = ExactVariant::new(
        base.exact,
        volts,
        &[(parameter.name, parameter.range)],
        modify,
        label,
    )?;
    let mut x = base_inputs(base)?;
    x.push(parameter.dry_run);
    model.detector(&x)?;
    Ok(one_more(
        ext,
        base,
        ExtensionPredictor::Exact,
        Arc::new(model),
        (
            parameter.name,
            parameter.unit,
            parameter.description,
            PriorDistribution::TruncatedNormal {
                mean: 0.0,
                sd: parameter.prior_sd,
                lo: None,
                hi: None,
            },
        ),
        0.0,
    ))
}

/// The start mode as model inputs of the surrogate's space (for a dry run of a modifier).
fn base_inputs(base: &Baseline) -> Result<Vec<f64>> {
    let names = base.model.inputs();
    let prior = Prior::bind(base.spec, &names, &base.model.domain())?;
    let mut x = vec![0.0; names.len()];
    prior.expand(base.mode, &mut x);
    Ok(x)
}

#[cfg(test)]
mod tests;
