//! The field solver from Python: the solver jobs of `hpge_solver::jobs` (C-V curves, the
//! capacitance matrix, pulses, fields, the sensitivity scan, grid convergence). Each function
//! runs the job the command line runs and returns its record, the JSON object `hpge-cv COMMAND
//! --json` prints, as a dict (lists of numbers as numpy arrays).

use std::path::PathBuf;

use hpge_solver::drift::AdlParameters;
use hpge_solver::jobs;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;

use crate::detector::{PyDetector, field_settings};
use crate::progress::progress_arg;
use crate::{err, json_to_py};

/// A job's error with its options spelt as this module's arguments (the library's names).
fn job_err(e: hpge_solver::Error) -> PyErr {
    err(e.respell(str::to_string))
}

/// A job's record as a dict: the JSON object of the command line, with the values under
/// `arrays` as numpy arrays (`(key, dtype)`: `None` lets numpy choose, `"float64"` turns null
/// into NaN).
fn record<'py>(
    py: Python<'py>,
    record: &impl Serialize,
    arrays: &[(&str, Option<&str>)],
) -> PyResult<Bound<'py, PyDict>> {
    let v = serde_json::to_value(record).map_err(err)?;
    let d = json_to_py(py, &v)?.cast_into::<PyDict>()?;
    let np = py.import("numpy")?;
    for (key, dtype) in arrays {
        if let Some(x) = d.get_item(key)? {
            let a = match dtype {
                Some(t) => np.call_method1("asarray", (x, *t))?,
                None => np.call_method1("asarray", (x,))?,
            };
            d.set_item(key, a)?;
        }
    }
    Ok(d)
}

/// The C-V curve c12(U_B) from the field solver, as `hpge-cv simulate`.
///
/// Arguments: `detector` (a `Detector`), `voltages` (V, positive; sorted and deduplicated),
/// `tolerance` (relative error target of c12, default 0.002), `grid` (`{"KEY": "VALUE"}` as
/// `--grid`), `progress` (True: a line per bias on stderr; a callable: called with (done,
/// total); False: silent).
///
/// Returns the dict `hpge-cv simulate --json` prints: `voltage_V`, `c12_pF`, `c12_err_pF`
/// (numpy arrays), `fully_depleted`, `tolerance_reached` (bool arrays), `depletion_voltage_V`
/// (the full-depletion voltage U_fd, V, or None) with `depletion_voltage_err_V` (its estimated
/// error, V), `pinch_off_voltage_V` (V or None) with `pinch_off_voltage_err_V`, `pockets` (per
/// bias a list of dicts: `carrier`, `level_V`, `volume_cm3`, `nodes`, `centroid_mm`,
/// `r_range_mm`, `z_range_mm`), the grids, method, backend, device, seconds and the detector's
/// provenance. The GIL is released while the solver runs.
#[pyfunction]
#[pyo3(signature = (detector, voltages, tolerance=None, grid=None, progress=None))]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltages: Vec<f64>,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    let progress = progress_arg(progress, "simulate: bias")?;
    let options = jobs::SimulateOptions {
        voltages_v: voltages,
        settings: field_settings(det, tolerance, grid)?,
    };
    let run = py
        .detach(|| jobs::simulate(det, &options, |k, n| progress.report(k, n)))
        .map_err(job_err)?;
    record(
        py,
        &run.record(),
        &[
            ("voltage_V", None),
            ("c12_pF", None),
            ("c12_err_pF", None),
            ("fully_depleted", None),
            ("tolerance_reached", None),
        ],
    )
}

/// The Maxwell capacitance matrix at one bias `voltage` (V), as `hpge-cv capacitance`.
///
/// Returns the dict `hpge-cv capacitance --json` prints: `contacts` (dicts of `id` and `name`,
/// in the matrices' order), `maxwell_pF` (energy form, 2-D array, pF, Q = C* U),
/// `maxwell_from_charges_pF`, `c12_pF` (= -C*_12, pF), `c12_err_pF`, `adaptive_passes`,
/// `tolerance_reached`, `fully_depleted`, the grid, method, backend and device. The GIL is
/// released while the solver runs.
#[pyfunction]
#[pyo3(signature = (detector, voltage, tolerance=None, grid=None))]
pub(crate) fn capacitance<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    let options = jobs::CapacitanceOptions {
        voltage_v: voltage,
        settings: field_settings(det, tolerance, grid)?,
    };
    let c = py
        .detach(|| jobs::capacitance(det, &options))
        .map_err(job_err)?;
    record(
        py,
        &c,
        &[
            ("maxwell_pF", Some("float64")),
            ("maxwell_from_charges_pF", Some("float64")),
        ],
    )
}

/// The charge signals of one interaction, as `hpge-cv pulse`: the field at `voltage` (V), an
/// electron and a hole drifted from `at` = (r mm, phi degrees, z mm) with the ADL model
/// (`drift_parameters`: a TOML file as `--drift-parameters`; None: the published 78 K values).
///
/// Returns the dict `hpge-cv pulse --json` prints: `t_ns` (array, ns), `contacts` (dicts of
/// `name` and `signal`, an array in units of the pair charge; divided by the bias contact's end
/// value when `normalise`), `collection_time_ns`, `electron` and `hole` (how each stopped),
/// `rise_time_10_90_ns` (ns or None), `fully_depleted`, the drift model and settings; and
/// `signals` (`{contact name: array}`, the same signals by name). Points outside the crystal,
/// in a contact or in undepleted volume raise `HpgeError`.
#[pyfunction]
#[pyo3(signature = (detector, voltage, at, normalise=false, drift_parameters=None, tolerance=None, grid=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pulse<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    at: (f64, f64, f64),
    normalise: bool,
    drift_parameters: Option<PathBuf>,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    let adl = match &drift_parameters {
        Some(p) => jobs::read_adl_parameters(p).map_err(err)?,
        None => AdlParameters::default(),
    };
    let options = jobs::PulseOptions {
        voltage_v: voltage,
        at,
        adl,
        drift_file: drift_parameters,
        normalise,
        settings: field_settings(det, tolerance, grid)?,
    };
    let (r, phi, z) = at;
    let run = py
        .detach(|| jobs::pulse(det, &options))
        .map_err(|e| match e {
            e @ (hpge_solver::Error::InteractionInContact { .. }
            | hpge_solver::Error::InteractionUndepleted { .. }
            | hpge_solver::Error::InteractionOutside { .. }) => {
                err(format!("at ({r}, {phi}, {z}): {e}"))
            }
            e => job_err(e),
        })?;
    let d = record(py, &run.record(), &[("t_ns", None)])?;
    let np = py.import("numpy")?;
    let signals = PyDict::new(py);
    for s in &run.pulse.signals {
        signals.set_item(&s.name, np.call_method1("asarray", (s.charge.clone(),))?)?;
    }
    d.set_item("signals", signals)?;
    Ok(d)
}

/// The electric-field strength |E| along r at (`phi_deg`, `z_mm`) and the bias `voltage` (V),
/// as `hpge-cv field`: `r_mm` the radii (mm; None: 201 across the crystal).
///
/// Returns the dict `hpge-cv field --json` prints: `r_mm`, `e_V_per_m`, `e_V_per_cm` (arrays,
/// NaN where the volume is undepleted, a contact or outside the crystal), `status` (per radius:
/// depleted, undepleted, contact, outside), `fully_depleted` and the inputs.
#[pyfunction]
#[pyo3(signature = (detector, voltage, phi_deg, z_mm, r_mm=None, tolerance=None, grid=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn field<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    phi_deg: f64,
    z_mm: f64,
    r_mm: Option<Vec<f64>>,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    let options = jobs::FieldOptions {
        voltage_v: voltage,
        phi_deg,
        z_mm,
        r_mm,
        settings: field_settings(det, tolerance, grid)?,
    };
    let run = py.detach(|| jobs::field(det, &options)).map_err(job_err)?;
    record(
        py,
        &run.record(),
        &[
            ("r_mm", None),
            ("e_V_per_m", Some("float64")),
            ("e_V_per_cm", Some("float64")),
        ],
    )
}

/// c12 at one bias `voltage` (V) for constant impurity densities `zetas_cm3` (cm^-3, positive
/// n-type), as `hpge-cv sensitivity` (the paper's section 5 scan).
///
/// Returns the dict `hpge-cv sensitivity --json` prints: `zeta_cm3`, `c12_pF` (arrays, pF),
/// `fully_depleted` (bool array), method, backend, device, seconds and the detector's
/// provenance. `progress` as for `simulate`. The GIL is released while the solver runs.
#[pyfunction]
#[pyo3(signature = (detector, voltage, zetas_cm3, tolerance=None, grid=None, progress=None))]
pub(crate) fn sensitivity<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    zetas_cm3: Vec<f64>,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    let progress = progress_arg(progress, "sensitivity: density")?;
    let n = zetas_cm3.len();
    let options = jobs::SensitivityOptions {
        voltage_v: voltage,
        zetas_cm3,
        settings: field_settings(det, tolerance, grid)?,
    };
    let run = py
        .detach(|| jobs::sensitivity(det, &options, &|k| progress.report(k, n)))
        .map_err(job_err)?;
    record(
        py,
        &run.record(),
        &[
            ("zeta_cm3", None),
            ("c12_pF", None),
            ("fully_depleted", None),
        ],
    )
}

/// Grid convergence of c12 at one bias `voltage` (V), as `hpge-cv convergence`: `levels` fixed
/// grids (the spacings times 2, 1, 1/2, ...; 1 to 8) and the adaptive solve at `tolerance`.
///
/// Returns the dict `hpge-cv convergence --json` prints: `rows` (dicts of `scale`,
/// `spacing_mm`, `nodes`, `c12_pF`, `c12_err_pF`, `adaptive`, `seconds`), `tolerance`, `grid`
/// (the settings) and the detector's provenance. The GIL is released while the solver runs.
#[pyfunction]
#[pyo3(signature = (detector, voltage, levels=4, tolerance=None, grid=None))]
pub(crate) fn convergence<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    levels: usize,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    let options = jobs::ConvergenceOptions {
        voltage_v: voltage,
        levels,
        settings: field_settings(det, tolerance, grid)?,
    };
    let (_, rec) = py
        .detach(|| jobs::convergence(det, &options))
        .map_err(job_err)?;
    record(py, &rec, &[])
}
