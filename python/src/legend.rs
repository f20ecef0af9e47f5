//! A LEGEND diode record from Python: a path to its JSON file, or the record as a dict.

use std::path::PathBuf;

use pyo3::prelude::*;

use crate::HpgeError;

/// The record's JSON text and the path that names it in messages (the file, or `<dict>`).
pub fn record_text(py: Python<'_>, record: &Bound<'_, PyAny>) -> PyResult<(String, PathBuf)> {
    if let Ok(path) = record.extract::<PathBuf>() {
        let text = std::fs::read_to_string(&path).map_err(|e| {
            HpgeError::new_err(format!("{}: cannot read the file: {e}", path.display()))
        })?;
        return Ok((text, path));
    }
    let name = record
        .get_item("name")
        .ok()
        .and_then(|n| n.extract::<String>().ok())
        .unwrap_or_else(|| "record".to_string());
    let text: String = py
        .import("json")?
        .call_method1("dumps", (record,))
        .map_err(|e| {
            HpgeError::new_err(format!(
                "the LEGEND record must be a path or a JSON-serialisable dict: {e}"
            ))
        })?
        .extract()?;
    Ok((text, PathBuf::from(format!("<dict {name}>"))))
}
