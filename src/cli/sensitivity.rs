//! `hpge-cv sensitivity`: c12 at one bias for constant impurity densities (the paper's
//! "impurity level sensitivity" scan, section 5; the scan itself is
//! `hpge_solver::scan::sensitivity_scan`). The face of `hpge_solver::jobs::sensitivity`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use hpge_reports::plot;
use hpge_solver::FieldSettings;
use hpge_solver::jobs;
use indicatif::{ProgressBar, ProgressStyle};

use super::DetectorInput;
use super::args::load_detector;

/// Options of `sensitivity`.
pub struct SensitivityOptions<'a> {
    pub input: &'a DetectorInput,
    pub voltage_v: f64,
    pub zetas_cm3: &'a [f64],
    pub json: bool,
    pub out: Option<&'a PathBuf>,
    pub plot: Option<&'a PathBuf>,
    /// Backend, method and precision (weighting: conductor).
    pub settings: FieldSettings,
    /// Grid and accuracy options.
    pub grid: &'a super::args::GridArgs,
}

/// Runs the scan and writes what was asked for.
pub fn run(o: &SensitivityOptions<'_>) -> Result<()> {
    if let Some(p) = o.plot {
        plot::check_output(p, "--plot")?;
    }
    let outputs: Vec<(&str, &std::path::Path)> = [("--out", o.out), ("--plot", o.plot)]
        .into_iter()
        .filter_map(|(f, p)| p.map(|p| (f, p.as_path())))
        .collect();
    super::args::check_outputs(&outputs, &super::args::detector_inputs(o.input))?;
    let det = load_detector(o.input)?;
    let options = jobs::SensitivityOptions {
        voltage_v: o.voltage_v,
        zetas_cm3: o.zetas_cm3.to_vec(),
        settings: o.grid.apply(&o.settings, &det)?,
    };
    let bar = ProgressBar::new(o.zetas_cm3.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} densities, {elapsed} elapsed, eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let run = jobs::sensitivity(&det, &options, &|k| bar.set_position(k as u64));
    bar.finish_and_clear();
    let run = run.map_err(|e| e.respell(super::args::flag))?;
    let points = &run.points;
    // The CSV under its name only once the figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = o.out {
        staged
            .write_with(path, |f| run.write_csv(f))
            .with_context(|| format!("--out {}: cannot write the file", path.display()))?;
    }
    if let Some(path) = o.plot {
        plot::sensitivity(
            points,
            o.voltage_v,
            &det.name,
            &plot::ScanMarks::sensitive_range(),
            path,
        )?;
    }
    super::args::commit(staged)?;
    if o.json {
        let v = serde_json::to_value(run.record())?;
        outln!("{v}");
    } else {
        outln!(
            "{:>14} {:>12} {:>8}",
            "zeta (cm^-3)",
            "c12 (pF)",
            "depleted"
        );
        for p in points {
            outln!(
                "{:>14.4e} {:>12.5} {:>8}",
                p.zeta_cm3,
                p.c12_pf,
                p.fully_depleted
            );
        }
        outln!(
            "{} densities at {} V in {:.2} s",
            points.len(),
            o.voltage_v,
            run.seconds
        );
    }
    Ok(())
}
