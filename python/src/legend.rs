//! LEGEND diode records from Python (a path to the JSON file, or the record as a dict): their
//! detector TOML text and their r-z outline, as `hpge-cv detector --from-legend` converts them.

use std::path::PathBuf;

use hpge_solver::detector::legend::LegendOptions;
use numpy::PyArray1;
use pyo3::prelude::*;

use crate::{HpgeError, array, err};

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

/// The detector TOML text of a record (`hpge-cv detector --from-legend`'s conversion, the
/// options not given at their defaults) and the path that names the record in messages.
pub(crate) fn convert(
    py: Python<'_>,
    record: &Bound<'_, PyAny>,
    n_plus_thickness_mm: Option<f64>,
    can_gap_mm: Option<f64>,
) -> PyResult<(String, PathBuf)> {
    let (text, source) = record_text(py, record)?;
    let mut o = LegendOptions::default();
    if let Some(t) = n_plus_thickness_mm {
        o.n_plus_thickness_mm = t;
    }
    if let Some(g) = can_gap_mm {
        o.can_gap_mm = g;
    }
    let toml = hpge_solver::detector::legend::convert_json(&text, &source, &o).map_err(err)?;
    Ok((toml, source))
}

/// The detector TOML text converted from a LEGEND diode record (a path to the JSON file, or the
/// record as a dict), as `hpge-cv detector --from-legend DIODE.json --out D.toml` writes it.
/// `n_plus_thickness_mm` (mm): the n+ dead layer where the record's `characterization` has none;
/// `can_gap_mm` (mm): the gap between the crystal and the grounded can.
#[pyfunction]
#[pyo3(signature = (record, n_plus_thickness_mm=None, can_gap_mm=None))]
pub(crate) fn legend_to_toml(
    py: Python<'_>,
    record: &Bound<'_, PyAny>,
    n_plus_thickness_mm: Option<f64>,
    can_gap_mm: Option<f64>,
) -> PyResult<String> {
    Ok(convert(py, record, n_plus_thickness_mm, can_gap_mm)?.0)
}

/// r (mm), z (mm) and the surface of each segment.
pub(crate) type Outline<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Vec<&'static str>,
);

/// The crystal's r-z outline (mm) of a LEGEND diode record as hpge-cv converts it: a tuple of
/// arrays (r_mm, z_mm), from the axis at the p+ face around to the axis (the closing segment
/// runs along the axis), and the surface of each segment ("p+", "n+", "passive").
#[pyfunction]
pub(crate) fn legend_outline<'py>(
    py: Python<'py>,
    record: &Bound<'py, PyAny>,
) -> PyResult<Outline<'py>> {
    let (text, source) = crate::legend::record_text(py, record)?;
    let d = hpge_solver::detector::legend::read_json(&text, &source, &LegendOptions::default())
        .map_err(err)?;
    let surfaces = d
        .surfaces
        .iter()
        .map(|s| match s {
            hpge_solver::detector::legend::Surface::PPlus => "p+",
            hpge_solver::detector::legend::Surface::NPlus => "n+",
            hpge_solver::detector::legend::Surface::Passive => "passive",
        })
        .collect();
    Ok((
        array(py, d.outline_mm.iter().map(|p| p[0]).collect()),
        array(py, d.outline_mm.iter().map(|p| p[1]).collect()),
        surfaces,
    ))
}
