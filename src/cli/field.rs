//! `hpge-cv field`: the electric-field strength |E| along r at one (phi, z) and bias (paper
//! Fig. 29a, section 9); null where the volume is undepleted, a contact or outside the crystal.

use std::io::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::drift::ElectricField;
use hpge_solver::drift::field_line;
use serde_json::json;

use super::DetectorInput;
use super::args::{RadiusRange, load_detector, parse_r_range};
use super::simulate::backend_json;
use hpge_solver::options::{SolverOptions, WeightingOptions};

/// V/m per V/cm.
const V_PER_M_PER_V_PER_CM: f64 = 100.0;

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
    if !(a.voltage.is_finite() && a.voltage > 0.0) {
        bail!(
            "--voltage {}: the bias must be a positive number of volts",
            a.voltage
        );
    }
    for (flag, v) in [("--phi", a.phi), ("--z", a.z)] {
        if !v.is_finite() {
            bail!("{flag} {v}: must be a finite number");
        }
    }
    let det = load_detector(&a.input)?;
    det.check_bias_contact()?;
    let b = det.semiconductor.geometry.bbox();
    if a.z < b.z_min_mm || a.z > b.z_max_mm {
        bail!(
            "--z {}: the crystal spans z in [{}, {}] mm",
            a.z,
            b.z_min_mm,
            b.z_max_mm
        );
    }
    let r_mm = match &a.r_range {
        Some(RadiusRange(r)) => r.clone(),
        None => (0..201)
            .map(|k| b.r_min_mm + (b.r_max_mm - b.r_min_mm) * k as f64 / 200.0)
            .collect(),
    };
    let settings = a.solver.grid.apply(
        &a.solver
            .field_settings(WeightingOptions::default().weighting),
        &det,
    )?;
    backend_json(&settings)?;
    let point = hpge_solver::solve_point(&det, a.voltage, &settings, None)?;
    let field = ElectricField::new(&det, &point);
    let line = field_line(&det, &field, a.phi.to_radians(), a.z, &r_mm);
    let v_cm: Vec<Option<f64>> = line
        .e_v_per_m
        .iter()
        .map(|e| e.map(|e| e / V_PER_M_PER_V_PER_CM))
        .collect();
    let provenance = format!(
        "hpge-cv {} field: detector {} impurity {} parameters [{}] U_B {} V, phi {} deg, z {} mm",
        env!("CARGO_PKG_VERSION"),
        det.file.display(),
        det.semiconductor.impurity_file().display(),
        det.parameters
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(" "),
        a.voltage,
        a.phi,
        a.z
    );
    // The CSV and its sidecar under their names only once the figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = &a.out {
        let ctx = || format!("--out {}: cannot write the file", path.display());
        staged
            .write_with(path, |f| -> std::io::Result<()> {
                writeln!(f, "r_mm,e_V_per_cm,status")?;
                for ((r, e), s) in line.r_mm.iter().zip(&v_cm).zip(&line.status) {
                    let e = e.map_or(String::new(), |e| e.to_string());
                    writeln!(f, "{r},{e},{}", s.as_str())?;
                }
                Ok(())
            })
            .with_context(ctx)?;
        super::sidecar::stage(
            &mut staged,
            path,
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
        let v = super::args::with_detector_provenance(
            json!({
                "r_mm": line.r_mm,
                "e_V_per_m": line.e_v_per_m,
                "e_V_per_cm": v_cm,
                "status": line.status.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
                "phi_deg": a.phi,
                "z_mm": a.z,
                "voltage_V": a.voltage,
                "fully_depleted": point.fully_depleted(),
            }),
            &det,
        );
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
        for ((r, e), s) in line.r_mm.iter().zip(&v_cm).zip(&line.status) {
            let e = e.map_or("-".to_string(), |e| format!("{e:.1}"));
            outln!("{r:>10.3} {e:>14} {:>11}", s.as_str());
        }
    }
    Ok(())
}
