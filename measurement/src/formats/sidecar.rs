//! The sidecar of a pulse file: `<stem>.toml` next to `<stem>.npy`, holding what the array does
//! not (bias, sampling period, charge unit) and optionally its shape as a cross-check.

use std::path::{Path, PathBuf};

use super::files::{read_text, toml_message, write_file};
use crate::error::{Error, Result};
use crate::types::Sidecar;

/// Picocoulombs per unit of each accepted `charge_unit`.
const CHARGE_UNITS: [(&str, f64); 2] = [("pC", 1.0), ("fC", 1e-3)];

/// The sidecar path of a pulse file: `<stem>.toml` in the same directory.
pub(super) fn sidecar_path(npy: &Path) -> PathBuf {
    npy.with_extension("toml")
}

/// A sidecar read and checked on its own (the shape cross-check needs the array, see
/// [`Checked::check_shape`]).
#[derive(Debug, Clone)]
pub(super) struct Checked {
    /// The sidecar file.
    pub file: PathBuf,
    /// The sidecar as written.
    pub sidecar: Sidecar,
    /// Factor from the file's charge unit to pC.
    pub to_pc: f64,
}

/// Reads and validates the sidecar of `npy`: it must exist, parse (no unknown keys), have a
/// finite positive `bias_V`, a finite positive `sampling_period_ns` and `charge_unit` "pC" or "fC".
pub(super) fn read_checked(npy: &Path) -> Result<Checked> {
    let file = sidecar_path(npy);
    if !file.is_file() {
        return Err(Error::format(
            npy,
            format!(
                "missing sidecar: expected {} (with bias_V, sampling_period_ns, charge_unit) next \
                 to the pulse file",
                file.display()
            ),
        ));
    }
    let text = read_text(&file)?;
    let sidecar: Sidecar = toml::from_str(&text).map_err(|e| {
        Error::format(
            &file,
            format!("invalid sidecar: {}", toml_message(&text, &e)),
        )
    })?;
    if !(sidecar.bias_v.is_finite() && sidecar.bias_v > 0.0) {
        return Err(Error::invalid(
            &file,
            "bias_V",
            format!(
                "the bias must be a finite number of volts above 0 (the reverse bias U_B, \
                 positive by this program's convention), got {}",
                sidecar.bias_v
            ),
        ));
    }
    let period = sidecar.sampling_period_ns;
    if !(period.is_finite() && period > 0.0) {
        return Err(Error::invalid(
            &file,
            "sampling_period_ns",
            format!("the sampling period must be a finite number of ns above 0, got {period}"),
        ));
    }
    let Some(&(_, to_pc)) = CHARGE_UNITS
        .iter()
        .find(|(unit, _)| *unit == sidecar.charge_unit)
    else {
        return Err(Error::invalid(
            &file,
            "charge_unit",
            format!(
                "unknown charge unit \"{}\": expected \"pC\" or \"fC\"",
                sidecar.charge_unit
            ),
        ));
    };
    Ok(Checked {
        file,
        sidecar,
        to_pc,
    })
}

impl Checked {
    /// Checks the optional `pulses` and `samples` against the array's shape.
    pub fn check_shape(&self, npy: &Path, n_pulses: usize, n_samples: usize) -> Result<()> {
        let array = npy.file_name().map_or_else(
            || npy.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let checks = [
            ("pulses", self.sidecar.pulses, n_pulses),
            ("samples", self.sidecar.samples, n_samples),
        ];
        for (key, declared, actual) in checks {
            if let Some(declared) = declared
                && declared != actual
            {
                return Err(Error::invalid(
                    &self.file,
                    key,
                    format!("sidecar says {declared} {key}, the array in {array} has {actual}"),
                ));
            }
        }
        Ok(())
    }
}

/// Writes the sidecar of `npy` for pulses in pC with the given shape.
pub(super) fn write(
    npy: &Path,
    bias_v: f64,
    sampling_period_ns: f64,
    n_pulses: usize,
    n_samples: usize,
) -> Result<()> {
    let file = sidecar_path(npy);
    let sidecar = Sidecar {
        bias_v,
        sampling_period_ns,
        charge_unit: "pC".to_string(),
        pulses: Some(n_pulses),
        samples: Some(n_samples),
    };
    let text = toml::to_string(&sidecar)
        .map_err(|e| Error::format(&file, format!("cannot format the sidecar: {e}")))?;
    write_file(&file, text.as_bytes())
}

/// The bias of a sidecar read loosely (any other key may be wrong or missing), V; for naming
/// the bias of a pulse file that could not be read.
pub(super) fn loose_bias_v(sidecar: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(sidecar).ok()?;
    let table: toml::Table = toml::from_str(&text).ok()?;
    match table.get("bias_V")? {
        toml::Value::Float(v) if v.is_finite() => Some(*v),
        toml::Value::Integer(v) => Some(*v as f64),
        _ => None,
    }
}
