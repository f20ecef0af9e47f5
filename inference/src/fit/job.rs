//! A fit set up from its four input files: the measured curve, the surrogate, the prior and the
//! detector, checked against each other (the model must have been trained for this detector,
//! its voltages must cover the data's) and bound into one likelihood and one prior.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use hpge_foundation::fnv1a;
use hpge_solver::{Detector, FieldSettings, GridOverrides, Parameters};
use hpge_surrogate::{ExactSolver, Surrogate};

use super::run::{Fit, FitSettings, fit};
use super::zeta::{ZETA_BAND_DRAWS, ZetaAtMode, zeta_profiles};
use crate::model::{CvModel, SurrogateModel};
use crate::posterior::{Likelihood, NoiseSettings, Posterior};
use crate::prior::{Prior, PriorSpec};
use crate::sampler::Status;
use crate::{Error, Result};
use hpge_measurement::{CvData, Data, load_data};

/// Target relative error of c12 (the adaptive grid's tolerance) of the exact solver of a fit
/// job, where neither `--tolerance` nor the detector's `[grid]` table sets one: the exact-solver
/// check of `fit`, the exact fits and checks of `discover`, and the exact-solver data of
/// `validate coverage --exact` and `validate discovery` (whose 3% noise dwarfs it). 1%, the
/// field-solver uncertainty f_s the likelihood already carries (paper, eq. 7), so the check
/// solves to the accuracy the likelihood assumes of a solver. The grid's estimate is an upper
/// bound (|c12_h - c12_H| over two coarsenings): on the shipped fit's posterior draws the curves
/// solved at 1% differ from those solved at the solver's default 0.2% by at most 0.36% (rms
/// 0.08%), a tenth of the likelihood's sigma of about 3.3% per point, at a fifth to a tenth of
/// the cost (reports/solver-performance.md, "The exact check of a fit").
pub const EXACT_CHECK_TOLERANCE: f64 = 0.01;

/// The four input files of a fit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FitFiles {
    /// The measured C-V curve (CSV, with or without its covariance file).
    pub data: PathBuf,
    /// The surrogate model file (safetensors with metadata).
    pub model: PathBuf,
    /// The prior (TOML).
    pub prior: PathBuf,
    /// The detector the model was trained for (TOML).
    pub detector: PathBuf,
}

/// Everything a fit is set up from, checked and bound.
pub struct FitJob {
    /// The files it was read from.
    pub files: FitFiles,
    /// The measured curve.
    pub data: CvData,
    /// The surrogate at the data's voltages.
    pub surrogate: SurrogateModel,
    /// The prior bound to the surrogate's inputs.
    pub prior: Prior,
    /// The likelihood of the data.
    pub likelihood: Likelihood,
    /// The exact field solver of the same space and detector (for the exact-solver check and the
    /// profiles at the mode).
    pub exact: ExactSolver,
    /// The inputs by name with their hashes (`data`, `data_hash`, `model`, ...), recorded in the
    /// summary.
    pub inputs: BTreeMap<String, String>,
    /// Warnings for the user (e.g. a model that records no detector, so none could be checked).
    pub warnings: Vec<String>,
}

/// FNV-1a hash of a file's bytes as 16 hex digits ("?" where the file cannot be read).
pub fn file_hash(path: &Path) -> String {
    std::fs::read(path).map_or_else(|_| "?".into(), |b| format!("{:016x}", fnv1a(&b)))
}

impl FitJob {
    /// Reads and checks data, model, prior and detector against each other; `grid` sets the
    /// exact solver's grid and accuracy on top of the detector file's `[grid]` table (without
    /// either, the grid's defaults at the tolerance [`EXACT_CHECK_TOLERANCE`]).
    ///
    /// # Errors
    /// Raw pulser data instead of a curve ([`Error::Format`]), a model trained for another
    /// detector ([`Error::DetectorMismatch`]), voltages outside the model's range, a prior that
    /// does not fit the model's inputs, and every read or parse error, each naming its file.
    pub fn from_files(
        files: &FitFiles,
        noise: NoiseSettings,
        grid: &GridOverrides,
    ) -> Result<Self> {
        let FitFiles {
            data,
            model,
            prior,
            detector,
        } = files;
        let data_curve = match load_data(data)? {
            Data::Curve(c) => c,
            Data::Raw(_) => {
                return Err(Error::format(
                    data,
                    format!(
                        "raw pulser data; make a C-V curve first: hpge-cv measure --raw {} --out cv.csv",
                        data.display()
                    ),
                ));
            }
        };
        let surrogate = Surrogate::load(model)?;
        let det_context = || format!("--detector {}", detector.display());
        let det = Detector::from_file(detector, &Parameters::new())
            .map_err(|e| Error::from(e).context(det_context()))?;
        // The check's own accuracy unless the detector's [grid] table or --tolerance sets one.
        let mut base = FieldSettings::default();
        base.grid.tolerance = EXACT_CHECK_TOLERANCE;
        let settings = grid.apply(&base, &det)?;
        let exact = ExactSolver::new(surrogate.info.space.clone(), detector, settings)
            .map_err(|e| Error::from(e).context(det_context()))?;
        let mut warnings = Vec::new();
        match &surrogate.info.detector {
            Some(d) if d.hash != exact.detector_hash() => {
                return Err(Error::DetectorMismatch {
                    model: model.clone(),
                    trained_file: d.file.clone(),
                    trained_hash: d.hash.clone(),
                    detector: detector.clone(),
                    hash: exact.detector_hash(),
                });
            }
            Some(_) => {}
            None => warnings.push(format!(
                "{} records no detector (trained without --detector); it cannot be checked against {}",
                model.display(),
                detector.display()
            )),
        }
        let sigma = match surrogate.error_model() {
            Some(m) if !noise.constant_sigma => format!(
                "per-point sigma_s calibrated on {} rows of {}",
                m.calibration.n, m.calibration.file
            ),
            _ => format!("sigma_p {:.3}%", 100.0 * surrogate.sigma_p()),
        };
        let describe = format!(
            "{} (recipe {}, {sigma})",
            model.display(),
            surrogate.info.recipe_name,
        );
        let sm = SurrogateModel::new(surrogate, &data_curve.voltage_v, describe)
            .map_err(|e| e.context(format!("the voltages of {}", data.display())))?
            .constant_sigma(noise.constant_sigma);
        let spec = PriorSpec::from_file(prior)?;
        let prior_b = Prior::bind(&spec, &sm.inputs(), &sm.domain())?;
        let likelihood = Likelihood::new(&data_curve, noise, sm.sigma_rel())?;
        let mut inputs = BTreeMap::new();
        inputs.insert("data".into(), data.display().to_string());
        inputs.insert("data_hash".into(), file_hash(data));
        inputs.insert("model".into(), model.display().to_string());
        inputs.insert("model_hash".into(), file_hash(model));
        inputs.insert("prior".into(), prior.display().to_string());
        inputs.insert("prior_hash".into(), file_hash(prior));
        inputs.insert("detector".into(), detector.display().to_string());
        inputs.insert("detector_hash".into(), exact.detector_hash());
        Ok(FitJob {
            files: files.clone(),
            data: data_curve,
            surrogate: sm,
            prior: prior_b,
            likelihood,
            exact,
            inputs,
            warnings,
        })
    }

    /// The posterior of the data with the surrogate and the prior.
    ///
    /// # Errors
    /// The surrogate's voltages and the likelihood's do not match.
    pub fn posterior(&self) -> Result<Posterior<'_>> {
        Posterior::new(&self.surrogate, &self.prior, &self.likelihood).map_err(|e| {
            e.context(format!(
                "{} with {}",
                self.files.data.display(),
                self.files.prior.display()
            ))
        })
    }

    /// Samples the posterior and summarises it ([`fit`]); `progress` sees every status update.
    ///
    /// # Errors
    /// See [`FitJob::posterior`] and [`fit`].
    pub fn run(&self, settings: &FitSettings, progress: &(dyn Fn(&Status) + Sync)) -> Result<Fit> {
        let posterior = self.posterior()?;
        let mut result = fit(&posterior, settings, self.inputs.clone(), progress)?;
        result.summary.posterior_outside_support = Some(self.outside_support(&result.samples));
        Ok(result)
    }

    /// The share of `samples`' draws with an input outside the surrogate's support (where fewer
    /// than `SUPPORT_ROWS` training rows lie beyond it, issue 24): there the surrogate
    /// extrapolates, and the posterior rests on its least accurate predictions.
    pub fn outside_support(&self, samples: &crate::sampler::Samples) -> f64 {
        let all = samples.all();
        if all.is_empty() {
            return 0.0;
        }
        let mut x = vec![0.0; self.prior.input_names.len()];
        let outside = all
            .iter()
            .filter(|theta| {
                self.prior.expand(theta, &mut x);
                self.surrogate.surrogate.check_support(&x, &[]).is_err()
            })
            .count();
        outside as f64 / all.len() as f64
    }

    /// The support guard for the data (issue 24): every voltage of the measured curve where the
    /// surrogate's training rows support it (the shipped models: 13.4-2996.6 V). Outside, the
    /// fit is refused unless `extrapolate`, in which case the warning is returned; `flag` is how
    /// the caller's user asks to extrapolate (`--extrapolate`, `extrapolate=True`).
    ///
    /// # Errors
    /// [`Error::Format`] naming the data file, the first voltage outside and the support.
    pub fn voltage_support_guard(&self, extrapolate: bool, flag: &str) -> Result<Option<String>> {
        let Err(e) = self
            .surrogate
            .surrogate
            .check_support(&[], &self.data.voltage_v)
        else {
            return Ok(None);
        };
        let file = self.files.data.display();
        if extrapolate {
            Ok(Some(format!("{file}: {e}; fitting anyway ({flag})")))
        } else {
            Err(Error::format(
                &self.files.data,
                format!("{e}; pass {flag} to fit there anyway"),
            ))
        }
    }

    /// zeta at the global mode of `result` with the posterior's 68.3% and 95.5% bands over
    /// [`ZETA_BAND_DRAWS`] thinned draws, and the truth's profiles where `truth` gives every
    /// parameter ([`zeta_profiles`]).
    ///
    /// # Errors
    /// The detector cannot be built at the mode or at the truth.
    pub fn zeta_at_mode(&self, result: &Fit, truth: Option<&[Option<f64>]>) -> Result<ZetaAtMode> {
        let all = result.samples.all();
        let draws: Vec<&[f64]> = super::predictive::thin_indices(all.len(), ZETA_BAND_DRAWS)
            .into_iter()
            .map(|i| all[i])
            .collect();
        let truth: Option<Vec<f64>> = truth.and_then(|t| t.iter().copied().collect());
        zeta_profiles(
            &self.exact,
            &self.prior,
            &result.mode,
            &draws,
            truth.as_deref(),
        )
    }
}
