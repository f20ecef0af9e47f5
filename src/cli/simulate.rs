//! `hpge-cv simulate` and `hpge-cv capacitance`: field solves from the command line.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::field::{
    VoltageEstimate, curve_depletion_voltage, curve_pinch_off_voltage, normalise_voltages,
};
use hpge_solver::gpu::gpu_adapter;
use hpge_solver::{
    Backend, CvCurve, Error, FieldSettings, Precision, cv_curve, solve_point, solve_potential,
};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

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
    let volts = normalise_voltages(o.voltages)?;
    if volts.len() != o.voltages.len() {
        eprintln!(
            "note: the voltage list was sorted and deduplicated ({} points)",
            volts.len()
        );
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
    det.check_bias_contact()?;
    let settings = o.grid.apply(&o.settings, &det)?;
    let device = backend_json(&settings)?;
    let bar = ProgressBar::new(volts.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} voltages, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = std::time::Instant::now();
    let curve = cv_curve(&det, &volts, &settings, |k, _| bar.set_position(k as u64));
    bar.finish_and_clear();
    let curve = match curve {
        Ok(c) => c,
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
                let p = solve_potential(&det, u, &settings, None)?;
                let at = (u == *bias_v).then_some((*r_mm, *z_mm));
                plot::field_map(&det, &p, at, path)?;
                eprintln!(
                    "note: the potential at {u} V is drawn in {} (red cross: where the undepleted region joins the contacts)",
                    path.display()
                );
            }
            return Err(e.into());
        }
        Err(e) => return Err(e.into()),
    };
    let missed: Vec<&hpge_solver::CvPoint> = curve
        .points
        .iter()
        .filter(|p| !p.tolerance_reached)
        .collect();
    // A value whose estimate misses the tolerance is still a value (issue 64): every point
    // comes back with `tolerance_reached: false` and its estimate; a note below names each, and
    // one more says what would help when none reached it. Exit 2 is kept for inputs that cannot
    // be solved at all.
    if settings.grid.adaptive && !missed.is_empty() && missed.len() == curve.points.len() {
        eprintln!(
            "warning: grid.tolerance {:e}: no bias reached it (estimated relative errors {:.1e} to {:.1e}); every value is flagged tolerance_reached = false. The grid cannot be refined further with min_tick_distance_mm = {} mm in {} passes and {} nodes: raise --tolerance (or --grid max_nodes=N) for values within it",
            settings.grid.tolerance,
            missed
                .iter()
                .map(|p| p.c12_err_pf / p.c12_pf)
                .fold(f64::INFINITY, f64::min),
            missed
                .iter()
                .map(|p| p.c12_err_pf / p.c12_pf)
                .fold(0.0, f64::max),
            settings.grid.min_tick_distance_mm,
            settings.grid.max_adaptive_passes,
            settings.grid.max_nodes
        );
    }
    for p in &missed {
        eprintln!(
            "note: at {} V the estimated error of c12 is {:.2}% (tolerance {:.2}%){}",
            p.voltage_v,
            100.0 * p.c12_err_pf / p.c12_pf,
            100.0 * settings.grid.tolerance,
            if p.pockets.is_empty() {
                ""
            } else if !p.pockets.iter().any(|k| k.resolved()) {
                ": an unresolved line of trapped carriers (one grid line wide, e.g. at a contact's corner; not counted as a pinch-off)"
            } else {
                ": a pocket's neck at pinch-off, where c12 changes faster than any grid resolves"
            }
        );
    }
    if curve.points.iter().all(|p| !p.fully_depleted) && curve.points.len() > 1 {
        eprintln!("note: the detector is not fully depleted at any listed voltage");
    }
    let pinch_off_v = curve_pinch_off_voltage(&det, &curve, &settings)?;
    let depletion_err_v = curve_depletion_voltage(&det, &curve, &settings)?.map(|e| e.err_v);
    let seconds = start.elapsed().as_secs_f64();
    // The CSV under its name only once every figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = o.out {
        staged
            .write_with(path, |f| write_csv(f, &curve, depletion_err_v, pinch_off_v))
            .with_context(|| format!("--out {}: cannot write the file", path.display()))?;
    }
    if let Some(path) = o.plot {
        plot::cv_curve(&curve, &det, path)?;
    }
    if let (Some(u), Some(path)) = (o.field, o.field_plot) {
        let p = solve_potential(&det, u, &settings, None)?;
        plot::field_map(&det, &p, None, path)?;
    }
    if let Some(path) = o.depletion_plot {
        let states =
            depletion_biases(&curve.points.iter().map(|p| p.voltage_v).collect::<Vec<_>>())
                .into_iter()
                .map(|u| solve_potential(&det, u, &settings, None))
                .collect::<std::result::Result<Vec<_>, _>>()?;
        plot::depletion_map(&det, &states, path)?;
    }
    super::args::commit(staged)?;
    let last = curve.points.last().map_or((0, 0), |p| p.grid);
    if o.json {
        let v = super::args::with_detector_provenance(
            json!({
                "voltage_V": curve.points.iter().map(|p| p.voltage_v).collect::<Vec<_>>(),
                "c12_pF": curve.points.iter().map(|p| p.c12_pf).collect::<Vec<_>>(),
                "c12_err_pF": curve.points.iter().map(|p| p.c12_err_pf).collect::<Vec<_>>(),
                "tolerance_reached": curve.points.iter().map(|p| p.tolerance_reached).collect::<Vec<_>>(),
                "tolerance": settings.grid.tolerance,
                "adaptive": settings.grid.adaptive,
                "fully_depleted": curve.points.iter().map(|p| p.fully_depleted).collect::<Vec<_>>(),
                "depletion_voltage_V": curve.depletion_voltage_v,
                "depletion_voltage_err_V": finite_or_null(depletion_err_v),
                "pinch_off_voltage_V": pinch_off_v.map(|e| e.voltage_v),
                "pinch_off_voltage_err_V": finite_or_null(pinch_off_v.map(|e| e.err_v)),
                "pockets": curve.points.iter().map(|p| p.pockets.iter().map(|k| json!({
                    "carrier": k.carrier,
                    "level_V": k.level_v,
                    "volume_cm3": k.volume_cm3,
                    "nodes": k.nodes,
                    "centroid_mm": [k.centroid_mm.0, k.centroid_mm.1],
                    "r_range_mm": [k.r_range_mm.0, k.r_range_mm.1],
                    "z_range_mm": [k.z_range_mm.0, k.z_range_mm.1],
                })).collect::<Vec<_>>()).collect::<Vec<_>>(),
                "grid": {"nr": last.0, "nz": last.1},
                "grid_per_point": curve.points.iter().map(|p| json!({"nr": p.grid.0, "nz": p.grid.1})).collect::<Vec<_>>(),
                "method": settings.method.as_str(),
                "weighting": settings.weighting.as_str(),
                "backend": settings.backend.as_str(),
                "device": device,
                "seconds": seconds,
            }),
            &det,
        );
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
        if let Some(e) = pinch_off_v {
            outln!(
                "pinch-off voltage {:.1} +- {} V (a pocket of trapped carriers forms)",
                e.voltage_v,
                plus_minus(e.err_v)
            );
        }
        match curve.depletion_voltage_v {
            Some(v) => outln!(
                "full-depletion voltage {v:.1} +- {} V",
                plus_minus(depletion_err_v.unwrap_or(f64::INFINITY))
            ),
            None => outln!("not fully depleted at any listed bias"),
        }
        outln!(
            "{} points in {seconds:.2} s ({} on {}{})",
            curve.points.len(),
            settings.method.as_str(),
            settings.backend.as_str(),
            device["adapter"]
                .as_str()
                .map_or(String::new(), |a| format!(": {a}, {}", device["precision"]))
        );
    }
    Ok(())
}

/// Checks the settings and, on the wgpu backend, finds the adapter (the clear error when there is
/// none comes here, before any work); returns what ran where, for the JSON output:
/// `{"adapter": name, "api": .., "device_type": .., "driver": .., "precision": "f64"|"f32"}` or
/// null on the cpu backend.
pub(super) fn backend_json(settings: &FieldSettings) -> Result<serde_json::Value> {
    settings
        .validate()
        .map_err(|m| anyhow::anyhow!("--method/--backend: {m}"))?;
    if settings.backend == Backend::Cpu {
        return Ok(serde_json::Value::Null);
    }
    let a = gpu_adapter()?;
    let double = match settings.gpu_precision {
        Precision::Auto => a.shader_f64,
        Precision::F32 => false,
        Precision::F64 if a.shader_f64 => true,
        Precision::F64 => bail!(
            "--gpu-precision f64: adapter `{}` has no shader-f64; use f32 or auto",
            a.name
        ),
    };
    Ok(json!({
        "adapter": a.name,
        "api": a.api,
        "device_type": a.device_type,
        "driver": a.driver,
        "precision": if double { "f64" } else { "f32" },
    }))
}

/// The curve as CSV: one row per bias; the curve's full-depletion and pinch-off voltages with
/// their error bars repeat on every row (empty where there is none; an error bar that could not
/// be estimated is `inf`).
fn write_csv(
    f: &mut impl Write,
    curve: &CvCurve,
    depletion_err_v: Option<f64>,
    pinch_off: Option<VoltageEstimate>,
) -> std::io::Result<()> {
    writeln!(
        f,
        "voltage_V,c12_pF,fully_depleted,c12_err_pF,tolerance_reached,depletion_voltage_V,depletion_voltage_err_V,pinch_off_voltage_V,pinch_off_voltage_err_V"
    )?;
    let cell = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
    let tail = [
        cell(curve.depletion_voltage_v),
        cell(depletion_err_v),
        cell(pinch_off.map(|e| e.voltage_v)),
        cell(pinch_off.map(|e| e.err_v)),
    ]
    .join(",");
    for p in &curve.points {
        writeln!(
            f,
            "{},{},{},{},{},{tail}",
            p.voltage_v, p.c12_pf, p.fully_depleted, p.c12_err_pf, p.tolerance_reached
        )?;
    }
    Ok(())
}

/// An error bar for JSON: null where it could not be estimated (infinite).
fn finite_or_null(err_v: Option<f64>) -> Option<f64> {
    err_v.filter(|e| e.is_finite())
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
    if !(voltage.is_finite() && voltage > 0.0) {
        bail!("--voltage {voltage}: the bias must be a positive number of volts");
    }
    let det = load_detector(input)?;
    det.check_bias_contact()?;
    let settings = &grid.apply(settings, &det)?;
    let device = backend_json(settings)?;
    let p = solve_point(&det, voltage, settings, None)?;
    let c = &p.capacitance;
    if as_json {
        let v = json!({
            "voltage_V": voltage,
            "contacts": det.contacts.iter().map(|c| json!({"id": c.id, "name": c.name})).collect::<Vec<_>>(),
            "maxwell_pF": c.energy_pf,
            "maxwell_from_charges_pF": c.charge_pf,
            "c12_pF": p.c12_pf,
            "c12_err_pF": p.accuracy.c12_err_pf,
            "adaptive_passes": p.accuracy.passes,
            "tolerance_reached": p.accuracy.reached,
            "fully_depleted": p.fully_depleted(),
            "grid": {"nr": p.mesh.grid.nr(), "nz": p.mesh.grid.nz()},
            "method": settings.method.as_str(),
            "weighting": settings.weighting.as_str(),
            "backend": settings.backend.as_str(),
            "device": device,
            "detector": det.file.display().to_string(),
            "version": env!("CARGO_PKG_VERSION"),
        });
        outln!("{v}");
    } else {
        outln!("Maxwell capacitance matrix C* (pF, Q = C* U) at U_B = {voltage} V:");
        out!("{:>28}", "");
        for k in &det.contacts {
            out!(
                " {:>14}",
                format!("{} ({})", k.id, k.name)
                    .chars()
                    .take(14)
                    .collect::<String>()
            );
        }
        outln!();
        for (i, k) in det.contacts.iter().enumerate() {
            out!(
                "{:>28}",
                format!("{} ({})", k.id, k.name)
                    .chars()
                    .take(28)
                    .collect::<String>()
            );
            for j in 0..det.contacts.len() {
                out!(" {:>14.5}", c.energy_pf[i][j]);
            }
            outln!();
        }
        outln!(
            "c12 = -C*_12 = {:.5} pF (estimated error {:.2e} pF, {} adaptive passes); fully depleted: {}",
            p.c12_pf,
            p.accuracy.c12_err_pf,
            p.accuracy.passes,
            p.fully_depleted()
        );
    }
    Ok(())
}

/// At most 13 of `voltages` (sorted, duplicates removed), evenly chosen, the first and the last
/// included: the biases of `--depletion-plot`.
fn depletion_biases(voltages: &[f64]) -> Vec<f64> {
    const MAX: usize = 13;
    let mut v = voltages.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    if v.len() <= MAX {
        return v;
    }
    let n = v.len() - 1;
    let mut out: Vec<f64> = (0..MAX)
        .map(|k| v[(k * n + (MAX - 1) / 2) / (MAX - 1)])
        .collect();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::depletion_biases;

    #[test]
    fn depletion_biases_keep_the_ends_and_at_most_13() {
        let v: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
        let b = depletion_biases(&v);
        assert_eq!(b.len(), 13);
        assert_eq!((b[0], b[12]), (25.0, 2975.0));
        assert!(b.windows(2).all(|w| w[1] > w[0]));
        assert_eq!(depletion_biases(&[300.0, 100.0, 100.0]), vec![100.0, 300.0]);
    }
}
