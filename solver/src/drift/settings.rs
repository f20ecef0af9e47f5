//! Settings of a drift with documented defaults.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// How carriers are drifted and signals sampled.
///
/// Step control: the midpoint (second-order Runge-Kutta) step dt is the smallest of
/// `max_step_ns` and `step_fraction` times the local cell size over the speed, so a step never
/// crosses more than a fraction of a cell of the bilinear field (whose gradient jumps at cell
/// edges, so a higher-order method would not be more accurate). Exits from the crystal are
/// located by bisection to `boundary_tol_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DriftSettings {
    /// Largest drift time, ns; a carrier still moving then stops with `StopReason::MaxTime`
    /// (default 20000 ns, far beyond the < 1 us collection of a depleted HPGe detector).
    pub max_time_ns: f64,
    /// Largest time step, ns (default 1 ns).
    pub max_step_ns: f64,
    /// Largest step as a fraction of the smaller side of the local grid cell (default 0.2).
    pub step_fraction: f64,
    /// Distance (mm) to which the point where a carrier leaves the crystal is located
    /// (default 1e-4 mm).
    pub boundary_tol_mm: f64,
    /// Sampling interval of the signals, ns (default 1 ns).
    pub sample_ns: f64,
    /// Largest number of steps per carrier (default 1_000_000): a guard against stagnation.
    pub max_steps: usize,
}

impl Default for DriftSettings {
    fn default() -> Self {
        Self {
            max_time_ns: 20_000.0,
            max_step_ns: 1.0,
            step_fraction: 0.2,
            boundary_tol_mm: 1e-4,
            sample_ns: 1.0,
            max_steps: 1_000_000,
        }
    }
}

impl DriftSettings {
    /// Checks every field; the message names the field.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("max_time_ns", self.max_time_ns),
            ("max_step_ns", self.max_step_ns),
            ("step_fraction", self.step_fraction),
            ("boundary_tol_mm", self.boundary_tol_mm),
            ("sample_ns", self.sample_ns),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid_value(
                    "drift settings",
                    format!("`{name}` must be a positive number, got {v}"),
                ));
            }
        }
        if self.step_fraction > 1.0 {
            return Err(Error::invalid_value(
                "drift settings",
                format!(
                    "`step_fraction` must not exceed 1, got {}",
                    self.step_fraction
                ),
            ));
        }
        if self.max_steps == 0 {
            return Err(Error::invalid_value(
                "drift settings",
                "`max_steps` must be at least 1",
            ));
        }
        if self.max_time_ns / self.sample_ns > 1e8 {
            return Err(Error::invalid_value(
                "drift settings",
                format!(
                    "`max_time_ns` / `sample_ns` = {:e} samples is too many (at most 1e8)",
                    self.max_time_ns / self.sample_ns
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_valid_and_bad_values_named() {
        assert!(DriftSettings::default().validate().is_ok());
        let bad = DriftSettings {
            step_fraction: 2.0,
            ..DriftSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("step_fraction")
        );
        let bad = DriftSettings {
            sample_ns: f64::NAN,
            ..DriftSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("sample_ns")
        );
        let bad = DriftSettings {
            max_steps: 0,
            ..DriftSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("max_steps")
        );
    }
}
