//! Grid settings with documented defaults.

use serde::{Deserialize, Serialize};

/// How the (r, z) grid is built and refined.
///
/// Defaults: max_distance_ratio 3.0 and min_tick_distance 10 um as in the paper's
/// SolidStateDetectors.jl settings (section 5); the spacings and the front refinement are this
/// project's, chosen by measurement (reports/solver-status.md): with the depletion front located
/// inside its cell (`field/front.rs`) c12 is converged to about 0.1% on Super-Siegfried and within
/// 0.1% of the closed form on the long coax at 1 mm in the crystal and 0.25 mm across the front.
/// The paper's potential-difference refinement (`GridSettings::paper_refinement_limits`) changes
/// c12 by less than 0.2% there at 10-100x the nodes, so it is off by default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GridSettings {
    /// Largest initial spacing (mm) over the semiconductor's extent along each axis.
    pub max_spacing_semiconductor_mm: f64,
    /// Largest initial spacing (mm) elsewhere in the world.
    pub max_spacing_mm: f64,
    /// Ticks closer than this (mm) are merged and intervals are never split below it
    /// (paper: 10 um).
    pub min_tick_distance_mm: f64,
    /// Largest ratio between neighbouring spacings (paper: 3.0).
    pub max_distance_ratio: f64,
    /// Refinement passes: in pass k, every interval across which the potential changes by more
    /// than `refinement_limits[k]` times the largest contact-potential difference is halved
    /// (paper: [`GridSettings::paper_refinement_limits`]; default: none).
    pub refinement_limits: Vec<f64>,
    /// Largest spacing (mm) across the depletion front: intervals between an undepleted and a
    /// depleted semiconductor node are halved until they are at most this wide. The front is a
    /// free boundary located to the nearest node and then inside its cell (vertex of the parabola
    /// through the potential next to it, second order); on the long coax at 25 V the c12 error is
    /// 2.5e-4 at 0.05 mm, 9.8e-4 at 0.25 mm, 5.3e-3 at 0.5 mm (default 0.25 mm).
    pub front_spacing_mm: f64,
}

impl Default for GridSettings {
    fn default() -> Self {
        Self {
            max_spacing_semiconductor_mm: 1.0,
            max_spacing_mm: 4.0,
            min_tick_distance_mm: 0.01,
            max_distance_ratio: 3.0,
            refinement_limits: Vec::new(),
            front_spacing_mm: 0.25,
        }
    }
}

impl GridSettings {
    /// The paper's refinement limits (section 5): [0.2, 0.2, 0.1, 0.1, 0.1, 0.05, 0.03, 0.02, 0.01].
    pub fn paper_refinement_limits() -> Vec<f64> {
        vec![0.2, 0.2, 0.1, 0.1, 0.1, 0.05, 0.03, 0.02, 0.01]
    }

    /// Checks every field; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("`{name}` must be a positive number, got {v}"))
            }
        };
        pos(
            "max_spacing_semiconductor_mm",
            self.max_spacing_semiconductor_mm,
        )?;
        pos("max_spacing_mm", self.max_spacing_mm)?;
        pos("min_tick_distance_mm", self.min_tick_distance_mm)?;
        pos("front_spacing_mm", self.front_spacing_mm)?;
        if self.min_tick_distance_mm > self.max_spacing_semiconductor_mm.min(self.max_spacing_mm) {
            return Err("`min_tick_distance_mm` must not exceed the largest spacings".into());
        }
        if !(self.max_distance_ratio.is_finite() && self.max_distance_ratio >= 1.5) {
            return Err(format!(
                "`max_distance_ratio` must be at least 1.5, got {}",
                self.max_distance_ratio
            ));
        }
        for (k, l) in self.refinement_limits.iter().enumerate() {
            if !(l.is_finite() && *l > 0.0 && *l < 1.0) {
                return Err(format!(
                    "`refinement_limits[{k}]` must lie in (0, 1), got {l}"
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_named() {
        assert_eq!(GridSettings::default().validate(), Ok(()));
        let bad = GridSettings {
            max_distance_ratio: 1.0,
            ..GridSettings::default()
        };
        assert!(bad.validate().unwrap_err().contains("max_distance_ratio"));
        let bad = GridSettings {
            refinement_limits: vec![0.2, 1.5],
            ..GridSettings::default()
        };
        assert!(bad.validate().unwrap_err().contains("refinement_limits[1]"));
        let bad = GridSettings {
            min_tick_distance_mm: f64::NAN,
            ..GridSettings::default()
        };
        assert!(bad.validate().unwrap_err().contains("min_tick_distance_mm"));
    }
}
