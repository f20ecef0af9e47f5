//! Solver jobs: one library call per solver command (`simulate`, `capacitance`, `field`,
//! `pulse`, `sensitivity`, `convergence`), so that the command line and the Python module are
//! two faces over the same pipeline (issue 62, item 1).
//!
//! Each job has its options declared once (a struct with `validate()`), one `run` taking the
//! detector, the options and, where the job is long, a progress observer, and a record
//! (serialisable: the JSON object both faces print or return). Jobs that write a table write it
//! here too, so that a CSV is the same from either face. Figures stay with the faces (the
//! drawing lives in `hpge-reports`, downstream of this crate).
//!
//! Errors are worded without any face's spelling: an option the job refuses is
//! [`Error::JobOption`] with the option's library name (the Python
//! argument's name, e.g. `voltage`, `phi_deg`); the command line turns it into its flag with
//! [`Error::respell`].
//!
//! # Example
//!
//! The C-V curve of the planar p-n detector at two biases, as `hpge-cv simulate --json` prints
//! it:
//!
//! ```
//! use std::path::Path;
//!
//! use hpge_solver::jobs::{SimulateOptions, simulate};
//! use hpge_solver::{Detector, FieldSettings, Parameters};
//!
//! let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/planar-pn.toml");
//! let det = Detector::from_file(&file, &Parameters::new())?;
//! let mut settings = FieldSettings::default().for_detector(&det);
//! settings.grid.adaptive = false;
//! let options = SimulateOptions { voltages_v: vec![200.0, 100.0], settings };
//! let run = simulate(&det, &options, |_, _| {})?;
//! let record = run.record();
//! assert_eq!(record.voltage_v, vec![100.0, 200.0]);
//! assert!(record.c12_pf.iter().all(|&c| c > 0.0));
//! # Ok::<(), hpge_solver::Error>(())
//! ```

mod capacitance;
mod convergence;
mod field;
mod pulse;
mod sensitivity;
mod simulate;

use std::collections::BTreeMap;

use serde::Serialize;

pub use capacitance::{CapacitanceOptions, CapacitanceRecord, ContactName, capacitance};
pub use convergence::{
    ConvergenceOptions, ConvergenceRecord, ConvergenceRowRecord, MAX_LEVELS, convergence,
};
pub use field::{FieldOptions, FieldRecord, FieldRun, V_PER_M_PER_V_PER_CM, field};
pub use pulse::{
    At, ContactSignal, DriftModelRecord, PulseOptions, PulseRecord, PulseRun, pulse,
    read_adl_parameters,
};
pub use sensitivity::{SensitivityOptions, SensitivityRecord, SensitivityRun, sensitivity};
pub use simulate::{
    GridSize, PocketRecord, SimulateOptions, SimulateRecord, Simulation, depletion_biases, simulate,
};

use crate::field::FieldSettings;
use crate::gpu::gpu_adapter;
use crate::{Detector, Error, Result};

/// The program version every record carries (the workspace's one version).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// What a single-detector record says about its detector: the detector and impurity files, the
/// parameters as evaluated, and the program version.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DetectorProvenance {
    /// The detector file as given.
    pub detector: String,
    /// The impurity-model file the detector uses.
    pub impurity_file: String,
    /// Every named parameter of the detector (`--param` overrides included).
    pub parameters: BTreeMap<String, f64>,
    /// The program version.
    pub version: &'static str,
}

impl DetectorProvenance {
    /// The provenance of `det`.
    pub fn of(det: &Detector) -> Self {
        Self {
            detector: det.file.display().to_string(),
            impurity_file: det.semiconductor.impurity_file().display().to_string(),
            parameters: parameters_of(det),
            version: VERSION,
        }
    }
}

/// Every named parameter of `det` by name, as records carry them.
fn parameters_of(det: &Detector) -> BTreeMap<String, f64> {
    det.parameters
        .iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
}

/// Where the fields of a job were solved: the wgpu adapter and the precision it ran in (the
/// cpu backend has none).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Device {
    /// Adapter name.
    pub adapter: String,
    /// Graphics API.
    pub api: String,
    /// discrete, integrated, virtual, cpu or other.
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
    /// `f64` or `f32`.
    pub precision: &'static str,
}

/// Checks `settings` and, on the wgpu backend, finds the adapter before any work (the clear
/// error where there is none comes here); `None` on the cpu backend.
///
/// Errors: settings that do not validate ([`Error::JobOption`] `method/backend`), no adapter
/// ([`Error::NoGpuAdapter`]), f64 asked of an adapter without shader-f64 ([`Error::JobOption`]
/// `gpu_precision`).
pub fn device(settings: &FieldSettings) -> Result<Option<Device>> {
    use crate::Precision;
    use crate::field::Backend;
    settings.validate().map_err(|e| Error::JobOption {
        option: "method/backend".into(),
        value: None,
        message: e.to_string(),
    })?;
    if settings.backend == Backend::Cpu {
        return Ok(None);
    }
    let a = gpu_adapter()?;
    let double = match settings.gpu_precision {
        Precision::Auto => a.shader_f64,
        Precision::F32 => false,
        Precision::F64 if a.shader_f64 => true,
        Precision::F64 => {
            return Err(Error::JobOption {
                option: "gpu_precision".into(),
                value: Some("f64".into()),
                message: format!("adapter `{}` has no shader-f64; use f32 or auto", a.name),
            });
        }
    };
    Ok(Some(Device {
        adapter: a.name,
        api: a.api,
        device_type: a.device_type,
        driver: a.driver,
        precision: if double { "f64" } else { "f32" },
    }))
}

/// Refuses a bias that is not a positive number of volts ([`Error::JobOption`] `option`).
pub(crate) fn check_bias(option: &'static str, voltage_v: f64) -> Result<()> {
    if voltage_v.is_finite() && voltage_v > 0.0 {
        Ok(())
    } else {
        Err(Error::JobOption {
            option: option.into(),
            value: Some(voltage_v.to_string()),
            message: "the bias must be a positive number of volts".into(),
        })
    }
}

/// An error bar for a record: `None` where it could not be estimated (infinite).
fn finite(err_v: Option<f64>) -> Option<f64> {
    err_v.filter(|e| e.is_finite())
}

#[cfg(test)]
mod tests;
