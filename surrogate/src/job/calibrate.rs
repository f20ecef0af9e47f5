//! `hpge-cv calibrate`: fits a model's per-point uncertainty sigma_s(p, U_B) on a calibration
//! set ([`crate::model::ErrorModel`], issue 21) and writes the model file with it; the weights
//! are copied unchanged (f32 in, f32 out), so every prediction stays bit for bit the same.

use std::path::PathBuf;

use super::evaluate::read_for_model;
use crate::model::{ErrorModel, Surrogate};
use crate::{Error, Result};

/// Everything a user chooses about a calibration.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct CalibrateOptions {
    /// The model file.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub model: PathBuf,
    /// Rows of the model's space the networks never saw (neither training nor test set), e.g.
    /// data/training/calibration.csv.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub data: PathBuf,
    /// The calibrated model file (default: --model itself, rewritten in place).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub out: Option<PathBuf>,
    /// On a surrogate with the pinch-off gate (recipe split-gate), leave the gate's proximity
    /// out of the error model's inputs: sigma_s then does not grow at the network's switch
    /// (with it, the main job's sampler mixed too slowly to converge: models/README.md).
    #[cfg_attr(feature = "clap", arg(long))]
    pub no_gate_input: bool,
}

impl CalibrateOptions {
    /// The file written.
    pub fn out_file(&self) -> &PathBuf {
        self.out.as_ref().unwrap_or(&self.model)
    }

    /// Loads the model, fits its error model on `--data`, writes the model with it and returns
    /// the error model.
    ///
    /// # Errors
    /// Reading the model or the data (a data set of another space names both), a data set that
    /// is the model's own training or test set ([`Error::Argument`]), the fit, or writing.
    pub fn run(&self) -> Result<ErrorModel> {
        let mut model = Surrogate::load(&self.model)?;
        let data = read_for_model(&model, &self.model, &self.data)?;
        for (what, used) in [
            ("training", &model.info.training),
            ("test", &model.info.test),
        ] {
            if used.hash == data.hash {
                return Err(Error::Argument {
                    name: "--data".into(),
                    message: format!(
                        "{} is the model's {what} set (hash {}): calibrate on rows it never saw",
                        self.data.display(),
                        data.hash
                    ),
                });
            }
        }
        let em = model.fit_error_model_with(&data, !self.no_gate_input)?;
        model.info.error_model = Some(em.clone());
        model.save(self.out_file())?;
        Ok(em)
    }
}
