//! The options of model discovery as a user states them. [`WorkflowOptions`] are those of the
//! workflow itself (its input files, the catalogue entries it tries, the fits' ESS target, the
//! exact solver's grid), shared by `discover` ([`DiscoverOptions`]) and the hidden-effect study
//! of the validation crate. The command line flattens these structs (feature `clap`), so every
//! option and default is declared here once.

use std::path::{Path, PathBuf};

use hpge_solver::GridOverrides;

use super::catalogue::catalogue;
use super::settings::{DEFAULT_MIN_LN_BAYES, DiscoverSettings};
use crate::fit::{
    DEFAULT_DATA, DEFAULT_DETECTOR, DEFAULT_MODEL, FIT_MAX_SECONDS, FitSettings, check_positive,
};
use crate::posterior::NoiseSettings;
use crate::sampler::{DEFAULT_ESS_MIN, DEFAULT_SEED, SampleSettings, SamplerKind};
use crate::{Error, Result};

/// The start model `discover` begins from: the paper's B_Z prior (priors/b-z.toml).
pub const DEFAULT_START_MODEL: &str = "b-z";

/// The options of the discovery workflow that every command running it takes.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct WorkflowOptions {
    /// The measured C-V curve (CSV with voltage_V, c12_pF, sigma_pF); the hidden-effect study
    /// takes only its voltages.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_DATA))]
    pub data: PathBuf,
    /// The detector the data were measured with (checked against the model's; the exact solver
    /// runs on it for the extensions outside the surrogate's space and for the probed regions).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "FILE", default_value = DEFAULT_DETECTOR)
    )]
    pub detector: PathBuf,
    /// The surrogate model (.safetensors); its space must contain the start model.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_MODEL))]
    pub model: PathBuf,
    /// Catalogue entries to try, comma-separated (default: all; see `discover --list`).
    #[cfg_attr(feature = "clap", arg(long, value_delimiter = ','))]
    pub only: Vec<String>,
    /// Target bulk and tail ESS of the MCMC fits (lower: faster; the CI's reduced hidden-effect
    /// run uses 300).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_ESS_MIN, allow_hyphen_values = true))]
    pub ess: f64,
    /// Write no figures.
    #[cfg_attr(feature = "clap", arg(long))]
    pub no_plots: bool,
    /// The exact solver's grid and accuracy.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub grid: GridOverrides,
}

impl Default for WorkflowOptions {
    /// The shipped defaults (the same as the command line's).
    fn default() -> Self {
        Self {
            data: DEFAULT_DATA.into(),
            detector: DEFAULT_DETECTOR.into(),
            model: DEFAULT_MODEL.into(),
            only: Vec::new(),
            ess: DEFAULT_ESS_MIN,
            no_plots: false,
            grid: GridOverrides::default(),
        }
    }
}

impl WorkflowOptions {
    /// Checks that every `only` entry names a catalogue entry.
    ///
    /// # Errors
    /// [`Error::BadOption`] naming `--only` and listing the entries.
    pub fn check_only(&self) -> Result<()> {
        let names: Vec<&str> = catalogue().iter().map(|e| e.name()).collect();
        match self.only.iter().find(|o| !names.contains(&o.as_str())) {
            Some(o) => Err(Error::BadOption {
                option: format!("--only {o}"),
                message: format!(
                    "no such catalogue entry; the entries are {}",
                    names.join(", ")
                ),
            }),
            None => Ok(()),
        }
    }

    /// The workflow's settings: Metropolis fits with these targets, a budget of `max_seconds`
    /// per fit, `noise` and `seed`, checked.
    ///
    /// # Errors
    /// Targets [`SampleSettings::validate`] refuses.
    pub fn settings(
        &self,
        noise: NoiseSettings,
        seed: u64,
        max_seconds: f64,
    ) -> Result<DiscoverSettings> {
        check_positive("--ess", self.ess, "effective draws")?;
        check_positive("--max-seconds", max_seconds, "seconds")?;
        let mut sample = SampleSettings::for_sampler(SamplerKind::Metropolis);
        sample.seed = seed;
        sample.ess_min = self.ess;
        sample.max_seconds = max_seconds;
        sample.validate()?;
        Ok(DiscoverSettings {
            fit: FitSettings {
                sample,
                noise,
                ..FitSettings::default()
            },
            only: self.only.clone(),
            seed,
            ..DiscoverSettings::default()
        })
    }
}

/// Everything a user chooses about `discover`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct DiscoverOptions {
    /// The inputs, catalogue entries, targets and grid.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub workflow: WorkflowOptions,
    /// The start model: a prior file, or the name of one in priors/ (b-z: the paper's B_Z).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "NAME|FILE", default_value = DEFAULT_START_MODEL)
    )]
    pub start_model: String,
    /// Output folder [default: discoveries/START_MODEL, under the working directory].
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR"))]
    pub out: Option<PathBuf>,
    /// Replace a discovery of another run (other inputs or settings) in the output folder;
    /// without it such a folder is refused (the same run again, or a resumed one, goes on).
    #[cfg_attr(feature = "clap", arg(long))]
    pub force: bool,
    /// Seed of every random step (sampling, predictive replicates).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_SEED))]
    pub seed: u64,
    /// Smallest Laplace ln Bayes factor for an extension to be added.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_MIN_LN_BAYES, allow_hyphen_values = true))]
    pub min_ln_bayes: f64,
    /// Stop each MCMC fit after this many seconds even if its targets are not reached.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = FIT_MAX_SECONDS, allow_hyphen_values = true))]
    pub max_seconds: f64,
    /// Fit and score on the surrogate wherever it can (MCMC, fast) instead of the exact solver
    /// (Laplace; the default, because the surrogate is up to 27% off on z-only profiles).
    #[cfg_attr(feature = "clap", arg(long))]
    pub surrogate_only: bool,
}

impl Default for DiscoverOptions {
    /// The shipped defaults (the same as the command line's).
    fn default() -> Self {
        Self {
            workflow: WorkflowOptions::default(),
            start_model: DEFAULT_START_MODEL.into(),
            out: None,
            force: false,
            seed: DEFAULT_SEED,
            min_ln_bayes: DEFAULT_MIN_LN_BAYES,
            max_seconds: FIT_MAX_SECONDS,
            surrogate_only: false,
        }
    }
}

impl DiscoverOptions {
    /// The start model's prior file: `start_model` as a path, else `priors/<start_model>.toml`.
    ///
    /// # Errors
    /// [`Error::BadOption`] naming `--start-model` when neither is a file.
    pub fn start_prior(&self) -> Result<PathBuf> {
        let name = &self.start_model;
        let p = PathBuf::from(name);
        if p.is_file() {
            return Ok(p);
        }
        let named = Path::new("priors").join(format!("{name}.toml"));
        if named.is_file() {
            return Ok(named);
        }
        Err(Error::BadOption {
            option: format!("--start-model {name}"),
            message: format!(
                "neither a prior file nor a name in priors/ ({} does not exist)",
                named.display()
            ),
        })
    }

    /// The output folder: `out`, else `discoveries/<stem of the start prior file>`.
    pub fn out_dir(&self, prior_file: &Path) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            PathBuf::from("discoveries").join(
                prior_file
                    .file_stem()
                    .map_or("discovery".into(), |s| s.to_string_lossy().to_string()),
            )
        })
    }

    /// The workflow's settings with `noise`, checked.
    ///
    /// # Errors
    /// Targets [`SampleSettings::validate`] refuses.
    pub fn settings(&self, noise: NoiseSettings) -> Result<DiscoverSettings> {
        if !self.min_ln_bayes.is_finite() {
            return Err(Error::BadOption {
                option: format!("--min-ln-bayes {}", self.min_ln_bayes),
                message: "must be a finite number (3: strong evidence)".into(),
            });
        }
        Ok(DiscoverSettings {
            min_ln_bayes: self.min_ln_bayes,
            exact: !self.surrogate_only,
            ..self.workflow.settings(noise, self.seed, self.max_seconds)?
        })
    }
}
