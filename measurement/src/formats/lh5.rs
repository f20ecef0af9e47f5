//! Pulse files in LH5, the HDF5 layout of the LEGEND data objects (as `legend-pydataobj`
//! writes them), with the same sidecar `<stem>.toml` as a `.npy` pulse file.
//!
//! # What is read
//!
//! One `.lh5` file holds the pulses of one bias, of one channel. The file must hold exactly one
//! waveform table: a group named `waveform` (anywhere, typically `ch000/raw/waveform` or
//! `raw/waveform`) with the datasets
//!
//! * `values`: 2-D [pulses, samples], float32 or float64 (an LGDO ArrayOfEqualSizedArrays), the
//!   samples in the sidecar's `charge_unit`; its `units` attribute, when present, must name the
//!   same unit;
//! * `dt`: 1-D [pulses], the sampling period of each pulse (all equal), in the unit of its
//!   `units` attribute (`ns`, `us`, `ms` or `s`; ns when absent); it must equal the sidecar's
//!   `sampling_period_ns` (relative 1e-9).
//!
//! `t0` and the other columns of the table are not used. The bias is the sidecar's `bias_V`:
//! the sidecar `<stem>.toml` is required as for `.npy` files (same keys, same checks).
//!
//! HDF5's own error printing is silenced by the `hdf5` crate; every failure of the library is a
//! [`Error::Lh5`] naming the file, the dataset and the reason.

use std::path::Path;

use hdf5::types::{FloatSize, TypeDescriptor, VarLenAscii, VarLenUnicode};

use super::sidecar;
use crate::error::{Error, Result};
use crate::types::PulseSet;

/// Name of the waveform table's group.
const WAVEFORM: &str = "waveform";

/// Nanoseconds per unit of each accepted `dt` unit.
const TIME_UNITS: [(&str, f64); 6] = [
    ("ns", 1.0),
    ("us", 1e3),
    ("\u{b5}s", 1e3),
    ("\u{3bc}s", 1e3),
    ("ms", 1e6),
    ("s", 1e9),
];

/// Relative tolerance between the file's `dt` and the sidecar's `sampling_period_ns`.
const PERIOD_TOLERANCE: f64 = 1e-9;

/// Shorthand for [`Error::Lh5`].
fn lh5(file: &Path, dataset: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::Lh5 {
        file: file.to_path_buf(),
        dataset: dataset.into(),
        reason: reason.into(),
    }
}

/// Reads an LH5 pulse file and its sidecar `<stem>.toml` into pulses in pC (see the module
/// documentation for the layout).
///
/// # Errors
/// [`Error::Hdf5Open`] for a file HDF5 cannot open (not HDF5, truncated); [`Error::Lh5`] for a
/// missing or ambiguous waveform table, a missing dataset, a wrong rank or dtype, unequal `dt`,
/// units that disagree with the sidecar, a non-finite sample; the sidecar's errors as for
/// `.npy` files.
pub fn read_lh5_pulses(path: &Path) -> Result<PulseSet> {
    let checked = sidecar::read_checked(path)?;
    let file = hdf5::File::open(path).map_err(|e| Error::Hdf5Open {
        file: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let root = file
        .as_group()
        .map_err(|e| lh5(path, "/", format!("cannot open the root group: {e}")))?;
    let mut tables = Vec::new();
    find_waveform_tables(path, &root, &mut tables)?;
    let table = match tables.len() {
        1 => tables.remove(0),
        0 => {
            return Err(lh5(
                path,
                "*/waveform",
                "no waveform table: expected a group `waveform` with the datasets `values` \
                 [pulses, samples] and `dt` (e.g. ch000/raw/waveform)",
            ));
        }
        _ => {
            let names: Vec<String> = tables.iter().map(|g| g.name()).collect();
            return Err(lh5(
                path,
                "*/waveform",
                format!(
                    "{} waveform tables ({}): one .lh5 file must hold the pulses of one bias \
                     and one channel",
                    names.len(),
                    names.join(", ")
                ),
            ));
        }
    };
    let table_name = table.name();
    let values_name = format!("{table_name}/values");
    let dt_name = format!("{table_name}/dt");

    // values: 2-D float [pulses, samples].
    let values = table
        .dataset("values")
        .map_err(|e| lh5(path, &values_name, format!("missing dataset: {e}")))?;
    let shape = values.shape();
    if shape.len() != 2 {
        return Err(lh5(
            path,
            &values_name,
            format!(
                "expected a 2-D array [pulses, samples], got {} dimension(s) {shape:?}",
                shape.len()
            ),
        ));
    }
    let (n_pulses, n_samples) = (shape[0], shape[1]);
    if n_pulses < 1 || n_samples < 2 {
        return Err(lh5(
            path,
            &values_name,
            format!(
                "expected at least 1 pulse of at least 2 samples, got {n_pulses} x {n_samples}"
            ),
        ));
    }
    check_float(path, &values_name, &values)?;
    if let Some(unit) = units(path, &values_name, &values)?
        && unit != checked.sidecar.charge_unit
    {
        return Err(lh5(
            path,
            &values_name,
            format!(
                "units \"{unit}\" disagree with the sidecar's charge_unit \"{}\" ({})",
                checked.sidecar.charge_unit,
                checked.file.display()
            ),
        ));
    }
    let array = values
        .read_2d::<f64>()
        .map_err(|e| lh5(path, &values_name, format!("cannot read: {e}")))?;
    checked.check_shape(path, n_pulses, n_samples)?;
    let mut charge_pc: Vec<f64> = array.iter().copied().collect();
    if let Some(k) = charge_pc.iter().position(|q| !q.is_finite()) {
        return Err(lh5(
            path,
            &values_name,
            format!(
                "pulse {}, sample {} (0-based) is {}: every sample must be finite",
                k / n_samples,
                k % n_samples,
                charge_pc[k]
            ),
        ));
    }
    if checked.to_pc != 1.0 {
        for q in &mut charge_pc {
            *q *= checked.to_pc;
        }
    }

    // dt: 1-D [pulses], all equal, in its units.
    let dt = table
        .dataset("dt")
        .map_err(|e| lh5(path, &dt_name, format!("missing dataset: {e}")))?;
    if dt.shape() != [n_pulses] {
        return Err(lh5(
            path,
            &dt_name,
            format!(
                "expected a 1-D array of {n_pulses} sampling periods (one per pulse), got shape {:?}",
                dt.shape()
            ),
        ));
    }
    let ns_per_unit = match units(path, &dt_name, &dt)? {
        None => 1.0,
        Some(unit) => TIME_UNITS
            .iter()
            .find(|(u, _)| *u == unit)
            .map(|&(_, f)| f)
            .ok_or_else(|| {
                lh5(
                    path,
                    &dt_name,
                    format!("unknown time unit \"{unit}\": expected ns, us, ms or s"),
                )
            })?,
    };
    let periods = dt
        .read_1d::<f64>()
        .map_err(|e| lh5(path, &dt_name, format!("cannot read: {e}")))?;
    let period_ns = checked.sidecar.sampling_period_ns;
    for (p, &d) in periods.iter().enumerate() {
        let d_ns = d * ns_per_unit;
        // NaN compares false: a NaN dt is refused too.
        let agrees = (d_ns - period_ns).abs() <= PERIOD_TOLERANCE * period_ns;
        if !agrees {
            return Err(lh5(
                path,
                &dt_name,
                format!(
                    "pulse {p} (0-based): dt = {d_ns} ns disagrees with the sidecar's \
                     sampling_period_ns = {period_ns} ({})",
                    checked.file.display()
                ),
            ));
        }
    }

    Ok(PulseSet {
        bias_v: checked.sidecar.bias_v,
        sampling_period_ns: period_ns,
        n_pulses,
        n_samples,
        charge_pc,
        source: path.to_path_buf(),
    })
}

/// Collects every group named `waveform` that holds a `values` dataset, depth first.
fn find_waveform_tables(
    path: &Path,
    group: &hdf5::Group,
    out: &mut Vec<hdf5::Group>,
) -> Result<()> {
    let children = group
        .groups()
        .map_err(|e| lh5(path, group.name(), format!("cannot list the group: {e}")))?;
    for child in children {
        let name = child.name();
        if name.rsplit('/').next() == Some(WAVEFORM) && child.link_exists("values") {
            out.push(child);
        } else {
            find_waveform_tables(path, &child, out)?;
        }
    }
    Ok(())
}

/// Checks that a dataset holds float32 or float64 numbers.
fn check_float(path: &Path, name: &str, ds: &hdf5::Dataset) -> Result<()> {
    let descriptor = ds
        .dtype()
        .and_then(|t| t.to_descriptor())
        .map_err(|e| lh5(path, name, format!("cannot read the element type: {e}")))?;
    match descriptor {
        TypeDescriptor::Float(FloatSize::U4 | FloatSize::U8) => Ok(()),
        other => Err(lh5(
            path,
            name,
            format!("expected float32 or float64 samples, got {other}"),
        )),
    }
}

/// The `units` attribute of a dataset, if it has one (a string, variable or fixed length).
fn units(path: &Path, name: &str, ds: &hdf5::Dataset) -> Result<Option<String>> {
    if !ds
        .attr_names()
        .is_ok_and(|n| n.iter().any(|a| a == "units"))
    {
        return Ok(None);
    }
    let attr = ds.attr("units").map_err(|e| {
        lh5(
            path,
            name,
            format!("cannot open the `units` attribute: {e}"),
        )
    })?;
    let text = attr
        .read_scalar::<VarLenUnicode>()
        .map(|s| s.as_str().to_string())
        .or_else(|_| {
            attr.read_scalar::<VarLenAscii>()
                .map(|s| s.as_str().to_string())
        })
        .or_else(|_| {
            attr.read_scalar::<hdf5::types::FixedAscii<256>>()
                .map(|s| s.as_str().to_string())
        })
        .or_else(|_| {
            attr.read_scalar::<hdf5::types::FixedUnicode<256>>()
                .map(|s| s.as_str().to_string())
        })
        .map_err(|e| {
            lh5(
                path,
                name,
                format!("the `units` attribute is not a string: {e}"),
            )
        })?;
    Ok(Some(text.trim().to_string()))
}
