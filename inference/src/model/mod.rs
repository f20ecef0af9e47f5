//! The one narrow trait inference sees a model through ([`CvModel`]: parameters -> a C-V curve),
//! implemented by the surrogate ([`SurrogateModel`]) and by the exact field solver
//! ([`ExactModel`]), so a fit runs on either and the two can be compared point for point.

mod exact;
mod surrogate;

pub use exact::ExactModel;
pub(crate) use exact::{check_domain, near_curves};
pub use surrogate::SurrogateModel;

use crate::Result;

/// c(x) and each nearby point's curve or its error ([`CvModel::curves_near`]).
pub type CurvesNear = (Vec<f64>, Vec<Result<Vec<f64>>>);

/// [`CvModel::curve_variance`] of a constant relative uncertainty `sigma_rel`: sigma_rel^2 at
/// every point, zero derivatives.
pub(crate) fn constant_variance(sigma_rel: f64, var_rel: &mut [f64], jac: Option<&mut [f64]>) {
    var_rel.fill(sigma_rel * sigma_rel);
    if let Some(j) = jac {
        j.fill(0.0);
    }
}

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
    /// Whether the model's relative uncertainty varies with the inputs and the voltage
    /// ([`CvModel::curve_variance`]); false: the constant [`CvModel::sigma_rel`] everywhere.
    fn has_point_variance(&self) -> bool {
        false
    }
    /// The squared relative uncertainty sigma_p,k(x)^2 of each point (the paper's eq. 13 with a
    /// sigma_p per point), and with `jac` d sigma_p,k^2 / dx_j (row-major, voltages x inputs).
    /// By default sigma_rel^2 everywhere, with zero derivatives.
    ///
    /// # Errors
    /// As [`CvModel::curve`].
    fn curve_variance(
        &self,
        _x: &[f64],
        var_rel: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> Result<()> {
        constant_variance(self.sigma_rel(), var_rel, jac);
        Ok(())
    }
    /// A short description for reports (file, recipe, ...).
    fn describe(&self) -> String;
    /// c12 (pF) at `x` and at every point of `near` (points close to `x`: forward-difference
    /// steps, draws of a narrow posterior), as (c(x), [c(near_0), ...]); a nearby point whose
    /// curve fails is its entry's error, not the call's. By default each curve is its own
    /// [`CvModel::curve`] (the nearby ones in parallel). The exact solver overrides it: the
    /// nearby curves are solved on `x`'s grids (`hpge_solver::field::cv_curves_near_each`), so
    /// their differences from c(x) are those of one discretisation, not of two adaptive grids.
    /// `progress(done, total)` counts curves, `x`'s included.
    ///
    /// # Errors
    /// The curve at `x` fails.
    fn curves_near(
        &self,
        x: &[f64],
        near: &[Vec<f64>],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<CurvesNear> {
        use rayon::prelude::*;
        use std::sync::atomic::{AtomicUsize, Ordering};
        let nv = self.voltages().len();
        let mut c = vec![0.0; nv];
        self.curve(x, &mut c)?;
        let total = near.len() + 1;
        progress(1, total);
        let done = AtomicUsize::new(1);
        let others = near
            .par_iter()
            .map(|xn| {
                let mut cn = vec![0.0; nv];
                let r = self.curve(xn, &mut cn).map(|()| cn);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                r
            })
            .collect();
        Ok((c, others))
    }
}
