//! The options of `measure` and `synthesize` as a user states them. The command line flattens
//! these structs (feature `clap`), so every option and default is declared here once.

use std::path::{Path, PathBuf};

use crate::measure::MeasureSettings;
use crate::synth::{DEFAULT_DECIMATE, DEFAULT_PULSER_PULSES, SynthSettings};
use crate::{Error, Result};

/// The fewest samples a synthesized (decimated) trace keeps: the baseline before the pulser edge
/// and the flat top after it must each span many samples for the amplitude fit.
pub const MIN_DECIMATED_SAMPLES: usize = 100;

/// Everything a user chooses about a measurement (the pipeline's settings are a TOML file).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct MeasureOptions {
    /// Directory of pulse files: STEM.npy [pulses, samples] in pC, or STEM.lh5 (an LH5
    /// waveform table, one bias per file), each with a STEM.toml sidecar (bias_V,
    /// sampling_period_ns, charge_unit); optional measurement.toml (voltages_V, circuit,
    /// uncertainties, tail fit). Or one .lh5 file (settings from measurement.toml beside it).
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR|FILE.lh5"))]
    pub raw: PathBuf,
    /// The C-V curve (voltage_V,c12_pF,sigma_pF); the covariance goes to STEM.covariance.csv
    /// and a report to STEM.measure.json.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub out: PathBuf,
    /// Measurement settings (TOML) instead of RAW/measurement.toml.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub settings: Option<PathBuf>,
}

impl MeasureOptions {
    /// The settings and where they came from: `settings`, else `RAW/measurement.toml` if
    /// present (the folder of `raw` when it is a file), else the defaults (source `defaults`).
    ///
    /// # Errors
    /// A settings file that cannot be read or is refused.
    pub fn measure_settings(&self) -> Result<(MeasureSettings, String)> {
        let path = match &self.settings {
            Some(p) => Some(p.clone()),
            None => {
                let dir = if self.raw.is_file() {
                    self.raw.parent().unwrap_or(Path::new("."))
                } else {
                    self.raw.as_path()
                };
                Some(dir.join("measurement.toml")).filter(|p| p.is_file())
            }
        };
        Ok(match path {
            Some(p) => (MeasureSettings::from_file(&p)?, p.display().to_string()),
            None => (MeasureSettings::default(), "defaults".to_string()),
        })
    }
}

/// Seed of `synthesize` when not given one.
pub const DEFAULT_SYNTH_SEED: u64 = 1;

/// Everything a user chooses about synthetic raw data (the rest is [`SynthSettings::default`]).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SynthOptions {
    /// The true curve: a CSV with columns voltage_V and c12_pF (e.g. from `simulate --out`).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub curve: PathBuf,
    /// Output directory for the pulse files, measurement.toml and truth.json.
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR"))]
    pub out: PathBuf,
    /// Seed of the random generator.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_SYNTH_SEED))]
    pub seed: u64,
    /// Full-depletion voltage of the truth (V) [default: where its -dc12/dU_B falls to 1e-3 pF/V].
    #[cfg_attr(feature = "clap", arg(long = "depletion-voltage", value_name = "V"))]
    pub depletion_voltage: Option<f64>,
    /// Pulser pulses per bias.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "N", default_value_t = DEFAULT_PULSER_PULSES)
    )]
    pub pulses: usize,
    /// Average blocks of K samples (4 ns each) to keep files small.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "K", default_value_t = DEFAULT_DECIMATE)
    )]
    pub decimate: usize,
    /// Draw the run's calibration error once: the true charge scale and circuit constants
    /// differ from the nominal ones (which `measure` assumes) by 3% normal draws each, so every
    /// point carries one common factor (sd 5.96%; recorded in truth.json).
    #[cfg_attr(feature = "clap", arg(long))]
    pub draw_calibration: bool,
    /// Relative part f_s of the detector's independent per-bias mismatch to the model's curve,
    /// c12_det = c12 + (f_s c12 + a_s) z (paper, eq. 7: 0.01) [default: 0, none].
    #[cfg_attr(
        feature = "clap",
        arg(long = "mismatch-rel", value_name = "F", default_value_t = 0.0)
    )]
    pub mismatch_rel: f64,
    /// Absolute part a_s of that mismatch, pF (paper, eq. 7: 1) [default: 0, none].
    #[cfg_attr(
        feature = "clap",
        arg(long = "mismatch-abs-pf", value_name = "PF", default_value_t = 0.0)
    )]
    pub mismatch_abs_pf: f64,
    /// Correlation length L of that mismatch in ln c12: 0 draws it independently per bias (as
    /// eq. 7 states it); L > 0 makes it a smooth function of the depletion state,
    /// z = h(ln c12) with correlation exp(-(ln c_i - ln c_j)^2 / (2 L^2)), as a real detector's
    /// geometry mismatch is [default: 0].
    #[cfg_attr(
        feature = "clap",
        arg(long = "mismatch-corr-lnc", value_name = "L", default_value_t = 0.0)
    )]
    pub mismatch_corr_lnc: f64,
}

impl SynthOptions {
    /// The defaults for `curve` into `out` (the same as the command line's).
    pub fn new(curve: &Path, out: &Path) -> Self {
        Self {
            curve: curve.into(),
            out: out.into(),
            seed: DEFAULT_SYNTH_SEED,
            depletion_voltage: None,
            pulses: DEFAULT_PULSER_PULSES,
            decimate: DEFAULT_DECIMATE,
            draw_calibration: false,
            mismatch_rel: 0.0,
            mismatch_abs_pf: 0.0,
            mismatch_corr_lnc: 0.0,
        }
    }

    /// Checks the numbers a user gives, naming the flag (not the settings' internal keys):
    /// `--pulses` at least 10, `--decimate` at least 1 and small enough to leave
    /// [`MIN_DECIMATED_SAMPLES`] samples per trace, `--depletion-voltage` positive.
    ///
    /// # Errors
    /// [`Error::Argument`] naming the flag and its value.
    pub fn validate(&self) -> Result<()> {
        let bad = |flag: String, message: String| {
            Err(Error::Argument {
                name: flag,
                message,
            })
        };
        if self.pulses < 10 {
            return bad(
                format!("--pulses {}", self.pulses),
                "at least 10 pulser pulses per bias are needed for a peak".into(),
            );
        }
        let defaults = SynthSettings::default();
        let native = (defaults.trace_ns / defaults.sampling_period_ns).round() as usize;
        let most = native / MIN_DECIMATED_SAMPLES;
        if self.decimate == 0 || self.decimate > most {
            return bad(
                format!("--decimate {}", self.decimate),
                format!(
                    "must lie in 1..={most}: a trace has {native} samples and must keep at least {MIN_DECIMATED_SAMPLES}"
                ),
            );
        }
        for (flag, v) in [
            ("--mismatch-rel", self.mismatch_rel),
            ("--mismatch-abs-pf", self.mismatch_abs_pf),
            ("--mismatch-corr-lnc", self.mismatch_corr_lnc),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(format!("{flag} {v}"), "must be a number >= 0".into());
            }
        }
        if let Some(v) = self.depletion_voltage
            && !(v.is_finite() && v > 0.0)
        {
            return bad(
                format!("--depletion-voltage {v}"),
                "must be a positive number of volts".into(),
            );
        }
        Ok(())
    }

    /// The synthesis settings: the defaults with these pulses and decimation.
    pub fn settings(&self) -> SynthSettings {
        SynthSettings {
            pulser_pulses: self.pulses,
            decimate: self.decimate,
            ..SynthSettings::default()
        }
    }
}
