//! The paper's section 9 (Fig. 29, counting its figures in order): the electric-field
//! strength along r at (phi = 30 deg, z = 35 mm) and the normalised n+ pulse of an interaction
//! at (r = 37 mm, phi = 30 deg, z = 35 mm), U_B = 3000 V, for the manufacturer's impurity
//! model with d_Li = 3 mm and the global modes of the B_Z and B_RZ fits; ADL drift with its
//! published 78 K parameters.

use std::path::{Path, PathBuf};

use super::models::{ModeDetectors, NamedModel, manufacturer};
use crate::plot::{self, Corner, Curve, LineFigure};
use crate::{Error, Result};
use hpge_solver::drift::AdlModel;
use hpge_solver::drift::DriftSettings;
use hpge_solver::drift::ElectricField;
use hpge_solver::drift::PointStatus;
use hpge_solver::drift::field_line;
use hpge_solver::drift::normalise_signals;
use hpge_solver::drift::point_status;
use hpge_solver::drift::reference_contact;
use hpge_solver::drift::rise_time_10_90_ns;
use hpge_solver::{FieldSettings, solve_point};
use serde_json::{Value, json};

/// V/m per V/cm.
const V_PER_M_PER_V_PER_CM: f64 = 100.0;

/// What section 9 is computed from (paths relative to the repository root by default).
#[derive(Debug, Clone)]
pub struct Section9Inputs {
    /// The detector (its default impurity model is the manufacturer's).
    pub detector: PathBuf,
    /// The surrogate whose parameter space maps a fit's parameters to the detector.
    pub surrogate: PathBuf,
    /// (key, legend, prior, fit summary) of each fitted model.
    pub fits: Vec<(String, String, PathBuf, PathBuf)>,
    /// Bias, V (paper: 3000).
    pub voltage_v: f64,
    /// Lithium thickness of the manufacturer's model, mm (paper: 3).
    pub d_li_manufacturer_mm: f64,
    /// Azimuth of the field line and the interaction, degrees (paper: 30).
    pub phi_deg: f64,
    /// Height of the field line and the interaction, mm (paper: 35).
    pub z_mm: f64,
    /// Radius of the interaction, mm (paper: 37).
    pub event_r_mm: f64,
    /// Radii at which |E| is tabulated, mm.
    pub radii_mm: Vec<f64>,
}

impl Default for Section9Inputs {
    fn default() -> Self {
        let fit = |key: &str, label: &str| {
            (
                key.to_string(),
                label.to_string(),
                PathBuf::from(format!("priors/{key}.toml")),
                PathBuf::from(format!("reports/fits/{key}/summary.json")),
            )
        };
        Self {
            detector: "detectors/super-siegfried-k1.toml".into(),
            surrogate: hpge_inference::fit::DEFAULT_MODEL.into(),
            fits: vec![
                fit("b-z", "zeta_BZ (global mode of B_Z)"),
                fit("b-rz", "zeta_BRZ (global mode of B_RZ)"),
            ],
            voltage_v: 3000.0,
            d_li_manufacturer_mm: 3.0,
            phi_deg: 30.0,
            z_mm: 35.0,
            event_r_mm: 37.0,
            radii_mm: vec![10.0, 20.0, 30.0, 37.0],
        }
    }
}

/// The numbers of one model.
struct ModelResult {
    model: NamedModel,
    r_mm: Vec<f64>,
    e_v_per_cm: Vec<Option<f64>>,
    status: Vec<PointStatus>,
    t_ns: Vec<f64>,
    nplus: Vec<f64>,
    summary: Value,
    table_row: Vec<String>,
}

/// Computes section 9 into `out` (created if missing): `field-r.svg/png`, `pulses-nplus.svg/png`,
/// `field-r.csv`, `pulses-nplus.csv`, `section9.csv` and `section9.json`; returns the paths.
pub fn section9(out: &Path, inputs: &Section9Inputs) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out).map_err(Error::io(out, "cannot create the folder"))?;
    let mut models = vec![manufacturer(&inputs.detector, inputs.d_li_manufacturer_mm)?];
    let modes = ModeDetectors::new(&inputs.surrogate, &inputs.detector)?;
    for (key, label, prior, summary) in &inputs.fits {
        models.push(modes.at_global_mode(key, label, prior, summary)?);
    }
    let n_r = 751;
    let b = models[0].detector.semiconductor.geometry.bbox();
    let r_mm: Vec<f64> = (0..n_r)
        .map(|k| b.r_max_mm * k as f64 / (n_r - 1) as f64)
        .collect();
    let results: Vec<ModelResult> = models
        .into_iter()
        .map(|m| one_model(m, inputs, &r_mm))
        .collect::<Result<_>>()?;
    let mut files = Vec::new();
    files.extend(figures(out, inputs, &results)?);
    files.extend(tables(out, inputs, &results)?);
    Ok(files)
}

fn one_model(model: NamedModel, inputs: &Section9Inputs, r_mm: &[f64]) -> Result<ModelResult> {
    let det = &model.detector;
    let point = solve_point(det, inputs.voltage_v, &FieldSettings::default(), None)
        .map_err(|e| Error::from(e).context(format!("field solve for {}", model.key)))?;
    let field = ElectricField::new(det, &point);
    let phi = inputs.phi_deg.to_radians();
    let line = field_line(det, &field, phi, inputs.z_mm, r_mm);
    let e_v_per_cm: Vec<Option<f64>> = line
        .e_v_per_m
        .iter()
        .map(|e| e.map(|e| e / V_PER_M_PER_V_PER_CM))
        .collect();
    let status = line.status;
    // The undepleted stretch of the field line, if any.
    let undepleted: Vec<f64> = r_mm
        .iter()
        .zip(&status)
        .filter(|(_, s)| **s == PointStatus::Undepleted)
        .map(|(r, _)| *r)
        .collect();
    let at_radii: Vec<Value> = inputs
        .radii_mm
        .iter()
        .map(|&r| {
            let e = field
                .magnitude_along_r(phi, inputs.z_mm, &[r])
                .pop()
                .flatten();
            json!({"r_mm": r, "e_V_per_cm": e.map(|e| e / V_PER_M_PER_V_PER_CM),
                   "status": point_status(det, &field, r, inputs.z_mm).as_str()})
        })
        .collect();
    let mut pulse = hpge_solver::pulse(
        det,
        &point,
        &AdlModel::default(),
        (inputs.event_r_mm, phi, inputs.z_mm),
        &DriftSettings::default(),
    )
    .map_err(|e| Error::from(e).context(format!("pulse for {}", model.key)))?;
    let k = reference_contact(det);
    let end_raw = pulse.signals[k].charge.last().copied().unwrap_or(f64::NAN);
    normalise_signals(&mut pulse, k).map_err(|e| Error::from(e).context("--normalise"))?;
    let nplus = pulse.signals[k].charge.clone();
    let rise = rise_time_10_90_ns(&pulse.t_ns, &nplus);
    let d_li = det.parameters.get("d_li_mm");
    let undepleted_box = undepleted_extent(&point);
    let summary = json!({
        "key": model.key,
        "label": model.label,
        "source": model.source,
        "values": model.values.iter().map(|(n, v)| json!({"name": n, "value": v})).collect::<Vec<_>>(),
        "d_li_mm": d_li,
        "fully_depleted": point.fully_depleted(),
        "undepleted_nodes": point.undepleted_nodes,
        "undepleted_contact_layers": point.contact_layers,
        "undepleted_extent_mm": undepleted_box,
        "field_line_undepleted_r_mm": undepleted.first().map(|lo| [*lo, *undepleted.last().unwrap_or(lo)]),
        "e_at_radii": at_radii,
        "e_max_V_per_cm": e_v_per_cm.iter().flatten().fold(f64::NAN, |a: f64, &b| a.max(b)),
        "e_min_V_per_cm": e_v_per_cm.iter().flatten().fold(f64::NAN, |a: f64, &b| a.min(b)),
        "collection_time_ns": pulse.collection_time_ns,
        "electron": pulse.electron.outcome(det),
        "hole": pulse.hole.outcome(det),
        "nplus_contact": det.contacts[k].name,
        "nplus_end_charge_before_normalisation": end_raw,
        "nplus_rise_time_10_90_ns": rise,
    });
    let fmt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
    let mut table_row = vec![
        model.key.clone(),
        fmt(d_li),
        point.fully_depleted().to_string(),
    ];
    for &r in &inputs.radii_mm {
        let e = field
            .magnitude_along_r(phi, inputs.z_mm, &[r])
            .pop()
            .flatten();
        table_row.push(fmt(e.map(|e| e / V_PER_M_PER_V_PER_CM)));
    }
    table_row.push(fmt(Some(pulse.collection_time_ns)));
    table_row.push(fmt(rise));
    table_row.push(summary["electron"]["stop"].as_str().unwrap_or("").into());
    table_row.push(summary["hole"]["stop"].as_str().unwrap_or("").into());
    Ok(ModelResult {
        model,
        r_mm: r_mm.to_vec(),
        e_v_per_cm,
        status,
        t_ns: pulse.t_ns,
        nplus,
        summary,
        table_row,
    })
}

/// The r and z extent (mm) of the undepleted semiconductor nodes, `null` when there are none.
fn undepleted_extent(point: &hpge_solver::PointResult) -> Value {
    let g = &point.mesh.grid;
    let (mut r, mut z) = (
        [f64::INFINITY, f64::NEG_INFINITY],
        [f64::INFINITY, f64::NEG_INFINITY],
    );
    for (i, &ri) in g.r_mm().iter().enumerate() {
        for (j, &zj) in g.z_mm().iter().enumerate() {
            if point.potential.undepleted[g.index(i, j)] {
                r = [r[0].min(ri), r[1].max(ri)];
                z = [z[0].min(zj), z[1].max(zj)];
            }
        }
    }
    if r[0].is_finite() {
        json!({"r_mm": r, "z_mm": z})
    } else {
        Value::Null
    }
}

fn provenance(inputs: &Section9Inputs) -> String {
    format!(
        "hpge-cv {} paper section 9: detector {}, surrogate space {}, fits {}; U_B {} V; ADL published defaults",
        env!("CARGO_PKG_VERSION"),
        inputs.detector.display(),
        inputs.surrogate.display(),
        inputs
            .fits
            .iter()
            .map(|f| format!("{} ({})", f.3.display(), f.2.display()))
            .collect::<Vec<_>>()
            .join(", "),
        inputs.voltage_v
    )
}

fn figures(out: &Path, inputs: &Section9Inputs, res: &[ModelResult]) -> Result<Vec<PathBuf>> {
    let foot = provenance(inputs);
    let field = LineFigure {
        title: format!(
            "|E| at phi = {} deg, z = {} mm, U_B = {} V",
            inputs.phi_deg, inputs.z_mm, inputs.voltage_v
        ),
        x_desc: "r (mm)".into(),
        y_desc: "|E| (V/cm)".into(),
        curves: res
            .iter()
            .map(|m| Curve {
                label: m.model.label.clone(),
                points: m
                    .r_mm
                    .iter()
                    .copied()
                    .zip(m.e_v_per_cm.iter().copied())
                    .collect(),
            })
            .collect(),
        y_from_zero: true,
        legend: Corner::LowerRight,
        footnotes: vec![
            foot.clone(),
            "gaps: borehole, n+ contact or undepleted volume".into(),
        ],
    };
    let pulses = LineFigure {
        title: format!(
            "normalised n+ pulse, interaction at r = {} mm, phi = {} deg, z = {} mm, U_B = {} V",
            inputs.event_r_mm, inputs.phi_deg, inputs.z_mm, inputs.voltage_v
        ),
        x_desc: "time (ns)".into(),
        y_desc: "n+ charge (normalised)".into(),
        curves: res
            .iter()
            .map(|m| Curve {
                label: m.model.label.clone(),
                points: m
                    .t_ns
                    .iter()
                    .copied()
                    .zip(m.nplus.iter().map(|&q| Some(q)))
                    .collect(),
            })
            .collect(),
        y_from_zero: true,
        legend: Corner::LowerRight,
        footnotes: vec![foot],
    };
    let mut files = Vec::new();
    for (stem, fig) in [("field-r", &field), ("pulses-nplus", &pulses)] {
        for ext in ["svg", "png"] {
            let p = out.join(format!("{stem}.{ext}"));
            plot::line_figure(fig, &p)?;
            files.push(p);
        }
    }
    Ok(files)
}

fn write_text(path: &Path, text: &str) -> Result<PathBuf> {
    hpge_files::write(path, text).map_err(Error::io(path, "cannot write the file"))?;
    Ok(path.to_path_buf())
}

fn tables(out: &Path, inputs: &Section9Inputs, res: &[ModelResult]) -> Result<Vec<PathBuf>> {
    let keys: Vec<&str> = res.iter().map(|m| m.model.key.as_str()).collect();
    // Field lines.
    let mut t = String::from("r_mm");
    for k in &keys {
        t += &format!(",e_V_per_cm_{k},status_{k}");
    }
    t.push('\n');
    for i in 0..res[0].r_mm.len() {
        t += &res[0].r_mm[i].to_string();
        for m in res {
            let e = m.e_v_per_cm[i].map_or(String::new(), |e| e.to_string());
            t += &format!(",{e},{}", m.status[i].as_str());
        }
        t.push('\n');
    }
    let mut files = vec![write_text(&out.join("field-r.csv"), &t)?];
    // Pulses on one time axis (each ends at its collection time; later samples repeat the end).
    let n = res.iter().map(|m| m.t_ns.len()).max().unwrap_or(0);
    let dt = DriftSettings::default().sample_ns;
    let mut t = String::from("t_ns");
    for k in &keys {
        t += &format!(",q_nplus_{k}");
    }
    t.push('\n');
    for i in 0..n {
        t += &(i as f64 * dt).to_string();
        for m in res {
            let q = m
                .nplus
                .get(i)
                .or(m.nplus.last())
                .copied()
                .unwrap_or(f64::NAN);
            t += &format!(",{q}");
        }
        t.push('\n');
    }
    files.push(write_text(&out.join("pulses-nplus.csv"), &t)?);
    // The numbers.
    let mut t = String::from("model,d_li_mm,fully_depleted");
    for r in &inputs.radii_mm {
        t += &format!(",e_V_per_cm_at_r{r}mm");
    }
    t += ",collection_time_ns,nplus_rise_time_10_90_ns,electron_stop,hole_stop\n";
    for m in res {
        t += &m.table_row.join(",");
        t.push('\n');
    }
    files.push(write_text(&out.join("section9.csv"), &t)?);
    let v = json!({
        "program": env!("CARGO_PKG_NAME"),
        "version": env!("CARGO_PKG_VERSION"),
        "inputs": {
            "detector": inputs.detector.display().to_string(),
            "surrogate": inputs.surrogate.display().to_string(),
            "fits": inputs.fits.iter().map(|f| json!({"key": f.0, "prior": f.2.display().to_string(), "summary": f.3.display().to_string()})).collect::<Vec<_>>(),
            "voltage_V": inputs.voltage_v,
            "d_li_manufacturer_mm": inputs.d_li_manufacturer_mm,
            "phi_deg": inputs.phi_deg,
            "z_mm": inputs.z_mm,
            "event_r_mm": inputs.event_r_mm,
            "drift_model": "ADL, published 78 K parameters",
            "drift_settings": DriftSettings::default(),
        },
        "models": res.iter().map(|m| m.summary.clone()).collect::<Vec<_>>(),
        "provenance": provenance(inputs),
        "tables": {
            "field-r.csv": "|E| in V/cm along r, empty where there is no field",
            "pulses-nplus.csv": "normalised n+ charge; each pulse repeats its end after its collection time",
            "section9.csv": "per impurity model: d_Li, full depletion, |E| at the radii, collection and rise times, where the carriers stopped",
        },
    });
    let text = serde_json::to_string_pretty(&v)?;
    files.push(write_text(&out.join("section9.json"), &(text + "\n"))?);
    Ok(files)
}
