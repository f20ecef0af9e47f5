//! Measurement of raw pulser data from Python: the `measure` job of `hpge_measurement::jobs`,
//! the one the command line runs.

use std::path::PathBuf;

use hpge_measurement::{MeasureOptions, jobs};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::{array, err, json_to_py, matrix};

/// Raw pulser data to a C-V curve, as `hpge-cv measure --raw DIR` (paper, sections 3-4).
///
/// Arguments: `raw` (folder of `<stem>.npy` pulse files in pC with `<stem>.toml` sidecars),
/// `settings` (measurement TOML; default `<raw>/measurement.toml` when present), `out` (a CSV
/// path: writes the files `hpge-cv measure --out` writes, the curve, `<stem>.covariance.csv`
/// and `<stem>.measure.json`, all or none; None writes nothing).
///
/// Returns a dict: `voltage_V`, `c12_pF`, `sigma_pF` (arrays), `covariance_pF2` (2-D array or
/// None), `depletion_voltage_V` (V or None), `problems` (list of `{file, bias_V, message}`: files
/// and fits that could not be used; the other biases are still measured) and `report` (the
/// object `hpge-cv measure --json` prints and `<stem>.measure.json` holds, its `command` this
/// call). The GIL is released while the pulses are fitted.
#[pyfunction]
#[pyo3(signature = (raw, settings=None, out=None))]
pub(crate) fn measure<'py>(
    py: Python<'py>,
    raw: PathBuf,
    settings: Option<PathBuf>,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let o = MeasureOptions {
        raw: raw.clone(),
        out: out.clone().unwrap_or_default(),
        settings,
    };
    let command: Vec<String> = ["hpge_cv.measure".to_string(), raw.display().to_string()]
        .into_iter()
        .chain(out.as_ref().map(|p| p.display().to_string()))
        .collect();
    let (run, report) = py.detach(|| -> PyResult<_> {
        let run = jobs::measure_raw(&o).map_err(err)?;
        let report = match &out {
            Some(path) => {
                let mut staged = hpge_files::Staged::new();
                let (report, stale) = run.stage(path, &command, &mut staged).map_err(err)?;
                staged.commit().map_err(|(file, e)| {
                    err(format!("{}: cannot write the file: {e}", file.display()))
                })?;
                if let Some(file) = stale.filter(|f| f.is_file()) {
                    std::fs::remove_file(&file).map_err(|e| {
                        err(format!(
                            "{}: cannot remove the stale covariance of the curve: {e}",
                            file.display()
                        ))
                    })?;
                }
                report
            }
            None => {
                let mut v = serde_json::to_value(run.report(&o.out)).map_err(err)?;
                if let Some(obj) = v.as_object_mut() {
                    obj.insert("command".into(), command.clone().into());
                    // No file written, so no covariance file beside it.
                    obj.insert("covariance_file".into(), serde_json::Value::Null);
                }
                v
            }
        };
        Ok((run, report))
    })?;
    let m = &run.measurement;
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
    for p in run.problems() {
        let q = PyDict::new(py);
        q.set_item("file", &p.file)?;
        q.set_item("bias_V", p.bias_v)?;
        q.set_item("message", &p.message)?;
        problems.append(q)?;
    }
    d.set_item("problems", problems)?;
    d.set_item("report", json_to_py(py, &report)?)?;
    Ok(d)
}
