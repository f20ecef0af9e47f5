//! `hpge-cv field`: the electric-field strength |E| along r at one (phi, z) and bias (paper
//! Fig. 29a, section 9); null where the volume is undepleted, a contact or outside the crystal.
//! The face of `hpge_solver::jobs::field`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use hpge_reports::plot;
use hpge_solver::jobs;
use serde_json::json;

use super::DetectorInput;
use super::args::{RadiusRange, load_detector, parse_r_range};
use hpge_solver::options::{SolverOptions, WeightingOptions};

#[derive(Debug, clap::Args)]
pub struct FieldArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Bias voltage U_B in V (positive).
    #[arg(long, value_name = "U", allow_hyphen_values = true)]
    voltage: f64,
    /// Azimuth phi in degrees (the field of the axisymmetric model does not depend on it; it
    /// sets the direction of E in the lab frame).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    phi: f64,
    /// Height z in mm.
    #[arg(long, value_name = "Z", allow_hyphen_values = true)]
    z: f64,
    /// Radii LO:HI:N in mm (N points, ends included) [default: the crystal's r extent, 201 points].
    #[arg(long = "r-range", value_name = "LO:HI:N", value_parser = parse_r_range)]
    r_range: Option<RadiusRange>,
    #[command(flatten)]
    solver: SolverOptions,
    /// Print exactly one JSON object on stdout (|E| null where there is no field).
    #[arg(long)]
    json: bool,
    /// Draw |E| against r (.svg or .png); gaps where there is no field.
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Write r_mm, |E| (V/cm, empty where there is no field) and the status as CSV.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// Runs `field`.
pub fn run(a: &FieldArgs) -> Result<()> {
    let outputs = super::args::csv_and_plot_outputs(a.out.as_deref(), a.plot.as_deref());
    super::args::check_outputs(&outputs, &super::args::detector_inputs(&a.input))?;
    if let Some(p) = &a.plot {
        plot::check_output(p, "--plot")?;
    }
    let det = load_detector(&a.input)?;
    let options = jobs::FieldOptions {
        voltage_v: a.voltage,
        phi_deg: a.phi,
        z_mm: a.z,
        r_mm: a.r_range.as_ref().map(|RadiusRange(r)| r.clone()),
        settings: a.solver.grid.apply(
            &a.solver
                .field_settings(WeightingOptions::default().weighting),
            &det,
        )?,
    };
    let run = jobs::field(&det, &options).map_err(|e| e.respell(super::args::flag))?;
    let line = &run.line;
    let v_cm = &run.e_v_per_cm;
    let provenance = run.provenance_line();
    // The CSV and its sidecar under their names only once the figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = &a.out {
        let ctx = || format!("--out {}: cannot write the file", path.display());
        staged
            .write_with(path, |f| run.write_csv(f))
            .with_context(ctx)?;
        hpge_foundation::sidecar::stage(
            &mut staged,
            path,
            &hpge_solver::made(),
            super::args::with_detector_provenance(
                json!({
                    "voltage_V": a.voltage,
                    "phi_deg": a.phi,
                    "z_mm": a.z,
                    "columns": {"r_mm": "radius (mm)", "e_V_per_cm": "|E| (V/cm), empty where there is no field", "status": "the radius's status"},
                }),
                &det,
            ),
        )?;
    }
    if let Some(path) = &a.plot {
        let fig = plot::LineFigure {
            title: format!(
                "{}: |E| at phi = {} deg, z = {} mm, U_B = {} V",
                det.name, a.phi, a.z, a.voltage
            ),
            x_desc: "r (mm)".into(),
            y_desc: "|E| (V/cm)".into(),
            curves: vec![plot::Curve {
                label: det.semiconductor.impurity_file().display().to_string(),
                points: line
                    .r_mm
                    .iter()
                    .copied()
                    .zip(v_cm.iter().copied())
                    .collect(),
            }],
            y_from_zero: true,
            legend: plot::Corner::LowerRight,
            footnotes: vec![
                provenance.clone(),
                "gaps: undepleted, contact or outside the crystal".into(),
            ],
        };
        plot::line_figure(&fig, path)?;
    }
    super::args::commit(staged)?;
    if a.json {
        let v = serde_json::to_value(run.record())?;
        outln!("{v}");
    } else {
        outln!(
            "|E| at phi = {} deg, z = {} mm, U_B = {} V ({})",
            a.phi,
            a.z,
            a.voltage,
            det.name
        );
        outln!("{:>10} {:>14} {:>11}", "r (mm)", "|E| (V/cm)", "status");
        for ((r, e), s) in line.r_mm.iter().zip(v_cm).zip(&line.status) {
            let e = e.map_or("-".to_string(), |e| format!("{e:.1}"));
            outln!("{r:>10.3} {e:>14} {:>11}", s.as_str());
        }
    }
    Ok(())
}
