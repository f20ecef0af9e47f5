//! The field solver from Python: C-V curves, the capacitance matrix, pulses and fields.

use hpge_solver::drift::{
    AdlModel, AdlParameters, DriftSettings, ElectricField, check_interaction_point, field_line,
    normalise_signals, reference_contact, rise_time_10_90_ns,
};
use hpge_solver::field::{curve_depletion_voltage, curve_pinch_off_voltage, normalise_voltages};
use hpge_solver::{cv_curve, solve_point};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::detector::{PyDetector, field_settings};
use crate::progress::progress_arg;
use crate::{HpgeError, array, err, matrix};

/// The C-V curve c12(U_B) from the field solver, as `hpge-cv simulate`.
///
/// Arguments: `detector` (a `Detector`), `voltages` (V, positive; sorted and deduplicated),
/// `tolerance` (relative error target of c12, default 0.002), `grid` (`{"KEY": "VALUE"}` as
/// `--grid`), `progress` (True: a line per bias on stderr; a callable: called with (done,
/// total); False: silent).
///
/// Returns a dict: `voltage_V`, `c12_pF`, `c12_err_pF` (numpy arrays), `fully_depleted`,
/// `tolerance_reached` (bool arrays), `depletion_voltage_V` (the full-depletion voltage U_fd, V,
/// or None) with `depletion_voltage_err_V` (its estimated error, V), `pinch_off_voltage_V` (V or
/// None) with `pinch_off_voltage_err_V`, and `pockets` (per bias a list of dicts:
/// `carrier`, `level_V`, `volume_cm3`, `centroid_mm`, `r_range_mm`, `z_range_mm`). The GIL is
/// released while the solver runs.
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
    let volts = normalise_voltages(&voltages).map_err(err)?;
    det.check_bias_contact().map_err(err)?;
    let settings = field_settings(det, tolerance, grid)?;
    let (curve, pinch, depletion) = py
        .detach(|| {
            let c = cv_curve(det, &volts, &settings, |k, n| progress.report(k, n))?;
            let p = curve_pinch_off_voltage(det, &c, &settings)?;
            let d = curve_depletion_voltage(det, &c, &settings)?;
            Ok::<_, hpge_solver::Error>((c, p, d))
        })
        .map_err(err)?;
    let d = PyDict::new(py);
    let pts = &curve.points;
    d.set_item(
        "voltage_V",
        array(py, pts.iter().map(|p| p.voltage_v).collect()),
    )?;
    d.set_item("c12_pF", array(py, pts.iter().map(|p| p.c12_pf).collect()))?;
    d.set_item(
        "c12_err_pF",
        array(py, pts.iter().map(|p| p.c12_err_pf).collect()),
    )?;
    d.set_item(
        "fully_depleted",
        PyArray1::from_vec(py, pts.iter().map(|p| p.fully_depleted).collect()),
    )?;
    d.set_item(
        "tolerance_reached",
        PyArray1::from_vec(py, pts.iter().map(|p| p.tolerance_reached).collect()),
    )?;
    // An error bar that could not be estimated (infinite) is None, as in the command's JSON.
    let finite = |e: Option<f64>| e.filter(|x| x.is_finite());
    d.set_item("depletion_voltage_V", curve.depletion_voltage_v)?;
    d.set_item(
        "depletion_voltage_err_V",
        finite(depletion.map(|e| e.err_v)),
    )?;
    d.set_item("pinch_off_voltage_V", pinch.map(|e| e.voltage_v))?;
    d.set_item("pinch_off_voltage_err_V", finite(pinch.map(|e| e.err_v)))?;
    let pockets = PyList::empty(py);
    for p in pts {
        let list = PyList::empty(py);
        for k in &p.pockets {
            let q = PyDict::new(py);
            q.set_item("carrier", k.carrier.as_str())?;
            q.set_item("level_V", k.level_v)?;
            q.set_item("volume_cm3", k.volume_cm3)?;
            q.set_item("centroid_mm", (k.centroid_mm.0, k.centroid_mm.1))?;
            q.set_item("r_range_mm", (k.r_range_mm.0, k.r_range_mm.1))?;
            q.set_item("z_range_mm", (k.z_range_mm.0, k.z_range_mm.1))?;
            list.append(q)?;
        }
        pockets.append(list)?;
    }
    d.set_item("pockets", pockets)?;
    Ok(d)
}

pub(crate) fn check_bias(voltage: f64) -> PyResult<()> {
    if voltage.is_finite() && voltage > 0.0 {
        Ok(())
    } else {
        Err(HpgeError::new_err(format!(
            "--voltage {voltage}: the bias must be a positive number of volts"
        )))
    }
}

/// The Maxwell capacitance matrix at one bias `voltage` (V), as `hpge-cv capacitance`.
///
/// Returns a dict: `contacts` (names), `maxwell_pF` (energy form, 2-D array, pF, Q = C* U),
/// `maxwell_from_charges_pF`, `c12_pF` (= -C*_12, pF), `c12_err_pF`, `fully_depleted`. The GIL
/// is released while the solver runs.
#[pyfunction]
#[pyo3(signature = (detector, voltage, tolerance=None, grid=None))]
pub(crate) fn capacitance<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
) -> PyResult<Bound<'py, PyDict>> {
    check_bias(voltage)?;
    let det = &detector.get().det;
    let settings = field_settings(det, tolerance, grid)?;
    let p = py
        .detach(|| solve_point(det, voltage, &settings, None))
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("voltage_V", voltage)?;
    d.set_item(
        "contacts",
        det.contacts
            .iter()
            .map(|c| c.name.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item("maxwell_pF", matrix(py, &p.capacitance.energy_pf)?)?;
    d.set_item(
        "maxwell_from_charges_pF",
        matrix(py, &p.capacitance.charge_pf)?,
    )?;
    d.set_item("c12_pF", p.c12_pf)?;
    d.set_item("c12_err_pF", p.accuracy.c12_err_pf)?;
    d.set_item("fully_depleted", p.fully_depleted())?;
    Ok(d)
}

/// The charge signals of one interaction, as `hpge-cv pulse` with the published ADL drift
/// parameters: the field at `voltage` (V), an electron and a hole drifted from `at` = (r mm, phi
/// degrees, z mm).
///
/// Returns a dict: `t_ns` (array, ns), `signals` (`{contact name: array}` in units of the pair
/// charge; divided by the bias contact's end value when `normalise`), `collection_time_ns`,
/// `rise_time_10_90_ns` (ns or None), `fully_depleted`. Points outside the crystal, in a
/// contact or in undepleted volume raise `HpgeError`.
#[pyfunction]
#[pyo3(signature = (detector, voltage, at, normalise=false))]
pub(crate) fn pulse<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    at: (f64, f64, f64),
    normalise: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_bias(voltage)?;
    let det = &detector.get().det;
    det.check_bias_contact().map_err(err)?;
    let (r_mm, phi_deg, z_mm) = at;
    let flag = format!("--at {r_mm},{phi_deg},{z_mm}");
    if r_mm < 0.0 || !(r_mm.is_finite() && phi_deg.is_finite() && z_mm.is_finite()) {
        return Err(HpgeError::new_err(format!(
            "{flag}: R must be a finite number >= 0 mm, PHI and Z finite"
        )));
    }
    if let hpge_solver::detector::Region::Contact(i) = det.classify(r_mm, z_mm) {
        let e = hpge_solver::Error::InteractionInContact {
            r_mm,
            z_mm,
            contact: det.contacts[i].name.clone(),
        };
        return Err(HpgeError::new_err(format!("{flag}: {e}")));
    }
    let model = AdlModel::new(AdlParameters::default())
        .map_err(|m| HpgeError::new_err(format!("drift parameters: {m}")))?;
    let settings = field_settings(det, None, None)?;
    let (p, rise, fully) = py.detach(|| -> PyResult<_> {
        let point = solve_point(det, voltage, &settings, None).map_err(err)?;
        let field = ElectricField::new(det, &point);
        check_interaction_point(det, &point, &field, (r_mm, z_mm))
            .map_err(|e| HpgeError::new_err(format!("{flag}: {e}")))?;
        let mut p = hpge_solver::pulse(
            det,
            &point,
            &model,
            (r_mm, phi_deg.to_radians(), z_mm),
            &DriftSettings::default(),
        )
        .map_err(err)?;
        let k_ref = reference_contact(det);
        if normalise {
            normalise_signals(&mut p, k_ref)
                .map_err(|e| HpgeError::new_err(format!("--normalise: {e}")))?;
        }
        let rise = rise_time_10_90_ns(&p.t_ns, &p.signals[k_ref].charge);
        Ok((p, rise, point.fully_depleted()))
    })?;
    let d = PyDict::new(py);
    d.set_item("t_ns", array(py, p.t_ns.clone()))?;
    let s = PyDict::new(py);
    for c in &p.signals {
        s.set_item(&c.name, array(py, c.charge.clone()))?;
    }
    d.set_item("signals", s)?;
    d.set_item("collection_time_ns", p.collection_time_ns)?;
    d.set_item("rise_time_10_90_ns", rise)?;
    d.set_item("fully_depleted", fully)?;
    Ok(d)
}

/// The electric-field strength |E| (V/cm) along r at (`phi_deg`, `z_mm`) and the bias `voltage`
/// (V), as `hpge-cv field`: `r_mm` the radii (mm).
///
/// Returns a dict: `r_mm`, `e_V_per_cm` (NaN where the volume is undepleted, a contact or
/// outside the crystal), `status` (per radius: depleted, undepleted, contact, outside).
#[pyfunction]
#[pyo3(signature = (detector, voltage, phi_deg, z_mm, r_mm))]
pub(crate) fn field<'py>(
    py: Python<'py>,
    detector: &Bound<'py, PyDetector>,
    voltage: f64,
    phi_deg: f64,
    z_mm: f64,
    r_mm: Vec<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    check_bias(voltage)?;
    if let Some(r) = r_mm.iter().find(|r| !(r.is_finite() && **r >= 0.0)) {
        return Err(HpgeError::new_err(format!(
            "r_mm: every radius must be a finite number >= 0 mm, got {r}"
        )));
    }
    let det = &detector.get().det;
    det.check_bias_contact().map_err(err)?;
    let settings = field_settings(det, None, None)?;
    let line = py
        .detach(|| {
            let point = solve_point(det, voltage, &settings, None)?;
            let field = ElectricField::new(det, &point);
            Ok::<_, hpge_solver::Error>(field_line(det, &field, phi_deg.to_radians(), z_mm, &r_mm))
        })
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("r_mm", array(py, line.r_mm.clone()))?;
    d.set_item(
        "e_V_per_cm",
        array(
            py,
            // 1 V/cm = 100 V/m.
            line.e_v_per_m
                .iter()
                .map(|e| e.map_or(f64::NAN, |e| e / 100.0))
                .collect(),
        ),
    )?;
    d.set_item(
        "status",
        line.status.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
    )?;
    Ok(d)
}
