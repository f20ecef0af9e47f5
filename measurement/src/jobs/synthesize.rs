//! The `synthesize` job: raw-like pulser data from a known C-V curve, a folder of one pulse
//! file per bias (`U<bias>V.npy` with its sidecar), `measurement.toml` listing the biases and
//! `truth.json` with the curve, seed and settings.

use std::path::{Path, PathBuf};

use serde_json::json;

use crate::stand_in::StandInDraws;
use crate::synth::voltage_seed;
use crate::{
    Error, PulseSet, Result, SynthOptions, SynthSettings, depletion_voltage, read_model_curve,
    synthesize_voltage, write_pulses,
};

/// A finished `synthesize` job.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthRun {
    /// The folder written.
    pub out: PathBuf,
    /// Pulse files written (one per bias).
    pub files: usize,
    /// The seed.
    pub seed: u64,
    /// The full-depletion voltage of the pulses' model, V.
    pub depletion_voltage_v: f64,
}

/// Runs the `synthesize` job into `o.out`: everything is checked before the folder is made
/// (the pulses' memory among it: [`crate::synth::MAX_SYNTH_BYTES_PER_BIAS`]); the folder is
/// filled under a temporary name beside it and put in place when complete, replacing an
/// earlier run's folder whole, so a killed or failed run leaves no partial raw folder that
/// `measure` would read as a short curve (issue 66). `observer(k, n)` is called as biases
/// finish.
///
/// Errors name the option as the command line spells it (`SynthOptions` is its option
/// struct): bad options, a curve that cannot be read, an unknown full-depletion voltage, an
/// `out` that is a file or a folder holding files this job did not write, and files that
/// cannot be written.
pub fn synthesize_folder(o: &SynthOptions, observer: impl Fn(usize, usize)) -> Result<SynthRun> {
    o.validate()?;
    check_synthesis_folder(&o.out)?;
    let settings = o.settings();
    settings.validate().map_err(|e| match e {
        Error::Setting { key, message } if key == "pulser_pulses" => Error::Argument {
            name: format!("--pulses {}", o.pulses),
            message,
        },
        e => Error::Argument {
            name: "synthesis settings".into(),
            message: e.to_string(),
        },
    })?;
    let (volts, c12) = read_model_curve(&o.curve).map_err(|e| Error::Argument {
        name: format!("--curve {}", o.curve.display()),
        message: e.to_string(),
    })?;
    let draws = StandInDraws::draw(o, &c12).map_err(|e| Error::Argument {
        name: format!("--curve {}", o.curve.display()),
        message: format!("the stand-in's draws: {e}"),
    })?;
    let ufd = match o.depletion_voltage {
        Some(v) if v.is_finite() && v > 0.0 => v,
        Some(v) => {
            return Err(Error::Argument {
                name: format!("--depletion-voltage {v}"),
                message: "must be a positive number of volts".into(),
            });
        }
        None => depletion_voltage(&volts, &c12, 1e-3).ok_or_else(|| Error::Argument {
            name: format!("--curve {}", o.curve.display()),
            message: "-dc12/dU_B never falls to 1e-3 pF/V, so the full-depletion voltage is unknown; give --depletion-voltage".into(),
        })?,
    };
    hpge_files::remove_stale_temporaries(hpge_files::parent_or_here(&o.out));
    let mut staged = hpge_files::Staged::new();
    let tmp = staged
        .replacing_folder(&o.out)
        .map_err(Error::io(&o.out, "cannot create the folder"))?;
    write_synthetic(o, &tmp, &settings, &volts, &c12, ufd, &draws, &observer)?;
    staged.commit().map_err(|(file, source)| Error::Io {
        file,
        action: "cannot write the file",
        source,
    })?;
    Ok(SynthRun {
        out: o.out.clone(),
        files: volts.len(),
        seed: o.seed,
        depletion_voltage_v: ufd,
    })
}

/// Refuses an `out` of `synthesize` that is a file, or a folder holding anything but what an
/// earlier `synthesize` wrote (`U<bias>V.*`, `measurement.toml`, `truth.json`): the job
/// replaces the folder whole, so it must not hold anything else.
pub fn check_synthesis_folder(out: &Path) -> Result<()> {
    let bad = |message: String| Error::Argument {
        name: format!("--out {}", out.display()),
        message,
    };
    if !out.exists() {
        return Ok(());
    }
    if !out.is_dir() {
        return Err(bad(
            "not a folder (synthesize writes a folder of pulse files)".into(),
        ));
    }
    let unreadable = |e: std::io::Error| bad(format!("cannot read the folder: {e}"));
    for e in std::fs::read_dir(out).map_err(unreadable)? {
        let e = e.map_err(unreadable)?;
        let name = e.file_name();
        let name = name.to_string_lossy();
        let ours = name == "measurement.toml"
            || name == "truth.json"
            || (name.starts_with('U')
                && name.split_once('.').is_some_and(|(stem, _)| {
                    stem.len() > 2
                        && stem.ends_with('V')
                        && stem[1..stem.len() - 1].bytes().all(|b| b.is_ascii_digit())
                })
                && e.file_type().is_ok_and(|t| t.is_file()));
        if !ours {
            return Err(bad(format!(
                "the folder holds {name}, which synthesize did not write; it replaces the folder \
                 whole (an earlier run's pulse files, measurement.toml, truth.json), so choose a \
                 new or empty folder"
            )));
        }
    }
    Ok(())
}

/// The files of [`synthesize_folder`] into the existing folder `dir` (`o.out` or its
/// temporary).
#[allow(clippy::too_many_arguments)]
fn write_synthetic(
    o: &SynthOptions,
    dir: &Path,
    settings: &SynthSettings,
    volts: &[f64],
    c12: &[f64],
    ufd: f64,
    draws: &StandInDraws,
    observer: &impl Fn(usize, usize),
) -> Result<()> {
    let settings = &draws.settings(settings);
    for (k, (&u, &c)) in volts.iter().zip(&draws.detector_pf).enumerate() {
        let v = synthesize_voltage(u, c, ufd, settings, voltage_seed(o.seed, k))?;
        let file = format!("U{:04}V.npy", u.round() as i64);
        let set = PulseSet {
            source: o.out.join(&file),
            ..v.set
        };
        write_pulses(&dir.join(&file), &set, true)?;
        observer(k + 1, volts.len());
    }
    let write = |path: PathBuf, text: String| {
        hpge_files::write(&path, text).map_err(Error::io(&path, "cannot write"))
    };
    let list = volts
        .iter()
        .map(|v| format!("{v}"))
        .collect::<Vec<_>>()
        .join(", ");
    write(
        dir.join("measurement.toml"),
        format!(
            "# Written by hpge-cv {} synthesize (seed {}); the default circuit and uncertainties.\nvoltages_V = [{list}]\n",
            env!("CARGO_PKG_VERSION"),
            o.seed
        ),
    )?;
    let truth = json!({
        "curve": o.curve.display().to_string(),
        "voltage_V": volts,
        "c12_pF": c12,
        "depletion_voltage_V": ufd,
        "seed": o.seed,
        "settings": settings,
        "mismatch": json!({
            "rel": o.mismatch_rel,
            "abs_pF": o.mismatch_abs_pf,
            "corr_lnc": o.mismatch_corr_lnc,
            "formula": "c12_detector = c12 + (rel c12 + abs) z, z ~ N(0, 1) (paper eq. 7); independent per bias when corr_lnc = 0, else z = h(ln c12) with correlation exp(-(ln c_i - ln c_j)^2 / (2 corr_lnc^2))",
        }),
        "c12_detector_pF": draws.detector_pf,
        "calibration": draws.calibration,
        "c12_expected_measured_pF": draws.expected_measured_pf(),
        "version": env!("CARGO_PKG_VERSION"),
    });
    write(dir.join("truth.json"), format!("{truth:#}\n"))
}
