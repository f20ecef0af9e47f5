//! `hpge-cv depletion`: U_fd and the pinch-off voltage with their error bars; with a measured
//! depletion voltage, the posterior of an impurity scale factor and the C-V curve at its
//! median; with `--records DIR`, every LEGEND diode record of a folder into one table
//! (`hpge_inference::depletion`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_foundation::Shard;
use hpge_inference::depletion::records::{csv_table, markdown_table};
use hpge_inference::depletion::{
    DEFAULT_GATE_V, DepletionOptions, DepletionReport, Measured, RecordsOptions, ScalePrior,
    TiltPrior, depletion, run_records,
};
use hpge_reports::plot;
use hpge_reports::plot::{Corner, Curve, LineFigure, line_figure};
use hpge_solver::detector::legend::{self, LegendOptions};
use hpge_solver::options::SolverOptions;
use hpge_solver::{Detector, FieldSettings, Parameters};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

/// The measured voltage's default standard uncertainty, V: data-sheet depletion voltages are
/// quoted in steps of 100-500 V (LEGEND's records: 3000, 4000 V), so their rounding alone is
/// 30-150 V.
pub const DEFAULT_SIGMA_V: f64 = 100.0;

#[derive(Debug, clap::Args)]
pub struct DepletionArgs {
    /// Detector description (TOML).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["record", "records"])]
    detector: Option<PathBuf>,
    /// A LEGEND diode record (legend-metadata's diodes/NAME.json or NAME.yaml), converted as
    /// `detector --from-legend` converts it.
    #[arg(long, value_name = "FILE", conflicts_with = "records")]
    record: Option<PathBuf>,
    /// Every diode record (*.json, *.yaml, *.yml) of a folder into one table; each record's
    /// characterization gives the measured voltage.
    #[arg(long, value_name = "DIR")]
    records: Option<PathBuf>,
    /// The measured depletion voltage, U±S or U+-S in V (S defaults to --measured-sigma), e.g.
    /// 3500±100: gives the posterior of the impurity scale factor.
    #[arg(long, value_name = "U±S", allow_hyphen_values = true)]
    measured: Option<String>,
    /// Standard uncertainty of a measured voltage given without one (and of the records'), V.
    #[arg(long, value_name = "V", default_value_t = DEFAULT_SIGMA_V, allow_hyphen_values = true)]
    measured_sigma: f64,
    /// The factor's log-uniform prior range LO:HI.
    #[arg(long, value_name = "LO:HI", default_value = "0.1:10")]
    factor_range: String,
    /// Fit the tilt of the density's variation along z too, uniform on LO:HI (1: the
    /// profile's gradient as given, 0: flat, 2: twice as steep), e.g. 0.5:1.5. The factor's
    /// interval then carries the gradient's uncertainty. Costs 4 more U_fd searches.
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true)]
    tilt_range: Option<String>,
    /// Flag |simulated - measured| above this many volts (LEGEND's gate).
    #[arg(long, value_name = "V", default_value_t = DEFAULT_GATE_V, allow_hyphen_values = true)]
    gate: f64,
    /// Skip the pinch-off search (U_fd alone: faster).
    #[arg(long)]
    no_pinch_off: bool,
    /// With --records: this process's shard K of M (record k of the sorted list where k mod M = K).
    #[arg(long, value_name = "K/M", value_parser = Shard::parse, default_value = "0/1")]
    shard: Shard,
    /// With --records: a folder for the per-record rows (resumable) and the tables (table.md,
    /// table.csv, and table.json: the CSV's provenance). Otherwise: the C-V curve at the posterior median as CSV.
    #[arg(long, value_name = "PATH")]
    out: Option<PathBuf>,
    /// Draw the factor's posterior (.svg or .png).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Draw the C-V curve at the posterior median (.svg or .png).
    #[arg(long = "curve-plot", value_name = "FILE")]
    curve_plot: Option<PathBuf>,
    /// With a record: the n+ (Li) layer thickness in mm where its characterization gives none.
    #[arg(long, value_name = "MM", default_value_t = LegendOptions::default().n_plus_thickness_mm)]
    n_plus_thickness: f64,
    /// With a record: the gap in mm between the crystal and the grounded can.
    #[arg(long, value_name = "MM", default_value_t = LegendOptions::default().can_gap_mm)]
    can_gap: f64,
    #[command(flatten)]
    solver: SolverOptions,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs `hpge-cv depletion`.
pub fn run(a: &DepletionArgs) -> Result<()> {
    let prior = ScalePrior::parse(&a.factor_range)?;
    let tilt = a.tilt_range.as_deref().map(TiltPrior::parse).transpose()?;
    if !(a.measured_sigma.is_finite() && a.measured_sigma >= 0.0) {
        bail!(
            "--measured-sigma {}: must be zero or a positive number of V",
            a.measured_sigma
        );
    }
    if !(a.gate.is_finite() && a.gate >= 0.0) {
        bail!("--gate {}: must be zero or a positive number of V", a.gate);
    }
    let legend = LegendOptions {
        n_plus_thickness_mm: a.n_plus_thickness,
        can_gap_mm: a.can_gap,
        ..Default::default()
    };
    for p in [&a.plot, &a.curve_plot].into_iter().flatten() {
        plot::check_output(p, "--plot")?;
    }
    let base = a.solver.field_settings(FieldSettings::default().weighting);
    if let Some(dir) = &a.records {
        if a.measured.is_some() {
            bail!(
                "--measured goes with one detector; with --records each record's characterization gives it (--measured-sigma its uncertainty)"
            );
        }
        if a.plot.is_some() || a.curve_plot.is_some() {
            bail!("--plot and --curve-plot go with one detector, not --records");
        }
        return records(a, dir, prior, tilt, legend, &base);
    }
    if a.shard != Shard::WHOLE {
        bail!("--shard goes with --records");
    }
    let (det, measured_default) = match (&a.detector, &a.record) {
        (Some(d), None) => (Detector::from_file(d, &Parameters::new())?, None),
        (None, Some(r)) => {
            let diode = legend::read_file(r, &legend)?;
            let text = legend::to_toml(&diode, r, &legend);
            let det = Detector::from_toml_str(&text, &r.with_extension("toml"), &Parameters::new())
                .with_context(|| format!("the description converted from {}", r.display()))?;
            (det, diode.depletion_voltage_v.filter(|&u| u > 0.0))
        }
        _ => bail!("give --detector FILE, --record FILE or --records DIR"),
    };
    det.check_bias_contact()?;
    let settings = a.solver.grid.apply(&base, &det)?;
    let measured = match (&a.measured, measured_default) {
        (Some(t), _) => Some(Measured::parse(t, a.measured_sigma)?),
        (None, Some(u)) => {
            eprintln!(
                "the record's characterization: depletion voltage {u} V (±{} V, --measured-sigma)",
                a.measured_sigma
            );
            Some(Measured {
                voltage_v: u,
                sigma_v: a.measured_sigma,
            })
        }
        (None, None) => None,
    };
    if measured.is_none() && tilt.is_some() {
        bail!("--tilt-range needs a measured voltage (--measured U±S, or a record that gives one)");
    }
    if measured.is_none() && (a.plot.is_some() || a.curve_plot.is_some() || a.out.is_some()) {
        bail!("--plot, --curve-plot and --out need a measured voltage (--measured U±S)");
    }
    let opts = DepletionOptions {
        measured,
        prior,
        tilt,
        pinch_off: !a.no_pinch_off,
        // The curve (25 solves) only where it is shown.
        curve: a.out.is_some() || a.curve_plot.is_some() || a.json,
        gate_v: a.gate,
    };
    let bar = spinner();
    let start = std::time::Instant::now();
    let report = depletion(&det, &settings, &opts, |m| bar.set_message(m.to_string()));
    bar.finish_and_clear();
    let report = report?;
    if let Some(p) = &a.out
        && let Some(c) = &report.curve
    {
        let mut s = String::from("voltage_V,c12_pF,c12_err_pF,fully_depleted\n");
        for k in 0..c.voltage_v.len() {
            s.push_str(&format!(
                "{},{},{},{}\n",
                c.voltage_v[k], c.c12_pf[k], c.c12_err_pf[k], c.fully_depleted[k]
            ));
        }
        hpge_files::write(p, s).with_context(|| format!("--out {}: cannot write", p.display()))?;
        eprintln!("wrote {}", p.display());
    }
    draw(&det, &report, a.plot.as_deref(), a.curve_plot.as_deref())?;
    if a.json {
        let mut v = report.to_json();
        v["seconds"] = json!(start.elapsed().as_secs_f64());
        outln!("{}", super::args::with_detector_provenance(v, &det));
        return Ok(());
    }
    print_report(&det, &report, !a.no_pinch_off)?;
    eprintln!("done in {:.1} s", start.elapsed().as_secs_f64());
    Ok(())
}

fn spinner() -> ProgressBar {
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

fn print_report(det: &Detector, r: &DepletionReport, pinch_searched: bool) -> Result<()> {
    outln!("{}", det.name);
    match r.voltages.full_depletion {
        Some(u) => outln!(
            "full-depletion voltage {:.1} ± {:.1} V",
            u.voltage_v,
            u.err_v
        ),
        None => outln!(
            "not fully depleted up to {} V",
            hpge_solver::field::CEILING_V
        ),
    }
    if r.voltages.full_depletion_converged == Some(false) {
        eprintln!(
            "warning: {}",
            hpge_inference::depletion::not_converged(r.voltages.full_depletion_halved_v)
        );
    }
    match r.voltages.pinch_off {
        Some(u) => outln!(
            "pinch-off voltage {:.1} ± {:.1} V (a pocket of trapped carriers forms)",
            u.voltage_v,
            u.err_v
        ),
        None if pinch_searched => {
            outln!("no pinch-off (no trapped-carrier pocket below full depletion)");
        }
        None => {}
    }
    if let Some(p) = &r.posterior {
        outln!(
            "measured {:.0} ± {:.0} V; |simulated - measured| {} the {:.0} V gate",
            p.measured.voltage_v,
            p.measured.sigma_v,
            if r.exceeds_gate == Some(true) {
                "EXCEEDS"
            } else {
                "is within"
            },
            r.gate_v
        );
        outln!(
            "impurity scale factor {:.4} (68.3%: [{:.4}, {:.4}], 95.4%: [{:.4}, {:.4}]; prior log-uniform [{}, {}])",
            p.median,
            p.interval_68.0,
            p.interval_68.1,
            p.interval_95.0,
            p.interval_95.1,
            p.prior.lo,
            p.prior.hi
        );
        if p.at_prior_bound {
            outln!("AT A PRIOR BOUND: widen --factor-range");
        }
    }
    if let Some(t) = &r.tilt {
        let m = &t.marginal;
        outln!(
            "tilt of the gradient {:.3} (68.3%: [{:.3}, {:.3}], 95.4%: [{:.3}, {:.3}]; prior uniform [{}, {}]); correlation with ln f {:.2}",
            m.median,
            m.interval_68.0,
            m.interval_68.1,
            m.interval_95.0,
            m.interval_95.1,
            t.prior.lo,
            t.prior.hi,
            t.correlation_log_factor
        );
        for n in &t.nodes {
            outln!(
                "  U_fd at tilt {:.4}: {:.1} ± {:.1} V",
                n.tilt,
                n.u_fd_v,
                n.err_v
            );
        }
    }
    Ok(())
}

fn draw(
    det: &Detector,
    r: &DepletionReport,
    plot_path: Option<&Path>,
    curve_path: Option<&Path>,
) -> Result<()> {
    if let (Some(path), Some(p)) = (plot_path, &r.posterior) {
        let (lo, hi) = (
            p.interval_95.0 - 2.0 * (p.interval_95.1 - p.interval_95.0),
            p.interval_95.1 + 2.0 * (p.interval_95.1 - p.interval_95.0),
        );
        let shown: Vec<&(f64, f64)> = p
            .table
            .iter()
            .filter(|(f, _)| *f >= lo && *f <= hi)
            .collect();
        let inside = |a: f64, b: f64| {
            shown
                .iter()
                .map(|&&(f, d)| (f, (f >= a && f <= b).then_some(d)))
                .collect()
        };
        let fig = LineFigure {
            title: format!(
                "{}: impurity scale factor given U_dep = {:.0} ± {:.0} V",
                det.name, p.measured.voltage_v, p.measured.sigma_v
            ),
            x_desc: "factor f (density × f)".into(),
            y_desc: "posterior density".into(),
            curves: vec![
                Curve {
                    label: format!("posterior, median {:.4}", p.median),
                    points: shown.iter().map(|&&(f, d)| (f, Some(d))).collect(),
                },
                Curve {
                    label: format!("68.3%: [{:.4}, {:.4}]", p.interval_68.0, p.interval_68.1),
                    points: inside(p.interval_68.0, p.interval_68.1),
                },
            ],
            y_from_zero: true,
            legend: Corner::UpperLeft,
            footnotes: vec![match &r.tilt {
                None => format!(
                    "hpge-cv {} depletion; U_fd(f) = f U_fd(1), U_fd(1) = {}; prior log-uniform [{}, {}]",
                    env!("CARGO_PKG_VERSION"),
                    r.voltages.full_depletion.map_or_else(
                        || "-".into(),
                        |u| format!("{:.1} ± {:.1} V", u.voltage_v, u.err_v)
                    ),
                    p.prior.lo,
                    p.prior.hi
                ),
                Some(t) => format!(
                    "hpge-cv {} depletion; marginal over the tilt (uniform [{}, {}], median {:.3}); U_fd(f, t) = f U_fd(1, t); prior log-uniform [{}, {}]",
                    env!("CARGO_PKG_VERSION"),
                    t.prior.lo,
                    t.prior.hi,
                    t.marginal.median,
                    p.prior.lo,
                    p.prior.hi
                ),
            }],
        };
        line_figure(&fig, path)?;
        eprintln!("wrote {}", path.display());
    }
    if let (Some(path), Some(c)) = (curve_path, &r.curve) {
        let fig = LineFigure {
            title: format!(
                "{}: C-V curve at the posterior median (density × {:.4})",
                det.name, c.factor
            ),
            x_desc: "bias U_B (V)".into(),
            y_desc: "c12 (pF)".into(),
            curves: vec![Curve {
                label: "c12".into(),
                points: c
                    .voltage_v
                    .iter()
                    .zip(&c.c12_pf)
                    .map(|(&u, &q)| (u, Some(q)))
                    .collect(),
            }],
            y_from_zero: true,
            legend: Corner::UpperLeft,
            footnotes: vec![format!(
                "hpge-cv {} depletion, {}",
                env!("CARGO_PKG_VERSION"),
                det.file.display()
            )],
        };
        line_figure(&fig, path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn records(
    a: &DepletionArgs,
    dir: &Path,
    prior: ScalePrior,
    tilt: Option<TiltPrior>,
    legend: LegendOptions,
    base: &FieldSettings,
) -> Result<()> {
    if !dir.is_dir() {
        bail!("--records {}: not a folder", dir.display());
    }
    let o = RecordsOptions {
        dir: dir.to_path_buf(),
        out: a.out.clone(),
        shard: a.shard,
        sigma_v: a.measured_sigma,
        prior,
        tilt,
        gate_v: a.gate,
        pinch_off: !a.no_pinch_off,
        legend,
        grid: a.solver.grid.clone(),
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} records, {elapsed} elapsed {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let rows = run_records(&o, base, |done, total, name| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(name.to_string());
    });
    bar.finish_and_clear();
    let rows = rows?;
    if rows
        .iter()
        .all(|r| r.depletion_voltage_v.is_none() && r.note.is_some())
    {
        for r in &rows {
            eprintln!("{}: {}", r.record, r.note.as_deref().unwrap_or(""));
        }
        bail!("--records {}: no record could be solved", dir.display());
    }
    let md = markdown_table(&rows, a.gate);
    if let Some(out) = &a.out {
        let header = format!(
            "# Depletion voltages of the records in {} (hpge-cv {}, solver \"{}\")\n\nMeasured: each record's characterization, ± {} V. Factor: posterior median of the impurity scale factor, central 68.3% interval, prior log-uniform [{}, {}].\n\n",
            dir.display(),
            env!("CARGO_PKG_VERSION"),
            hpge_solver::field::PHYSICS_REVISION,
            a.measured_sigma,
            prior.lo,
            prior.hi
        );
        // table.csv's provenance (its JSON sidecar, as every CSV without a summary of its own).
        let csv_path = out.join("table.csv");
        let sidecar = hpge_foundation::sidecar::record(
            &csv_path,
            &hpge_solver::made(),
            serde_json::json!({
                "records": dir.display().to_string(),
                "rows": rows.len(),
                "gate_V": a.gate,
                "measured_sigma_V": a.measured_sigma,
                "prior": {"lo": prior.lo, "hi": prior.hi},
            }),
        );
        let sidecar = serde_json::to_string_pretty(&sidecar)? + "\n";
        for (name, text) in [
            ("table.md", format!("{header}{md}")),
            ("table.csv", csv_table(&rows)),
            ("table.json", sidecar),
        ] {
            let p = out.join(name);
            hpge_files::write(&p, text)
                .with_context(|| format!("--out: cannot write {}", p.display()))?;
            eprintln!("wrote {}", p.display());
        }
    }
    if a.json {
        outln!(
            "{}",
            json!({ "records": rows, "gate_V": a.gate, "version": env!("CARGO_PKG_VERSION") })
        );
    } else {
        outln!("{md}");
    }
    Ok(())
}
