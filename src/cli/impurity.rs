//! `hpge-cv impurity`: the impurity density at points.

use anyhow::Result;
use serde::Serialize;

use super::DetectorInput;
use super::args::load_detector;

#[derive(Serialize)]
struct PointOut {
    r_mm: f64,
    z_mm: f64,
    y: Option<f64>,
    x: Option<f64>,
    zeta_cm3: f64,
    inside_semiconductor: bool,
}

#[derive(Serialize)]
struct Output<'a> {
    points: Vec<PointOut>,
    model: &'a str,
    detector: String,
    impurity_file: String,
    parameters: std::collections::BTreeMap<&'a str, f64>,
    program: &'static str,
    version: &'static str,
}

/// Prints y, x and zeta (cm^-3) at each point.
pub fn run(input: &DetectorInput, at: &[(f64, f64)], json: bool) -> Result<()> {
    let det = load_detector(input)?;
    let model = det.impurity();
    let points: Vec<PointOut> = at
        .iter()
        .map(|&(r, z)| {
            let p = model.evaluate(r, z);
            PointOut {
                r_mm: r,
                z_mm: z,
                y: p.y,
                x: p.x,
                zeta_cm3: p.zeta_cm3,
                inside_semiconductor: det.semiconductor.geometry.contains(r, z, 1e-9),
            }
        })
        .collect();
    for p in points.iter().filter(|p| !p.inside_semiconductor) {
        eprintln!(
            "warning: ({}, {}) mm lies outside the semiconductor of {}; the value is the model's extrapolation",
            p.r_mm,
            p.z_mm,
            det.file.display()
        );
    }
    if json {
        let out = Output {
            model: model.name(),
            detector: det.file.display().to_string(),
            impurity_file: det.semiconductor.impurity_file().display().to_string(),
            parameters: det.parameters.iter().collect(),
            program: env!("CARGO_PKG_NAME"),
            version: env!("CARGO_PKG_VERSION"),
            points,
        };
        outln!("{}", serde_json::to_string(&out)?);
    } else {
        outln!(
            "impurity model \"{}\" from {}",
            model.name(),
            det.semiconductor.impurity_file().display()
        );
        outln!(
            "{:>10} {:>10} {:>14} {:>14} {:>14}",
            "r_mm",
            "z_mm",
            "y",
            "x",
            "zeta_cm3"
        );
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.8}"));
        for p in &points {
            outln!(
                "{:>10} {:>10} {:>14} {:>14} {:>14.6e}{}",
                p.r_mm,
                p.z_mm,
                opt(p.y),
                opt(p.x),
                p.zeta_cm3,
                if p.inside_semiconductor {
                    ""
                } else {
                    "  (outside the crystal)"
                }
            );
        }
    }
    Ok(())
}
