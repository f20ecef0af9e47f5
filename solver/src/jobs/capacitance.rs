//! The `capacitance` job: the full Maxwell capacitance matrix at one bias.

use serde::Serialize;

use super::{Device, VERSION, check_bias, device};
use crate::field::{FieldSettings, solve_point};
use crate::{Detector, Result};

/// Options of the `capacitance` job.
#[derive(Debug, Clone, PartialEq)]
pub struct CapacitanceOptions {
    /// Bias U_B, V (positive).
    pub voltage_v: f64,
    /// Field settings, already adapted to the detector.
    pub settings: FieldSettings,
}

impl CapacitanceOptions {
    /// Checks the options: a positive bias ([`crate::Error::JobOption`] `voltage`) and valid
    /// settings.
    pub fn validate(&self) -> Result<()> {
        check_bias("voltage", self.voltage_v)?;
        self.settings.validate()
    }
}

/// One contact of the detector, as records name it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactName {
    /// The contact's id in the detector file.
    pub id: u32,
    /// Its name.
    pub name: String,
}

/// The record of a `capacitance` job (`hpge-cv capacitance --json`; `hpge_cv.capacitance`
/// returns the same keys, the matrices as 2-D numpy arrays).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CapacitanceRecord {
    /// The bias, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: f64,
    /// The contacts, in the matrices' order.
    pub contacts: Vec<ContactName>,
    /// The Maxwell matrix C* from the energy form, pF (Q = C* U).
    #[serde(rename = "maxwell_pF")]
    pub maxwell_pf: Vec<Vec<f64>>,
    /// The same from the charges on the contacts, pF.
    #[serde(rename = "maxwell_from_charges_pF")]
    pub maxwell_from_charges_pf: Vec<Vec<f64>>,
    /// c12 = -C*_12, pF.
    #[serde(rename = "c12_pF")]
    pub c12_pf: f64,
    /// Its estimated error, pF.
    #[serde(rename = "c12_err_pF")]
    pub c12_err_pf: f64,
    /// Adaptive passes.
    pub adaptive_passes: usize,
    /// Whether the estimate is within the tolerance.
    pub tolerance_reached: bool,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: bool,
    /// The final grid.
    pub grid: super::GridSize,
    /// The potential method.
    pub method: &'static str,
    /// The weighting-potential mode.
    pub weighting: &'static str,
    /// The backend.
    pub backend: &'static str,
    /// Where it ran (null on the cpu backend).
    pub device: Option<Device>,
    /// The detector file.
    pub detector: String,
    /// The program version.
    pub version: &'static str,
}

/// Runs the `capacitance` job: one adaptive solve at the bias (`field::solve_point`), the
/// Maxwell matrix in both forms and c12 = -C*_12 with its error estimate.
///
/// Errors: bad options, a detector without a bias contact, no adapter on the wgpu backend, the
/// solver's.
pub fn capacitance(det: &Detector, options: &CapacitanceOptions) -> Result<CapacitanceRecord> {
    options.validate()?;
    det.check_bias_contact()?;
    let settings = &options.settings;
    let device = device(settings)?;
    let p = solve_point(det, options.voltage_v, settings, None)?;
    Ok(CapacitanceRecord {
        voltage_v: options.voltage_v,
        contacts: det
            .contacts
            .iter()
            .map(|c| ContactName {
                id: c.id,
                name: c.name.clone(),
            })
            .collect(),
        maxwell_pf: p.capacitance.energy_pf.clone(),
        maxwell_from_charges_pf: p.capacitance.charge_pf.clone(),
        c12_pf: p.c12_pf,
        c12_err_pf: p.accuracy.c12_err_pf,
        adaptive_passes: p.accuracy.passes,
        tolerance_reached: p.accuracy.reached,
        fully_depleted: p.fully_depleted(),
        grid: super::GridSize {
            nr: p.mesh.grid.nr(),
            nz: p.mesh.grid.nz(),
        },
        method: settings.method.as_str(),
        weighting: settings.weighting.as_str(),
        backend: settings.backend.as_str(),
        device,
        detector: det.file.display().to_string(),
        version: VERSION,
    })
}
