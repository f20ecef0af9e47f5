//! Settings of a field calculation: grid, method, weighting mode, backend.

use serde::{Deserialize, Serialize};

use super::report::{Backend, Method};
use super::weighting::WeightingMode;
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::gpu::Precision;
use crate::grid::GridSettings;

/// Settings of a field calculation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FieldSettings {
    /// Grid construction and refinement.
    pub grid: GridSettings,
    /// Potential method.
    pub method: Method,
    /// Locate the depletion front inside its cell and carry it into the weighting potentials
    /// (see `field/front.rs`); off: the front sits on nodes, as in SolidStateDetectors.jl.
    /// Used by `WeightingMode::Conductor` only.
    pub subcell_front: bool,
    /// How undepleted semiconductor enters the weighting potentials.
    pub weighting: WeightingMode,
    /// Where the potential and weighting potentials are solved; `Wgpu` runs the `Sor` method.
    pub backend: Backend,
    /// Arithmetic on the wgpu backend.
    pub gpu_precision: Precision,
}

impl Default for FieldSettings {
    fn default() -> Self {
        Self {
            grid: GridSettings::default(),
            method: Method::Fast,
            subcell_front: true,
            weighting: WeightingMode::Conductor,
            backend: Backend::Cpu,
            gpu_precision: Precision::Auto,
        }
    }
}

impl FieldSettings {
    /// These settings with the detector's `[grid]` table in force (grid and accuracy settings of
    /// that detector), where its file has one.
    pub fn for_detector(&self, det: &Detector) -> FieldSettings {
        FieldSettings {
            grid: det.grid.clone().unwrap_or_else(|| self.grid.clone()),
            ..self.clone()
        }
    }

    /// Checks all fields (the message names the field).
    pub fn validate(&self) -> Result<()> {
        self.grid
            .validate()
            .map_err(|m| Error::invalid_value("field settings", format!("grid: {m}")))?;
        if self.backend == Backend::Wgpu && self.method != Method::Sor {
            return Err(Error::invalid_value(
                "field settings",
                format!(
                    "method: the wgpu backend runs the sor method; `{}` (sparse Cholesky) runs on the cpu backend only",
                    self.method.as_str()
                ),
            ));
        }
        Ok(())
    }
}
