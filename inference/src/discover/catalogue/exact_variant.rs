//! The exact field solver with effects outside the surrogate's space: the exact model's inputs
//! set on the detector as usual ([`ExactSolver::detector`]), then the extension's own inputs
//! applied to the built detector (its impurity model, a contact's geometry) before the C-V curve
//! is solved.

use hpge_solver::{Detector, cv_curve};
use hpge_surrogate::ExactSolver;

use crate::model::{CurvesNear, CvModel, ExactModel, check_domain, near_curves};
use crate::{Error, Result};

/// Applies an extension's values (`extra`, in the order of [`ExactVariant`]'s added inputs) to a
/// detector built at the space's values; an error ([`Error::Extension`], a rejected point for
/// a sampler) names what cannot be built.
pub type Modifier = fn(&mut Detector, &[f64]) -> Result<()>;

/// The exact model ([`ExactModel`]) with added inputs.
pub struct ExactVariant {
    /// The exact solver on the space's inputs, bound to the voltages.
    base: ExactModel,
    names: Vec<String>,
    domain: Vec<[f64; 2]>,
    n_space: usize,
    modify: Modifier,
    label: String,
}

impl ExactVariant {
    /// The solver's inputs (its space without the bias) followed by `extra` (name, [lo, hi]);
    /// `modify` applies the extra values. `volts` must increase.
    pub fn new(
        solver: &ExactSolver,
        volts: &[f64],
        extra: &[(&str, [f64; 2])],
        modify: Modifier,
        label: &str,
    ) -> Result<Self> {
        let base = ExactModel::new(solver.clone(), volts)?;
        let mut names = base.inputs();
        let mut domain = base.domain();
        let n_space = names.len();
        for (n, r) in extra {
            names.push((*n).into());
            domain.push(*r);
        }
        Ok(Self {
            base,
            names,
            domain,
            n_space,
            modify,
            label: label.into(),
        })
    }

    /// The detector at inputs `x` (space values, then the extension's).
    pub fn detector(&self, x: &[f64]) -> Result<Detector> {
        let mut det = self.base.solver.detector(&x[..self.n_space])?;
        (self.modify)(&mut det, &x[self.n_space..])?;
        Ok(det)
    }
}

impl CvModel for ExactVariant {
    fn inputs(&self) -> Vec<String> {
        self.names.clone()
    }

    fn domain(&self) -> Vec<[f64; 2]> {
        self.domain.clone()
    }

    fn voltages(&self) -> &[f64] {
        self.base.voltages()
    }

    fn sigma_rel(&self) -> f64 {
        self.base.sigma_rel()
    }

    /// c12 (pF) from the field solver ([`cv_curve`]) on the modified detector.
    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        check_domain(&self.names, &self.domain, x)?;
        let det = self.detector(x)?;
        let curve = cv_curve(&det, self.voltages(), &self.base.solver.settings, |_, _| {})
            .map_err(|e| Error::Surrogate(e.into()))?;
        for (c, p) in c_pf.iter_mut().zip(&curve.points) {
            *c = p.c12_pf;
        }
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        false
    }

    fn curve_jacobian(&self, _x: &[f64], _c_pf: &mut [f64], _jac: &mut [f64]) -> Result<()> {
        Err(Error::Argument {
            name: "jacobian".into(),
            message: format!("{}: the exact solver has no Jacobian", self.label),
        })
    }

    fn describe(&self) -> String {
        format!("{} with {}", self.base.describe(), self.label)
    }

    /// The nearby curves on `x`'s grids, as [`ExactModel`] solves them.
    fn curves_near(
        &self,
        x: &[f64],
        near: &[Vec<f64>],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<CurvesNear> {
        let detector = |x: &[f64]| self.detector(x);
        let inputs = (self.names.as_slice(), self.domain.as_slice());
        near_curves(&self.base, inputs, x, near, &detector, progress)
    }
}
