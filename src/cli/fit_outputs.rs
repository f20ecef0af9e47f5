//! The files `fit` writes: samples, the posterior predictive, zeta at the mode, figures and the
//! report; and the truth a stand-in data set may come with.

use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use hpge_inference::{Fit, Prior};
use hpge_reports::plot::{ZetaAtMode, ZetaProfile};
use hpge_surrogate::ExactSolver;
use serde::Serialize;

use super::fit::{FitOptions, Setup};

/// Truth values by parameter name (a TOML table NAME = VALUE).
pub fn read_truth(path: &Path, prior: &Prior) -> Result<Vec<Option<f64>>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--truth {}: cannot read the file", path.display()))?;
    let table: BTreeMap<String, f64> = toml::from_str(&text)
        .with_context(|| format!("--truth {}: expected NAME = number lines", path.display()))?;
    Ok(prior
        .names()
        .iter()
        .map(|n| table.get(n).copied())
        .collect())
}

/// The fitted zeta at the global mode along z at five radii and along r at three heights,
/// inside the semiconductor only (a borehole or groove is left out).
fn zeta_at_mode(exact: &ExactSolver, prior: &Prior, mode: &[f64]) -> Result<ZetaAtMode> {
    let mut x = vec![0.0; prior.input_names.len()];
    prior.expand(mode, &mut x);
    let det = exact.detector(&x)?;
    let b = det.semiconductor.geometry.bbox();
    // Strictly inside (a negative tolerance), so the axis of a borehole does not count.
    let inside = |r: f64, z: f64| det.semiconductor.geometry.contains(r, z, -1e-6);
    let model = det.impurity();
    let n = 141;
    let lin = |a: f64, c: f64| -> Vec<f64> {
        (0..n)
            .map(|i| a + (c - a) * i as f64 / (n - 1) as f64)
            .collect()
    };
    // The radii the semiconductor spans at mid-height.
    let z_mid = 0.5 * (b.z_min_mm + b.z_max_mm);
    let rs_mid: Vec<f64> = lin(b.r_min_mm, b.r_max_mm)
        .into_iter()
        .filter(|&r| inside(r, z_mid))
        .collect();
    let (r_lo, r_hi) = (
        rs_mid.first().copied().unwrap_or(b.r_min_mm),
        rs_mid.last().copied().unwrap_or(b.r_max_mm),
    );
    let profile = |label: String, pts: Vec<(f64, f64, f64)>| ZetaProfile {
        label,
        x_mm: pts.iter().map(|p| p.0).collect(),
        zeta_cm3: pts.iter().map(|p| model.density_cm3(p.1, p.2)).collect(),
    };
    let along_z = [0.02, 0.25, 0.5, 0.75, 0.98]
        .iter()
        .map(|f| {
            let r = r_lo + f * (r_hi - r_lo);
            let pts = lin(b.z_min_mm, b.z_max_mm)
                .into_iter()
                .filter(|&z| inside(r, z))
                .map(|z| (z, r, z))
                .collect();
            profile(format!("r = {r:.1} mm"), pts)
        })
        .filter(|p| !p.x_mm.is_empty())
        .collect();
    let along_r = [0.02, 0.5, 0.98]
        .iter()
        .map(|f| {
            let z = b.z_min_mm + f * (b.z_max_mm - b.z_min_mm);
            let pts = lin(b.r_min_mm, b.r_max_mm)
                .into_iter()
                .filter(|&r| inside(r, z))
                .map(|r| (r, r, z))
                .collect();
            profile(format!("z = {z:.1} mm"), pts)
        })
        .filter(|p| !p.x_mm.is_empty())
        .collect();
    Ok(ZetaAtMode { along_z, along_r })
}

#[derive(Serialize)]
pub struct TruthRecord {
    pub name: String,
    pub value: f64,
    pub inside_683: bool,
    pub inside_955: bool,
}

pub fn write_outputs(
    o: &FitOptions,
    s: &Setup,
    fit: &Fit,
    truth: Option<&[Option<f64>]>,
    truth_records: Option<&[TruthRecord]>,
) -> Result<()> {
    let header = format!(
        "# hpge-cv {} fit: data {} model {} prior {} detector {} sampler {} seed {} likelihood {}",
        env!("CARGO_PKG_VERSION"),
        o.data.display(),
        o.model.display(),
        o.prior.display(),
        o.detector.display(),
        o.sampler,
        o.seed,
        o.likelihood
    );
    // Samples.
    let path = o.out.join("samples.csv");
    let mut w = std::io::BufWriter::new(
        std::fs::File::create(&path)
            .with_context(|| format!("cannot create {}", path.display()))?,
    );
    writeln!(w, "{header}")?;
    writeln!(w, "chain,draw,{},ln_posterior", fit.samples.names.join(","))?;
    for (c, ch) in fit.samples.chains.iter().enumerate() {
        for (i, (t, l)) in ch.theta.iter().zip(&ch.ln_posterior).enumerate() {
            let vals: Vec<String> = t.iter().map(|v| format!("{v}")).collect();
            writeln!(w, "{c},{i},{},{l}", vals.join(","))?;
        }
    }
    w.flush()?;
    // Posterior predictive.
    let p = &fit.predictive;
    let path = o.out.join("predictive.csv");
    let mut w = std::io::BufWriter::new(
        std::fs::File::create(&path)
            .with_context(|| format!("cannot create {}", path.display()))?,
    );
    writeln!(w, "{header}")?;
    writeln!(
        w,
        "voltage_V,c_m_pF,c_mode_pF,sigma_pF,pull_at_mode,diff_median_pF,diff_lo683_pF,diff_hi683_pF,diff_lo955_pF,diff_hi955_pF,diff_lo997_pF,diff_hi997_pF"
    )?;
    for k in 0..p.voltage_v.len() {
        let b: Vec<String> = p.bands_pf[k]
            .iter()
            .flat_map(|[a, c]| [format!("{a}"), format!("{c}")])
            .collect();
        writeln!(
            w,
            "{},{},{},{},{},{},{}",
            p.voltage_v[k],
            p.c_m_pf[k],
            p.c_mode_pf[k],
            p.sigma_pf[k],
            (p.c_mode_pf[k] - p.c_m_pf[k]) / p.sigma_pf[k],
            p.median_pf[k],
            b.join(",")
        )?;
    }
    w.flush()?;
    // zeta at the mode.
    let zeta = zeta_at_mode(&s.exact, &s.prior, &fit.mode)?;
    let path = o.out.join("zeta-mode.csv");
    let mut w = std::io::BufWriter::new(
        std::fs::File::create(&path)
            .with_context(|| format!("cannot create {}", path.display()))?,
    );
    writeln!(w, "{header}")?;
    writeln!(w, "profile,label,coordinate_mm,zeta_cm3")?;
    for (kind, list) in [("along_z", &zeta.along_z), ("along_r", &zeta.along_r)] {
        for prof in list {
            for (x, v) in prof.x_mm.iter().zip(&prof.zeta_cm3) {
                writeln!(w, "{kind},{},{x},{v}", prof.label)?;
            }
        }
    }
    w.flush()?;
    let mut figures = Vec::new();
    if !o.no_plots {
        let names = s.prior.names();
        let pairs = default_pairs(&names);
        let truth_vals: Option<Vec<f64>> =
            truth.map(|t| t.iter().map(|v| v.unwrap_or(f64::NAN)).collect());
        let title = format!("{} fit", s.prior.name);
        figures = hpge_reports::plot::fit_figures(
            &o.out.join("figures"),
            fit,
            &zeta,
            &pairs,
            truth_vals.as_deref(),
            &title,
        )?;
    }
    super::fit_report::write_report(
        &o.out.join("report.md"),
        o,
        s,
        fit,
        &figures,
        truth_records.map(|t| {
            t.iter()
                .map(|r| (r.name.clone(), r.value, r.inside_683, r.inside_955))
                .collect::<Vec<_>>()
        }),
    )?;
    Ok(())
}

/// The 2D marginals to draw: the paper's (bottom vs top level) where the names show it.
fn default_pairs(names: &[String]) -> Vec<(usize, usize)> {
    let find = |n: &str| names.iter().position(|x| x == n);
    let mut pairs = Vec::new();
    for (a, b) in [
        ("y_bot", "y_top"),
        ("y1_bot", "y1_top"),
        ("y4_bot", "y4_top"),
        ("d_li_mm", "y1_bot"),
    ] {
        if let (Some(i), Some(j)) = (find(a), find(b)) {
            pairs.push((i, j));
        }
    }
    if pairs.is_empty() && names.len() >= 2 {
        pairs.push((0, 1));
    }
    pairs
}
