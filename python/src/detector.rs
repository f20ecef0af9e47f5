//! `Detector`: a detector description read from TOML or converted from a LEGEND record, and
//! the solver settings a call asks for.

use std::path::PathBuf;

use hpge_solver::options::{SolverOptions, WeightingOptions};
use hpge_solver::{Detector, FieldSettings, GridOverrides, Parameters};
use pyo3::prelude::*;

use crate::{HpgeError, err};

/// A detector description: geometry, materials, contacts, passives, world and impurity model.
///
/// `Detector(path, impurity=None, params=None)` reads a detector TOML file (detectors/README.md),
/// optionally with the impurity model from its own TOML file and parameter overrides
/// (`{"d_li_mm": 3.0}`), exactly as `hpge-cv detector --detector D [--impurity I] [--param
/// NAME=VALUE]`. `Detector.from_legend(record, ...)` converts a LEGEND diode record.
#[pyclass(name = "Detector", module = "hpge_cv", frozen)]
pub(crate) struct PyDetector {
    pub(crate) det: Detector,
}

pub(crate) fn overrides(params: Option<Vec<(String, f64)>>) -> Parameters {
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
        let (toml, source) = crate::legend::convert(py, record, n_plus_thickness_mm, can_gap_mm)?;
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

/// The solver settings the command line uses, with `--tolerance` and `--grid KEY=VALUE`.
pub(crate) fn field_settings(
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
