//! The tables a fit writes beside its summary: `samples.csv` (every draw), `predictive.csv`
//! (c_p - c_m bands per voltage), `zeta-mode.csv` (the profiles at the global mode with their posterior bands) and
//! `summary.json`. The CSVs are plain tables (one header row, no comment lines) that
//! `pandas.read_csv` and `numpy.genfromtxt(names=True, delimiter=',')` load as they are; their
//! provenance (program version, inputs with hashes, sampler, seed, likelihood) is in
//! `summary.json` (`program_version`, `inputs`, `settings`, `likelihood`).

use std::path::Path;

use super::Fit;
use super::truth::TruthRecord;
use super::zeta::ZetaAtMode;
use crate::{Error, Result};

/// Writes `text` (lines already newline-terminated) to `path`, whole or not at all.
fn write_text(path: &Path, text: &str) -> Result<()> {
    hpge_files::write(path, text.as_bytes()).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        action: "cannot write the file",
        source,
    })
}

/// `samples.csv`: `chain,draw,<parameters>,ln_posterior`, one row per draw.
pub fn write_samples(path: &Path, fit: &Fit) -> Result<()> {
    let mut w = String::new();
    w.push_str(&format!(
        "chain,draw,{},ln_posterior\n",
        fit.samples.names.join(",")
    ));
    for (c, ch) in fit.samples.chains.iter().enumerate() {
        for (i, (t, l)) in ch.theta.iter().zip(&ch.ln_posterior).enumerate() {
            let vals: Vec<String> = t.iter().map(|v| format!("{v}")).collect();
            w.push_str(&format!("{c},{i},{},{l}\n", vals.join(",")));
        }
    }
    write_text(path, &w)
}

/// The draws of a `samples.csv` ([`write_samples`]) read back: each row's parameter values, in
/// the file's order.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read, [`Error::Format`] for an empty file or a row
/// whose values are not numbers.
pub fn read_samples(path: &Path) -> Result<Vec<Vec<f64>>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        action: "cannot read the file",
        source,
    })?;
    let mut lines = text.lines();
    let header = lines.next().ok_or_else(|| {
        Error::format(path, "empty: expected a chain,draw,...,ln_posterior header")
    })?;
    let np = header.split(',').count().saturating_sub(3);
    lines
        .enumerate()
        .map(|(i, l)| {
            l.split(',')
                .skip(2)
                .take(np)
                .map(|v| v.parse::<f64>())
                .collect::<std::result::Result<Vec<f64>, _>>()
                .map_err(|e| Error::format(path, format!("row {}: {e}", i + 2)))
        })
        .collect()
}

/// `predictive.csv`: per voltage the data, the curve at the global mode, sigma, the pull at the
/// mode and the median and 68.3/95.5/99.7% bands of c_p - c_m over the posterior.
pub fn write_predictive(path: &Path, fit: &Fit) -> Result<()> {
    let p = &fit.predictive;
    let mut w = String::from(
        "voltage_V,c_m_pF,c_mode_pF,sigma_pF,pull_at_mode,diff_median_pF,diff_lo683_pF,diff_hi683_pF,diff_lo955_pF,diff_hi955_pF,diff_lo997_pF,diff_hi997_pF\n",
    );
    for k in 0..p.voltage_v.len() {
        let b: Vec<String> = p.bands_pf[k]
            .iter()
            .flat_map(|[a, c]| [format!("{a}"), format!("{c}")])
            .collect();
        w.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            p.voltage_v[k],
            p.c_m_pf[k],
            p.c_mode_pf[k],
            p.sigma_pf[k],
            (p.c_mode_pf[k] - p.c_m_pf[k]) / p.sigma_pf[k],
            p.median_pf[k],
            b.join(",")
        ));
    }
    write_text(path, &w)
}

/// `zeta-mode.csv`: `profile,label,coordinate_mm,zeta_cm3` (the global mode; profiles
/// `along_z`, `along_r`), then `lo_683_cm3,hi_683_cm3,lo_955_cm3,hi_955_cm3` (the posterior's
/// central bands) and `truth_cm3`, each column empty where it was not computed.
pub fn write_zeta(path: &Path, zeta: &ZetaAtMode) -> Result<()> {
    let mut w = String::from(
        "profile,label,coordinate_mm,zeta_cm3,lo_683_cm3,hi_683_cm3,lo_955_cm3,hi_955_cm3,truth_cm3\n",
    );
    let pair = |b: Option<&[f64; 2]>| b.map_or(",".to_string(), |b| format!("{},{}", b[0], b[1]));
    for (kind, list) in [("along_z", &zeta.along_z), ("along_r", &zeta.along_r)] {
        for prof in list {
            for (k, (x, v)) in prof.x_mm.iter().zip(&prof.zeta_cm3).enumerate() {
                w.push_str(&format!(
                    "{kind},{},{x},{v},{},{},{}\n",
                    prof.label,
                    pair(prof.band_683_cm3.get(k)),
                    pair(prof.band_955_cm3.get(k)),
                    prof.truth_cm3
                        .get(k)
                        .map_or(String::new(), |t| t.to_string())
                ));
            }
        }
    }
    write_text(path, &w)
}

/// The summary as JSON, with the truth records (`truth`) where a truth was given.
pub fn summary_json(fit: &Fit, truth: Option<&[TruthRecord]>) -> Result<serde_json::Value> {
    let to_value = |e: serde_json::Error| Error::Numerical {
        what: "the summary as JSON".into(),
        message: e.to_string(),
    };
    let mut json = serde_json::to_value(&fit.summary).map_err(to_value)?;
    if let (Some(t), Some(obj)) = (truth, json.as_object_mut()) {
        obj.insert("truth".into(), serde_json::to_value(t).map_err(to_value)?);
    }
    Ok(json)
}

/// Writes `summary.json` (pretty, newline-terminated).
pub fn write_summary(path: &Path, json: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(json).map_err(|e| Error::Numerical {
        what: "the summary as JSON".into(),
        message: e.to_string(),
    })?;
    write_text(path, &(text + "\n"))
}

/// The file name of the error model a refined fit writes beside its summary.
pub const ERROR_MODEL_FILE: &str = "error-model.json";

/// A refined fit's model of the surrogate's error (`error-model.json`): the exact curves it was
/// taught, as log-ratios ln(c_exact / c_surrogate) at the data's voltages, and its
/// hyperparameters, from which [`ErrorModelFile::correction`] rebuilds it exactly. It belongs
/// to this data set and this surrogate (both named with their hashes); the shipped model is
/// never changed.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorModelFile {
    /// hpge-cv version.
    pub program_version: String,
    /// What this is, in words.
    pub description: String,
    /// The fit's inputs (data, model, prior, detector, with hashes).
    pub inputs: std::collections::BTreeMap<String, String>,
    /// The surrogate's input names (the columns of `x`).
    pub input_names: Vec<String>,
    /// The voltages (V) of the columns of `log_ratio`.
    pub voltages_v: Vec<f64>,
    /// The Gaussian process's hyperparameters.
    pub hyper: crate::refine::GpHyper,
    /// Model inputs of the exact curves.
    pub x: Vec<Vec<f64>>,
    /// ln(c_exact / c_surrogate) of each curve at each voltage.
    pub log_ratio: Vec<Vec<f64>>,
}

impl ErrorModelFile {
    /// The file of `job`'s refined fit: its `training` points and the `correction` fitted to
    /// them (None: no correction, hyperparameters empty).
    pub fn new(
        job: &super::FitJob,
        training: &[(Vec<f64>, Vec<f64>)],
        correction: Option<&crate::refine::GpCorrection>,
    ) -> Self {
        use crate::model::CvModel as _;
        Self {
            program_version: env!("CARGO_PKG_VERSION").into(),
            description: "Gaussian-process model of ln(c_exact / c_surrogate) at the data's voltages, taught by the exact curves of the fit's refinement rounds (hpge_inference::refine)".into(),
            inputs: job.inputs.clone(),
            input_names: job.surrogate.inputs(),
            voltages_v: job.data.voltage_v.clone(),
            hyper: correction.map_or_else(
                || crate::refine::GpHyper {
                    lengths: Vec::new(),
                    sf: 0.0,
                    sn: 0.0,
                },
                |c| c.hyper.clone(),
            ),
            x: training.iter().map(|t| t.0.clone()).collect(),
            log_ratio: training.iter().map(|t| t.1.clone()).collect(),
        }
    }

    /// The error model rebuilt from the points and hyperparameters.
    ///
    /// # Errors
    /// As [`crate::refine::GpCorrection::with_hyper`].
    pub fn correction(&self) -> Result<crate::refine::GpCorrection> {
        crate::refine::GpCorrection::with_hyper(&self.x, &self.log_ratio, self.hyper.clone())
    }
}

/// Writes `error-model.json` (pretty, newline-terminated).
pub fn write_error_model(path: &Path, file: &ErrorModelFile) -> Result<()> {
    let text = serde_json::to_string_pretty(file).map_err(|e| Error::Numerical {
        what: "the error model as JSON".into(),
        message: e.to_string(),
    })?;
    write_text(path, &(text + "\n"))
}
