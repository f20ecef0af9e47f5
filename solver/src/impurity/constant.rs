//! The `constant` model: one density everywhere (the paper's sensitivity scan).

use super::model::ImpurityModel;
use super::spec::{BuildModel, ImpurityContext, Keys};
use crate::error::{Error, Result};
use crate::expr::Quantity;

/// The keys of `model = "constant"`.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantSpec {
    /// The signed density in cm^-3 (a number or an expression over the detector's parameters).
    pub zeta_cm3: Quantity,
}

impl BuildModel for ConstantSpec {
    fn build_model(
        &self,
        _ctx: &ImpurityContext,
        keys: Keys<'_>,
    ) -> Result<Box<dyn ImpurityModel>> {
        let zeta = keys.value("zeta_cm3", &self.zeta_cm3)?;
        let model = ConstantModel::new(zeta).map_err(|e| keys.err("model", e.to_string()))?;
        Ok(Box::new(model))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::impurity::PointDensity;

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
}
