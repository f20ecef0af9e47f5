//! Pulse files: a 2-D `.npy` array [pulses, samples] with its sidecar (see [`super::sidecar`]).
//!
//! # How the `.npy` file is read
//!
//! A hybrid of `ndarray-npy` and a few lines of our own, chosen for the error messages and for
//! robustness against corrupt files:
//!
//! * the preamble (magic `\x93NUMPY`, version 1.0/2.0/3.0, header length) is checked here, so
//!   that an empty file, a wrong magic, an unknown version and a file cut inside the header each
//!   get their own message, and a corrupt header length cannot trigger a huge allocation;
//! * the header dictionary (a Python literal with `descr`, `fortran_order`, `shape`) is parsed by
//!   `ndarray_npy::npy::header::Header`, the one part worth not rewriting;
//! * dtype, order and shape are then checked here, the data length compared with the file's
//!   before anything is allocated, and the little-endian samples decoded directly.
//!
//! Reading whole arrays through `ndarray_npy::ReadNpyExt` (as f64, then f32 on a type mismatch)
//! was the alternative: its errors say neither which dimension nor how many bytes are missing
//! ("reached EOF before reading all data"), it allocates the declared size before reading, and
//! it needs the file read twice for the f32 fallback. Writing uses `ndarray_npy::WriteNpyExt`.

use std::path::Path;

use ndarray::Array2;
use ndarray_npy::WriteNpyExt;
use ndarray_npy::npy::header::{Header, Layout};

use super::files::write_file;
use super::sidecar;
use crate::error::{Error, Result};
use crate::types::PulseSet;

/// The magic string every `.npy` file starts with.
const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// The accepted element types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dtype {
    /// Little-endian float32, `<f4`.
    F32,
    /// Little-endian float64, `<f8`.
    F64,
}

impl Dtype {
    fn size(self) -> usize {
        match self {
            Dtype::F32 => 4,
            Dtype::F64 => 8,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Dtype::F32 => "float32",
            Dtype::F64 => "float64",
        }
    }
}

/// A 2-D array of finite samples as read from an `.npy` file, row-major, in the file's unit.
struct Array {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

/// Reads a pulse file `<stem>.npy` and its sidecar `<stem>.toml` into pulses in pC.
///
/// The array must be 2-D [pulses, samples], little-endian float32 or float64, C order, with at
/// least 1 pulse and 2 samples, every sample finite. The sidecar must give a finite `bias_V`
/// (V), a finite positive `sampling_period_ns` (ns) and `charge_unit` "pC" or "fC" (fC are
/// converted to pC); its optional `pulses` and `samples` must equal the array's shape. Unknown
/// sidecar keys are an error.
pub fn read_pulses(npy: &Path) -> Result<PulseSet> {
    let checked = sidecar::read_checked(npy)?;
    let array = read_array(npy)?;
    checked.check_shape(npy, array.rows, array.cols)?;
    let mut charge_pc = array.data;
    if checked.to_pc != 1.0 {
        for q in &mut charge_pc {
            *q *= checked.to_pc;
        }
    }
    Ok(PulseSet {
        bias_v: checked.sidecar.bias_v,
        sampling_period_ns: checked.sidecar.sampling_period_ns,
        n_pulses: array.rows,
        n_samples: array.cols,
        charge_pc,
        source: npy.to_path_buf(),
    })
}

/// Writes `set` as a pulse file `npy` (float32 if `single_precision`, else float64; C order)
/// and its sidecar `<stem>.toml` (`bias_V`, `sampling_period_ns`, `charge_unit = "pC"`,
/// `pulses`, `samples`), so that [`read_pulses`] reads it back.
///
/// The set is checked first (shape consistent with the data, at least 1 pulse and 2 samples,
/// finite bias, finite positive period, finite samples, also after rounding to float32), so a
/// file that cannot be read back is never written.
pub fn write_pulses(npy: &Path, set: &PulseSet, single_precision: bool) -> Result<()> {
    check_set(npy, set)?;
    let shape = (set.n_pulses, set.n_samples);
    let mut bytes = Vec::new();
    let written = if single_precision {
        let data: Vec<f32> = set.charge_pc.iter().map(|&q| q as f32).collect();
        if let Some(k) = data.iter().position(|q| !q.is_finite()) {
            return Err(argument(
                npy,
                format!(
                    "pulse {}, sample {} (0-based): {:e} pC does not fit in float32",
                    k / set.n_samples,
                    k % set.n_samples,
                    set.charge_pc[k]
                ),
            ));
        }
        Array2::from_shape_vec(shape, data)
            .map_err(|e| argument(npy, e.to_string()))?
            .write_npy(&mut bytes)
    } else {
        Array2::from_shape_vec(shape, set.charge_pc.clone())
            .map_err(|e| argument(npy, e.to_string()))?
            .write_npy(&mut bytes)
    };
    written.map_err(|e| Error::format(npy, format!("cannot encode the .npy array: {e}")))?;
    write_file(npy, &bytes)?;
    sidecar::write(
        npy,
        set.bias_v,
        set.sampling_period_ns,
        set.n_pulses,
        set.n_samples,
    )
}

/// An invalid pulse set handed to [`write_pulses`].
fn argument(npy: &Path, message: String) -> Error {
    Error::Argument {
        name: "set".to_string(),
        message: format!("cannot write {}: {message}", npy.display()),
    }
}

fn check_set(npy: &Path, set: &PulseSet) -> Result<()> {
    let expected = set.n_pulses.checked_mul(set.n_samples);
    if expected != Some(set.charge_pc.len()) {
        return Err(argument(
            npy,
            format!(
                "{} pulses x {} samples, but {} charges",
                set.n_pulses,
                set.n_samples,
                set.charge_pc.len()
            ),
        ));
    }
    if set.n_pulses < 1 || set.n_samples < 2 {
        return Err(argument(
            npy,
            format!(
                "{} pulses x {} samples: at least 1 pulse of 2 samples is needed",
                set.n_pulses, set.n_samples
            ),
        ));
    }
    if !set.bias_v.is_finite() {
        return Err(argument(
            npy,
            format!("bias {} V is not finite", set.bias_v),
        ));
    }
    if !(set.sampling_period_ns.is_finite() && set.sampling_period_ns > 0.0) {
        return Err(argument(
            npy,
            format!(
                "sampling period {} ns is not a finite number above 0",
                set.sampling_period_ns
            ),
        ));
    }
    if let Some(k) = set.charge_pc.iter().position(|q| !q.is_finite()) {
        return Err(argument(
            npy,
            format!(
                "pulse {}, sample {} (0-based) is {}; every sample must be finite",
                k / set.n_samples,
                k % set.n_samples,
                set.charge_pc[k]
            ),
        ));
    }
    Ok(())
}

/// Reads and checks the `.npy` array (see the module documentation).
fn read_array(npy: &Path) -> Result<Array> {
    let bytes = std::fs::read(npy).map_err(|source| Error::Io {
        file: npy.to_path_buf(),
        action: "cannot read the pulse file",
        source,
    })?;
    let header_end = check_preamble(npy, &bytes)?;
    let header = Header::from_reader(&mut &bytes[..header_end])
        .map_err(|e| Error::format(npy, format!("malformed .npy header ({e})")))?;
    let dtype = dtype(npy, &header)?;
    if matches!(header.layout, Layout::Fortran) {
        return Err(Error::format(
            npy,
            "the array is stored in Fortran order; save it in C order \
             (numpy.ascontiguousarray) as [pulses, samples]",
        ));
    }
    let [rows, cols] = header.shape[..] else {
        return Err(Error::format(
            npy,
            format!(
                "expected a 2-D array [pulses, samples], got a {}-D array of shape {}",
                header.shape.len(),
                shape_text(&header.shape)
            ),
        ));
    };
    if rows < 1 || cols < 2 {
        return Err(Error::invalid(
            npy,
            "shape",
            format!(
                "{rows} pulses x {cols} samples: at least 1 pulse of at least 2 samples is needed"
            ),
        ));
    }
    let data = &bytes[header_end..];
    let needed = rows
        .checked_mul(cols)
        .and_then(|n| n.checked_mul(dtype.size()));
    match needed {
        Some(needed) if data.len() == needed => {}
        Some(needed) if data.len() < needed => {
            return Err(Error::format(
                npy,
                format!(
                    "truncated data: the header declares {rows} x {cols} {} samples ({needed} \
                     bytes), the file holds only {} bytes of data",
                    dtype.name(),
                    data.len()
                ),
            ));
        }
        Some(needed) => {
            return Err(Error::format(
                npy,
                format!(
                    "{} unexpected bytes after the {rows} x {cols} {} samples the header declares",
                    data.len() - needed,
                    dtype.name()
                ),
            ));
        }
        None => {
            return Err(Error::format(
                npy,
                format!("the shape {} is too large", shape_text(&header.shape)),
            ));
        }
    }
    let values: Vec<f64> = match dtype {
        Dtype::F32 => data
            .chunks_exact(4)
            .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            .collect(),
        Dtype::F64 => data
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
            .collect(),
    };
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            npy,
            format!("pulse {}, sample {}", k / cols, k % cols),
            format!(
                "the sample is {}; every sample must be finite (indices are 0-based)",
                values[k]
            ),
        ));
    }
    Ok(Array {
        rows,
        cols,
        data: values,
    })
}

/// Checks magic, version and header length; returns the offset where the data start.
fn check_preamble(npy: &Path, bytes: &[u8]) -> Result<usize> {
    if bytes.is_empty() {
        return Err(Error::format(
            npy,
            "the file is empty (0 bytes); expected an .npy array",
        ));
    }
    let start = &bytes[..bytes.len().min(MAGIC.len())];
    if start != &MAGIC[..start.len()] {
        return Err(Error::format(
            npy,
            format!(
                "not an .npy file: it starts with b\"{}\", not the magic string b\"\\x93NUMPY\"",
                start.escape_ascii()
            ),
        ));
    }
    let truncated = |what: &str| {
        Error::format(
            npy,
            format!(
                "truncated in the header: the file ({} bytes) ends {what}",
                bytes.len()
            ),
        )
    };
    if bytes.len() < MAGIC.len() + 2 {
        return Err(truncated("before the format version"));
    }
    let (major, minor) = (bytes[6], bytes[7]);
    let (len_bytes, header_len): (usize, _) = match (major, minor) {
        (1, 0) => (
            2,
            bytes
                .get(8..10)
                .map(|b| usize::from(u16::from_le_bytes([b[0], b[1]]))),
        ),
        (2, 0) | (3, 0) => (
            4,
            bytes
                .get(8..12)
                .and_then(|b| usize::try_from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])).ok()),
        ),
        _ => {
            return Err(Error::format(
                npy,
                format!(
                    "unsupported .npy format version {major}.{minor} (supported: 1.0, 2.0, 3.0)"
                ),
            ));
        }
    };
    let Some(header_len) = header_len else {
        return Err(truncated("inside the header length"));
    };
    let header_end = (8 + len_bytes).saturating_add(header_len);
    if header_end > bytes.len() {
        return Err(truncated(&format!(
            "inside the header, which declares {header_len} bytes of header dictionary \
             ({header_end} bytes in all)"
        )));
    }
    Ok(header_end)
}

/// The accepted dtype of a header, or an error naming the one found.
fn dtype(npy: &Path, header: &Header) -> Result<Dtype> {
    let expected = "the samples must be float32 or float64 ('<f4' or '<f8')";
    let Some(descr) = header.type_descriptor.as_string() else {
        return Err(Error::format(
            npy,
            format!(
                "unsupported structured dtype {}: {expected}",
                header.type_descriptor
            ),
        ));
    };
    match descr.as_str() {
        "<f4" => Ok(Dtype::F32),
        "<f8" => Ok(Dtype::F64),
        ">f4" | ">f8" => Err(Error::format(
            npy,
            format!("big-endian dtype '{descr}' is not supported: {expected}, little-endian"),
        )),
        d if matches!(
            d.trim_start_matches(['<', '>', '|', '=']).chars().next(),
            Some('i' | 'u' | 'b' | '?')
        ) =>
        {
            Err(Error::format(
                npy,
                format!("integer or boolean dtype '{descr}' is not supported: {expected}"),
            ))
        }
        _ => Err(Error::format(
            npy,
            format!("unsupported dtype '{descr}': {expected}"),
        )),
    }
}

/// A shape as numpy prints it: `(3,)`, `(2, 3, 4)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}
