//! The options of the validation studies as a user states them: simulation-based calibration
//! ([`CoverageOptions`], `validate coverage`) and the hidden-effect tests of model discovery
//! ([`HiddenOptions`], `validate discovery`). The command line flattens these structs (feature
//! `clap`), so every option and default is declared here once.

use std::path::PathBuf;

use hpge_foundation::Shard;
use hpge_inference::discover::WorkflowOptions;
use hpge_inference::fit::{
    DEFAULT_DATA, DEFAULT_DETECTOR, DEFAULT_MODEL, DEFAULT_PRIOR, DEFAULT_REFINE_ROUNDS,
    FIT_LIKELIHOOD, FitOptions, RefineSettings, noise_settings,
};
use hpge_inference::posterior::NoiseSettings;
use hpge_inference::sampler::{DEFAULT_MODE_STARTS, DEFAULT_SEED};
use hpge_inference::{DiscoverSettings, SamplerKind};

use super::coverage::{CoverageSettings, DataFrom, PipelineSettings};
use crate::error::Result;

/// The folder, under the working directory, that holds a coverage study's folder
/// (`PRIOR[-exact]`) when `--out` is not given.
pub const COVERAGE_OUT: &str = "coverage";
/// Target bulk and tail ESS of each fit of a coverage study: the main job's
/// ([`hpge_inference::sampler::DEFAULT_ESS_MIN`], 1000; issue 60: a study tests the pipeline the
/// README runs, so every fit setting is `fit`'s unless a flag says otherwise; until 2026-12-06
/// studies used 300 and 20 000 draws).
pub const COVERAGE_ESS: f64 = hpge_inference::sampler::DEFAULT_ESS_MIN;
/// L: posterior draws each truth is ranked among (ranks 0..=99, 100 bins).
pub const COVERAGE_RANKS: usize = 99;
/// Sampling budget (s) of each fit of a coverage study: a safety net only, and the one sampler
/// setting that differs from `fit`'s 300 s on purpose. A study needs many fits: one that has
/// not reached its ESS after `fit`'s draw limit (100 000 kept draws per chain) stops there and is
/// counted as unconverged. The draw cap, not the clock, ends such a fit, so a study's ranks are
/// the same on a loaded or a quiet machine; with a clock limit a loaded machine cut fits shorter
/// than a quiet one. `report status` does not count it as a difference from the main job.
pub const COVERAGE_FIT_MAX_SECONDS: f64 = 3600.0;

/// Everything a user chooses about a coverage study.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct CoverageOptions {
    /// Number of truths.
    #[cfg_attr(feature = "clap", arg(long))]
    pub truths: usize,
    /// The prior (truths are drawn from it).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_PRIOR))]
    pub prior: PathBuf,
    /// The surrogate that is fitted.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_MODEL))]
    pub model: PathBuf,
    /// A measured curve: its voltages (and covariance, for --likelihood covariance) are used.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_DATA))]
    pub data: PathBuf,
    /// The detector (for --exact and the model check).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "FILE", default_value = DEFAULT_DETECTOR)
    )]
    pub detector: PathBuf,
    /// Simulate the data with the exact field solver instead of the surrogate (what surrogate
    /// error does to coverage): each fit then runs `fit`'s full pipeline, exact check and
    /// refinement included (1-4 min per B_RZ truth on 2 cores; `--no-exact-check` leaves them out).
    #[cfg_attr(feature = "clap", arg(long))]
    pub exact: bool,
    /// Likelihood: paper, covariance, or auto (covariance where the data have one, else paper;
    /// `fit`'s default): the simulated data's noise is drawn from it.
    #[cfg_attr(feature = "clap", arg(long, default_value = FIT_LIKELIHOOD))]
    pub likelihood: String,
    /// Sampler: metropolis or nuts.
    #[cfg_attr(feature = "clap", arg(long, default_value = SamplerKind::default().as_str()))]
    pub sampler: String,
    /// Seed of the truths, the noise and the fits.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_SEED))]
    pub seed: u64,
    /// Target bulk and tail ESS of each fit (`fit`'s default).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = COVERAGE_ESS))]
    pub ess: f64,
    /// Posterior draws each truth is ranked among.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = COVERAGE_RANKS))]
    pub ranks: usize,
    /// Nelder-Mead starts of each fit's mode search.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_MODE_STARTS))]
    pub mode_starts: usize,
    /// Output folder for coverage.json, ranks.csv, the figures and truths/ (each fitted truth,
    /// written as it finishes: the same command again resumes, more --truths extend the study)
    /// [default: coverage/PRIOR[-exact] in the working directory; the committed studies are
    /// regenerated with --out reports/coverage/PRIOR[-exact]].
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR"))]
    pub out: Option<PathBuf>,
    /// With --exact: fit each truth with the surrogate alone, without the exact check and
    /// refinement of `fit`'s default pipeline (what the surrogate's error does on its own).
    #[cfg_attr(feature = "clap", arg(long))]
    pub no_exact_check: bool,
    /// With --exact: rounds of refinement at most per fit, the first (plain surrogate)
    /// included, as `fit --refine-rounds`.
    #[cfg_attr(feature = "clap", arg(long, value_name = "N", default_value_t = DEFAULT_REFINE_ROUNDS))]
    pub refine_rounds: usize,
    /// This process's shard K of M: the truths i with i mod M = K (shards of one study share
    /// --out; whichever finds every truth done writes the report).
    #[cfg_attr(feature = "clap", arg(long, value_name = "K/M", default_value = "0/1"))]
    pub shard: String,
    /// Run nothing: print the study's statistics over the truths written so far in --out (of
    /// this study: the same arguments) and exit 0. Safe beside the running study: it takes no
    /// lock and removes nothing. The bands are those of the truths done, not of --truths.
    #[cfg_attr(feature = "clap", arg(long))]
    pub progress: bool,
}

impl CoverageOptions {
    /// The shipped defaults with `truths` truths (the same as the command line's).
    pub fn new(truths: usize) -> Self {
        Self {
            truths,
            prior: DEFAULT_PRIOR.into(),
            model: DEFAULT_MODEL.into(),
            data: DEFAULT_DATA.into(),
            detector: DEFAULT_DETECTOR.into(),
            exact: false,
            likelihood: FIT_LIKELIHOOD.into(),
            sampler: SamplerKind::default().as_str().into(),
            seed: DEFAULT_SEED,
            ess: COVERAGE_ESS,
            ranks: COVERAGE_RANKS,
            mode_starts: DEFAULT_MODE_STARTS,
            out: None,
            no_exact_check: false,
            refine_rounds: DEFAULT_REFINE_ROUNDS,
            shard: "0/1".into(),
            progress: false,
        }
    }

    /// The output folder: `out`, else [`COVERAGE_OUT`]`/<prior file stem>` (with `-exact` for
    /// exact-solver data) under the working directory, never the committed studies in
    /// `reports/coverage/` unless `--out` names them.
    pub fn out_dir(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            let stem = self
                .prior
                .file_stem()
                .map_or("coverage".into(), |s| s.to_string_lossy().to_string());
            PathBuf::from(COVERAGE_OUT).join(if self.exact {
                format!("{stem}-exact")
            } else {
                stem
            })
        })
    }

    /// Checks the counts.
    ///
    /// # Errors
    /// [`hpge_inference::Error::BadOption`] naming `--truths` (fewer than 2) or `--ranks`
    /// (fewer than 9).
    pub fn validate(&self) -> Result<()> {
        let bad = |option: String, message: &str| -> Result<()> {
            Err(hpge_inference::Error::BadOption {
                option,
                message: message.into(),
            }
            .into())
        };
        if self.truths < 2 {
            return bad(
                format!("--truths {}", self.truths),
                "need at least 2 truths",
            );
        }
        if self.ranks < 9 {
            return bad(
                format!("--ranks {}", self.ranks),
                "need at least 9 draws to rank among",
            );
        }
        if self.refine_rounds == 0 {
            return bad(
                "--refine-rounds 0".into(),
                "need at least 1 round (1: the plain surrogate, checked, not refined)",
            );
        }
        self.shard()?;
        Ok(())
    }

    /// The shard `--shard` names.
    ///
    /// # Errors
    /// Not K/M with 0 <= K < M.
    pub fn shard(&self) -> Result<Shard> {
        Shard::parse(&self.shard).map_err(|e| {
            hpge_inference::Error::BadOption {
                option: format!("--shard {}", self.shard),
                message: e.to_string(),
            }
            .into()
        })
    }

    /// Where the data come from (`--exact`); coverage.json names it.
    pub fn data_from(&self) -> DataFrom {
        if self.exact {
            DataFrom::Exact
        } else {
            DataFrom::Surrogate
        }
    }

    /// The noise model named by `likelihood`.
    ///
    /// # Errors
    /// An unknown likelihood.
    pub fn noise(&self) -> Result<NoiseSettings> {
        Ok(noise_settings(&self.likelihood)?)
    }

    /// The study's settings: the counts checked, each fit with `fit`'s settings (sampler,
    /// chains, R-hat and ESS targets, draw limit, likelihood, exact check and refinement) except
    /// where a flag of the study says otherwise, and the study's clock budget
    /// ([`COVERAGE_FIT_MAX_SECONDS`]).
    ///
    /// # Errors
    /// What [`Self::validate`] refuses, an unknown sampler or likelihood, or targets
    /// [`hpge_inference::SampleSettings::validate`] refuses.
    pub fn settings(&self) -> Result<CoverageSettings> {
        self.validate()?;
        let fit_options = self.fit_options();
        let mut fit = fit_options.settings()?;
        fit.sample.max_seconds = COVERAGE_FIT_MAX_SECONDS;
        fit.sample.validate()?;
        let pipeline = if self.exact && !self.no_exact_check {
            Some(PipelineSettings {
                check: fit_options.exact_check()?,
                refine: RefineSettings {
                    max_rounds: self.refine_rounds,
                    ..fit_options.refine()?
                },
            })
        } else {
            None
        };
        Ok(CoverageSettings {
            n_truths: self.truths,
            seed: self.seed,
            fit,
            ranks: self.ranks,
            pipeline,
        })
    }

    /// `fit`'s options with this study's sampler, likelihood, seed, ESS target, mode starts
    /// and refinement rounds: the main job's pipeline as the study runs it.
    pub fn fit_options(&self) -> FitOptions {
        FitOptions {
            sampler: self.sampler.clone(),
            likelihood: self.likelihood.clone(),
            seed: self.seed,
            ess: self.ess,
            mode_starts: self.mode_starts,
            refine_rounds: self.refine_rounds,
            ..FitOptions::default()
        }
    }
}

/// Seed of the hidden-effect study (data set i uses seed + i; the workflow runs with it too).
pub const HIDDEN_SEED: u64 = 7;
/// Output folder of the hidden-effect study when `--out` is not given (under the working
/// directory; the committed study, `reports/discovery/hidden`, is regenerated with `--out`).
pub const HIDDEN_OUT: &str = "discoveries/hidden";
/// The start model of the hidden-effect study: the paper's B_Z, which the base truth fits
/// exactly.
pub const HIDDEN_START_MODEL: &str = "priors/b-z.toml";
/// Sampling budget (s) of each MCMC fit of the hidden-effect study: the study runs the workflow
/// on six data sets, so each fit gets less than a command-line fit's five minutes
/// ([`hpge_inference::fit::FIT_MAX_SECONDS`]).
pub const HIDDEN_FIT_MAX_SECONDS: f64 = 120.0;

/// Everything a user chooses about the hidden-effect study.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct HiddenOptions {
    /// Seed of the noise (data set i uses seed + i) and of the workflow.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = HIDDEN_SEED))]
    pub seed: u64,
    /// Output folder: one sub-folder per data set (cv.csv, truth.json, the workflow's outputs),
    /// and summary.json / summary.md.
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR", default_value = HIDDEN_OUT))]
    pub out: PathBuf,
    /// Hidden effects to run, comma-separated (default: all: none, radial, stray-capacitance,
    /// calibration-scale, quadratic-z, li-slope).
    #[cfg_attr(feature = "clap", arg(long, value_delimiter = ','))]
    pub effects: Vec<String>,
    /// The start model's prior.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "FILE", default_value = HIDDEN_START_MODEL)
    )]
    pub start_model: PathBuf,
    /// The workflow's inputs, catalogue entries, targets and grid.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub workflow: WorkflowOptions,
}

impl Default for HiddenOptions {
    /// The shipped defaults (the same as the command line's).
    fn default() -> Self {
        Self {
            seed: HIDDEN_SEED,
            out: HIDDEN_OUT.into(),
            effects: Vec::new(),
            start_model: HIDDEN_START_MODEL.into(),
            workflow: WorkflowOptions::default(),
        }
    }
}

impl HiddenOptions {
    /// The workflow's settings with `noise` and the study's budget per fit, checked (each data
    /// set then runs with its own seed).
    ///
    /// # Errors
    /// Targets [`hpge_inference::SampleSettings::validate`] refuses.
    pub fn settings(&self, noise: NoiseSettings) -> Result<DiscoverSettings> {
        Ok(self
            .workflow
            .settings(noise, self.seed, HIDDEN_FIT_MAX_SECONDS)?)
    }
}
