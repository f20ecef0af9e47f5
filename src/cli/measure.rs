//! `hpge-cv measure` (raw pulser data to a C-V curve with its covariance) and
//! `hpge-cv synthesize` (a known C-V curve to raw-like pulser data).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_measurement::stand_in::StandInDraws;
use hpge_measurement::synth::voltage_seed;
use hpge_measurement::{
    MeasureOptions, Measurement, PulseSet, RawProblem, SynthOptions, depletion_voltage, measure,
    read_model_curve, read_raw_dir, synthesize_voltage, write_pulses,
};
use hpge_reports::plot;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

/// Runs the measurement pipeline and writes the curve, its covariance, a JSON report and the
/// figures.
pub fn run(o: &MeasureOptions, plot: Option<&PathBuf>, json: bool) -> Result<()> {
    let report_path = o.out.with_extension("measure.json");
    let mut outputs = vec![
        ("--out", o.out.clone()),
        (
            "--out's covariance",
            hpge_measurement::covariance_path(&o.out),
        ),
        ("--out's report", report_path.clone()),
    ];
    if let Some(dir) = plot {
        outputs.push(("--plot", dir.clone()));
    }
    let mut inputs = vec![("--raw", o.raw.as_path())];
    if let Some(s) = &o.settings {
        inputs.push(("--settings", s.as_path()));
    }
    super::args::check_outputs(&outputs, &inputs)?;
    // What a killed run left under temporary names beside the outputs.
    for (_, path) in &outputs {
        hpge_files::remove_stale_temporaries(super::args::parent_or_here(path));
    }
    let (settings, settings_source) = o.measure_settings()?;
    let run = read_raw_dir(&o.raw, settings.voltages_v.as_deref())?;
    for p in &run.problems {
        eprintln!(
            "problem: {}{}: {}",
            p.file.display(),
            p.bias_v.map_or(String::new(), |v| format!(" ({v} V)")),
            p.message
        );
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} fitting {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.set_message(format!("{} pulse files", run.sets.len()));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let m = measure(&run.sets, &settings, &o.raw);
    bar.finish_and_clear();
    let m = m?;
    for p in &m.problems {
        eprintln!(
            "problem: {}{}: {}",
            p.file.display(),
            p.bias_v.map_or(String::new(), |v| format!(" ({v} V)")),
            p.message
        );
    }
    // Every output written under a temporary name and put in place together at the end: all
    // of them or none, whether a later step fails or the process is killed (issue 66).
    let mut staged = hpge_files::Staged::new();
    let figures = match plot {
        Some(dir) => Some(
            staged
                .folder(dir)
                .with_context(|| format!("--plot {}: cannot create the folder", dir.display()))?,
        ),
        None => None,
    };
    let (table, covariance) = hpge_measurement::curve_texts(&o.out, &m.curve, &[])?;
    staged
        .write(&o.out, table.as_bytes())
        .with_context(|| format!("{}: cannot write the file", o.out.display()))?;
    let covariance_file = hpge_measurement::covariance_path(&o.out);
    if let Some(text) = &covariance {
        staged
            .write(&covariance_file, text.as_bytes())
            .with_context(|| format!("{}: cannot write the file", covariance_file.display()))?;
    }
    let mut report = report_json(&m, &o.raw, &settings_source, &run.problems);
    if let Some(obj) = report.as_object_mut() {
        // The curve's provenance (cv.csv is a plain table: one header row, no comment lines).
        obj.insert("program".into(), "hpge-cv".into());
        obj.insert("version".into(), env!("CARGO_PKG_VERSION").into());
        obj.insert(
            "command".into(),
            std::env::args().skip(1).collect::<Vec<_>>().into(),
        );
        obj.insert(
            "uncertainties".into(),
            serde_json::to_value(&settings.uncertainties)?,
        );
        obj.insert(
            "covariance_file".into(),
            m.curve
                .covariance_pf2
                .as_ref()
                .map(|_| covariance_name(&o.out))
                .into(),
        );
    }
    staged
        .write(&report_path, format!("{report:#}\n").as_bytes())
        .with_context(|| format!("{}: cannot write the report", report_path.display()))?;
    if let Some(dir) = &figures {
        plot::measurement(&m, &run.sets, dir)?;
    }
    super::args::commit(staged)?;
    // A curve without a covariance: an older covariance beside it would be read with it.
    if covariance.is_none() && covariance_file.is_file() {
        std::fs::remove_file(&covariance_file).with_context(|| {
            format!(
                "{}: cannot remove the stale covariance of the curve",
                covariance_file.display()
            )
        })?;
    }
    if json {
        outln!("{report}");
    } else {
        outln!(
            "{:>8} {:>11} {:>9} {:>8} {:>7} {:>11}",
            "U_B (V)",
            "c12 (pF)",
            "sigma",
            "stat",
            "pulses",
            "failed fits"
        );
        for (p, s) in m.points.iter().zip(&m.curve.sigma_pf) {
            outln!(
                "{:>8} {:>11.4} {:>9.4} {:>8.1e} {:>7} {:>11}",
                p.bias_v,
                p.c12_pf,
                s,
                p.sigma_stat_pf,
                p.n_pulses,
                p.n_failed()
            );
        }
        match m.depletion_voltage_v {
            Some(v) => outln!(
                "full-depletion voltage (-dc12/dU_B = {} pF/V): {v:.0} V",
                settings.depletion_slope_pf_per_v
            ),
            None => outln!("-dc12/dU_B does not fall to the threshold within the curve"),
        }
        outln!(
            "wrote {} (+ .covariance.csv, .measure.json); {} problem(s)",
            o.out.display(),
            run.problems.len() + m.problems.len()
        );
    }
    Ok(())
}

/// The name of the curve's covariance file: `<stem>.covariance.csv`.
fn covariance_name(csv: &Path) -> String {
    format!(
        "{}.covariance.csv",
        csv.file_stem().unwrap_or_default().to_string_lossy()
    )
}

/// Everything about the run as one JSON object (also written beside the curve).
fn report_json(
    m: &Measurement,
    raw: &Path,
    settings: &str,
    read_problems: &[RawProblem],
) -> serde_json::Value {
    let problems: Vec<serde_json::Value> = read_problems
        .iter()
        .chain(&m.problems)
        .map(|p| json!({"file": p.file.display().to_string(), "voltage_V": p.bias_v, "message": p.message}))
        .collect();
    json!({
        "raw": raw.display().to_string(),
        "settings": settings,
        "voltage_V": m.curve.voltage_v,
        "c12_pF": m.curve.c12_pf,
        "sigma_pF": m.curve.sigma_pf,
        "sigma_stat_pF": m.points.iter().map(|p| p.sigma_stat_pf).collect::<Vec<_>>(),
        "depletion_voltage_V": m.depletion_voltage_v,
        "points": m.points.iter().map(|p| json!({
            "voltage_V": p.bias_v,
            "file": p.source.display().to_string(),
            "pulses": p.n_pulses,
            "failed_fits": p.failed.iter().map(|(f, n)| json!({"reason": f.as_str(), "count": n})).collect::<Vec<_>>(),
            "peak_mean_pC": p.peak.mean_pc,
            "peak_mean_err_pC": p.peak.mean_err_pc,
            "peak_width_pC": p.peak.sigma_pc,
            "peak_events": p.peak.amplitude,
        })).collect::<Vec<_>>(),
        "problems": problems,
        "version": env!("CARGO_PKG_VERSION"),
    })
}

/// Writes one pulse file per bias (`U<bias>V.npy` + sidecar), `measurement.toml` listing the
/// biases, and `truth.json` with the curve, seed and settings.
///
/// Everything is checked before the folder is made (the pulses' memory among it:
/// [`hpge_measurement::synth::MAX_SYNTH_BYTES_PER_BIAS`]); a folder this run made is removed
/// again when a later step fails, so a failure leaves no empty or partial folder behind.
pub fn synthesize(o: &SynthOptions) -> Result<()> {
    o.validate()?;
    super::args::check_outputs(
        &[("--out", o.out.as_path())],
        &[("--curve", o.curve.as_path())],
    )?;
    check_synthesis_folder(&o.out)?;
    let settings = o.settings();
    settings.validate().map_err(|e| match &e {
        hpge_measurement::Error::Setting { key, message } if key == "pulser_pulses" => {
            anyhow::anyhow!("--pulses {}: {message}", o.pulses)
        }
        _ => anyhow::anyhow!("synthesis settings: {e}"),
    })?;
    let (volts, c12) =
        read_model_curve(&o.curve).with_context(|| format!("--curve {}", o.curve.display()))?;
    let draws = StandInDraws::draw(o, &c12)
        .with_context(|| format!("--curve {}: the stand-in's draws", o.curve.display()))?;
    let ufd = match o.depletion_voltage {
        Some(v) if v.is_finite() && v > 0.0 => v,
        Some(v) => bail!("--depletion-voltage {v}: must be a positive number of volts"),
        None => depletion_voltage(&volts, &c12, 1e-3).with_context(|| {
            format!(
                "--curve {}: -dc12/dU_B never falls to 1e-3 pF/V, so the full-depletion voltage is unknown; give --depletion-voltage",
                o.curve.display()
            )
        })?,
    };
    // The folder is filled under a temporary name beside it and put in place when complete: a
    // killed or failed run leaves no partial raw folder that `measure` would read as a short
    // curve, and a folder of an earlier run is replaced whole, none of its files kept among
    // this run's (issue 66).
    hpge_files::remove_stale_temporaries(super::args::parent_or_here(&o.out));
    let mut staged = hpge_files::Staged::new();
    let tmp = staged
        .replacing_folder(&o.out)
        .with_context(|| format!("--out {}: cannot create the folder", o.out.display()))?;
    write_synthetic(o, &tmp, &settings, &volts, &c12, ufd, &draws)?;
    super::args::commit(staged)?;
    outln!(
        "wrote {} pulse files to {} (seed {}, U_fd {ufd:.0} V)",
        volts.len(),
        o.out.display(),
        o.seed
    );
    Ok(())
}

/// Refuses an `--out` of `synthesize` that is a file, or a folder holding anything but what an
/// earlier `synthesize` wrote (`U<bias>V.*`, `measurement.toml`, `truth.json`): the run replaces
/// the folder whole, so it must not hold anything else.
fn check_synthesis_folder(out: &Path) -> Result<()> {
    if !out.exists() {
        return Ok(());
    }
    if !out.is_dir() {
        bail!(
            "--out {}: not a folder (synthesize writes a folder of pulse files)",
            out.display()
        );
    }
    let entries = std::fs::read_dir(out)
        .with_context(|| format!("--out {}: cannot read the folder", out.display()))?;
    for e in entries {
        let e = e.with_context(|| format!("--out {}: cannot read the folder", out.display()))?;
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
            bail!(
                "--out {}: the folder holds {name}, which synthesize did not write; it replaces \
                 the folder whole (an earlier run's pulse files, measurement.toml, truth.json), \
                 so choose a new or empty folder",
                out.display()
            );
        }
    }
    Ok(())
}

/// The files of [`synthesize`] into the existing folder `dir` (`o.out` or its temporary).
fn write_synthetic(
    o: &SynthOptions,
    dir: &Path,
    settings: &hpge_measurement::SynthSettings,
    volts: &[f64],
    c12: &[f64],
    ufd: f64,
    draws: &StandInDraws,
) -> Result<()> {
    let settings = &draws.settings(settings);
    let bar = ProgressBar::new(volts.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} voltages, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    for (k, (&u, &c)) in volts.iter().zip(&draws.detector_pf).enumerate() {
        let v = synthesize_voltage(u, c, ufd, settings, voltage_seed(o.seed, k))?;
        let file = format!("U{:04}V.npy", u.round() as i64);
        let name = dir.join(&file);
        let set = PulseSet {
            source: o.out.join(&file),
            ..v.set
        };
        write_pulses(&name, &set, true)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let toml_path = dir.join("measurement.toml");
    let list = volts
        .iter()
        .map(|v| format!("{v}"))
        .collect::<Vec<_>>()
        .join(", ");
    hpge_files::write(
        &toml_path,
        format!(
            "# Written by hpge-cv {} synthesize (seed {}); the default circuit and uncertainties.\nvoltages_V = [{list}]\n",
            env!("CARGO_PKG_VERSION"),
            o.seed
        ),
    )
    .with_context(|| format!("{}: cannot write", toml_path.display()))?;
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
    let truth_path = dir.join("truth.json");
    hpge_files::write(&truth_path, format!("{truth:#}\n"))
        .with_context(|| format!("{}: cannot write", truth_path.display()))?;
    Ok(())
}
