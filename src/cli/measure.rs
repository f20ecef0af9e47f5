//! `hpge-cv measure` (raw pulser data to a C-V curve with its covariance) and
//! `hpge-cv synthesize` (a known C-V curve to raw-like pulser data): the faces of
//! `hpge_measurement::jobs`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use hpge_measurement::{MeasureOptions, SynthOptions, jobs};
use hpge_reports::plot;
use indicatif::{ProgressBar, ProgressStyle};

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
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} fitting {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.set_message(format!("the pulse files of {}", o.raw.display()));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let run = jobs::measure_raw(o);
    bar.finish_and_clear();
    let run = run?;
    for p in run.problems() {
        eprintln!(
            "problem: {}{}: {}",
            p.file.display(),
            p.bias_v.map_or(String::new(), |v| format!(" ({v} V)")),
            p.message
        );
    }
    let m = &run.measurement;
    let settings = &run.settings;
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
    let command: Vec<String> = std::env::args().skip(1).collect();
    let (report, stale_covariance) = run.stage(&o.out, &command, &mut staged)?;
    if let Some(dir) = &figures {
        plot::measurement(m, &run.read.sets, dir)?;
    }
    super::args::commit(staged)?;
    // A curve without a covariance: an older covariance beside it would be read with it.
    if let Some(file) = stale_covariance.filter(|f| f.is_file()) {
        std::fs::remove_file(&file).with_context(|| {
            format!(
                "{}: cannot remove the stale covariance of the curve",
                file.display()
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
            run.problems().count()
        );
    }
    Ok(())
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
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} voltages, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let run = jobs::synthesize_folder(o, |k, n| {
        bar.set_length(n as u64);
        bar.set_position(k as u64);
    });
    bar.finish_and_clear();
    let run = run?;
    outln!(
        "wrote {} pulse files to {} (seed {}, U_fd {:.0} V)",
        run.files,
        run.out.display(),
        run.seed,
        run.depletion_voltage_v
    );
    Ok(())
}
