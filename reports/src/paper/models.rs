//! The three impurity models of the paper's section 9 as detectors: the manufacturer's model
//! with a chosen lithium thickness, and the global modes of the B_Z and B_RZ fits turned into a
//! detector through the surrogate's parameter space and the fit's prior.

use std::path::{Path, PathBuf};

use hpge_inference::{CvModel, ExactModel, Prior, PriorSpec};
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_surrogate::{ExactSolver, Surrogate};
use serde_json::Value;

use crate::error::{Error, Result};

/// One impurity model of the comparison and where it came from.
#[derive(Debug, Clone)]
pub struct NamedModel {
    /// Short key for files and JSON (`manufacturer`, `b-z`, `b-rz`).
    pub key: String,
    /// Legend entry.
    pub label: String,
    /// The detector with the model set.
    pub detector: Detector,
    /// Parameter values that define it (name, value).
    pub values: Vec<(String, f64)>,
    /// Where the values came from (a summary file, or "detector default").
    pub source: String,
}

/// The detector's own (manufacturer's) impurity model with `d_li_mm` set.
pub fn manufacturer(detector: &Path, d_li_mm: f64) -> Result<NamedModel> {
    let mut p = Parameters::new();
    p.set("d_li_mm".to_string(), d_li_mm);
    let det = Detector::from_file(detector, &p)?;
    Ok(NamedModel {
        key: "manufacturer".into(),
        label: format!("zeta_M* (manufacturer, d_Li = {d_li_mm} mm)"),
        values: vec![("d_li_mm".into(), d_li_mm)],
        source: format!(
            "{} default impurity model ({})",
            detector.display(),
            det.semiconductor.impurity_file().display()
        ),
        detector: det,
    })
}

/// Builds detectors from fit summaries: the surrogate's parameter space on `detector` with the
/// exact solver's mapping of parameters to the detector.
pub struct ModeDetectors {
    model: ExactModel,
    /// The surrogate file the space came from.
    pub surrogate: PathBuf,
}

impl ModeDetectors {
    /// Loads the surrogate `surrogate` (for its parameter space) and sets up the exact solver on
    /// `detector`.
    pub fn new(surrogate: &Path, detector: &Path) -> Result<Self> {
        let s = Surrogate::load(surrogate)?;
        let exact = ExactSolver::new(s.info.space.clone(), detector, FieldSettings::default())?;
        let model = ExactModel::new(exact, &[1.0])?;
        Ok(Self {
            model,
            surrogate: surrogate.into(),
        })
    }

    /// The detector at the global mode of the fit summarised in `summary` (a `fit` summary.json,
    /// `parameters[].global_mode` by name), bound through `prior`.
    pub fn at_global_mode(
        &self,
        key: &str,
        label: &str,
        prior: &Path,
        summary: &Path,
    ) -> Result<NamedModel> {
        let spec = PriorSpec::from_file(prior)?;
        let prior_b = Prior::bind(&spec, &self.model.inputs(), &self.model.domain())?;
        let theta = global_mode(summary, &prior_b.names())?;
        let mut x = vec![0.0; prior_b.input_names.len()];
        prior_b.expand(&theta, &mut x);
        let det = self.model.solver.detector(&x)?;
        Ok(NamedModel {
            key: key.into(),
            label: label.into(),
            values: prior_b.names().into_iter().zip(theta).collect(),
            source: format!(
                "global mode in {} (prior {}, space of {})",
                summary.display(),
                prior.display(),
                self.surrogate.display()
            ),
            detector: det,
        })
    }
}

/// The `global_mode` of each parameter in `names` from a fit summary.
pub fn global_mode(summary: &Path, names: &[String]) -> Result<Vec<f64>> {
    let text = std::fs::read_to_string(summary).map_err(|source| Error::Read {
        file: summary.to_path_buf(),
        what: "the fit summary",
        source,
    })?;
    let v: Value = serde_json::from_str(&text).map_err(|source| Error::Json {
        file: summary.to_path_buf(),
        what: "not a JSON fit summary",
        source,
    })?;
    let params = v["parameters"].as_array().ok_or_else(|| Error::Content {
        file: summary.to_path_buf(),
        message: "no `parameters` list".into(),
    })?;
    names
        .iter()
        .map(|n| {
            params
                .iter()
                .find(|p| p["name"].as_str() == Some(n))
                .and_then(|p| p["global_mode"].as_f64())
                .ok_or_else(|| Error::Content {
                    file: summary.to_path_buf(),
                    message: format!("no `global_mode` for the parameter `{n}`"),
                })
        })
        .collect()
}
