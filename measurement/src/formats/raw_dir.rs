//! A raw-data directory: one pulse file (`<stem>.npy` or `<stem>.lh5`, + `<stem>.toml`) per
//! bias, whatever the format: the analysis sees only [`PulseSet`]s.

use std::path::{Path, PathBuf};

use super::files::{MEASUREMENT_FILE, VOLTAGE_TOLERANCE_V};
use super::lh5::read_lh5_pulses;
use super::npy::read_pulses;
use super::sidecar;
use crate::error::{Error, Result};
use crate::measure::Problem;
use crate::types::PulseSet;

/// The formats of a pulse file, by extension; each has the sidecar `<stem>.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PulseFormat {
    /// `<stem>.npy`: a 2-D array [pulses, samples] ([`read_pulses`]).
    Npy,
    /// `<stem>.lh5`: an HDF5 file with a LEGEND waveform table ([`read_lh5_pulses`]).
    Lh5,
}

impl PulseFormat {
    /// Every format, in the order their extensions are tried.
    pub const ALL: [PulseFormat; 2] = [PulseFormat::Npy, PulseFormat::Lh5];

    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            PulseFormat::Npy => "npy",
            PulseFormat::Lh5 => "lh5",
        }
    }

    /// The format of a file by its extension (case-insensitive), if it is a pulse file.
    pub fn of(path: &Path) -> Option<PulseFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        PulseFormat::ALL.into_iter().find(|f| f.extension() == ext)
    }
}

/// Reads a pulse file of either format (by extension) with its sidecar into pulses in pC.
///
/// # Errors
/// Those of [`read_pulses`] or [`read_lh5_pulses`]; a file with another extension is an
/// [`Error::Format`].
pub fn read_pulse_file(path: &Path) -> Result<PulseSet> {
    match PulseFormat::of(path) {
        Some(PulseFormat::Npy) => read_pulses(path),
        Some(PulseFormat::Lh5) => read_lh5_pulses(path),
        None => Err(Error::format(
            path,
            "not a pulse file: expected the extension .npy or .lh5",
        )),
    }
}

/// The pulse files of a raw-data directory, read as far as possible.
#[derive(Debug, Clone)]
pub struct RawRun {
    /// The directory.
    pub dir: PathBuf,
    /// The pulse sets that were read, sorted by increasing bias.
    pub sets: Vec<PulseSet>,
    /// What could not be used, in the order found (by file name, then the missing biases).
    pub problems: Vec<RawProblem>,
}

/// A file of a raw-data directory that could not be used, or an expected bias without data:
/// the same record as a measurement's [`Problem`] (`file`: the file at fault, the directory
/// itself for an expected bias without a pulse file; `bias_v`: from the sidecar, read loosely,
/// or from the expected voltages; `message`: for a file that failed to read, the full error),
/// so the two lists of a run chain into one.
pub type RawProblem = Problem;

/// Reads every pulse file of a directory (not recursive, in file-name order) with
/// [`read_pulse_file`]: `.npy` and `.lh5` files (see [`PulseFormat`]). `dir` may also be one
/// `.lh5` file: a run of that one bias, whose errors are returned as such.
///
/// Problems that do not stop the reading are collected in [`RawRun::problems`]: a pulse file
/// that fails to read (bad array, missing or invalid sidecar), a sidecar `<stem>.toml` without
/// its `<stem>.npy` (the run's settings file `measurement.toml` is not a sidecar), a second file
/// with the bias of an earlier one (the first is kept), and each bias of `expected_voltages_v`
/// (V, matched within 1e-6 V) without a pulse set. Other files are ignored.
///
/// Errors: the directory does not exist, is not a directory or cannot be listed, it holds no
/// readable pulse file at all (the message lists the problems), or a sidecar declares a bias that
/// is not a finite number of volts above 0 (`bias_V`: a mistake in the run's description, not an
/// unreadable file; measuring the rest would write a curve that silently lacks that bias).
pub fn read_raw_dir(dir: &Path, expected_voltages_v: Option<&[f64]>) -> Result<RawRun> {
    let io = |action: &'static str| {
        move |source: std::io::Error| Error::Io {
            file: dir.to_path_buf(),
            action,
            source,
        }
    };
    let meta = std::fs::metadata(dir).map_err(io("cannot open the raw-data directory"))?;
    if meta.is_file() && PulseFormat::of(dir) == Some(PulseFormat::Lh5) {
        let set = read_lh5_pulses(dir)?;
        return Ok(RawRun {
            dir: dir.to_path_buf(),
            sets: vec![set],
            problems: Vec::new(),
        });
    }
    if !meta.is_dir() {
        return Err(Error::format(
            dir,
            "not a directory: raw data are a directory of pulse files <stem>.npy or <stem>.lh5 \
             with sidecars <stem>.toml, or one .lh5 file",
        ));
    }
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io("cannot list the raw-data directory"))? {
        let path = entry
            .map_err(io("cannot list the raw-data directory"))?
            .path();
        if path.is_file() {
            files.push(path);
        }
    }
    files.sort();
    let has_extension = |p: &Path, ext: &str| p.extension().is_some_and(|e| e == ext);

    let mut sets: Vec<PulseSet> = Vec::new();
    let mut problems = Vec::new();
    for file in &files {
        if PulseFormat::of(file).is_some() {
            match read_pulse_file(file) {
                Ok(set) => match sets
                    .iter()
                    .find(|s| (s.bias_v - set.bias_v).abs() <= VOLTAGE_TOLERANCE_V)
                {
                    Some(first) => problems.push(RawProblem {
                        file: file.clone(),
                        bias_v: Some(set.bias_v),
                        message: format!(
                            "bias {} V already has the pulse file {}; this file is ignored",
                            set.bias_v,
                            first.source.display()
                        ),
                    }),
                    None => sets.push(set),
                },
                Err(e) if matches!(&e, Error::Invalid { key, .. } if key == "bias_V") => {
                    return Err(e);
                }
                Err(e) => problems.push(RawProblem {
                    file: file.clone(),
                    bias_v: sidecar::loose_bias_v(&sidecar::sidecar_path(file)),
                    message: e.to_string(),
                }),
            }
        } else if has_extension(file, "toml")
            && file.file_name().is_none_or(|n| n != MEASUREMENT_FILE)
        {
            let npy = file.with_extension("npy");
            let has_pulses = PulseFormat::ALL
                .iter()
                .any(|f| file.with_extension(f.extension()).is_file());
            if !has_pulses {
                problems.push(RawProblem {
                    file: file.clone(),
                    bias_v: sidecar::loose_bias_v(file),
                    message: format!(
                        "sidecar without pulse file: expected {} (or .lh5) next to it",
                        npy.display()
                    ),
                });
            }
        }
    }

    if sets.is_empty() {
        let listing: String = problems
            .iter()
            .map(|p| format!("\n  {}", p.message))
            .collect();
        let what = if problems.is_empty() {
            " (no <stem>.npy or <stem>.lh5 file with a <stem>.toml sidecar was found)".to_string()
        } else {
            format!("; the problems:{listing}")
        };
        return Err(Error::format(
            dir,
            format!("no readable pulse file in the raw-data directory{what}"),
        ));
    }
    sets.sort_by(|a, b| a.bias_v.total_cmp(&b.bias_v));

    for &v in expected_voltages_v.unwrap_or(&[]) {
        let matches = |b: f64| (b - v).abs() <= VOLTAGE_TOLERANCE_V;
        if sets.iter().any(|s| matches(s.bias_v)) {
            continue;
        }
        let failed = problems
            .iter()
            .find(|p| p.bias_v.is_some_and(matches))
            .map(|p| p.file.clone());
        let message = match failed {
            Some(file) => format!(
                "no readable pulse file for this bias ({} could not be used)",
                file.display()
            ),
            None => "no pulse file for this bias".to_string(),
        };
        problems.push(RawProblem {
            file: dir.to_path_buf(),
            bias_v: Some(v),
            message,
        });
    }

    Ok(RawRun {
        dir: dir.to_path_buf(),
        sets,
        problems,
    })
}
