//! `hpge-cv simulate` and `hpge-cv capacitance`: the command line's face of the solver jobs
//! (`hpge_solver::jobs`): parse, one library call, print; the figures are drawn here.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::{Error, FieldSettings, jobs, solve_potential};
use indicatif::{ProgressBar, ProgressStyle};

use super::DetectorInput;
use super::args::{GridArgs, load_detector};

/// Options of `simulate`.
pub struct SimulateOptions<'a> {
    pub input: &'a DetectorInput,
    pub d_li_mm: Option<f64>,
    pub voltages: &'a [f64],
    pub settings: FieldSettings,
    pub grid: &'a GridArgs,
    pub json: bool,
    pub out: Option<&'a PathBuf>,
    pub plot: Option<&'a PathBuf>,
    pub field: Option<f64>,
    pub field_plot: Option<&'a PathBuf>,
    pub depletion_plot: Option<&'a PathBuf>,
}

/// Runs a C-V curve and writes what was asked for.
pub fn run(o: &SimulateOptions<'_>) -> Result<()> {
    let outputs: Vec<(&str, &Path)> = [
        ("--out", o.out),
        ("--plot", o.plot),
        ("--field-plot", o.field_plot),
        ("--depletion-plot", o.depletion_plot),
    ]
    .into_iter()
    .filter_map(|(f, p)| p.map(|p| (f, p.as_path())))
    .collect();
    super::args::check_outputs(&outputs, &super::args::detector_inputs(o.input))?;
    if let Some(p) = o.plot {
        plot::check_output(p, "--plot")?;
    }
    if let Some(p) = o.depletion_plot {
        plot::check_output(p, "--depletion-plot")?;
    }
    if let Some(p) = o.field_plot {
        plot::check_output(p, "--field-plot")?;
        if o.field.is_none() {
            bail!("--field-plot needs --field U (the bias in V at which to draw the potential)");
        }
    }
    if let (Some(u), None) = (o.field, o.field_plot) {
        bail!(
            "--field {u}: draws the potential only with --field-plot FILE (.svg or .png); give both, or neither"
        );
    }
    if let Some(u) = o.field
        && !(u.is_finite() && u > 0.0)
    {
        bail!("--field {u}: the bias must be a positive number of volts");
    }
    let mut input = DetectorInput {
        detector: o.input.detector.clone(),
        impurity: o.input.impurity.clone(),
        params: o.input.params.clone(),
    };
    if let Some(d) = o.d_li_mm {
        if !(d.is_finite() && d > 0.0) {
            bail!("--d-li {d}: the lithium thickness must be a positive number of mm");
        }
        if input.params.iter().any(|(k, _)| k == "d_li_mm") {
            bail!("--d-li {d}: --param d_li_mm is given too; give the thickness once");
        }
        input.params.push(("d_li_mm".to_string(), d));
    }
    let det = load_detector(&input)?;
    let options = jobs::SimulateOptions {
        voltages_v: o.voltages.to_vec(),
        settings: o.grid.apply(&o.settings, &det)?,
    };
    let bar = ProgressBar::new(o.voltages.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} voltages, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let run = jobs::simulate(&det, &options, |k, n| {
        bar.set_length(n as u64);
        bar.set_position(k as u64)
    });
    bar.finish_and_clear();
    let run = match run {
        Ok(r) => r,
        Err(e @ Error::UndepletedBridge { .. }) => {
            // Draw the state that fails (at --field U, or at the failing bias) before giving up.
            if let (
                Some(path),
                Error::UndepletedBridge {
                    bias_v, r_mm, z_mm, ..
                },
            ) = (o.field_plot, &e)
            {
                let u = o.field.unwrap_or(*bias_v);
                let p = solve_potential(&det, u, &options.settings, None)?;
                let at = (u == *bias_v).then_some((*r_mm, *z_mm));
                plot::field_map(&det, &p, at, path)?;
                eprintln!(
                    "note: the potential at {u} V is drawn in {} (red cross: where the undepleted region joins the contacts)",
                    path.display()
                );
            }
            return Err(e.into());
        }
        Err(e) => return Err(e.respell(super::args::flag).into()),
    };
    for note in run.notes() {
        eprintln!("{note}");
    }
    let settings = &run.settings;
    let curve = &run.curve;
    // The CSV under its name only once every figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = o.out {
        staged
            .write_with(path, |f| run.write_csv(f))
            .with_context(|| format!("--out {}: cannot write the file", path.display()))?;
    }
    if let Some(path) = o.plot {
        plot::cv_curve(curve, &det, path)?;
    }
    if let (Some(u), Some(path)) = (o.field, o.field_plot) {
        let p = solve_potential(&det, u, settings, None)?;
        plot::field_map(&det, &p, None, path)?;
    }
    if let Some(path) = o.depletion_plot {
        plot::depletion_map(&det, &run.depletion_states(&det)?, path)?;
    }
    super::args::commit(staged)?;
    let record = run.record();
    if o.json {
        let v = serde_json::to_value(&record)?;
        outln!("{v}");
    } else {
        outln!(
            "{:>10} {:>12} {:>10} {:>8} {:>11}",
            "U_B (V)",
            "c12 (pF)",
            "+- (pF)",
            "depleted",
            "grid"
        );
        for p in &curve.points {
            outln!(
                "{:>10} {:>12.5} {:>10.2e} {:>8} {:>5}x{:<5}",
                p.voltage_v,
                p.c12_pf,
                p.c12_err_pf,
                p.fully_depleted,
                p.grid.0,
                p.grid.1
            );
        }
        for p in curve.points.iter().filter(|p| !p.pockets.is_empty()) {
            for k in &p.pockets {
                outln!(
                    "  {:>6} V: pocket of trapped {}s at {:.1} V, {:.3} cm^3, centre (r, z) = ({:.1}, {:.1}) mm",
                    p.voltage_v,
                    k.carrier.as_str(),
                    k.level_v,
                    k.volume_cm3,
                    k.centroid_mm.0,
                    k.centroid_mm.1
                );
            }
        }
        if let Some(e) = run.pinch_off {
            outln!(
                "pinch-off voltage {:.1} +- {} V (a pocket of trapped carriers forms)",
                e.voltage_v,
                plus_minus(e.err_v)
            );
        }
        match curve.depletion_voltage_v {
            Some(v) => outln!(
                "full-depletion voltage {v:.1} +- {} V",
                plus_minus(run.depletion.map_or(f64::INFINITY, |e| e.err_v))
            ),
            None => outln!("not fully depleted at any listed bias"),
        }
        outln!(
            "{} points in {:.2} s ({} on {}{})",
            curve.points.len(),
            run.seconds,
            settings.method.as_str(),
            settings.backend.as_str(),
            run.device.as_ref().map_or(String::new(), |d| format!(
                ": {}, {}",
                d.adapter, d.precision
            ))
        );
    }
    Ok(())
}

/// An error bar for text: `?` where it could not be estimated.
fn plus_minus(err_v: f64) -> String {
    if err_v.is_finite() {
        format!("{err_v:.1}")
    } else {
        "? (a coarser grid finds no threshold near it)".into()
    }
}

/// `capacitance`: the full Maxwell matrix at one bias.
pub fn capacitance(
    input: &DetectorInput,
    voltage: f64,
    settings: &FieldSettings,
    grid: &GridArgs,
    as_json: bool,
) -> Result<()> {
    let det = load_detector(input)?;
    let options = jobs::CapacitanceOptions {
        voltage_v: voltage,
        settings: grid.apply(settings, &det)?,
    };
    let c = jobs::capacitance(&det, &options).map_err(|e| e.respell(super::args::flag))?;
    if as_json {
        outln!("{}", serde_json::to_value(&c)?);
    } else {
        outln!("Maxwell capacitance matrix C* (pF, Q = C* U) at U_B = {voltage} V:");
        out!("{:>28}", "");
        for k in &c.contacts {
            out!(
                " {:>14}",
                format!("{} ({})", k.id, k.name)
                    .chars()
                    .take(14)
                    .collect::<String>()
            );
        }
        outln!();
        for (i, k) in c.contacts.iter().enumerate() {
            out!(
                "{:>28}",
                format!("{} ({})", k.id, k.name)
                    .chars()
                    .take(28)
                    .collect::<String>()
            );
            for j in 0..c.contacts.len() {
                out!(" {:>14.5}", c.maxwell_pf[i][j]);
            }
            outln!();
        }
        outln!(
            "c12 = -C*_12 = {:.5} pF (estimated error {:.2e} pF, {} adaptive passes); fully depleted: {}",
            c.c12_pf,
            c.c12_err_pf,
            c.adaptive_passes,
            c.fully_depleted
        );
    }
    Ok(())
}
