//! Surrogate predictions from Python.

use std::path::PathBuf;

use hpge_surrogate::Surrogate;
use hpge_surrogate::job::parse_params;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{HpgeError, array, err, matrix};

/// c12 along a curve from a surrogate model file, as `hpge-cv predict`.
///
/// Arguments: `model` (.safetensors), `params` (`{name: value}` in the model's units, every
/// parameter of the model), `voltages` (V), `jacobian` (also dc12/dp), `extrapolate` (predict
/// also where the training rows thin out, as `--extrapolate`).
///
/// Returns a dict: `voltage_V`, `c12_pF`, `sigma_pF` (sigma_p c12), `ensemble_spread_pF`
/// (ensembles only), `jacobian_pF` (2-D array [voltage, parameter], pF per parameter unit, when
/// asked), `parameter_names`, `sigma_p`. Parameters or voltages outside the training space
/// raise `HpgeError` (never an extrapolation), and so, unless `extrapolate`, do those outside
/// the range the training rows support (the model's support, as the command line).
#[pyfunction]
#[pyo3(signature = (model, params, voltages, jacobian=false, extrapolate=false))]
pub(crate) fn predict<'py>(
    py: Python<'py>,
    model: PathBuf,
    params: std::collections::BTreeMap<String, f64>,
    voltages: Vec<f64>,
    jacobian: bool,
    extrapolate: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = Surrogate::load(&model).map_err(err)?;
    let items: Vec<String> = params.iter().map(|(k, v)| format!("{k}={v}")).collect();
    let p = parse_params(&m, &items).map_err(|e| HpgeError::new_err(format!("--params: {e}")))?;
    m.voltages(&voltages).map_err(err)?;
    m.check_params(&p).map_err(err)?;
    if !extrapolate {
        m.check_support(&p, &voltages).map_err(|e| {
            HpgeError::new_err(format!(
                "{e}; pass extrapolate=True to predict there anyway"
            ))
        })?;
    }
    let pred = py
        .detach(|| m.predict(&p, &voltages, jacobian))
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("voltage_V", array(py, voltages))?;
    d.set_item("sigma_pF", array(py, pred.sigma_pf))?;
    d.set_item("c12_pF", array(py, pred.c12_pf))?;
    if m.members() > 1 {
        d.set_item("ensemble_spread_pF", array(py, pred.spread_pf))?;
    }
    if let Some(j) = pred.jacobian_pf {
        d.set_item("jacobian_pF", matrix(py, &j)?)?;
    }
    d.set_item("parameter_names", m.parameter_names())?;
    d.set_item("sigma_p", m.sigma_p())?;
    Ok(d)
}
