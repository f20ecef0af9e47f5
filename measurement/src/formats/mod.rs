//! The file formats of the measurement side, and the one function that validates both kinds of
//! input ([`load_data`]).
//!
//! * Raw data: a directory of pulse files, one per bias: `<stem>.npy` (a 2-D little-endian
//!   float32/float64 array [pulses, samples], C order) with its sidecar `<stem>.toml`
//!   ([`crate::Sidecar`]: `bias_V`, `sampling_period_ns`, `charge_unit`, optional `pulses`,
//!   `samples`). The directory may hold the run's settings `measurement.toml`, whose optional
//!   top-level `voltages_V` array lists the biases expected to have a pulse file. See
//!   [`read_pulses`], [`write_pulses`], [`read_raw_dir`].
//! * Raw data in LH5: `<stem>.lh5` instead of `<stem>.npy` (HDF5 as `legend-pydataobj` writes a
//!   waveform table, one file per bias), with the same sidecar `<stem>.toml`. See
//!   [`read_lh5_pulses`]; [`read_pulse_file`] reads either kind, [`read_raw_dir`] both kinds in
//!   one directory, or one `.lh5` file given instead of a directory.
//! * A C-V curve: a CSV `voltage_V,c12_pF,sigma_pF` (lines starting with `#` are comments), with
//!   an optional covariance `<stem>.covariance.csv` (pF^2). See [`read_curve`], [`write_curve`].
//!
//! Every error names the file and, where it applies, the key, column, line or pulse at fault.

pub(crate) mod curve;
mod files;
mod lh5;
mod npy;
mod raw_dir;
mod sidecar;

use std::path::Path;

pub use curve::{
    covariance_path, curve_texts, read_curve, read_model_curve, write_curve,
    write_curve_with_comments,
};
pub use lh5::read_lh5_pulses;
pub use npy::{read_pulses, write_pulses};
pub use raw_dir::{PulseFormat, RawProblem, RawRun, read_pulse_file, read_raw_dir};

use files::{MEASUREMENT_FILE, read_text, toml_message};

use crate::error::{Error, Result};
use crate::types::CvData;

/// Either kind of measured input, as found by [`load_data`].
#[derive(Debug, Clone)]
pub enum Data {
    /// A directory of raw pulse files (one [`crate::PulseSet`] per bias).
    Raw(RawRun),
    /// A C-V curve (c12 in pF per bias in V), with its covariance if one was found.
    Curve(CvData),
}

/// Reads and validates measured input of either kind.
///
/// * A directory is a raw run: [`read_raw_dir`], with the expected biases taken from the
///   top-level `voltages_V` array (V) of `<dir>/measurement.toml` when that file exists and has
///   the key (other keys of that file are ignored here).
/// * A `.csv` file is a C-V curve: [`read_curve`], with `<stem>.covariance.csv` read when it
///   exists.
/// * Anything else is an error saying what was expected.
pub fn load_data(path: &Path) -> Result<Data> {
    let meta = std::fs::metadata(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        action: "cannot open the measured data (a raw-data directory or a .csv C-V curve)",
        source,
    })?;
    if meta.is_dir() {
        let expected = expected_voltages(&path.join(MEASUREMENT_FILE))?;
        return read_raw_dir(path, expected.as_deref()).map(Data::Raw);
    }
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("csv") => read_curve(path, None).map(Data::Curve),
        Some("lh5") => read_raw_dir(path, None).map(Data::Raw),
        Some("npy") => Err(Error::format(
            path,
            "a single pulse file is not a measurement: pass the directory that holds the pulse \
             files (<stem>.npy with <stem>.toml sidecars), or a .csv C-V curve",
        )),
        _ => Err(Error::format(
            path,
            "unknown kind of measured data: expected a directory of raw pulse files \
             (<stem>.npy with <stem>.toml sidecars) or a C-V curve with the extension .csv",
        )),
    }
}

/// The `voltages_V` array of a run's `measurement.toml`, V; `None` when the file or the key is
/// absent. The file is parsed loosely: other keys are ignored.
fn expected_voltages(file: &Path) -> Result<Option<Vec<f64>>> {
    if !file.is_file() {
        return Ok(None);
    }
    let text = read_text(file)?;
    let table: toml::Table =
        toml::from_str(&text).map_err(|e| Error::format(file, toml_message(&text, &e)))?;
    let Some(value) = table.get("voltages_V") else {
        return Ok(None);
    };
    let Some(items) = value.as_array() else {
        return Err(Error::invalid(
            file,
            "voltages_V",
            format!(
                "must be an array of bias voltages in V, not a TOML {}",
                value.type_str()
            ),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(k, item)| match item {
            toml::Value::Float(v) => Ok(*v),
            toml::Value::Integer(v) => Ok(*v as f64),
            other => Err(Error::invalid(
                file,
                format!("voltages_V[{k}]"),
                format!("must be a number (V), not a TOML {}", other.type_str()),
            )),
        })
        .collect::<Result<Vec<f64>>>()
        .map(Some)
}
