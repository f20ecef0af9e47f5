//! The open set of impurity-density models, and the two simple ones (constant, linear in z).

use crate::error::{Error, Result};

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

/// A density constant in space, zeta_c (the paper's sensitivity scan, Fig.
/// "impurity_level_sensitivity").
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ConstantModel {
    /// The signed density in cm^-3.
    pub zeta_cm3: f64,
}

impl ConstantModel {
    /// A constant density; errors if it is not finite.
    pub fn new(zeta_cm3: f64) -> Result<Self> {
        if !zeta_cm3.is_finite() {
            return Err(Error::invalid_value(
                "impurity model",
                format!("the density must be a finite number, got {zeta_cm3}"),
            ));
        }
        Ok(ConstantModel { zeta_cm3 })
    }
}

impl ImpurityModel for ConstantModel {
    fn name(&self) -> &'static str {
        "constant"
    }

    /// zeta(r, z) = zeta_c.
    fn density_cm3(&self, _r_mm: f64, _z_mm: f64) -> f64 {
        self.zeta_cm3
    }
}

/// The manufacturer's model zeta_M(z), linear in z (paper Eq. (14)
/// `eq:ManufacturerImpurityDensity`), independent of r.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LinearZModel {
    /// Signed density at z = z_bottom_mm, in cm^-3.
    pub bottom_cm3: f64,
    /// Signed density at z = z_top_mm, in cm^-3.
    pub top_cm3: f64,
    /// z of the crystal's bottom face in mm.
    pub z_bottom_mm: f64,
    /// z of the crystal's top face in mm.
    pub z_top_mm: f64,
}

impl LinearZModel {
    /// The linear model; errors unless all values are finite and z_top_mm > z_bottom_mm.
    ///
    /// ```
    /// use hpge_solver::impurity::{ImpurityModel, LinearZModel};
    /// // The manufacturer's p-type levels of Super-Siegfried (cm^-3, negative: p-type).
    /// let m = LinearZModel::new(-0.7e10, -0.55e10, 0.0, 70.0)?;
    /// assert!((m.density_cm3(10.0, 35.0) + 0.625e10).abs() < 1.0);
    /// assert_eq!(m.density_cm3(0.0, 0.0), m.density_cm3(30.0, 0.0), "independent of r");
    /// assert!(LinearZModel::new(-1e10, -1e10, 5.0, 5.0).is_err());
    /// # Ok::<(), hpge_solver::Error>(())
    /// ```
    pub fn new(bottom_cm3: f64, top_cm3: f64, z_bottom_mm: f64, z_top_mm: f64) -> Result<Self> {
        for (name, value) in [
            ("bottom_cm3", bottom_cm3),
            ("top_cm3", top_cm3),
            ("z_bottom_mm", z_bottom_mm),
            ("z_top_mm", z_top_mm),
        ] {
            if !value.is_finite() {
                return Err(Error::invalid_value(
                    "impurity model",
                    format!("`{name}` must be a finite number, got {value}"),
                ));
            }
        }
        if z_top_mm <= z_bottom_mm {
            return Err(Error::invalid_value(
                "impurity model",
                format!(
                    "the top z ({z_top_mm} mm) must be greater than the bottom z ({z_bottom_mm} mm)"
                ),
            ));
        }
        Ok(LinearZModel {
            bottom_cm3,
            top_cm3,
            z_bottom_mm,
            z_top_mm,
        })
    }
}

impl ImpurityModel for LinearZModel {
    fn name(&self) -> &'static str {
        "linear-z"
    }

    /// zeta_M(z) = bottom + (top - bottom) (z - z_bottom) / (z_top - z_bottom) (paper Eq. (14),
    /// where z_bottom = 0 and z_top - z_bottom = l_D); not clamped: it extrapolates outside.
    fn density_cm3(&self, _r_mm: f64, z_mm: f64) -> f64 {
        let fraction = (z_mm - self.z_bottom_mm) / (self.z_top_mm - self.z_bottom_mm);
        self.bottom_cm3 + (self.top_cm3 - self.bottom_cm3) * fraction
    }
}

/// A density along z, piecewise linear through a table, constant beyond its ends; the same at
/// every radius.
#[derive(Debug, Clone, PartialEq)]
pub struct ZTableModel {
    /// Heights in mm, strictly increasing.
    pub z_mm: Vec<f64>,
    /// Signed densities (cm^-3) at `z_mm`.
    pub values_cm3: Vec<f64>,
}

impl ImpurityModel for ZTableModel {
    fn name(&self) -> &'static str {
        "z-table"
    }

    fn density_cm3(&self, _r_mm: f64, z_mm: f64) -> f64 {
        let (z, v) = (&self.z_mm, &self.values_cm3);
        let n = z.len();
        if z_mm <= z[0] {
            return v[0];
        }
        if z_mm >= z[n - 1] {
            return v[n - 1];
        }
        let k = z.partition_point(|&x| x <= z_mm).clamp(1, n - 1);
        let t = (z_mm - z[k - 1]) / (z[k] - z[k - 1]);
        v[k - 1] + t * (v[k] - v[k - 1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_table_interpolates_and_holds_its_ends() {
        let m = ZTableModel {
            z_mm: vec![0.0, 10.0, 30.0],
            values_cm3: vec![-1e10, -2e10, 0.0],
        };
        assert_eq!(m.density_cm3(0.0, -5.0), -1e10);
        assert!((m.density_cm3(3.0, 5.0) + 1.5e10).abs() < 1.0);
        assert!((m.density_cm3(3.0, 20.0) + 1e10).abs() < 1.0);
        assert_eq!(m.density_cm3(3.0, 40.0), 0.0);
    }

    #[test]
    fn constant() {
        let m = ConstantModel::new(-3e9).unwrap();
        assert_eq!(m.name(), "constant");
        assert_eq!(m.density_cm3(1.0, 2.0), -3e9);
        assert_eq!(
            m.evaluate(0.0, 0.0),
            PointDensity {
                y: None,
                x: None,
                zeta_cm3: -3e9
            }
        );
        assert!(ConstantModel::new(f64::NAN).is_err());
        assert!(ConstantModel::new(f64::INFINITY).is_err());
    }

    #[test]
    fn linear_z() {
        let m = LinearZModel::new(1.3e10, 0.44e10, 0.0, 70.0).unwrap();
        assert_eq!(m.name(), "linear-z");
        assert_eq!(m.density_cm3(5.0, 0.0), 1.3e10);
        assert!((m.density_cm3(0.0, 70.0) - 0.44e10).abs() < 1.0);
        assert!((m.density_cm3(30.0, 35.0) - 0.87e10).abs() < 1.0);
        // Not clamped outside [z_bottom, z_top].
        assert!(m.density_cm3(0.0, -70.0) > 1.3e10);
        assert_eq!(m.evaluate(0.0, 0.0).y, None);
        assert!(LinearZModel::new(1.0, 1.0, 5.0, 5.0).is_err());
        assert!(LinearZModel::new(1.0, 1.0, 5.0, 4.0).is_err());
        assert!(LinearZModel::new(f64::NAN, 1.0, 0.0, 4.0).is_err());
        assert!(LinearZModel::new(1.0, 1.0, 0.0, f64::INFINITY).is_err());
    }

    #[test]
    fn models_are_object_safe() {
        let models: Vec<Box<dyn ImpurityModel>> = vec![
            Box::new(ConstantModel::new(1.0).unwrap()),
            Box::new(LinearZModel::new(1.0, 2.0, 0.0, 1.0).unwrap()),
        ];
        assert_eq!(models[1].density_cm3(0.0, 0.5), 1.5);
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
