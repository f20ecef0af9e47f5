//! `hpge-cv pulse`: the charge signals of one interaction (paper section 9): the field at one
//! bias, an electron and a hole drifted with the ADL model, Shockley-Ramo signals on every
//! contact. The face of `hpge_solver::jobs::pulse`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::drift::AdlParameters;
use hpge_solver::{Detector, Error, jobs};
use serde_json::json;

use super::DetectorInput;
use super::args::{load_detector, parse_cylindrical};
use hpge_solver::options::{SolverOptions, WeightingOptions};

#[derive(Debug, clap::Args)]
pub struct PulseArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Bias voltage U_B in V (positive).
    #[arg(long, value_name = "U", allow_hyphen_values = true)]
    voltage: f64,
    /// The interaction point "R,PHI,Z": r in mm, azimuth phi in degrees, z in mm (e.g. 37,30,35).
    #[arg(long, value_name = "R,PHI,Z", allow_hyphen_values = true, value_parser = parse_cylindrical)]
    at: (f64, f64, f64),
    #[command(flatten)]
    solver: SolverOptions,
    /// ADL drift-model parameters (TOML with the keys of the published defaults: e100, e111,
    /// h100, h111 tables of mu0_cm2_per_vs, beta, e0_v_per_cm, mun_cm2_per_vs; ml_over_me,
    /// mt_over_me, phi110_deg); missing keys keep the published 78 K values.
    #[arg(long = "drift-parameters", value_name = "FILE")]
    drift_parameters: Option<PathBuf>,
    /// Divide every signal by the end value of the bias (n+) contact's signal, so that it ends at
    /// exactly +1 (without this, signals are in units of the pair charge and the bias contact
    /// ends at +1 only for complete collection).
    #[arg(long)]
    normalise: bool,
    /// Print exactly one JSON object on stdout: t_ns, contacts [{name, signal}],
    /// collection_time_ns, how each carrier stopped, inputs and version.
    #[arg(long)]
    json: bool,
    /// Draw the signals of every contact against time (.svg or .png).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Write the signals as CSV (t_ns, then one column per contact), the provenance in the sidecar
    /// `<stem>.json`.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// Runs `pulse`.
pub fn run(a: &PulseArgs) -> Result<()> {
    let outputs = super::args::csv_and_plot_outputs(a.out.as_deref(), a.plot.as_deref());
    let mut inputs = super::args::detector_inputs(&a.input);
    if let Some(d) = &a.drift_parameters {
        inputs.push(("--drift-parameters", d.as_path()));
    }
    super::args::check_outputs(&outputs, &inputs)?;
    if let Some(p) = &a.plot {
        plot::check_output(p, "--plot")?;
    }
    if let Some(p) = &a.out
        && let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        bail!(
            "--out {}: the folder {} does not exist",
            p.display(),
            dir.display()
        );
    }
    let adl = match &a.drift_parameters {
        Some(p) => jobs::read_adl_parameters(p).context("--drift-parameters")?,
        None => AdlParameters::default(),
    };
    let det = load_detector(&a.input)?;
    let options = jobs::PulseOptions {
        voltage_v: a.voltage,
        at: a.at,
        adl,
        drift_file: a.drift_parameters.clone(),
        normalise: a.normalise,
        settings: a.solver.grid.apply(
            &a.solver
                .field_settings(WeightingOptions::default().weighting),
            &det,
        )?,
    };
    let (r_mm, phi_deg, z_mm) = a.at;
    let run = jobs::pulse(&det, &options).map_err(|e| match e {
        // Where the point cannot start a drift, the message names the flag and the point.
        e @ (Error::InteractionInContact { .. }
        | Error::InteractionUndepleted { .. }
        | Error::InteractionOutside { .. }) => {
            anyhow::Error::new(e).context(format!("--at {r_mm},{phi_deg},{z_mm}"))
        }
        e => e.respell(super::args::flag).into(),
    })?;
    // The CSV and its sidecar under their names only once the figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = &a.out {
        write_csv(&mut staged, path, &run, &det)?;
    }
    if let Some(path) = &a.plot {
        plot::line_figure(&pulse_figure(&run), path)?;
    }
    super::args::commit(staged)?;
    if a.json {
        outln!("{}", serde_json::to_value(run.record())?);
    } else {
        print_summary(&det, &run)?;
    }
    Ok(())
}

fn print_summary(det: &Detector, run: &jobs::PulseRun) -> Result<()> {
    let (r, phi, z) = run.options.at;
    let p = &run.pulse;
    outln!(
        "pulse at r = {r} mm, phi = {phi} deg, z = {z} mm; U_B = {} V ({})",
        run.options.voltage_v,
        det.name
    );
    for d in [&p.electron, &p.hole] {
        let end = d.path.last().map_or([f64::NAN; 3], |s| s.x_mm);
        outln!(
            "  {:8} {} after {:.1} ns, at r = {:.2} mm, z = {:.2} mm",
            d.carrier.as_str(),
            d.stop.describe(det),
            d.end_time_ns(),
            end[0].hypot(end[1]),
            end[2]
        );
    }
    outln!("collection time {:.1} ns", p.collection_time_ns);
    let unit = if run.normalised_by.is_some() {
        "normalised"
    } else {
        "units of the pair charge"
    };
    let ends: Vec<String> = p
        .signals
        .iter()
        .map(|s| format!("{} {:+.4}", s.name, s.charge.last().unwrap_or(&0.0)))
        .collect();
    outln!("end charges ({unit}): {}", ends.join(", "));
    if let Some(t) = run.rise_time_10_90_ns {
        outln!(
            "10-90% rise time of {}: {t:.1} ns",
            p.signals[run.reference_contact].name
        );
    }
    Ok(())
}

fn write_csv(
    staged: &mut hpge_files::Staged,
    path: &Path,
    run: &jobs::PulseRun,
    det: &Detector,
) -> Result<()> {
    let ctx = || format!("--out {}: cannot write the file", path.display());
    staged
        .write_with(path, |f| run.write_csv(f))
        .with_context(ctx)?;
    let (r, phi, z) = run.options.at;
    let normalised = run.options.normalise;
    hpge_foundation::sidecar::stage(
        staged,
        path,
        &hpge_solver::made(),
        super::args::with_detector_provenance(
            json!({
                "provenance": run.provenance_line(),
                "voltage_V": run.options.voltage_v,
                "at": {"r_mm": r, "phi_deg": phi, "z_mm": z},
                "drift_parameters": run.options.drift_file.as_ref().map(|f| f.display().to_string()),
                "normalised": normalised,
                "columns": det.contacts.iter().map(|c| (format!("q{}", c.id), serde_json::Value::from(c.name.clone()))).collect::<serde_json::Map<_, _>>(),
                "unit": if normalised { "normalised" } else { "units of the pair charge" },
            }),
            det,
        ),
    )?;
    Ok(())
}

fn pulse_figure(run: &jobs::PulseRun) -> plot::LineFigure {
    let (r, phi, z) = run.options.at;
    let p = &run.pulse;
    plot::LineFigure {
        title: format!(
            "{}: signals of an interaction at r = {r} mm, phi = {phi} deg, z = {z} mm, U_B = {} V",
            run.detector_name, run.options.voltage_v
        ),
        x_desc: "time (ns)".into(),
        y_desc: if run.options.normalise {
            "induced charge (normalised: bias contact ends at 1)".into()
        } else {
            "induced charge (units of the pair charge)".into()
        },
        curves: p
            .signals
            .iter()
            .map(|s| plot::Curve {
                label: s.name.clone(),
                points: p
                    .t_ns
                    .iter()
                    .zip(&s.charge)
                    .map(|(&t, &q)| (t, Some(q)))
                    .collect(),
            })
            .collect(),
        y_from_zero: false,
        legend: plot::Corner::UpperLeft,
        footnotes: vec![run.provenance_line()],
    }
}
