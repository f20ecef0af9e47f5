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
/// parameter of the model), `voltages` (V), `jacobian` (also dc12/dp).
///
/// Returns a dict: `voltage_V`, `c12_pF`, `sigma_pF` (sigma_p c12), `ensemble_spread_pF`
/// (ensembles only), `jacobian_pF` (2-D array [voltage, parameter], pF per parameter unit, when
/// asked), `parameter_names`, `sigma_p`. Parameters or voltages outside the training space raise
/// `HpgeError` (never an extrapolation).
#[pyfunction]
#[pyo3(signature = (model, params, voltages, jacobian=false))]
pub(crate) fn predict<'py>(
    py: Python<'py>,
    model: PathBuf,
    params: std::collections::BTreeMap<String, f64>,
    voltages: Vec<f64>,
    jacobian: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = Surrogate::load(&model).map_err(err)?;
    let items: Vec<String> = params.iter().map(|(k, v)| format!("{k}={v}")).collect();
    let p = parse_params(&m, &items).map_err(|e| HpgeError::new_err(format!("--params: {e}")))?;
    let u = m.voltages(&voltages).map_err(err)?;
    let n = voltages.len();
    let np = m.n_params();
    let (c, spread, jac, sigma) = py
        .detach(|| {
            let mut c = vec![0.0; n];
            let mut spread = vec![0.0; n];
            m.curve_into(&p, &u, &mut c, Some(&mut spread))?;
            let jac = if jacobian {
                let mut j = vec![0.0; n * np];
                let mut c2 = vec![0.0; n];
                m.curve_jacobian_into(&p, &u, &mut c2, &mut j)?;
                Some(j.chunks(np).map(<[f64]>::to_vec).collect::<Vec<_>>())
            } else {
                None
            };
            let sigma = m.curve_sigma_pf(&p, &u, &c)?;
            Ok::<_, hpge_surrogate::Error>((c, spread, jac, sigma))
        })
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("voltage_V", array(py, voltages))?;
    d.set_item("sigma_pF", array(py, sigma))?;
    d.set_item("c12_pF", array(py, c))?;
    if m.members() > 1 {
        d.set_item("ensemble_spread_pF", array(py, spread))?;
    }
    if let Some(j) = jac {
        d.set_item("jacobian_pF", matrix(py, &j)?)?;
    }
    d.set_item("parameter_names", m.parameter_names())?;
    d.set_item("sigma_p", m.sigma_p())?;
    Ok(d)
}
