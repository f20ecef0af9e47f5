//! What every file format shares: reading and writing a file with the file named in the error,
//! TOML parse errors as one line, and the tolerances and names common to the formats.

use std::path::Path;

use crate::error::{Error, Result};

/// Name of the run's settings file inside a raw-data directory; it is not a sidecar.
pub(crate) const MEASUREMENT_FILE: &str = "measurement.toml";

/// Tolerance when matching two bias voltages, V.
pub(crate) const VOLTAGE_TOLERANCE_V: f64 = 1e-6;

/// Reads a text file, naming it in the error.
pub(crate) fn read_text(file: &Path) -> Result<String> {
    std::fs::read_to_string(file).map_err(|source| Error::Io {
        file: file.to_path_buf(),
        action: "cannot read the file",
        source,
    })
}

/// Writes a file whole or not at all (a temporary renamed onto it: [`hpge_files::write`]),
/// naming it in the error.
pub(crate) fn write_file(file: &Path, contents: &[u8]) -> Result<()> {
    hpge_files::write(file, contents).map_err(|source| Error::Io {
        file: file.to_path_buf(),
        action: "cannot write the file",
        source,
    })
}

/// A TOML parse error as one line: "line L, column C: message".
pub(crate) fn toml_message(text: &str, err: &toml::de::Error) -> String {
    let message = err.message().trim();
    match err.span() {
        Some(span) => {
            let start = span.start.min(text.len());
            let before = text.get(..start).unwrap_or("");
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message.to_string(),
    }
}
