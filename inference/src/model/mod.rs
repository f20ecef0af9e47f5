//! The one narrow trait inference sees a model through ([`CvModel`]: parameters -> a C-V curve),
//! implemented by the surrogate ([`SurrogateModel`]) and by the exact field solver
//! ([`ExactModel`]), so a fit runs on either and the two can be compared point for point.

mod exact;
mod surrogate;

pub use exact::ExactModel;
pub(crate) use exact::{check_domain, near_curves};
pub use surrogate::SurrogateModel;

use crate::Result;

/// A model of c12 along a fixed list of bias voltages.
///
/// Inputs are the model's own parameters in physical units (for the paper's surrogate: d_Li in
/// mm and the eight y of the rz model, the bias excluded); a prior ties the fit's parameters to
/// them. A point outside [`CvModel::domain`] or a failed solve is an error that a sampler treats
/// as zero posterior density (a rejected proposal), never a panic.
pub trait CvModel: Send + Sync {
    /// Input names, e.g. `d_li_mm`, `y1_bot`, ...
    fn inputs(&self) -> Vec<String>;
    /// [lo, hi] of each input (where the model is valid).
    fn domain(&self) -> Vec<[f64; 2]>;
    /// The bias voltages (V) of every curve this model computes.
    fn voltages(&self) -> &[f64];
    /// The relative model uncertainty sigma_p (sigma_c^p = sigma_p c_p, the paper's eq. 13);
    /// zero for the exact solver (its own uncertainty is the 1% + 1 pF term).
    fn sigma_rel(&self) -> f64;
    /// c12 (pF) at every voltage for inputs `x`.
    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()>;
    /// Whether [`CvModel::curve_jacobian`] is available (gradient-based samplers need it).
    fn has_jacobian(&self) -> bool;
    /// c12 (pF) and dc_k/dx_j (row-major, voltages x inputs).
    fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], jac: &mut [f64]) -> Result<()>;
    /// A short description for reports (file, recipe, ...).
    fn describe(&self) -> String;
    /// c12 (pF) at `x` and at every point of `near` (points close to `x`: forward-difference
    /// steps), as (c(x), [c(near_0), ...]). By default each curve is its own
    /// [`CvModel::curve`] (the nearby ones in parallel). The exact solver overrides it: the
    /// nearby curves are solved on `x`'s grids (`hpge_solver::field::cv_curves_near`), so their
    /// differences from c(x) are those of one discretisation, not of two adaptive grids.
    fn curves_near(&self, x: &[f64], near: &[Vec<f64>]) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
        use rayon::prelude::*;
        let nv = self.voltages().len();
        let mut c = vec![0.0; nv];
        self.curve(x, &mut c)?;
        let others = near
            .par_iter()
            .map(|xn| {
                let mut cn = vec![0.0; nv];
                self.curve(xn, &mut cn).map(|()| cn)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok((c, others))
    }
}
