//! `hpge_cv`: the Python module of hpge-cv (PyO3). Every function calls the libraries the
//! command line calls (hpge-solver, hpge-surrogate, hpge-measurement, hpge-inference,
//! hpge-reports), so the numbers are the command line's; errors are [`HpgeError`] with the
//! library's message. Long calls release the GIL and report progress (stderr lines or a Python
//! callable).
//!
//! Units at every interface: lengths mm, potentials V, densities cm^-3 (signed: positive is
//! n-type), capacitances pF, times ns, fields V/cm.

use std::path::PathBuf;

use hpge_inference::fit::{FitJob, FitOptions, outputs};
use hpge_measurement::{MeasureOptions, measure as measure_run, read_raw_dir};
use hpge_solver::drift::{
    AdlModel, AdlParameters, DriftSettings, ElectricField, check_interaction_point, field_line,
    normalise_signals, reference_contact, rise_time_10_90_ns,
};
use hpge_solver::field::{curve_pinch_off_voltage, normalise_voltages};
use hpge_solver::options::{SolverOptions, WeightingOptions};
use hpge_solver::{Detector, FieldSettings, GridOverrides, Parameters, cv_curve, solve_point};
use hpge_surrogate::Surrogate;
use hpge_surrogate::job::parse_params;
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

mod legend;

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

/// Where a long call reports how far it is.
enum Progress {
    /// Nothing.
    Off,
    /// One line on stderr per step.
    Stderr(&'static str),
    /// A Python callable called with (done, total).
    Callback(Py<PyAny>),
}

impl Progress {
    /// `progress=True|False|callable`.
    fn from_arg(arg: &Bound<'_, PyAny>, what: &'static str) -> PyResult<Self> {
        if arg.is_callable() {
            Ok(Progress::Callback(arg.clone().unbind()))
        } else if arg.is_truthy()? {
            Ok(Progress::Stderr(what))
        } else {
            Ok(Progress::Off)
        }
    }

    /// Reports `done` of `total` steps (any thread; takes the GIL only for a callback).
    fn report(&self, done: usize, total: usize) {
        match self {
            Progress::Off => {}
            Progress::Stderr(what) => eprintln!("hpge_cv: {what} {done}/{total}"),
            Progress::Callback(f) => Python::attach(|py| {
                if let Err(e) = f.call1(py, (done, total)) {
                    e.print(py);
                }
            }),
        }
    }
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

/// A detector description: geometry, materials, contacts, passives, world and impurity model.
///
/// `Detector(path, impurity=None, params=None)` reads a detector TOML file (detectors/README.md),
/// optionally with the impurity model from its own TOML file and parameter overrides
/// (`{"d_li_mm": 3.0}`), exactly as `hpge-cv detector --detector D [--impurity I] [--param
/// NAME=VALUE]`. `Detector.from_legend(record, ...)` converts a LEGEND diode record.
#[pyclass(name = "Detector", module = "hpge_cv", frozen)]
struct PyDetector {
    det: Detector,
}

fn overrides(params: Option<Vec<(String, f64)>>) -> Parameters {
    let mut p = Parameters::new();
    for (k, v) in params.unwrap_or_default() {
        p.set(k, v);
    }
    p
}

#[pymethods]
impl PyDetector {
    #[new]
    #[pyo3(signature = (path, impurity=None, params=None))]
    fn new(
        path: PathBuf,
        impurity: Option<PathBuf>,
        params: Option<std::collections::BTreeMap<String, f64>>,
    ) -> PyResult<Self> {
        let mut det =
            Detector::from_file(&path, &overrides(params.map(|m| m.into_iter().collect())))
                .map_err(err)?;
        if let Some(i) = impurity {
            det.set_impurity_file(&i).map_err(|e| {
                HpgeError::new_err(format!("impurity model for {}: {e}", path.display()))
            })?;
        }
        Ok(Self { det })
    }

    /// A detector from a LEGEND diode record (legend-metadata's `diodes/*.json`, as a path or a
    /// dict already read), converted as `hpge-cv detector --from-legend DIODE.json` does: the
    /// crystal's r-z outline from `geometry`, the impurity profile from `production.impcc`, the
    /// default environment (grounded can `can_gap_mm` (mm) from the crystal, n+ dead layer
    /// `n_plus_thickness_mm` (mm) from `characterization` where the record has it, else the
    /// argument). `toml` returns the detector file's text instead of loading it.
    #[staticmethod]
    #[pyo3(signature = (record, n_plus_thickness_mm=None, can_gap_mm=None))]
    fn from_legend(
        py: Python<'_>,
        record: &Bound<'_, PyAny>,
        n_plus_thickness_mm: Option<f64>,
        can_gap_mm: Option<f64>,
    ) -> PyResult<Self> {
        let (text, source) = legend::record_text(py, record)?;
        let toml = hpge_solver::detector::legend::convert_json(
            &text,
            &source,
            &legend_options(n_plus_thickness_mm, can_gap_mm),
        )
        .map_err(err)?;
        let det = Detector::from_toml_str(&toml, &source, &Parameters::new()).map_err(err)?;
        Ok(Self { det })
    }

    /// The detector's name.
    #[getter]
    fn name(&self) -> String {
        self.det.name.clone()
    }

    /// The file it was read from.
    #[getter]
    fn file(&self) -> PathBuf {
        self.det.file.clone()
    }

    /// The contacts' names, in the order of the capacitance matrix.
    #[getter]
    fn contacts(&self) -> Vec<String> {
        self.det.contacts.iter().map(|c| c.name.clone()).collect()
    }

    /// The detector's named parameters (overrides applied), e.g. `d_li_mm` (mm).
    #[getter]
    fn parameters(&self) -> std::collections::BTreeMap<String, f64> {
        self.det
            .parameters
            .iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }

    /// The impurity density zeta (cm^-3, positive n-type) at (r_mm, z_mm) in the crystal.
    fn impurity_density(&self, r_mm: f64, z_mm: f64) -> f64 {
        self.det.semiconductor.impurity().density_cm3(r_mm, z_mm)
    }

    fn __repr__(&self) -> String {
        format!(
            "Detector({:?}, contacts={:?})",
            self.det.name,
            self.contacts()
        )
    }
}

fn legend_options(
    n_plus_thickness_mm: Option<f64>,
    can_gap_mm: Option<f64>,
) -> hpge_solver::detector::legend::LegendOptions {
    let mut o = hpge_solver::detector::legend::LegendOptions::default();
    if let Some(t) = n_plus_thickness_mm {
        o.n_plus_thickness_mm = t;
    }
    if let Some(g) = can_gap_mm {
        o.can_gap_mm = g;
    }
    o
}

/// The solver settings the command line uses, with `--tolerance` and `--grid KEY=VALUE`.
fn field_settings(
    det: &Detector,
    tolerance: Option<f64>,
    grid: Option<std::collections::BTreeMap<String, String>>,
) -> PyResult<FieldSettings> {
    let base = SolverOptions::default().field_settings(WeightingOptions::default().weighting);
    let o = GridOverrides {
        tolerance,
        grid: grid.unwrap_or_default().into_iter().collect(),
    };
    o.apply(&base, det).map_err(err)
}

/// The C-V curve c12(U_B) from the field solver, as `hpge-cv simulate`.
///
/// Arguments: `detector` (a `Detector`), `voltages` (V, positive; sorted and deduplicated),
/// `tolerance` (relative error target of c12, default 0.002), `grid` (`{"KEY": "VALUE"}` as
/// `--grid`), `progress` (True: a line per bias on stderr; a callable: called with (done,
/// total); False: silent).
///
/// Returns a dict: `voltage_V`, `c12_pF`, `c12_err_pF` (numpy arrays), `fully_depleted`,
/// `tolerance_reached` (bool arrays), `depletion_voltage_V` (the full-depletion voltage U_fd, V,
/// or None), `pinch_off_voltage_V` (V or None) and `pockets` (per bias a list of dicts:
/// `carrier`, `level_V`, `volume_cm3`, `centroid_mm`, `r_range_mm`, `z_range_mm`). The GIL is
/// released while the solver runs.
#[pyfunction]
#[pyo3(signature = (detector, voltages, tolerance=None, grid=None, progress=None))]
fn simulate<'py>(
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
    let (curve, pinch) = py
        .detach(|| {
            let c = cv_curve(det, &volts, &settings, |k, n| progress.report(k, n))?;
            let p = curve_pinch_off_voltage(det, &c, &settings)?;
            Ok::<_, hpge_solver::Error>((c, p))
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
    d.set_item("depletion_voltage_V", curve.depletion_voltage_v)?;
    d.set_item("pinch_off_voltage_V", pinch)?;
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

/// `progress=None` (the default) prints lines on stderr.
fn progress_arg(arg: Option<Bound<'_, PyAny>>, what: &'static str) -> PyResult<Progress> {
    match arg {
        Some(a) => Progress::from_arg(&a, what),
        None => Ok(Progress::Stderr(what)),
    }
}

fn check_bias(voltage: f64) -> PyResult<()> {
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
fn capacitance<'py>(
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
fn pulse<'py>(
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
fn field<'py>(
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
fn predict<'py>(
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
fn measure<'py>(
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
    let all = run
        .problems
        .iter()
        .map(|p| (p.file.clone(), p.bias_v, p.message.clone()))
        .chain(
            m.problems
                .iter()
                .map(|p| (p.file.clone(), p.bias_v, p.message.clone())),
        );
    for (file, bias, message) in all {
        let q = PyDict::new(py);
        q.set_item("file", file)?;
        q.set_item("bias_V", bias)?;
        q.set_item("message", message)?;
        problems.append(q)?;
    }
    d.set_item("problems", problems)?;
    Ok(d)
}

/// The posterior of an impurity model given a measured C-V curve, as `hpge-cv fit` (paper,
/// section 8): the same library path (`FitJob`), so the same seed gives the same numbers.
///
/// Arguments (defaults: the command line's, relative to the working directory): `data` (C-V
/// CSV), `model` (surrogate), `prior` (TOML), `detector` (TOML), `seed`, `sampler`
/// ("metropolis" or "nuts"), `likelihood` ("auto", the default: the measured covariance
/// where the curve has one, else "paper"; or "paper", "covariance"), `chains`, `ess`, `rhat`,
/// `max_seconds` (s), `exact_check` (re-weight `exact_draws` draws with the field solver; off by
/// default here, on in the command line; `exact_grids` "mode" or "own" and `exact_grid_check`,
/// as `--exact-grids` and `--exact-grid-check`; while the check fails, up to `refine_rounds`
/// rounds of posterior-adaptive refinement, as `--refine-rounds`, the refined likelihood's
/// variance `refine_variance` "best" or "local", as `--refine-variance`),
/// `out` (a folder: also write every file and figure
/// `hpge-cv fit --out` writes), `progress`, `extrapolate` (fit a curve with voltages outside the
/// surrogate's support, as `--extrapolate`), `constant_sigma` (the model's constant sigma_p in
/// the likelihood even where its file has a calibrated per-point sigma_s, as `--constant-sigma`),
/// `exact_ascents` (after a passing check, climb the exact posterior from this many local modes
/// in other basins, as `--exact-ascents`).
///
/// Returns a dict: `summary` (the `summary.json` object as a dict), `names` (parameters),
/// `draws` (array [chain, draw, parameter] in the prior's units), `ln_posterior` ([chain, draw]),
/// `mode` (the global mode). The GIL is released while sampling.
#[pyfunction]
#[pyo3(signature = (
    data=None, model=None, prior=None, detector=None, seed=None, sampler=None, likelihood=None,
    chains=None, ess=None, rhat=None, max_seconds=None, exact_check=false, exact_draws=None,
    out=None, progress=None, extrapolate=false, exact_grids=None, exact_grid_check=None,
    refine_rounds=None, constant_sigma=false, exact_ascents=None, refine_variance=None
))]
#[allow(clippy::too_many_arguments)]
fn fit<'py>(
    py: Python<'py>,
    data: Option<PathBuf>,
    model: Option<PathBuf>,
    prior: Option<PathBuf>,
    detector: Option<PathBuf>,
    seed: Option<u64>,
    sampler: Option<String>,
    likelihood: Option<String>,
    chains: Option<usize>,
    ess: Option<f64>,
    rhat: Option<f64>,
    max_seconds: Option<f64>,
    exact_check: bool,
    exact_draws: Option<usize>,
    out: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
    extrapolate: bool,
    exact_grids: Option<String>,
    exact_grid_check: Option<usize>,
    refine_rounds: Option<usize>,
    constant_sigma: bool,
    exact_ascents: Option<usize>,
    refine_variance: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = FitOptions::default();
    let o = FitOptions {
        data: data.unwrap_or(d.data),
        model: model.unwrap_or(d.model),
        prior: prior.unwrap_or(d.prior),
        detector: detector.unwrap_or(d.detector),
        out: out.clone(),
        sampler: sampler.unwrap_or(d.sampler),
        seed: seed.unwrap_or(d.seed),
        no_exact_check: !exact_check,
        exact_draws: exact_draws.unwrap_or(d.exact_draws),
        exact_grids: exact_grids.unwrap_or(d.exact_grids),
        exact_grid_check: exact_grid_check.unwrap_or(d.exact_grid_check),
        exact_ascents: exact_ascents.unwrap_or(d.exact_ascents),
        refine_rounds: refine_rounds.unwrap_or(d.refine_rounds),
        refine_variance: refine_variance.unwrap_or(d.refine_variance),
        likelihood: likelihood.unwrap_or(d.likelihood),
        chains: chains.unwrap_or(d.chains),
        ess: ess.unwrap_or(d.ess),
        rhat: rhat.unwrap_or(d.rhat),
        max_seconds: max_seconds.unwrap_or(d.max_seconds),
        extrapolate,
        constant_sigma,
        ..d
    };
    let progress = progress_arg(progress, "fit")?;
    let (fit, summary) = if out.is_some() {
        let observer = FitProgress(progress);
        let run = py
            .detach(|| hpge_reports::fit::run_fit(&o, &observer))
            .map_err(err)?;
        (run.fit, run.summary_json)
    } else {
        py.detach(|| -> Result<_, hpge_inference::Error> {
            o.sampler_kind()?;
            let job = FitJob::from_files(&o.files(), o.noise()?, &o.grid)?;
            if let Some(w) = job.voltage_support_guard(o.extrapolate, "extrapolate=True")? {
                eprintln!("hpge_cv: warning: {w}");
            }
            let settings = o.settings()?;
            let sampling = |s: &hpge_inference::Status| {
                if let Progress::Stderr(_) = progress {
                    eprintln!(
                        "hpge_cv: fit [{:6.1} s] {:?}: R-hat {:.4}, min ESS {:.0}, acceptance {:.2}",
                        s.seconds, s.phase, s.rhat_max, s.ess_min, s.acceptance
                    );
                } else {
                    progress.report(s.draws, 0);
                }
            };
            let fit = if o.no_exact_check {
                job.run(&settings, &sampling)?
            } else {
                job.run_refined(
                    &settings,
                    &o.exact_check()?,
                    &o.refine()?,
                    hpge_inference::fit::RefineProgress {
                        sampling: &sampling,
                        sampled: &|_| {},
                        exact: &|done, total| progress.report(done, total),
                        round: &|r| {
                            if let Progress::Stderr(_) = progress {
                                eprintln!(
                                    "hpge_cv: refinement round {}: k-hat {:.2}, largest shift {:.2} sd, {}",
                                    r.round,
                                    r.pareto_k,
                                    r.max_abs_shift_sd,
                                    if r.pass { "pass" } else { "fail" }
                                );
                            }
                        },
                    },
                    None,
                )?
                .fit
            };
            let summary = outputs::summary_json(&fit, None)?;
            Ok((fit, summary))
        })
        .map_err(err)?
    };
    let r = PyDict::new(py);
    r.set_item("summary", json_to_py(py, &summary)?)?;
    r.set_item("names", fit.samples.names.clone())?;
    let draws: Vec<Vec<Vec<f64>>> = fit.samples.chains.iter().map(|c| c.theta.clone()).collect();
    r.set_item(
        "draws",
        PyArray3::from_vec3(py, &draws).map_err(|e| HpgeError::new_err(format!("draws: {e}")))?,
    )?;
    let lp: Vec<Vec<f64>> = fit
        .samples
        .chains
        .iter()
        .map(|c| c.ln_posterior.clone())
        .collect();
    r.set_item("ln_posterior", matrix(py, &lp)?)?;
    r.set_item("mode", array(py, fit.mode.clone()))?;
    Ok(r)
}

/// Model discovery, as `hpge-cv discover` (issue 9): fits the start model, finds windows of
/// same-sign residuals, scores the catalogue of extensions by Laplace Bayes factors, fits the
/// best.
///
/// Arguments (defaults: the command line's, relative to the working directory): `data`,
/// `model`, `detector`, `start_model` (a prior file or a name in priors/, default "b-z"),
/// `only` (catalogue entries, e.g. ["radial"]), `seed`, `ess`, `max_seconds` (sampling budget of
/// each MCMC fit, s: a fit that reaches it stops at a number of draws that depends on the
/// machine's speed; pass a large value for results that depend on the seed alone),
/// `min_ln_bayes` (smallest ln Bayes factor for an extension to be added), `surrogate_only`
/// (leave out the exact-solver extensions, which are slow), `out` (a folder: also write
/// `discovery.json`, `residuals.csv`, `report.md` and the figures there), `progress`.
///
/// Returns the summary (`discovery.json`'s object) as a dict. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    data=None, model=None, detector=None, start_model=None, only=None, seed=None, ess=None,
    max_seconds=None, min_ln_bayes=None, surrogate_only=false, out=None, progress=None
))]
#[allow(clippy::too_many_arguments)]
fn discover<'py>(
    py: Python<'py>,
    data: Option<PathBuf>,
    model: Option<PathBuf>,
    detector: Option<PathBuf>,
    start_model: Option<String>,
    only: Option<Vec<String>>,
    seed: Option<u64>,
    ess: Option<f64>,
    max_seconds: Option<f64>,
    min_ln_bayes: Option<f64>,
    surrogate_only: bool,
    out: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    use hpge_inference::discover::DiscoverOptions;
    let mut o = DiscoverOptions::default();
    if let Some(d) = data {
        o.workflow.data = d;
    }
    if let Some(m) = model {
        o.workflow.model = m;
    }
    if let Some(d) = detector {
        o.workflow.detector = d;
    }
    if let Some(s) = start_model {
        o.start_model = s;
    }
    if let Some(v) = only {
        o.workflow.only = v;
    }
    if let Some(s) = seed {
        o.seed = s;
    }
    if let Some(e) = ess {
        o.workflow.ess = e;
    }
    if let Some(s) = max_seconds {
        o.max_seconds = s;
    }
    if let Some(b) = min_ln_bayes {
        o.min_ln_bayes = b;
    }
    o.surrogate_only = surrogate_only;
    o.out = out.clone();
    o.workflow.no_plots = out.is_none();
    let progress = DiscoverProgress(progress_arg(progress, "discover")?);
    let summary = py.detach(|| -> PyResult<serde_json::Value> {
        let w = &o.workflow;
        w.check_only().map_err(err)?;
        let prior_file = o.start_prior().map_err(err)?;
        let noise = hpge_inference::fit::noise_settings(
            hpge_inference::posterior::NoiseKind::Paper.as_str(),
        )
        .map_err(err)?;
        let files = hpge_inference::fit::FitFiles {
            data: w.data.clone(),
            model: w.model.clone(),
            prior: prior_file.clone(),
            detector: w.detector.clone(),
        };
        let s = FitJob::from_files(&files, noise, &w.grid).map_err(err)?;
        let spec = hpge_inference::PriorSpec::from_file(&prior_file).map_err(err)?;
        let settings = o.settings(noise).map_err(err)?;
        let dir = out.as_ref().map(|_| o.out_dir(&prior_file));
        let d = hpge_reports::discover::run_discover(
            &s,
            &spec,
            &prior_file,
            &settings,
            dir.as_deref(),
            w.no_plots,
            &progress,
        )
        .map_err(err)?;
        serde_json::to_value(&d.summary).map_err(err)
    })?;
    json_to_py(py, &summary)
}

/// Discovery's stages and sampling progress.
struct DiscoverProgress(Progress);

impl hpge_inference::Progress for DiscoverProgress {
    fn stage(&self, message: &str) {
        if let Progress::Stderr(_) = self.0 {
            eprintln!("hpge_cv: discover: {message}");
        }
    }
    fn sampling(&self, s: &hpge_inference::Status) {
        if let Progress::Callback(_) = self.0 {
            self.0.report(s.draws, 0);
        }
    }
}

/// A fit's progress for `run_fit` (lines on stderr or the callback).
struct FitProgress(Progress);

impl hpge_reports::fit::FitObserver for FitProgress {
    fn setup_done(&self, _: &FitJob, _: &FitOptions, _: &hpge_inference::FitSettings) {}
    fn sampling(&self, s: &hpge_inference::Status) {
        if let Progress::Stderr(_) = self.0 {
            eprintln!(
                "hpge_cv: fit [{:6.1} s] {:?}: R-hat {:.4}, min ESS {:.0}, acceptance {:.2}",
                s.seconds, s.phase, s.rhat_max, s.ess_min, s.acceptance
            );
        } else {
            self.0.report(s.draws, 0);
        }
    }
    fn sampling_done(&self) {}
    fn exact_start(&self, _: usize) {}
    fn exact_progress(&self, done: usize, total: usize) {
        self.0.report(done, total);
    }
    fn exact_done(&self) {}
    fn finished(&self, _: &hpge_reports::fit::FitRun) {}
}

/// The detector TOML text converted from a LEGEND diode record (a path to the JSON file, or the
/// record as a dict), as `hpge-cv detector --from-legend DIODE.json --out D.toml` writes it.
/// `n_plus_thickness_mm` (mm): the n+ dead layer where the record's `characterization` has none;
/// `can_gap_mm` (mm): the gap between the crystal and the grounded can.
#[pyfunction]
#[pyo3(signature = (record, n_plus_thickness_mm=None, can_gap_mm=None))]
fn legend_to_toml(
    py: Python<'_>,
    record: &Bound<'_, PyAny>,
    n_plus_thickness_mm: Option<f64>,
    can_gap_mm: Option<f64>,
) -> PyResult<String> {
    let (text, source) = legend::record_text(py, record)?;
    hpge_solver::detector::legend::convert_json(
        &text,
        &source,
        &legend_options(n_plus_thickness_mm, can_gap_mm),
    )
    .map_err(err)
}

/// r (mm), z (mm) and the surface of each segment.
type Outline<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Vec<&'static str>,
);

/// The crystal's r-z outline (mm) of a LEGEND diode record as hpge-cv converts it: a tuple of
/// arrays (r_mm, z_mm), from the axis at the p+ face around to the axis (the closing segment
/// runs along the axis), and the surface of each segment ("p+", "n+", "passive").
#[pyfunction]
fn legend_outline<'py>(py: Python<'py>, record: &Bound<'py, PyAny>) -> PyResult<Outline<'py>> {
    let (text, source) = legend::record_text(py, record)?;
    let d = hpge_solver::detector::legend::read_json(
        &text,
        &source,
        &hpge_solver::detector::legend::LegendOptions::default(),
    )
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

/// hpge-cv from Python: detectors, C-V curves, capacitance, pulses and fields from the field
/// solver; surrogate predictions; measurement of raw pulser data; Bayesian fits. Units: mm, V,
/// cm^-3 (signed, positive n-type), pF, ns, V/cm.
#[pymodule]
fn hpge_cv(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("HpgeError", m.py().get_type::<HpgeError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyDetector>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(capacitance, m)?)?;
    m.add_function(wrap_pyfunction!(pulse, m)?)?;
    m.add_function(wrap_pyfunction!(field, m)?)?;
    m.add_function(wrap_pyfunction!(predict, m)?)?;
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(discover, m)?)?;
    m.add_function(wrap_pyfunction!(legend_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(legend_outline, m)?)?;
    Ok(())
}
