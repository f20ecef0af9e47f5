//! A raw-data directory: one pulse file (`<stem>.npy` + `<stem>.toml`) per bias.

use std::path::{Path, PathBuf};

use super::files::{MEASUREMENT_FILE, VOLTAGE_TOLERANCE_V};
use super::npy::read_pulses;
use super::sidecar;
use crate::error::{Error, Result};
use crate::types::PulseSet;

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

/// A file of a raw-data directory that could not be used, or an expected bias without data.
#[derive(Debug, Clone)]
pub struct RawProblem {
    /// The file at fault (the directory itself for an expected bias without a pulse file).
    pub file: PathBuf,
    /// The bias the problem concerns, V, when known (from the sidecar, read loosely, or from the
    /// expected voltages).
    pub bias_v: Option<f64>,
    /// What is wrong (for a file that failed to read, the full error message).
    pub message: String,
}

/// Reads every pulse file of a directory (not recursive, in file-name order) with
/// [`read_pulses`].
///
/// Problems that do not stop the reading are collected in [`RawRun::problems`]: a pulse file
/// that fails to read (bad array, missing or invalid sidecar), a sidecar `<stem>.toml` without
/// its `<stem>.npy` (the run's settings file `measurement.toml` is not a sidecar), a second file
/// with the bias of an earlier one (the first is kept), and each bias of `expected_voltages_v`
/// (V, matched within 1e-6 V) without a pulse set. Other files are ignored.
///
/// Errors: the directory does not exist, is not a directory or cannot be listed, or it holds no
/// readable pulse file at all (the message lists the problems).
pub fn read_raw_dir(dir: &Path, expected_voltages_v: Option<&[f64]>) -> Result<RawRun> {
    let io = |action: &'static str| {
        move |source: std::io::Error| Error::Io {
            file: dir.to_path_buf(),
            action,
            source,
        }
    };
    let meta = std::fs::metadata(dir).map_err(io("cannot open the raw-data directory"))?;
    if !meta.is_dir() {
        return Err(Error::format(
            dir,
            "not a directory: raw data are a directory of pulse files <stem>.npy with sidecars \
             <stem>.toml",
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
        if has_extension(file, "npy") {
            match read_pulses(file) {
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
            if !npy.is_file() {
                problems.push(RawProblem {
                    file: file.clone(),
                    bias_v: sidecar::loose_bias_v(file),
                    message: format!(
                        "sidecar without pulse file: expected {} next to it",
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
            " (no <stem>.npy file with a <stem>.toml sidecar was found)".to_string()
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
