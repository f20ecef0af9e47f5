//! `hpge_cv`: the Python module of hpge-cv (PyO3). Every function calls the libraries the
//! command line calls (hpge-solver, hpge-surrogate, hpge-measurement, hpge-inference,
//! hpge-reports), so the numbers are the command line's; errors are [`HpgeError`] with the
//! library's message. Long calls release the GIL and report progress (stderr lines or a Python
//! callable).
//!
//! Units at every interface: lengths mm, potentials V, densities cm^-3 (signed: positive is
//! n-type), capacitances pF, times ns, fields V/cm.

use numpy::{PyArray1, PyArray2};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod depletion;
mod detector;
mod fit;
mod legend;
mod measure;
mod progress;
mod solve;
mod surrogate;

create_exception!(
    hpge_cv,
    HpgeError,
    PyValueError,
    "Bad input or a failed computation in hpge-cv. The message is the command line's: it names the file, key or value and the problem."
);

/// Any library error as an [`HpgeError`] carrying its message.
fn err<E: std::fmt::Display>(e: E) -> PyErr {
    HpgeError::new_err(e.to_string())
}

/// A JSON value as the Python object `json.loads` makes of it.
fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).map_err(err)?;
    py.import("json")?.call_method1("loads", (text,))
}

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

fn matrix<'py>(py: Python<'py>, rows: &[Vec<f64>]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray2::from_vec2(py, rows).map_err(err)
}

/// hpge-cv from Python: detectors, C-V curves, capacitance, pulses, fields, sensitivity scans
/// and grid convergence from the field solver (the command line's jobs, the same records); surrogate predictions; measurement of raw pulser data; Bayesian fits. Units: mm, V,
/// cm^-3 (signed, positive n-type), pF, ns, V/cm.
#[pymodule]
fn hpge_cv(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("HpgeError", m.py().get_type::<HpgeError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<detector::PyDetector>()?;
    m.add_function(wrap_pyfunction!(solve::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(solve::capacitance, m)?)?;
    m.add_function(wrap_pyfunction!(depletion::depletion_voltages, m)?)?;
    m.add_function(wrap_pyfunction!(depletion::depletion_records, m)?)?;
    m.add_function(wrap_pyfunction!(solve::pulse, m)?)?;
    m.add_function(wrap_pyfunction!(solve::field, m)?)?;
    m.add_function(wrap_pyfunction!(solve::sensitivity, m)?)?;
    m.add_function(wrap_pyfunction!(solve::convergence, m)?)?;
    m.add_function(wrap_pyfunction!(surrogate::predict, m)?)?;
    m.add_function(wrap_pyfunction!(measure::measure, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(fit::discover, m)?)?;
    m.add_function(wrap_pyfunction!(legend::legend_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(legend::legend_outline, m)?)?;
    Ok(())
}
