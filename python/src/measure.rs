//! Measurement of raw pulser data from Python.

use std::path::PathBuf;

use hpge_measurement::{MeasureOptions, measure as measure_run, read_raw_dir};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::{array, err, matrix};

/// Raw pulser data to a C-V curve, as `hpge-cv measure --raw DIR` (paper, sections 3-4).
///
/// Arguments: `raw` (folder of `<stem>.npy` pulse files in pC with `<stem>.toml` sidecars),
/// `settings` (measurement TOML; default `<raw>/measurement.toml` when present).
///
/// Returns a dict: `voltage_V`, `c12_pF`, `sigma_pF` (arrays), `covariance_pF2` (2-D array or
/// None), `depletion_voltage_V` (V or None), `problems` (list of `{file, bias_V, message}`: files
/// and fits that could not be used; the other biases are still measured). The GIL is released
/// while the pulses are fitted.
#[pyfunction]
#[pyo3(signature = (raw, settings=None))]
pub(crate) fn measure<'py>(
    py: Python<'py>,
    raw: PathBuf,
    settings: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let o = MeasureOptions {
        raw: raw.clone(),
        out: PathBuf::new(),
        settings,
    };
    let (s, _source) = o.measure_settings().map_err(err)?;
    let (run, m) = py
        .detach(|| {
            let run = read_raw_dir(&raw, s.voltages_v.as_deref())?;
            let m = measure_run(&run.sets, &s, &raw)?;
            Ok::<_, hpge_measurement::Error>((run, m))
        })
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("voltage_V", array(py, m.curve.voltage_v.clone()))?;
    d.set_item("c12_pF", array(py, m.curve.c12_pf.clone()))?;
    d.set_item("sigma_pF", array(py, m.curve.sigma_pf.clone()))?;
    match &m.curve.covariance_pf2 {
        Some(c) => d.set_item("covariance_pF2", matrix(py, c)?)?,
        None => d.set_item("covariance_pF2", py.None())?,
    }
    d.set_item("depletion_voltage_V", m.depletion_voltage_v)?;
    let problems = PyList::empty(py);
    for p in run.problems.iter().chain(&m.problems) {
        let q = PyDict::new(py);
        q.set_item("file", &p.file)?;
        q.set_item("bias_V", p.bias_v)?;
        q.set_item("message", &p.message)?;
        problems.append(q)?;
    }
    d.set_item("problems", problems)?;
    Ok(d)
}
