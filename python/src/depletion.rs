//! Depletion voltages and the impurity scale factor from Python, as `hpge-cv depletion`.

use hpge_foundation::Shard;
use hpge_inference::depletion::{
    DEFAULT_GATE_V, DepletionOptions, Measured, RecordsOptions, ScalePrior, TiltPrior, depletion,
    run_records,
};
use hpge_solver::detector::legend::LegendOptions;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detector::{PyDetector, field_settings};
use crate::{array, err, json_to_py};

/// The measured voltage's default standard uncertainty, V (as the command's --measured-sigma).
const DEFAULT_SIGMA_V: f64 = 100.0;

fn measured_arg(measured: Option<(f64, Option<f64>)>, sigma: f64) -> PyResult<Option<Measured>> {
    measured
        .map(|(u, s)| {
            let m = Measured {
                voltage_v: u,
                sigma_v: s.unwrap_or(sigma),
            };
            m.validate().map(|()| m).map_err(err)
        })
        .transpose()
}

fn prior_arg(factor_range: (f64, f64)) -> PyResult<ScalePrior> {
    ScalePrior::parse(&format!("{}:{}", factor_range.0, factor_range.1)).map_err(err)
}

fn tilt_arg(tilt_range: Option<(f64, f64)>) -> PyResult<Option<TiltPrior>> {
    tilt_range
        .map(|(lo, hi)| {
            let t = TiltPrior { lo, hi };
            t.validate().map(|()| t).map_err(err)
        })
        .transpose()
}

/// U_fd and the pinch-off voltage with their error bars, as `hpge-cv depletion`; with
/// `measured` (a voltage in V, or a (voltage, sigma) pair; sigma defaults to `sigma`, 100 V),
/// the posterior of a factor multiplying the impurity density (log-uniform prior on
/// `factor_range`) and, with `curve`, the C-V curve at its median. `tilt_range` (lo, hi) fits
/// the tilt of the density's gradient too (uniform prior; 1 is the profile as given), as
/// `--tilt-range`: the result's `tilt` then has its marginal and the exact solves at its nodes.
///
/// Returns the dict `hpge-cv depletion --json` prints: `depletion_voltage_V`,
/// `depletion_voltage_err_V`, `pinch_off_voltage_V`, `pinch_off_voltage_err_V`, `grid`,
/// `measured`, `gate_V`, `exceeds_gate` (|U_fd - measured| > `gate`), `factor` (`median`,
/// `mean`, `sd`, `interval_68`, `interval_95`, `at_prior_bound`, ...) and `curve_at_median`,
/// plus `factor_table` (`f` and `density` arrays: the posterior density of the factor). The GIL
/// is released while the solver runs.
#[pyfunction(name = "depletion")]
#[pyo3(signature = (detector, measured=None, sigma=DEFAULT_SIGMA_V, factor_range=(0.1, 10.0), gate=DEFAULT_GATE_V, pinch_off=true, curve=true, tolerance=None, grid=None, tilt_range=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn depletion_voltages<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    measured: Option<(f64, Option<f64>)>,
    sigma: f64,
    factor_range: (f64, f64),
    gate: f64,
    pinch_off: bool,
    curve: bool,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
    tilt_range: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let det = &detector.get().det;
    det.check_bias_contact().map_err(err)?;
    let settings = field_settings(det, tolerance, grid)?;
    let o = DepletionOptions {
        measured: measured_arg(measured, sigma)?,
        prior: prior_arg(factor_range)?,
        tilt: tilt_arg(tilt_range)?,
        pinch_off,
        curve,
        gate_v: gate,
    };
    let report = py
        .detach(|| depletion(det, &settings, &o, |_| {}))
        .map_err(err)?;
    let d = json_to_py(py, &report.to_json())?.cast_into::<PyDict>()?;
    if let Some(p) = &report.posterior {
        let t = PyDict::new(py);
        t.set_item("f", array(py, p.table.iter().map(|r| r.0).collect()))?;
        t.set_item("density", array(py, p.table.iter().map(|r| r.1).collect()))?;
        d.set_item("factor_table", t)?;
    }
    Ok(d)
}

/// Every LEGEND diode record (*.json, *.yaml) of `folder` into one table, as `hpge-cv depletion
/// --records`: a list of dicts (`record`, `name`, `kind`, `depletion_voltage_v`,
/// `depletion_voltage_err_v`, `pinch_off_voltage_v`, `pinch_off_voltage_err_v`, `measured_v`,
/// `factor`, `factor_68`, `tilt`, `tilt_68`, `exceeds_gate`, `note`). `out` (a folder) keeps
/// each record's row and makes the run resumable; `shard` is "K/M"; `tilt_range` as in
/// `depletion`, for the records whose density varies along z.
#[pyfunction]
#[pyo3(signature = (folder, out=None, shard="0/1", sigma=DEFAULT_SIGMA_V, factor_range=(0.1, 10.0), gate=DEFAULT_GATE_V, pinch_off=true, tolerance=None, grid=None, tilt_range=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn depletion_records<'py>(
    py: Python<'py>,
    folder: std::path::PathBuf,
    out: Option<std::path::PathBuf>,
    shard: &str,
    sigma: f64,
    factor_range: (f64, f64),
    gate: f64,
    pinch_off: bool,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
    tilt_range: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyAny>> {
    let o = RecordsOptions {
        dir: folder,
        out,
        shard: Shard::parse(shard).map_err(err)?,
        sigma_v: sigma,
        prior: prior_arg(factor_range)?,
        tilt: tilt_arg(tilt_range)?,
        gate_v: gate,
        pinch_off,
        legend: LegendOptions::default(),
        grid: hpge_solver::GridOverrides {
            tolerance,
            grid: grid.unwrap_or_default().into_iter().collect(),
        },
    };
    let base = hpge_solver::FieldSettings::default();
    let rows = py
        .detach(|| run_records(&o, &base, |_, _, _| {}))
        .map_err(err)?;
    json_to_py(py, &serde_json::to_value(rows).map_err(err)?)
}
