//! The files `fit` writes: the tables (through the library's writers), figures and the report.

use std::path::Path;

use anyhow::Result;
use hpge_inference::Fit;
use hpge_inference::fit::{TruthRecord, outputs};

use super::fit::{FitOptions, Setup};

pub fn write_outputs(
    o: &FitOptions,
    out: &Path,
    s: &Setup,
    fit: &Fit,
    truth: Option<&[Option<f64>]>,
    truth_records: Option<&[TruthRecord]>,
) -> Result<()> {
    let header = outputs::output_header(&s.files, &o.sampler, o.seed, &o.likelihood);
    outputs::write_samples(&out.join("samples.csv"), &header, fit)?;
    outputs::write_predictive(&out.join("predictive.csv"), &header, fit)?;
    let zeta = s.zeta_at_mode(fit)?;
    outputs::write_zeta(&out.join("zeta-mode.csv"), &header, &zeta)?;
    let mut figures = Vec::new();
    if !o.no_plots {
        let names = s.prior.names();
        let pairs = default_pairs(&names);
        let truth_vals: Option<Vec<f64>> =
            truth.map(|t| t.iter().map(|v| v.unwrap_or(f64::NAN)).collect());
        let title = format!("{} fit", s.prior.name);
        figures = hpge_reports::plot::fit_figures(
            &out.join("figures"),
            fit,
            &zeta,
            &pairs,
            truth_vals.as_deref(),
            &title,
        )?;
    }
    super::fit_report::write_report(
        &out.join("report.md"),
        o,
        out,
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
