//! The `convergence` job: c12 at one bias against the grid resolution, with the error estimate
//! ([`crate::field::convergence_study`]).

use std::collections::BTreeMap;

use serde::Serialize;

use super::{VERSION, check_bias, device};
use crate::field::{ConvergenceRow, FieldSettings, convergence_study};
use crate::grid::GridSettings;
use crate::{Detector, Error, Result};

/// The most fixed grids a study takes (each halves the spacings: 2^8 times the nodes of the
/// first in 2D).
pub const MAX_LEVELS: usize = 8;

/// Options of the `convergence` job.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceOptions {
    /// Bias U_B, V (positive).
    pub voltage_v: f64,
    /// Fixed grids: the spacings times 2, 1, 1/2, ... (1 to [`MAX_LEVELS`]).
    pub levels: usize,
    /// Field settings, already adapted to the detector.
    pub settings: FieldSettings,
}

impl ConvergenceOptions {
    /// Checks the options: a positive bias ([`Error::JobOption`] `voltage`), 1 to 8 levels
    /// (`levels`), valid settings.
    pub fn validate(&self) -> Result<()> {
        check_bias("voltage", self.voltage_v)?;
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return Err(Error::JobOption {
                option: "levels".into(),
                value: Some(self.levels.to_string()),
                message: format!("give 1 to {MAX_LEVELS} fixed grids"),
            });
        }
        self.settings.validate()
    }
}

/// One row of a convergence record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvergenceRowRecord {
    /// Spacing scale.
    pub scale: f64,
    /// Largest spacing in the crystal, mm.
    pub spacing_mm: f64,
    /// Grid nodes.
    pub nodes: usize,
    /// c12, pF.
    #[serde(rename = "c12_pF")]
    pub c12_pf: f64,
    /// Its estimated error, pF.
    #[serde(rename = "c12_err_pF")]
    pub c12_err_pf: f64,
    /// The adaptive solve at the tolerance.
    pub adaptive: bool,
    /// Wall time, s.
    pub seconds: f64,
}

/// The record of a `convergence` job (`hpge-cv convergence --json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvergenceRecord {
    /// The detector file.
    pub detector: String,
    /// The bias, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: f64,
    /// The relative tolerance of the adaptive row.
    pub tolerance: f64,
    /// The fixed grids, coarse to fine, then the adaptive one.
    pub rows: Vec<ConvergenceRowRecord>,
    /// The grid settings.
    pub grid: GridSettings,
    /// The detector's parameters.
    pub parameters: BTreeMap<String, f64>,
    /// The program version.
    pub version: &'static str,
}

/// Runs the `convergence` job: c12 on fixed grids with the spacings times 2, 1, 1/2, ... and
/// adaptively at the tolerance, each with its error estimate. Returns the rows with the
/// record.
///
/// Errors: bad options, a detector without a bias contact, no adapter on the wgpu backend, the
/// solver's.
pub fn convergence(
    det: &Detector,
    options: &ConvergenceOptions,
) -> Result<(Vec<ConvergenceRow>, ConvergenceRecord)> {
    options.validate()?;
    det.check_bias_contact()?;
    device(&options.settings)?;
    let rows = convergence_study(det, options.voltage_v, &options.settings, options.levels)?;
    let record = ConvergenceRecord {
        detector: det.file.display().to_string(),
        voltage_v: options.voltage_v,
        tolerance: options.settings.grid.tolerance,
        rows: rows
            .iter()
            .map(|r| ConvergenceRowRecord {
                scale: r.scale,
                spacing_mm: r.spacing_mm,
                nodes: r.nodes,
                c12_pf: r.c12_pf,
                c12_err_pf: r.c12_err_pf,
                adaptive: r.adaptive,
                seconds: r.seconds,
            })
            .collect(),
        grid: options.settings.grid.clone(),
        parameters: super::parameters_of(det),
        version: VERSION,
    };
    Ok((rows, record))
}
