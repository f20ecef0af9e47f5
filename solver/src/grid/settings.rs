//! Grid settings with documented defaults.

use crate::error::{Error, Result};
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
    /// Refine each point until the estimated relative error of c12 is below `tolerance`
    /// (`field::adaptive`: the larger difference to the same problem on the two grids with every
    /// other non-geometry tick removed, odd or even ones; intervals split where the weighting
    /// potentials change most and across the depletion front).
    /// Off: c12 on the grid above, with its estimate all the same.
    pub adaptive: bool,
    /// Target relative error of c12 for the adaptive refinement (default 0.2%, issue 18: the
    /// 4x-finer reference is then within 0.3% on every shipped detector type).
    pub tolerance: f64,
    /// Largest number of adaptive refinement passes per point; a point that has not reached
    /// `tolerance` by then is an error naming the estimate.
    pub max_adaptive_passes: usize,
    /// Largest number of grid nodes the adaptive refinement may reach: a refined grid above it is
    /// not solved, and the point keeps its estimate with the tolerance not reached. The shipped
    /// detectors' fully depleted points end at up to 270 000 nodes (2-4 s); a pocket point of
    /// Super-Siegfried's space went to 451 000 nodes and 128 s without it.
    pub max_nodes: usize,
}

/// Smallest `tolerance` accepted: below it the estimate is dominated by the solvers' own
/// stopping tolerances and round-off, not by the grid.
pub const MIN_TOLERANCE: f64 = 1e-6;

impl Default for GridSettings {
    fn default() -> Self {
        Self {
            max_spacing_semiconductor_mm: 1.0,
            max_spacing_mm: 4.0,
            min_tick_distance_mm: 0.01,
            max_distance_ratio: 3.0,
            refinement_limits: Vec::new(),
            front_spacing_mm: 0.25,
            adaptive: true,
            tolerance: 2e-3,
            max_adaptive_passes: 10,
            max_nodes: 300_000,
        }
    }
}

impl GridSettings {
    /// The paper's refinement limits (section 5): [0.2, 0.2, 0.1, 0.1, 0.1, 0.05, 0.03, 0.02, 0.01].
    pub fn paper_refinement_limits() -> Vec<f64> {
        vec![0.2, 0.2, 0.1, 0.1, 0.1, 0.05, 0.03, 0.02, 0.01]
    }

    /// These settings with some keys replaced: each `(key, value)` names a field of the `[grid]`
    /// table and gives its value in TOML syntax (`front_spacing_mm`, `0.1`; `adaptive`, `false`;
    /// `refinement_limits`, `[0.2, 0.1]`), as `--grid KEY=VALUE` does. Unknown keys, values of
    /// the wrong type and invalid results are errors naming the key.
    pub fn with_overrides(&self, overrides: &[(String, String)]) -> Result<GridSettings> {
        let mut table = toml::Table::try_from(self)
            .map_err(|e| Error::invalid_value("grid settings", e.to_string()))?;
        for (key, text) in overrides {
            if !table.contains_key(key) {
                let known: Vec<&str> = table.keys().map(String::as_str).collect();
                return Err(Error::invalid_value(
                    "grid settings",
                    format!("unknown grid key `{key}` (known: {})", known.join(", ")),
                ));
            }
            let v: toml::Table = toml::from_str(&format!("v = {text}")).map_err(|_| {
                Error::invalid_value(
                    "grid settings",
                    format!("`{key}`: `{text}` is not a TOML value"),
                )
            })?;
            table.insert(key.clone(), v["v"].clone());
        }
        let out: GridSettings = table.try_into().map_err(|e: toml::de::Error| {
            Error::invalid_value("grid settings", e.message().to_string())
        })?;
        out.validate()?;
        Ok(out)
    }

    /// Checks every field; the message names the field.
    pub fn validate(&self) -> Result<()> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid_value(
                    "grid settings",
                    format!("`{name}` must be a positive number, got {v}"),
                ))
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
            return Err(Error::invalid_value(
                "grid settings",
                "`min_tick_distance_mm` must not exceed the largest spacings",
            ));
        }
        if !(self.max_distance_ratio.is_finite() && self.max_distance_ratio >= 1.5) {
            return Err(Error::invalid_value(
                "grid settings",
                format!(
                    "`max_distance_ratio` must be at least 1.5, got {}",
                    self.max_distance_ratio
                ),
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance >= MIN_TOLERANCE && self.tolerance < 1.0)
        {
            return Err(Error::invalid_value(
                "grid settings",
                format!(
                    "`tolerance` (relative error of c12) must lie in [{MIN_TOLERANCE:e}, 1), got {}",
                    self.tolerance
                ),
            ));
        }
        if self.max_adaptive_passes == 0 {
            return Err(Error::invalid_value(
                "grid settings",
                "`max_adaptive_passes` must be at least 1",
            ));
        }
        if self.max_nodes < 100 {
            return Err(Error::invalid_value(
                "grid settings",
                format!("`max_nodes` must be at least 100, got {}", self.max_nodes),
            ));
        }
        for (k, l) in self.refinement_limits.iter().enumerate() {
            if !(l.is_finite() && *l > 0.0 && *l < 1.0) {
                return Err(Error::invalid_value(
                    "grid settings",
                    format!("`refinement_limits[{k}]` must lie in (0, 1), got {l}"),
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
        assert!(GridSettings::default().validate().is_ok());
        let bad = GridSettings {
            max_distance_ratio: 1.0,
            ..GridSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("max_distance_ratio")
        );
        let bad = GridSettings {
            refinement_limits: vec![0.2, 1.5],
            ..GridSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("refinement_limits[1]")
        );
        let bad = GridSettings {
            min_tick_distance_mm: f64::NAN,
            ..GridSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("min_tick_distance_mm")
        );
        for t in [0.0, -1e-3, 1e-9, f64::NAN, 1.0] {
            let bad = GridSettings {
                tolerance: t,
                ..GridSettings::default()
            };
            assert!(
                bad.validate()
                    .unwrap_err()
                    .to_string()
                    .contains("tolerance"),
                "{t}"
            );
        }
    }

    #[test]
    fn overrides_by_key() {
        let kv = |k: &str, v: &str| (k.to_string(), v.to_string());
        let g = GridSettings::default()
            .with_overrides(&[
                kv("front_spacing_mm", "0.1"),
                kv("adaptive", "false"),
                kv("refinement_limits", "[0.2, 0.1]"),
            ])
            .unwrap();
        assert_eq!(g.front_spacing_mm, 0.1);
        assert!(!g.adaptive);
        assert_eq!(g.refinement_limits, vec![0.2, 0.1]);
        let e = GridSettings::default()
            .with_overrides(&[kv("front_spacing", "0.1")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown grid key `front_spacing`"), "{e}");
        let e = GridSettings::default()
            .with_overrides(&[kv("adaptive", "yes")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("adaptive"), "{e}");
        let e = GridSettings::default()
            .with_overrides(&[kv("tolerance", "0")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("tolerance"), "{e}");
    }
}
