//! The `z-table` model: a density along z through a table (e.g. a LEGEND record's profile).

use super::model::ImpurityModel;
use super::spec::{BuildModel, ImpurityContext, Keys};
use crate::error::Result;
use crate::expr::Quantity;

/// The keys of `model = "z-table"`.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ZTableSpec {
    /// Heights in mm (strictly increasing).
    pub z_mm: Vec<f64>,
    /// The signed density (cm^-3) at each of `z_mm`.
    pub values_cm3: Vec<Quantity>,
}

impl BuildModel for ZTableSpec {
    fn build_model(
        &self,
        _ctx: &ImpurityContext,
        keys: Keys<'_>,
    ) -> Result<Box<dyn ImpurityModel>> {
        let z = &self.z_mm;
        if z.len() != self.values_cm3.len() || z.is_empty() {
            return Err(keys.err(
                "values_cm3",
                format!(
                    "has {} values for {} heights in `z_mm` (need the same number, at least one)",
                    self.values_cm3.len(),
                    z.len()
                ),
            ));
        }
        for (i, &x) in z.iter().enumerate() {
            keys.finite(&format!("z_mm[{i}]"), x)?;
            if i > 0 && x <= z[i - 1] {
                return Err(keys.err(
                    &format!("z_mm[{i}]"),
                    format!("heights must increase: {x} mm after {} mm", z[i - 1]),
                ));
            }
        }
        let values_cm3 = keys.values("values_cm3", &self.values_cm3)?;
        Ok(Box::new(ZTableModel {
            z_mm: z.clone(),
            values_cm3,
        }))
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
}
