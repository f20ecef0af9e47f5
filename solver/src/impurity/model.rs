//! The open set of impurity-density models and the modifiers any model takes (scale, tilt).

/// What a model says at one point.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PointDensity {
    /// The model's y (paper Eq. (21)), for models parametrised in y.
    pub y: Option<f64>,
    /// x = T(y) (paper Eqs. (19), (20)), for models parametrised in y.
    pub x: Option<f64>,
    /// The signed impurity density in cm^-3 (positive: n-type).
    pub zeta_cm3: f64,
}

/// A signed impurity density zeta(r, z) in cm^-3 (positive: n-type, paper Eqs. (12), (13)).
pub trait ImpurityModel: std::fmt::Debug + Send + Sync {
    /// Short name as in the TOML `model` key: "constant", "linear-z", "rz".
    fn name(&self) -> &'static str;
    /// Signed density in cm^-3 at (r, z) in mm.
    fn density_cm3(&self, r_mm: f64, z_mm: f64) -> f64;
    /// The radii of the model's knots, mm (the rz model's r_1..r_4; none for a model without
    /// radial knots): where a figure marks the fitted values.
    fn knots_r_mm(&self) -> Vec<f64> {
        Vec::new()
    }
    /// y, x (where the model has them) and zeta at (r, z).
    fn evaluate(&self, r_mm: f64, z_mm: f64) -> PointDensity {
        PointDensity {
            y: None,
            x: None,
            zeta_cm3: self.density_cm3(r_mm, z_mm),
        }
    }
}

/// Another model's density times a positive factor (the `scale` key of any model):
/// zeta(r, z) = factor * zeta_inner(r, z); y and x are not defined for the product.
#[derive(Debug)]
pub struct ScaledModel {
    /// The model scaled.
    pub inner: Box<dyn ImpurityModel>,
    /// The factor (positive).
    pub factor: f64,
}

impl ImpurityModel for ScaledModel {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn density_cm3(&self, r_mm: f64, z_mm: f64) -> f64 {
        self.factor * self.inner.density_cm3(r_mm, z_mm)
    }
    fn knots_r_mm(&self) -> Vec<f64> {
        self.inner.knots_r_mm()
    }
}

/// Another model with its variation along z scaled about the crystal's mid-height (the `tilt`
/// key of any model, issue 64): zeta(r, z) = zeta_inner(r, z_mid) + tilt * (zeta_inner(r, z) -
/// zeta_inner(r, z_mid)). Tilt 1 is the inner model, 0 the density at mid-height everywhere
/// along z, 2 twice its gradient; a model constant in z is unchanged by any tilt.
#[derive(Debug)]
pub struct TiltedModel {
    /// The model tilted.
    pub inner: Box<dyn ImpurityModel>,
    /// The factor on the variation along z.
    pub tilt: f64,
    /// The height the tilt pivots about (the crystal's mid-height), mm.
    pub z_mid_mm: f64,
}

impl ImpurityModel for TiltedModel {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn density_cm3(&self, r_mm: f64, z_mm: f64) -> f64 {
        let mid = self.inner.density_cm3(r_mm, self.z_mid_mm);
        mid + self.tilt * (self.inner.density_cm3(r_mm, z_mm) - mid)
    }
    fn knots_r_mm(&self) -> Vec<f64> {
        self.inner.knots_r_mm()
    }
}

#[cfg(test)]
mod tilt_tests {
    use super::*;
    use crate::impurity::{ConstantModel, LinearZModel};

    #[test]
    fn a_tilt_scales_the_variation_along_z_about_mid_height() {
        // linear-z from 1 at z = 0 to 3 at z = 10: mid-height value 2, gradient 0.2 / mm.
        let inner = LinearZModel::new(1.0, 3.0, 0.0, 10.0).unwrap();
        let t = TiltedModel {
            inner: Box::new(inner),
            tilt: 1.5,
            z_mid_mm: 5.0,
        };
        assert!((t.density_cm3(0.0, 5.0) - 2.0).abs() < 1e-12);
        assert!((t.density_cm3(0.0, 0.0) - 0.5).abs() < 1e-12);
        assert!((t.density_cm3(7.0, 10.0) - 3.5).abs() < 1e-12);
        let flat = TiltedModel {
            inner: Box::new(ConstantModel::new(4.0).unwrap()),
            tilt: 3.0,
            z_mid_mm: 5.0,
        };
        assert_eq!(flat.density_cm3(1.0, 9.0), 4.0);
    }
}
