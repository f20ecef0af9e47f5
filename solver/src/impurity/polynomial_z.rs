//! The `polynomial-z` model: a density quadratic in the height above the crystal's bottom face,
//! the profile of LEGEND's diode records (`production.impcc.function_pars`: `z0`, `gradient`,
//! `quadratic` in the distance from the point contact, which sits on the bottom face).
//!
//! zeta(r, z) = z0_cm3 + gradient_cm3_per_mm d + quadratic_cm3_per_mm2 d^2, d = z - z_bottom_mm,
//! the same at every radius and not clamped beyond the faces.
//!
//! ```toml
//! model = "polynomial-z"
//! z0_cm3 = -1.3e10                 # at the bottom face
//! gradient_cm3_per_mm = 6e7        # towards the top face
//! quadratic_cm3_per_mm2 = "q"      # optional (default 0); here a parameter of the detector
//! ```

use super::model::ImpurityModel;
use super::spec::{BuildModel, ImpurityContext, Keys};
use crate::error::Result;
use crate::expr::Quantity;

/// The keys of `model = "polynomial-z"`.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PolynomialZSpec {
    /// The signed density at the bottom face, cm^-3.
    pub z0_cm3: Quantity,
    /// Its change per mm of height, cm^-3 / mm.
    pub gradient_cm3_per_mm: Quantity,
    /// The quadratic coefficient, cm^-3 / mm^2 (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_cm3_per_mm2: Option<Quantity>,
}

impl BuildModel for PolynomialZSpec {
    fn build_model(&self, ctx: &ImpurityContext, keys: Keys<'_>) -> Result<Box<dyn ImpurityModel>> {
        ctx.check_z_range()?;
        Ok(Box::new(PolynomialZModel {
            z0_cm3: keys.value("z0_cm3", &self.z0_cm3)?,
            gradient_cm3_per_mm: keys.value("gradient_cm3_per_mm", &self.gradient_cm3_per_mm)?,
            quadratic_cm3_per_mm2: match &self.quadratic_cm3_per_mm2 {
                Some(q) => keys.value("quadratic_cm3_per_mm2", q)?,
                None => 0.0,
            },
            z_bottom_mm: ctx.z_bottom_mm,
        }))
    }
}

/// zeta(z) = z0 + g d + q d^2 with d = z - z_bottom_mm (cm^-3), independent of r.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PolynomialZModel {
    /// Signed density at the bottom face, cm^-3.
    pub z0_cm3: f64,
    /// Linear coefficient, cm^-3 / mm.
    pub gradient_cm3_per_mm: f64,
    /// Quadratic coefficient, cm^-3 / mm^2.
    pub quadratic_cm3_per_mm2: f64,
    /// Height of the bottom face, mm.
    pub z_bottom_mm: f64,
}

impl ImpurityModel for PolynomialZModel {
    fn name(&self) -> &'static str {
        "polynomial-z"
    }

    /// zeta = z0 + g d + q d^2, d = z - z_bottom (Horner form).
    fn density_cm3(&self, _r_mm: f64, z_mm: f64) -> f64 {
        let d = z_mm - self.z_bottom_mm;
        self.z0_cm3 + d * (self.gradient_cm3_per_mm + d * self.quadratic_cm3_per_mm2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Parameters;
    use crate::impurity::{ImpuritySpec, LinearZModel};
    use std::path::Path;

    fn ctx(parameters: Parameters) -> ImpurityContext {
        ImpurityContext {
            z_bottom_mm: 5.0,
            z_top_mm: 85.0,
            default_knots_mm: None,
            parameters,
        }
    }

    fn build(text: &str, parameters: Parameters) -> Result<Box<dyn ImpurityModel>> {
        let file = Path::new("impurity.toml");
        ImpuritySpec::from_toml_str(text, file)?.build(&ctx(parameters), file, "")
    }

    #[test]
    fn without_a_quadratic_term_it_is_the_linear_model() {
        // -1.3e10 at the bottom face (z = 5), -0.8e10 at the top (z = 85): 6.25e7 per mm.
        let m = build(
            "model = \"polynomial-z\"\nz0_cm3 = -1.3e10\ngradient_cm3_per_mm = 6.25e7\n",
            Parameters::new(),
        )
        .unwrap();
        let lin = LinearZModel::new(-1.3e10, -0.8e10, 5.0, 85.0).unwrap();
        for z in [0.0, 5.0, 30.0, 85.0, 90.0] {
            let (a, b) = (m.density_cm3(7.0, z), lin.density_cm3(7.0, z));
            assert!((a - b).abs() <= 1e-6 * b.abs(), "z {z}: {a} vs {b}");
        }
        assert_eq!(m.name(), "polynomial-z");
    }

    #[test]
    fn the_quadratic_term_and_a_parameter() {
        let mut p = Parameters::new();
        p.set("q", 1e6);
        let m = build(
            "model = \"polynomial-z\"\nz0_cm3 = -1e10\ngradient_cm3_per_mm = 0\n\
             quadratic_cm3_per_mm2 = \"q\"\n",
            p,
        )
        .unwrap();
        // d = 10 mm: -1e10 + 1e6 * 100.
        assert_eq!(m.density_cm3(0.0, 15.0), -1e10 + 1e8);
        assert_eq!(
            m.density_cm3(30.0, 5.0),
            -1e10,
            "independent of r, z0 at the bottom"
        );
    }

    #[test]
    fn bad_values_name_the_key() {
        let err = build(
            "model = \"polynomial-z\"\nz0_cm3 = \"-1e10 * nope\"\ngradient_cm3_per_mm = 0\n",
            Parameters::new(),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("z0_cm3") && err.contains("nope"), "{err}");
        let err = ImpuritySpec::from_toml_str(
            "model = \"polynomial-z\"\nz0_cm3 = 1.0\n",
            Path::new("impurity.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("gradient_cm3_per_mm"), "{err}");
    }
}
