//! `hpge-cv pulse`: the charge signals of one interaction (paper section 9): the field at one
//! bias, an electron and a hole drifted with the ADL model, Shockley-Ramo signals on every
//! contact.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::drift::AdlModel;
use hpge_solver::drift::AdlParameters;
use hpge_solver::drift::DriftSettings;
use hpge_solver::drift::ElectricField;
use hpge_solver::drift::check_interaction_point;
use hpge_solver::drift::normalise_signals;
use hpge_solver::drift::reference_contact;
use hpge_solver::drift::rise_time_10_90_ns;
use hpge_solver::{Detector, Pulse};
use serde_json::json;

use super::DetectorInput;
use super::args::{load_detector, parse_cylindrical};
use super::simulate::backend_json;
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
    if !(a.voltage.is_finite() && a.voltage > 0.0) {
        bail!(
            "--voltage {}: the bias must be a positive number of volts",
            a.voltage
        );
    }
    let adl = match &a.drift_parameters {
        Some(p) => read_adl_parameters(p, "--drift-parameters")?,
        None => AdlParameters::default(),
    };
    let model =
        AdlModel::new(adl.clone()).map_err(|m| anyhow::anyhow!("--drift-parameters: {m}"))?;
    let det = load_detector(&a.input)?;
    det.check_bias_contact()?;
    let (r_mm, phi_deg, z_mm) = a.at;
    let flag = format!("--at {r_mm},{phi_deg},{z_mm}");
    // Cheap geometric checks before the field solve.
    if let hpge_solver::detector::Region::Contact(i) = det.classify(r_mm, z_mm) {
        let e = hpge_solver::Error::InteractionInContact {
            r_mm,
            z_mm,
            contact: det.contacts[i].name.clone(),
        };
        return Err(anyhow::Error::new(e).context(flag));
    }
    let settings = a.solver.grid.apply(
        &a.solver
            .field_settings(WeightingOptions::default().weighting),
        &det,
    )?;
    backend_json(&settings)?;
    let point = hpge_solver::solve_point(&det, a.voltage, &settings, None)?;
    let field = ElectricField::new(&det, &point);
    check_interaction_point(&det, &point, &field, (r_mm, z_mm)).context(flag)?;
    let drift = DriftSettings::default();
    let mut p = hpge_solver::pulse(
        &det,
        &point,
        &model,
        (r_mm, phi_deg.to_radians(), z_mm),
        &drift,
    )?;
    let k_ref = reference_contact(&det);
    let divisor = if a.normalise {
        Some(normalise_signals(&mut p, k_ref).context("--normalise")?)
    } else {
        None
    };
    let provenance = Provenance {
        det: &det,
        voltage_v: a.voltage,
        at: a.at,
        drift_file: a.drift_parameters.as_deref(),
        normalised: a.normalise,
    };
    // The CSV and its sidecar under their names only once the figure is drawn too.
    let mut staged = hpge_files::Staged::new();
    if let Some(path) = &a.out {
        write_csv(&mut staged, path, &p, &provenance)?;
    }
    if let Some(path) = &a.plot {
        plot::line_figure(&pulse_figure(&p, &provenance), path)?;
    }
    super::args::commit(staged)?;
    let rise = rise_time_10_90_ns(&p.t_ns, &p.signals[k_ref].charge);
    if a.json {
        let v = super::args::with_detector_provenance(
            json!({
                "t_ns": p.t_ns,
                "contacts": p.signals.iter().map(|s| json!({"name": s.name, "signal": s.charge})).collect::<Vec<_>>(),
                "collection_time_ns": p.collection_time_ns,
                "electron": p.electron.outcome(&det),
                "hole": p.hole.outcome(&det),
                "normalised": a.normalise,
                "normalised_by": divisor,
                "reference_contact": det.contacts[k_ref].name,
                "rise_time_10_90_ns": rise,
                "at": {"r_mm": r_mm, "phi_deg": phi_deg, "z_mm": z_mm},
                "voltage_V": a.voltage,
                "fully_depleted": point.fully_depleted(),
                "drift_model": {"name": "ADL", "file": a.drift_parameters.as_ref().map(|f| f.display().to_string()), "parameters": adl},
                "drift_settings": drift,
            }),
            &det,
        );
        outln!("{v}");
    } else {
        print_summary(&det, &p, &provenance, rise, divisor)?;
    }
    Ok(())
}

/// ADL parameters from a TOML file (missing keys keep the published defaults), checked.
fn read_adl_parameters(path: &Path, flag: &str) -> Result<AdlParameters> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{flag} {}: cannot read the file", path.display()))?;
    let p: AdlParameters = toml::from_str(&text)
        .with_context(|| format!("{flag} {}: not a valid ADL parameter file", path.display()))?;
    p.validate()
        .map_err(|m| anyhow::anyhow!("{flag} {}: {m}", path.display()))?;
    Ok(p)
}

/// The inputs every output records.
struct Provenance<'a> {
    det: &'a Detector,
    voltage_v: f64,
    at: (f64, f64, f64),
    drift_file: Option<&'a Path>,
    normalised: bool,
}

impl Provenance<'_> {
    fn line(&self) -> String {
        let (r, phi, z) = self.at;
        let params: Vec<String> = self
            .det
            .parameters
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        format!(
            "hpge-cv {} pulse: detector {} impurity {} parameters [{}] U_B {} V at r {r} mm phi {phi} deg z {z} mm; ADL {}{}",
            env!("CARGO_PKG_VERSION"),
            self.det.file.display(),
            self.det.semiconductor.impurity_file().display(),
            params.join(" "),
            self.voltage_v,
            self.drift_file
                .map_or("published defaults".to_string(), |f| f
                    .display()
                    .to_string()),
            if self.normalised { "; normalised" } else { "" }
        )
    }
}

fn print_summary(
    det: &Detector,
    p: &Pulse,
    prov: &Provenance<'_>,
    rise: Option<f64>,
    divisor: Option<f64>,
) -> Result<()> {
    let (r, phi, z) = prov.at;
    outln!(
        "pulse at r = {r} mm, phi = {phi} deg, z = {z} mm; U_B = {} V ({})",
        prov.voltage_v,
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
    let unit = if divisor.is_some() {
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
    if let Some(t) = rise {
        outln!(
            "10-90% rise time of {}: {t:.1} ns",
            det.contacts[reference_contact(det)].name
        );
    }
    Ok(())
}

fn write_csv(
    staged: &mut hpge_files::Staged,
    path: &Path,
    p: &Pulse,
    prov: &Provenance<'_>,
) -> Result<()> {
    let ctx = || format!("--out {}: cannot write the file", path.display());
    let head: Vec<String> = prov
        .det
        .contacts
        .iter()
        .map(|c| format!("q{}", c.id))
        .collect();
    staged
        .write_with(path, |f| -> std::io::Result<()> {
            writeln!(f, "t_ns,{}", head.join(","))?;
            for (i, t) in p.t_ns.iter().enumerate() {
                let row: Vec<String> = p.signals.iter().map(|s| s.charge[i].to_string()).collect();
                writeln!(f, "{t},{}", row.join(","))?;
            }
            Ok(())
        })
        .with_context(ctx)?;
    let (r, phi, z) = prov.at;
    super::sidecar::stage(
        staged,
        path,
        super::args::with_detector_provenance(
            json!({
                "provenance": prov.line(),
                "voltage_V": prov.voltage_v,
                "at": {"r_mm": r, "phi_deg": phi, "z_mm": z},
                "drift_parameters": prov.drift_file.map(|f| f.display().to_string()),
                "normalised": prov.normalised,
                "columns": prov.det.contacts.iter().map(|c| (format!("q{}", c.id), serde_json::Value::from(c.name.clone()))).collect::<serde_json::Map<_, _>>(),
                "unit": if prov.normalised { "normalised" } else { "units of the pair charge" },
            }),
            prov.det,
        ),
    )?;
    Ok(())
}

fn pulse_figure(p: &Pulse, prov: &Provenance<'_>) -> plot::LineFigure {
    let (r, phi, z) = prov.at;
    plot::LineFigure {
        title: format!(
            "{}: signals of an interaction at r = {r} mm, phi = {phi} deg, z = {z} mm, U_B = {} V",
            prov.det.name, prov.voltage_v
        ),
        x_desc: "time (ns)".into(),
        y_desc: if prov.normalised {
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
        footnotes: vec![prov.line()],
    }
}
