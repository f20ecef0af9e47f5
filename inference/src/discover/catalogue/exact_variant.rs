//! The exact field solver with effects outside the surrogate's space: the space's inputs set on
//! the detector as usual ([`ExactSolver::detector`]), then the extension's own inputs applied to
//! the built detector (its impurity model, a contact's geometry) before the C-V curve is solved.

use hpge_solver::{Detector, cv_curve};
use hpge_surrogate::ExactSolver;

use crate::model::{CvModel, check_domain};
use crate::{Error, Result};

/// Applies an extension's values (`extra`, in the order of [`ExactVariant`]'s added inputs) to a
/// detector built at the space's values; an error names what cannot be built.
pub type Modifier = fn(&mut Detector, &[f64]) -> std::result::Result<(), String>;

/// The exact solver with added inputs.
pub struct ExactVariant {
    solver: ExactSolver,
    volts: Vec<f64>,
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
        let base = crate::ExactModel::new(solver.clone(), volts)?;
        let mut names = base.inputs();
        let mut domain = base.domain();
        let n_space = names.len();
        for (n, r) in extra {
            names.push((*n).into());
            domain.push(*r);
        }
        Ok(Self {
            solver: solver.clone(),
            volts: volts.to_vec(),
            names,
            domain,
            n_space,
            modify,
            label: label.into(),
        })
    }

    /// The detector at inputs `x` (space values, then the extension's).
    pub fn detector(&self, x: &[f64]) -> Result<Detector> {
        let mut det = self.solver.detector(&x[..self.n_space])?;
        (self.modify)(&mut det, &x[self.n_space..]).map_err(|message| Error::Argument {
            name: self.label.clone(),
            message,
        })?;
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
        &self.volts
    }

    fn sigma_rel(&self) -> f64 {
        0.0
    }

    /// c12 (pF) from the field solver ([`cv_curve`]) on the modified detector.
    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        check_domain(&self.names, &self.domain, x)?;
        let det = self.detector(x)?;
        let curve = cv_curve(&det, &self.volts, &self.solver.settings, |_, _| {})
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
        format!(
            "exact solver ({}) with {}",
            self.solver.detector_file.display(),
            self.label
        )
    }
}
