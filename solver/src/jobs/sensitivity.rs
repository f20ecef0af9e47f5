//! The `sensitivity` job: c12 at one bias for constant impurity densities (the paper's
//! "impurity level sensitivity" scan, section 5; the scan itself is
//! [`crate::scan::sensitivity_scan`]).

use std::collections::BTreeMap;
use std::io::Write;

use serde::Serialize;

use super::{Device, VERSION, check_bias, device};
use crate::field::FieldSettings;
use crate::scan::{ScanPoint, sensitivity_scan};
use crate::{Detector, Error, Result};

/// Options of the `sensitivity` job.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityOptions {
    /// Bias U_B, V (positive).
    pub voltage_v: f64,
    /// Constant net impurity densities, cm^-3 (finite, at least one; positive: n-type).
    pub zetas_cm3: Vec<f64>,
    /// Field settings, already adapted to the detector.
    pub settings: FieldSettings,
}

impl SensitivityOptions {
    /// Checks the options: a positive bias ([`Error::JobOption`] `voltage`), at least one finite
    /// density (`zetas_cm3`), valid settings.
    pub fn validate(&self) -> Result<()> {
        check_bias("voltage", self.voltage_v)?;
        if self.zetas_cm3.is_empty() {
            return Err(Error::JobOption {
                option: "zetas_cm3".into(),
                value: None,
                message: "no density given".into(),
            });
        }
        if let Some(z) = self.zetas_cm3.iter().find(|z| !z.is_finite()) {
            return Err(Error::JobOption {
                option: "zetas_cm3".into(),
                value: Some(z.to_string()),
                message: "every density must be a finite number of cm^-3".into(),
            });
        }
        self.settings.validate()
    }
}

/// A finished `sensitivity` job.
#[derive(Debug, Clone)]
pub struct SensitivityRun {
    /// c12 per density, in the options' order.
    pub points: Vec<ScanPoint>,
    /// Where it ran.
    pub device: Option<Device>,
    /// Wall time, s.
    pub seconds: f64,
    /// The options it ran with.
    pub options: SensitivityOptions,
    /// The detector file.
    pub detector: String,
    /// The detector's name.
    pub detector_name: String,
    /// The detector's parameters.
    pub parameters: BTreeMap<String, f64>,
}

/// The record of a `sensitivity` job (`hpge-cv sensitivity --json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensitivityRecord {
    /// The densities, cm^-3.
    pub zeta_cm3: Vec<f64>,
    /// c12 at each, pF.
    #[serde(rename = "c12_pF")]
    pub c12_pf: Vec<f64>,
    /// No undepleted semiconductor at the bias, per density.
    pub fully_depleted: Vec<bool>,
    /// The bias, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: f64,
    /// The potential method.
    pub method: &'static str,
    /// The backend.
    pub backend: &'static str,
    /// Where it ran.
    pub device: Option<Device>,
    /// Wall time, s.
    pub seconds: f64,
    /// The detector file.
    pub detector: String,
    /// The detector's parameters.
    pub parameters: BTreeMap<String, f64>,
    /// The program version.
    pub version: &'static str,
}

/// Runs the `sensitivity` job: c12(U_B; zeta) for each constant density zeta(r, z) = zeta,
/// the rest of the detector unchanged. `observer(k)` is called as densities finish.
///
/// Errors: bad options, a detector without a bias contact, no adapter on the wgpu backend, a
/// failed solve ([`Error::ScanPointFailed`], naming the density).
pub fn sensitivity(
    det: &Detector,
    options: &SensitivityOptions,
    observer: &dyn Fn(usize),
) -> Result<SensitivityRun> {
    options.validate()?;
    det.check_bias_contact()?;
    let device = device(&options.settings)?;
    let start = std::time::Instant::now();
    let points = sensitivity_scan(
        det,
        options.voltage_v,
        &options.zetas_cm3,
        &options.settings,
        observer,
    )?;
    Ok(SensitivityRun {
        points,
        device,
        seconds: start.elapsed().as_secs_f64(),
        options: options.clone(),
        detector: det.file.display().to_string(),
        detector_name: det.name.clone(),
        parameters: super::parameters_of(det),
    })
}

impl SensitivityRun {
    /// The record both faces print or return.
    pub fn record(&self) -> SensitivityRecord {
        SensitivityRecord {
            zeta_cm3: self.points.iter().map(|p| p.zeta_cm3).collect(),
            c12_pf: self.points.iter().map(|p| p.c12_pf).collect(),
            fully_depleted: self.points.iter().map(|p| p.fully_depleted).collect(),
            voltage_v: self.options.voltage_v,
            method: self.options.settings.method.as_str(),
            backend: self.options.settings.backend.as_str(),
            device: self.device.clone(),
            seconds: self.seconds,
            detector: self.detector.clone(),
            parameters: self.parameters.clone(),
            version: VERSION,
        }
    }

    /// The scan as CSV: `zeta_cm3`, `c12_pF`, `fully_depleted`.
    pub fn write_csv(&self, f: &mut impl Write) -> std::io::Result<()> {
        writeln!(f, "zeta_cm3,c12_pF,fully_depleted")?;
        for p in &self.points {
            writeln!(f, "{:e},{},{}", p.zeta_cm3, p.c12_pf, p.fully_depleted)?;
        }
        Ok(())
    }
}
