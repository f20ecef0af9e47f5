//! `hpge-cv sensitivity`: c12 at one bias for constant impurity densities (the paper's
//! "impurity level sensitivity" scan, section 5; the scan itself is
//! `hpge_solver::scan::sensitivity_scan`).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::FieldSettings;
use hpge_solver::scan::sensitivity_scan;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

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
    if !(o.voltage_v.is_finite() && o.voltage_v > 0.0) {
        bail!(
            "--voltage {}: the bias must be a positive number of volts",
            o.voltage_v
        );
    }
    if let Some(p) = o.plot {
        plot::check_output(p, "--plot")?;
    }
    let outputs: Vec<(&str, &std::path::Path)> = [("--out", o.out), ("--plot", o.plot)]
        .into_iter()
        .filter_map(|(f, p)| p.map(|p| (f, p.as_path())))
        .collect();
    super::args::check_outputs(&outputs, &super::args::detector_inputs(o.input))?;
    let det = load_detector(o.input)?;
    det.check_bias_contact()?;
    let settings = o.grid.apply(&o.settings, &det)?;
    let device = super::simulate::backend_json(&settings)?;
    let bar = ProgressBar::new(o.zetas_cm3.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} densities, {elapsed} elapsed, eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = std::time::Instant::now();
    let points = sensitivity_scan(&det, o.voltage_v, o.zetas_cm3, &settings, &|k| {
        bar.set_position(k as u64)
    })?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    // The CSV under its name only once the figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = o.out {
        staged
            .write_with(path, |f| -> std::io::Result<()> {
                writeln!(f, "zeta_cm3,c12_pF,fully_depleted")?;
                for p in &points {
                    writeln!(f, "{:e},{},{}", p.zeta_cm3, p.c12_pf, p.fully_depleted)?;
                }
                Ok(())
            })
            .with_context(|| format!("--out {}: cannot write the file", path.display()))?;
    }
    if let Some(path) = o.plot {
        plot::sensitivity(
            &points,
            o.voltage_v,
            &det.name,
            &plot::ScanMarks::sensitive_range(),
            path,
        )?;
    }
    super::args::commit(staged)?;
    if o.json {
        let v = json!({
            "zeta_cm3": points.iter().map(|p| p.zeta_cm3).collect::<Vec<_>>(),
            "c12_pF": points.iter().map(|p| p.c12_pf).collect::<Vec<_>>(),
            "fully_depleted": points.iter().map(|p| p.fully_depleted).collect::<Vec<_>>(),
            "voltage_V": o.voltage_v,
            "method": settings.method.as_str(),
            "backend": settings.backend.as_str(),
            "device": device,
            "seconds": seconds,
            "detector": det.file.display().to_string(),
            "parameters": det.parameters.iter().collect::<std::collections::BTreeMap<_, _>>(),
            "version": env!("CARGO_PKG_VERSION"),
        });
        outln!("{v}");
    } else {
        outln!(
            "{:>14} {:>12} {:>8}",
            "zeta (cm^-3)",
            "c12 (pF)",
            "depleted"
        );
        for p in &points {
            outln!(
                "{:>14.4e} {:>12.5} {:>8}",
                p.zeta_cm3,
                p.c12_pf,
                p.fully_depleted
            );
        }
        outln!(
            "{} densities at {} V in {seconds:.2} s",
            points.len(),
            o.voltage_v
        );
    }
    Ok(())
}
