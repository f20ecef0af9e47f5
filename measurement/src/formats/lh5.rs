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
//! LEGEND's encoded waveforms (`values` a group with a `codec` attribute, as
//! `lh5.compression.encode` writes them) are refused with an error naming the codec: decode them
//! to floats first.
//!
//! The file is read by `hdf5-pure`, an HDF5 reader in Rust (no HDF5 C library, nothing printed
//! by it): contiguous and chunked datasets, deflate (gzip), shuffle, LZF and Fletcher-32, which
//! covers what legend-pydataobj writes by default (chunked, shuffle + gzip). Datasets behind
//! plugin filters (zstd, blosc, ...) are an error naming the filter. Every failure is an
//! [`Error::Lh5`] naming the file, the dataset and the reason.

use std::path::Path;

use hdf5_pure::{AttrValue, DType};

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
    let file_bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let file = hdf5_pure::File::open(path).map_err(|e| Error::Hdf5Open {
        file: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    // A file cut short (an interrupted copy) can still parse where its cut-off part holds
    // nothing the reader visits; the superblock's end-of-file address says how long it was
    // written (the check libhdf5 makes on opening).
    let superblock = file.superblock();
    let written = superblock
        .base_address
        .get()
        .saturating_add(superblock.eof_address);
    if file_bytes < written {
        return Err(Error::Hdf5Open {
            file: path.to_path_buf(),
            reason: format!(
                "truncated file: {file_bytes} bytes where its superblock records {written}"
            ),
        });
    }
    let mut tables = Vec::new();
    find_waveform_tables(path, &file.root(), "", &mut tables)?;
    let (table_name, table) = match tables.len() {
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
            let names: Vec<String> = tables.iter().map(|(name, _)| name.clone()).collect();
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
    let values_name = format!("{table_name}/values");
    let dt_name = format!("{table_name}/dt");

    // values: 2-D float [pulses, samples].
    if let Ok(encoded) = table.group("values") {
        let codec = encoded
            .attrs()
            .ok()
            .and_then(|a| a.get("codec").and_then(attr_text))
            .unwrap_or_else(|| "unknown".to_string());
        return Err(lh5(
            path,
            &values_name,
            format!(
                "LEGEND-encoded waveforms (codec {codec}) are not read: decode them to float \
                 samples in the sidecar's charge_unit first (lh5.compression.decode)"
            ),
        ));
    }
    let values = table
        .dataset("values")
        .map_err(|e| lh5(path, &values_name, format!("missing dataset: {e}")))?;
    let shape = values
        .shape()
        .map_err(|e| lh5(path, &values_name, format!("cannot read the shape: {e}")))?;
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
    let (n_pulses, n_samples) = (to_usize(shape[0]), to_usize(shape[1]));
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
    check_size(path, &values_name, n_pulses, n_samples, file_bytes)?;
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
    checked.check_shape(path, n_pulses, n_samples)?;
    let mut charge_pc = values
        .read_f64()
        .map_err(|e| lh5(path, &values_name, format!("cannot read: {e}")))?;
    if charge_pc.len() != n_pulses * n_samples {
        return Err(lh5(
            path,
            &values_name,
            format!(
                "read {} samples where the shape {n_pulses} x {n_samples} declares {}",
                charge_pc.len(),
                n_pulses * n_samples
            ),
        ));
    }
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
    let dt_shape = dt
        .shape()
        .map_err(|e| lh5(path, &dt_name, format!("cannot read the shape: {e}")))?;
    if dt_shape != [n_pulses as u64] {
        return Err(lh5(
            path,
            &dt_name,
            format!(
                "expected a 1-D array of {n_pulses} sampling periods (one per pulse), got shape \
                 {dt_shape:?}"
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
        .read_f64()
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

/// Collects every group named `waveform` that holds a member `values`, depth first, with its
/// absolute path (`/ch000/raw/waveform`).
fn find_waveform_tables(
    path: &Path,
    group: &hdf5_pure::Group,
    group_name: &str,
    out: &mut Vec<(String, hdf5_pure::Group)>,
) -> Result<()> {
    let listed = if group_name.is_empty() {
        "/"
    } else {
        group_name
    };
    let children = group
        .groups()
        .map_err(|e| lh5(path, listed, format!("cannot list the group: {e}")))?;
    for name in children {
        let child_name = format!("{group_name}/{name}");
        let child = group
            .group(&name)
            .map_err(|e| lh5(path, &child_name, format!("cannot open the group: {e}")))?;
        if name == WAVEFORM && has_member(&child, "values") {
            out.push((child_name, child));
        } else {
            find_waveform_tables(path, &child, &child_name, out)?;
        }
    }
    Ok(())
}

/// Whether a group has a dataset or a group of this name.
fn has_member(group: &hdf5_pure::Group, name: &str) -> bool {
    group.datasets().is_ok_and(|d| d.iter().any(|n| n == name))
        || group.groups().is_ok_and(|g| g.iter().any(|n| n == name))
}

/// A dimension of an HDF5 shape as `usize` (saturating: a shape too large for memory is refused
/// by [`check_size`] anyway).
fn to_usize(n: u64) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}

/// Largest ratio of decoded to stored bytes of the filters read (deflate's limit is 1032:1;
/// shuffle and Fletcher-32 keep the size, LZF compresses less).
const MAX_EXPANSION: u64 = 1032;

/// Refuses a shape that the file cannot hold even at the filters' highest compression ratio
/// (a damaged header declaring billions of samples), before memory is allocated for it.
fn check_size(
    path: &Path,
    name: &str,
    n_pulses: usize,
    n_samples: usize,
    file_bytes: u64,
) -> Result<()> {
    let bytes = (n_pulses as u64)
        .saturating_mul(n_samples as u64)
        .saturating_mul(8);
    let limit = file_bytes.saturating_mul(MAX_EXPANSION).max(1 << 20);
    if bytes > limit {
        return Err(lh5(
            path,
            name,
            format!(
                "the shape {n_pulses} x {n_samples} declares more samples than a file of \
                 {file_bytes} bytes can hold (damaged file?)"
            ),
        ));
    }
    Ok(())
}

/// Checks that a dataset holds float32 or float64 numbers.
fn check_float(path: &Path, name: &str, ds: &hdf5_pure::Dataset) -> Result<()> {
    let dtype = ds
        .dtype()
        .map_err(|e| lh5(path, name, format!("cannot read the element type: {e}")))?;
    match dtype {
        DType::F32 | DType::F64 => Ok(()),
        other => Err(lh5(
            path,
            name,
            format!("expected float32 or float64 samples, got {other}"),
        )),
    }
}

/// The text of a string attribute (fixed or variable length, ASCII or UTF-8), `None` for any
/// other type.
fn attr_text(value: &AttrValue) -> Option<String> {
    match value {
        AttrValue::String(s)
        | AttrValue::AsciiString(s)
        | AttrValue::VarLenString(s)
        | AttrValue::VarLenAsciiString(s)
        | AttrValue::StringSized { value: s, .. }
        | AttrValue::AsciiStringSized { value: s, .. } => Some(s.clone()),
        AttrValue::StringArray(v)
        | AttrValue::AsciiStringArray(v)
        | AttrValue::VarLenStringArray(v)
        | AttrValue::VarLenAsciiStringArray(v)
            if v.len() == 1 =>
        {
            Some(v[0].clone())
        }
        _ => None,
    }
}

/// The `units` attribute of a dataset, if it has one (a string, variable or fixed length).
fn units(path: &Path, name: &str, ds: &hdf5_pure::Dataset) -> Result<Option<String>> {
    let attrs = ds
        .attrs()
        .map_err(|e| lh5(path, name, format!("cannot read the attributes: {e}")))?;
    let Some(value) = attrs.get("units") else {
        return Ok(None);
    };
    let text = attr_text(value).ok_or_else(|| {
        lh5(
            path,
            name,
            format!("the `units` attribute is not a string: {value:?}"),
        )
    })?;
    Ok(Some(text.trim().to_string()))
}
