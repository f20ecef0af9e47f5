//! The surrogate corrected by a model of its error: c(x) = c_s(x) exp(mean(x)), with the error
//! model's variance var(x) as the relative uncertainty of each point (sigma_p,k^2 = var_k(x),
//! the paper's eq. 13 with a sigma_p per point and input), so the likelihood knows where the
//! correction has been taught by exact curves and where it has not.

use super::gp::GpCorrection;
use crate::Result;
use crate::model::CvModel;

/// A model corrected by a [`GpCorrection`] fitted at its voltages.
pub struct CorrectedModel<'a> {
    base: &'a dyn CvModel,
    gp: GpCorrection,
    sigma_centre: f64,
    describe: String,
    /// The error model's variance at one reference point, used at every input (see
    /// [`CorrectedModel::variance_fixed_at`]); None: its variance at each input.
    fixed_var: Option<Vec<f64>>,
}

impl<'a> CorrectedModel<'a> {
    /// `base` corrected by `gp` (whose outputs are `base`'s voltages, in order).
    ///
    /// # Errors
    /// [`crate::Error::Argument`] when the error model has another number of outputs or
    /// inputs than `base` has voltages or inputs.
    pub fn new(base: &'a dyn CvModel, gp: GpCorrection) -> Result<Self> {
        if gp.scale.len() != base.voltages().len() || gp.centre.len() != base.inputs().len() {
            return Err(crate::Error::Argument {
                name: "error model".into(),
                message: format!(
                    "{} outputs and {} inputs for a model of {} voltages and {} inputs",
                    gp.scale.len(),
                    gp.centre.len(),
                    base.voltages().len(),
                    base.inputs().len()
                ),
            });
        }
        let at_centre = gp.predict(&gp.centre, false);
        let sigma_centre = (at_centre.var.iter().sum::<f64>() / at_centre.var.len() as f64).sqrt();
        let describe = format!(
            "{}, corrected by {} exact curves",
            base.describe(),
            gp.len()
        );
        Ok(Self {
            base,
            gp,
            sigma_centre,
            describe,
            fixed_var: None,
        })
    }

    /// This model with the error model's variance at `x_ref` as every input's point variance
    /// (var_k(x) = var_k(x_ref), zero derivatives).
    pub fn variance_fixed_at(mut self, x_ref: &[f64]) -> Self {
        self.fixed_var = Some(self.gp.predict(x_ref, false).var);
        self
    }

    /// The error model.
    pub fn correction(&self) -> &GpCorrection {
        &self.gp
    }
}

impl CvModel for CorrectedModel<'_> {
    fn inputs(&self) -> Vec<String> {
        self.base.inputs()
    }

    fn domain(&self) -> Vec<[f64; 2]> {
        self.base.domain()
    }

    fn voltages(&self) -> &[f64] {
        self.base.voltages()
    }

    /// The error model's rms relative uncertainty at the centre of its training points (for
    /// reports; the likelihood uses [`CvModel::curve_variance`], point by point).
    fn sigma_rel(&self) -> f64 {
        self.sigma_centre
    }

    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        self.base.curve(x, c_pf)?;
        let mean = self.gp.mean(x);
        for (c, m) in c_pf.iter_mut().zip(&mean) {
            *c *= m.exp();
        }
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        self.base.has_jacobian()
    }

    /// dc_k/dx_j = exp(mean_k) dc_s,k/dx_j + c_k dmean_k/dx_j.
    fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.base.curve_jacobian(x, c_pf, jac)?;
        let nx = x.len();
        let (mean, dm) = self.gp.mean_gradient(x);
        for (k, c) in c_pf.iter_mut().enumerate() {
            let e = mean[k].exp();
            *c *= e;
            for j in 0..nx {
                jac[k * nx + j] = e * jac[k * nx + j] + *c * dm[k * nx + j];
            }
        }
        Ok(())
    }

    fn describe(&self) -> String {
        self.describe.clone()
    }

    fn has_point_variance(&self) -> bool {
        true
    }

    fn curve_variance(
        &self,
        x: &[f64],
        var_rel: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> Result<()> {
        if let Some(v) = &self.fixed_var {
            var_rel.copy_from_slice(v);
            if let Some(j) = jac {
                j.fill(0.0);
            }
            return Ok(());
        }
        let p = self.gp.predict(x, jac.is_some());
        var_rel.copy_from_slice(&p.var);
        if let (Some(j), Some(dv)) = (jac, p.d_var) {
            j.copy_from_slice(&dv);
        }
        Ok(())
    }
}
