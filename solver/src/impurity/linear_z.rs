//! The `linear-z` model: the manufacturer's zeta_M(z), linear between the crystal's faces.

use super::model::ImpurityModel;
use super::spec::{BuildModel, ImpurityContext, Keys};
use crate::error::{Error, Result};
use crate::expr::Quantity;

/// The keys of `model = "linear-z"`.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LinearZSpec {
    /// The density at the crystal's bottom face (z_bottom_mm) in cm^-3.
    pub bottom_cm3: Quantity,
    /// The density at the crystal's top face (z_top_mm) in cm^-3.
    pub top_cm3: Quantity,
}

impl BuildModel for LinearZSpec {
    fn build_model(&self, ctx: &ImpurityContext, keys: Keys<'_>) -> Result<Box<dyn ImpurityModel>> {
        let bottom = keys.value("bottom_cm3", &self.bottom_cm3)?;
        let top = keys.value("top_cm3", &self.top_cm3)?;
        ctx.check_z_range()?;
        let model = LinearZModel::new(bottom, top, ctx.z_bottom_mm, ctx.z_top_mm)
            .map_err(|e| keys.err("model", e.to_string()))?;
        Ok(Box::new(model))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::impurity::ConstantModel;

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
