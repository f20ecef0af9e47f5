//! The workflow's settings, inputs and results.

use std::collections::BTreeMap;
use std::sync::Arc;

use hpge_surrogate::ExactSolver;
use serde::Serialize;

use super::checks::{Elpd, ResidualCheck};
use super::summary::DiscoverySummary;
use crate::fit::{Fit, FitSettings};
use crate::model::CvModel;
use crate::posterior::Likelihood;
use crate::posterior::{LaplaceFit, LaplaceSettings};
use crate::prior::PriorSpec;
use crate::sampler::Status;
use crate::{Error, Result};

/// Smallest Laplace ln Bayes factor for an extension to be chosen: 3 is "strong" evidence on
/// Kass & Raftery's (1995) scale (2 ln B > 6).
pub const DEFAULT_MIN_LN_BAYES: f64 = 3.0;

/// Settings of the workflow.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DiscoverSettings {
    /// The start model's and the chosen extension's MCMC fits.
    pub fit: FitSettings,
    /// The quick fits.
    pub laplace: LaplaceSettings,
    /// Shortest run of same-sign residuals that counts as a window.
    pub min_run: usize,
    /// A window is reported as disagreement when its (look-elsewhere corrected) p-value is below
    /// this.
    pub window_p: f64,
    /// Smallest Laplace ln Bayes factor for an extension to be chosen: 3 is "strong" evidence
    /// on Kass & Raftery's (1995) scale (2 ln B > 6).
    pub min_ln_bayes: f64,
    /// Blocks of the leave-window-out elpd (contiguous voltage windows).
    pub elpd_blocks: usize,
    /// Posterior draws for the residual check and the elpd.
    pub draws: usize,
    /// Run the quick fits, the residual check and the full fit of an extension on the exact
    /// solver (Laplace), the surrogate only seeding the start model's mode. Off: everything
    /// on the surrogate where it can (MCMC), the exact solver only for entries outside its
    /// space. On by default: the surrogate is up to 27% off the exact solver on z-only
    /// profiles at 25 V (a corner of its space), enough to fake any effect.
    pub exact: bool,
    /// Catalogue entries to try (empty: all).
    pub only: Vec<String>,
    /// Seed of every random step.
    pub seed: u64,
}

impl Default for DiscoverSettings {
    fn default() -> Self {
        Self {
            fit: FitSettings::default(),
            laplace: LaplaceSettings::default(),
            min_run: 3,
            window_p: 0.01,
            min_ln_bayes: DEFAULT_MIN_LN_BAYES,
            elpd_blocks: 10,
            draws: 1000,
            exact: true,
            only: Vec::new(),
            seed: 1,
        }
    }
}

impl DiscoverSettings {
    /// Checks the values (an [`Error::Argument`] named `discover settings`, whose message names
    /// the field).
    pub fn validate(&self) -> Result<()> {
        let bad = |message: String| {
            Err(Error::Argument {
                name: "discover settings".into(),
                message,
            })
        };
        if self.min_run < 2 {
            return bad(format!("min_run: {} < 2", self.min_run));
        }
        if !(self.window_p > 0.0 && self.window_p < 1.0) {
            return bad(format!("window_p: {} is not in (0, 1)", self.window_p));
        }
        if self.elpd_blocks < 2 {
            return bad(format!("elpd_blocks: {} < 2", self.elpd_blocks));
        }
        if self.draws < 100 {
            return bad(format!("draws: {} < 100", self.draws));
        }
        Ok(())
    }
}

/// What the workflow starts from.
pub struct DiscoverInputs<'a> {
    /// The surrogate bound to the data's voltages.
    pub surrogate: Arc<dyn CvModel>,
    /// The exact solver on the surrogate's space and the detector.
    pub exact: &'a ExactSolver,
    /// The start model's prior.
    pub start: &'a PriorSpec,
    /// The likelihood of the data (its sigma_p is the surrogate's; used for every predictor so
    /// that scores compare alike).
    pub likelihood: &'a Likelihood,
    /// Input files and hashes for the summary.
    pub inputs: BTreeMap<String, String>,
    /// Where the finished stages go and are taken back from (`OUT/stages`, see
    /// [`super::Stages`]); None: nothing is written, nothing resumed.
    pub stages: Option<&'a super::Stages>,
}

/// One model's fit, as the workflow keeps it.
#[derive(Debug, Clone)]
pub struct ModelFit {
    /// The model's prior name.
    pub model: String,
    /// Parameter names.
    pub names: Vec<String>,
    /// The MCMC fit (None for a Laplace fit).
    pub mcmc: Option<Fit>,
    /// The Laplace fit (None for an MCMC fit).
    pub laplace: Option<LaplaceFit>,
    /// Its residual check.
    pub check: ResidualCheck,
    /// Its leave-window-out elpd.
    pub elpd: Elpd,
    /// c_p at the mode, pF.
    pub c_mode: Vec<f64>,
    /// sigma at the mode, pF.
    pub sigma_mode: Vec<f64>,
}

/// Everything the workflow found.
#[derive(Debug, Clone)]
pub struct Discovery {
    /// The summary (JSON).
    pub summary: DiscoverySummary,
    /// The start model.
    pub before: ModelFit,
    /// The extended model (None when nothing was chosen).
    pub after: Option<ModelFit>,
    /// Bias voltages, V.
    pub voltage_v: Vec<f64>,
    /// Measured c12, pF.
    pub c_m_pf: Vec<f64>,
    /// The start model's inputs at its global mode (the surrogate's input order; the exact
    /// solver's detector there is what the probed regions were computed on).
    pub start_inputs: Vec<f64>,
}

/// Progress of the workflow.
pub trait Progress: Sync {
    /// A stage begins (one line).
    fn stage(&self, message: &str);
    /// MCMC progress.
    fn sampling(&self, status: &Status);
}
