//! The options of a fit as a user states them: the four input files, the sampler and its
//! targets, the likelihood, the exact-solver check and the output folder. The command line
//! flattens this struct (feature `clap`), so every option and default is declared here once.

use std::path::PathBuf;

use hpge_solver::GridOverrides;

use super::ascent::DEFAULT_ASCENTS;
use super::exact_check::{DEFAULT_GRID_CHECK, ExactCheckSettings, ExactGrids};
use super::job::FitFiles;
use super::refine::{DEFAULT_REFINE_ROUNDS, RefineSettings, RefineVariance};
use super::run::FitSettings;
use crate::posterior::{NoiseKind, NoiseSettings};
use crate::sampler::{
    DEFAULT_CHAINS, DEFAULT_ESS_MIN, DEFAULT_MODE_STARTS, DEFAULT_RHAT_MAX, DEFAULT_SEED,
    SampleSettings, SamplerKind,
};
use crate::{Error, Result};

/// The shipped Super-Siegfried curve (a stand-in made by this program; data/super-siegfried-k1/).
pub const DEFAULT_DATA: &str = "data/super-siegfried-k1/cv.csv";
/// The shipped surrogate a fit uses by default: the `split-steps` recipe with a 256 x 3 trunk, a
/// 128 head and AdamW's weight decay 0.01, trained on the regenerated training set
/// (`TRUNK=256,256,256 HEAD=128 WEIGHT_DECAY=0.01 bash models/train.sh split-steps 0`;
/// models/README.md).
pub const DEFAULT_MODEL: &str =
    "models/super-siegfried-rz-split-steps-t256-256-256-hd128-wd0.01.safetensors";
/// The paper's B_RZ prior (section 8.2).
pub const DEFAULT_PRIOR: &str = "priors/b-rz.toml";
/// The detector of the shipped data.
pub const DEFAULT_DETECTOR: &str = "detectors/super-siegfried-k1.toml";
/// Posterior draws a fit re-weights with the exact solver.
pub const DEFAULT_EXACT_DRAWS: usize = 100;
/// Sampling budget (s) of a fit on the command line (`fit`, and each MCMC fit of `discover`):
/// five minutes, so that a fit that cannot reach its targets returns (unconverged, exit code 3)
/// while a user waits; the shipped fit converges in about 30 s. Half the library's budget
/// ([`crate::sampler::DEFAULT_MAX_SECONDS`]), which is meant for unattended runs.
pub const FIT_MAX_SECONDS: f64 = 300.0;
/// The likelihood of `fit` unless `--likelihood` names one: the measured covariance where the
/// curve has one. A measured curve's calibration error is one scale shared by every point
/// (5.96% for the paper's circuit uncertainties); the paper's 3% independent term weighs a
/// common scale delta as 60 (delta / 3%)^2 in chi^2, the covariance as (delta / 5.96%)^2.
pub const FIT_LIKELIHOOD: &str = "auto";

/// Everything a user chooses about a fit.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct FitOptions {
    /// The measured C-V curve (CSV with voltage_V, c12_pF, sigma_pF; its covariance is read from
    /// STEM.covariance.csv when present).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_DATA))]
    pub data: PathBuf,
    /// The surrogate model (.safetensors).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_MODEL))]
    pub model: PathBuf,
    /// The prior (TOML): priors/b-rz.toml (the paper's B_RZ) or priors/b-z.toml (B_Z).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_PRIOR))]
    pub prior: PathBuf,
    /// The detector the data were measured with (checked against the model's; used by the
    /// exact-solver check and for zeta at the mode).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "FILE", default_value = DEFAULT_DETECTOR)
    )]
    pub detector: PathBuf,
    /// Output folder [default: fits/PRIOR_NAME, under the working directory].
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR"))]
    pub out: Option<PathBuf>,
    /// Replace a fit of another run (other inputs or settings) in the output folder; without
    /// it such a folder is refused (the same fit again, or a resumed one, goes on without it).
    #[cfg_attr(feature = "clap", arg(long))]
    pub force: bool,
    /// Sampler: metropolis (adaptive, like BAT.jl's default) or nuts.
    #[cfg_attr(feature = "clap", arg(long, default_value = SamplerKind::default().as_str()))]
    pub sampler: String,
    /// Seed of the sampler (starting points, proposals).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_SEED))]
    pub seed: u64,
    /// Skip the exact-solver re-weighting check.
    #[cfg_attr(feature = "clap", arg(long))]
    pub no_exact_check: bool,
    /// Fit a curve with voltages where the surrogate's training rows thin out (outside its
    /// support, e.g. below 13.4 V for the shipped models, where it is off by tens of percent);
    /// without it such a curve is refused. The fit then warns.
    #[cfg_attr(feature = "clap", arg(long))]
    pub extrapolate: bool,
    /// Posterior draws re-weighted with the exact solver (each a curve at the data's voltages,
    /// a few seconds of one core at the check's tolerance).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_EXACT_DRAWS))]
    pub exact_draws: usize,
    /// Where the check solves the draws' exact curves: mode (every draw on the global mode's
    /// refined grids, carried with the geometry; a few draws also on their own grids to show the
    /// difference) or own (each draw on its own adaptive grids, several times slower).
    #[cfg_attr(feature = "clap", arg(long, default_value = ExactGrids::default().as_str()))]
    pub exact_grids: String,
    /// With --exact-grids mode: draws also solved on their own adaptive grids to measure the
    /// grids' difference (0: none).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_GRID_CHECK))]
    pub exact_grid_check: usize,
    /// After a passing exact check: climb the exact posterior from this many of the sampler's
    /// local modes in other basins; an ascent that ends in another basin more than e^1 times as
    /// dense as the fit's mode fails the check, and its curves refine the surrogate there
    /// (0: none).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_ASCENTS))]
    pub exact_ascents: usize,
    /// Rounds of posterior-adaptive refinement at most, the first (plain surrogate) included:
    /// while the exact check fails, its exact curves teach a model of the surrogate's error
    /// (a Gaussian process at the voltages) and the fit samples again with the corrected
    /// surrogate, whose uncertainty enters the likelihood point by point (1: no refinement).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_REFINE_ROUNDS))]
    pub refine_rounds: usize,
    /// Point variance of a refined round's corrected surrogate: best (the error model's
    /// variance at the exact curve of highest exact likelihood so far, the same at every input)
    /// or local (its variance at each input: wider where no exact curve taught it, which a
    /// model that misfits the data runs to).
    #[cfg_attr(feature = "clap", arg(long, default_value = RefineVariance::default().as_str()))]
    pub refine_variance: String,
    /// Exit with 0 even when the exact-solver check fails after refinement (otherwise exit
    /// code 4).
    #[cfg_attr(feature = "clap", arg(long))]
    pub allow_exact_mismatch: bool,
    /// Likelihood: paper (independent, 3% measurement term), covariance (the measured
    /// covariance instead of the 3% term: one calibration scale shared by every point), or auto
    /// (covariance where the curve comes with its STEM.covariance.csv, else paper).
    #[cfg_attr(feature = "clap", arg(long, default_value = FIT_LIKELIHOOD))]
    pub likelihood: String,
    /// The surrogate's constant sigma_p in the likelihood (the paper's eq. 13) even where its
    /// model file has a calibrated per-point uncertainty sigma_s(p, U_B) (`hpge-cv calibrate`).
    #[cfg_attr(feature = "clap", arg(long))]
    pub constant_sigma: bool,
    /// Chains (run in parallel).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_CHAINS))]
    pub chains: usize,
    /// Target bulk and tail ESS of every parameter.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_ESS_MIN, allow_hyphen_values = true))]
    pub ess: f64,
    /// Target R-hat (rank-normalised, split).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_RHAT_MAX, allow_hyphen_values = true))]
    pub rhat: f64,
    /// The time budget of each sampling run (its mode search and tuning included): it stops
    /// when the budget is spent even if the targets are not reached, and the fit then skips
    /// the exact check (exit code 3).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = FIT_MAX_SECONDS, allow_hyphen_values = true))]
    pub max_seconds: f64,
    /// Known parameter values (TOML NAME = VALUE) to mark on the figures and check against the
    /// smallest intervals, e.g. data/super-siegfried-k1/truth-b-rz.toml.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub truth: Option<PathBuf>,
    /// Write no figures.
    #[cfg_attr(feature = "clap", arg(long))]
    pub no_plots: bool,
    /// Nelder-Mead starts of the mode search before sampling (0: none).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_MODE_STARTS))]
    pub mode_starts: usize,
    /// The exact solver's grid and accuracy.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub grid: GridOverrides,
}

impl Default for FitOptions {
    /// The shipped defaults (the same as the command line's).
    fn default() -> Self {
        Self {
            data: DEFAULT_DATA.into(),
            model: DEFAULT_MODEL.into(),
            prior: DEFAULT_PRIOR.into(),
            detector: DEFAULT_DETECTOR.into(),
            out: None,
            force: false,
            sampler: SamplerKind::default().as_str().into(),
            seed: DEFAULT_SEED,
            no_exact_check: false,
            extrapolate: false,
            exact_draws: DEFAULT_EXACT_DRAWS,
            exact_grids: ExactGrids::default().as_str().into(),
            exact_grid_check: DEFAULT_GRID_CHECK,
            exact_ascents: DEFAULT_ASCENTS,
            refine_rounds: DEFAULT_REFINE_ROUNDS,
            refine_variance: RefineVariance::default().as_str().into(),
            allow_exact_mismatch: false,
            likelihood: FIT_LIKELIHOOD.into(),
            constant_sigma: false,
            chains: DEFAULT_CHAINS,
            ess: DEFAULT_ESS_MIN,
            rhat: DEFAULT_RHAT_MAX,
            max_seconds: FIT_MAX_SECONDS,
            truth: None,
            no_plots: false,
            mode_starts: DEFAULT_MODE_STARTS,
            grid: GridOverrides::default(),
        }
    }
}

impl FitOptions {
    /// The four input files.
    pub fn files(&self) -> FitFiles {
        FitFiles {
            data: self.data.clone(),
            model: self.model.clone(),
            prior: self.prior.clone(),
            detector: self.detector.clone(),
        }
    }

    /// The output folder: `out`, else `fits/<prior file stem>`.
    pub fn out_dir(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            let stem = self
                .prior
                .file_stem()
                .map_or("fit".into(), |s| s.to_string_lossy().to_string());
            PathBuf::from("fits").join(stem)
        })
    }

    /// The sampler named by `sampler`.
    ///
    /// # Errors
    /// [`Error::BadOption`] for an unknown name.
    pub fn sampler_kind(&self) -> Result<SamplerKind> {
        sampler_kind(&self.sampler)
    }

    /// The paper's noise constants with the likelihood named by `likelihood`.
    ///
    /// # Errors
    /// [`Error::BadOption`] for an unknown name.
    pub fn noise(&self) -> Result<NoiseSettings> {
        Ok(NoiseSettings {
            constant_sigma: self.constant_sigma,
            ..noise_settings(&self.likelihood)?
        })
    }

    /// The exact-solver check's settings (`--exact-draws`, `--exact-grids`,
    /// `--exact-grid-check`).
    ///
    /// # Errors
    /// [`Error::BadOption`] for an unknown `--exact-grids`.
    pub fn exact_check(&self) -> Result<ExactCheckSettings> {
        Ok(ExactCheckSettings {
            draws: self.exact_draws,
            grids: ExactGrids::parse(&self.exact_grids)?,
            grid_check: self.exact_grid_check,
            ascents: self.exact_ascents,
        })
    }

    /// The refinement's settings (`--refine-rounds`, `--refine-variance`).
    ///
    /// # Errors
    /// [`Error::BadOption`] for an unknown `--refine-variance`.
    pub fn refine(&self) -> Result<RefineSettings> {
        Ok(RefineSettings {
            max_rounds: self.refine_rounds,
            variance: RefineVariance::parse(&self.refine_variance)?,
            ..RefineSettings::default()
        })
    }

    /// Checks the numbers a user gives, naming the flag: `--max-seconds` and `--ess` must be
    /// positive and finite, `--exact-draws` at least 2 (unless `--no-exact-check`),
    /// `--refine-rounds` at least 1, and the sampler and likelihood known names.
    ///
    /// # Errors
    /// [`Error::BadOption`] naming the flag and its value.
    pub fn validate(&self) -> Result<()> {
        self.sampler_kind()?;
        self.noise()?;
        self.exact_check()?;
        self.refine()?;
        if self.chains < 2 {
            return Err(Error::BadOption {
                option: format!("--chains {}", self.chains),
                message: "R-hat needs at least 2 chains".into(),
            });
        }
        check_positive("--max-seconds", self.max_seconds, "seconds")?;
        check_positive("--ess", self.ess, "effective draws")?;
        if !(self.rhat.is_finite() && self.rhat > 1.0) {
            return Err(Error::BadOption {
                option: format!("--rhat {}", self.rhat),
                message: "the R-hat target must be a number above 1 (e.g. 1.01)".into(),
            });
        }
        if self.refine_rounds == 0 {
            return Err(Error::BadOption {
                option: "--refine-rounds 0".into(),
                message: "at least 1 round (the plain surrogate's); 1 means no refinement".into(),
            });
        }
        // One draw has no spread: its "shift in sd" would be 0/0 and its Pareto k-hat NaN, a
        // check that passes on nothing (issue 66).
        if self.exact_draws < 2 && !self.no_exact_check {
            return Err(Error::BadOption {
                option: format!("--exact-draws {}", self.exact_draws),
                message: "the exact-solver check needs at least 2 draws (its Pareto k-hat at \
                          least 21); pass --no-exact-check to skip it"
                    .into(),
            });
        }
        Ok(())
    }

    /// The fit's settings: the sampler's defaults with these targets, checked.
    ///
    /// # Errors
    /// An unknown sampler or likelihood, or targets [`FitOptions::validate`] or
    /// [`SampleSettings::validate`] refuses.
    pub fn settings(&self) -> Result<FitSettings> {
        self.validate()?;
        let mut sample = SampleSettings::for_sampler(self.sampler_kind()?);
        sample.seed = self.seed;
        sample.chains = self.chains;
        sample.ess_min = self.ess;
        sample.rhat_max = self.rhat;
        sample.max_seconds = self.max_seconds;
        sample.mode_starts = self.mode_starts;
        sample.validate()?;
        Ok(FitSettings {
            sample,
            noise: self.noise()?,
            ..FitSettings::default()
        })
    }
}

/// Refuses a flag's value unless it is a positive finite number (`what`: its unit, in words).
///
/// # Errors
/// [`Error::BadOption`] naming the flag and its value.
pub fn check_positive(flag: &str, value: f64, what: &str) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::BadOption {
            option: format!("{flag} {value}"),
            message: format!("must be a positive number of {what}"),
        })
    }
}

/// The sampler of a name (`metropolis`, `nuts`).
///
/// # Errors
/// [`Error::BadOption`] naming `--sampler` for an unknown name.
pub fn sampler_kind(name: &str) -> Result<SamplerKind> {
    SamplerKind::parse(name).ok_or_else(|| Error::BadOption {
        option: format!("--sampler {name}"),
        message: "unknown sampler; use metropolis or nuts".into(),
    })
}

/// The paper's noise constants with the likelihood of a name (`paper`, `covariance`).
///
/// # Errors
/// [`Error::BadOption`] naming `--likelihood` for an unknown name.
pub fn noise_settings(likelihood: &str) -> Result<NoiseSettings> {
    let kind = NoiseKind::parse(likelihood).ok_or_else(|| Error::BadOption {
        option: format!("--likelihood {likelihood}"),
        message: "use paper, covariance or auto".into(),
    })?;
    Ok(NoiseSettings {
        kind,
        ..Default::default()
    })
}
