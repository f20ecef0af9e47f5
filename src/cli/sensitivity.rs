//! `hpge-cv sensitivity`: c12 at one bias for constant impurity densities (the paper's
//! "impurity level sensitivity" scan, section 5; the scan itself is
//! `hpge_solver::scan::sensitivity_scan`).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use hpge_reports::plot;
use hpge_solver::FieldSettings;
use hpge_solver::scan::{log_spaced, sensitivity_scan};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

use super::DetectorInput;
use super::args::load_detector;

/// Parses `MIN:MAX:N`: N densities (cm^-3) spaced evenly in log between MIN and MAX (> 0).
pub fn parse_range(s: &str) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = s.split(':').map(str::trim).collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(format!("`{s}`: expected MIN:MAX:N, e.g. 1e7:2e11:17"));
    };
    let num = |t: &str| t.parse::<f64>().map_err(|e| format!("`{t}` in `{s}`: {e}"));
    let (lo, hi) = (num(a)?, num(b)?);
    let n: usize = n
        .parse()
        .map_err(|e| format!("`{n}` in `{s}`: the count must be a whole number ({e})"))?;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(format!("`{s}`: need 0 < MIN < MAX (densities in cm^-3)"));
    }
    if !(2..=1000).contains(&n) {
        return Err(format!("`{s}`: the count N must lie in 2..=1000, got {n}"));
    }
    log_spaced(lo, hi, n).map_err(|e| format!("`{s}`: {e}"))
}

/// Options of `sensitivity`.
pub struct SensitivityOptions<'a> {
    pub input: &'a DetectorInput,
    pub voltage_v: f64,
    pub zetas_cm3: &'a [f64],
    pub json: bool,
    pub out: Option<&'a PathBuf>,
    pub plot: Option<&'a PathBuf>,
    /// Backend, method and precision (weighting: conductor).
    pub settings: FieldSettings,
    /// Grid and accuracy options.
    pub grid: &'a super::args::GridArgs,
}

/// Runs the scan and writes what was asked for.
pub fn run(o: &SensitivityOptions<'_>) -> Result<()> {
    if !(o.voltage_v.is_finite() && o.voltage_v > 0.0) {
        bail!(
            "--voltage {}: the bias must be a positive number of volts",
            o.voltage_v
        );
    }
    if let Some(p) = o.plot {
        plot::check_output(p, "--plot")?;
    }
    let det = load_detector(o.input)?;
    let settings = o.grid.apply(&o.settings, &det)?;
    let device = super::simulate::backend_json(&settings)?;
    let bar = ProgressBar::new(o.zetas_cm3.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} densities, {elapsed} elapsed, eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = std::time::Instant::now();
    let points = sensitivity_scan(&det, o.voltage_v, o.zetas_cm3, &settings, &|k| {
        bar.set_position(k as u64)
    })?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    if let Some(path) = o.out {
        let mut f = std::fs::File::create(path)
            .with_context(|| format!("--out {}: cannot create the file", path.display()))?;
        writeln!(f, "zeta_cm3,c12_pF,fully_depleted")?;
        for p in &points {
            writeln!(f, "{:e},{},{}", p.zeta_cm3, p.c12_pf, p.fully_depleted)?;
        }
    }
    if let Some(path) = o.plot {
        plot::sensitivity(&points, o.voltage_v, &det.name, path)?;
    }
    if o.json {
        let v = json!({
            "zeta_cm3": points.iter().map(|p| p.zeta_cm3).collect::<Vec<_>>(),
            "c12_pF": points.iter().map(|p| p.c12_pf).collect::<Vec<_>>(),
            "fully_depleted": points.iter().map(|p| p.fully_depleted).collect::<Vec<_>>(),
            "voltage_V": o.voltage_v,
            "method": settings.method.as_str(),
            "backend": settings.backend.as_str(),
            "device": device,
            "seconds": seconds,
            "detector": det.file.display().to_string(),
            "parameters": det.parameters.iter().collect::<std::collections::BTreeMap<_, _>>(),
            "version": env!("CARGO_PKG_VERSION"),
        });
        println!("{v}");
    } else {
        println!(
            "{:>14} {:>12} {:>8}",
            "zeta (cm^-3)", "c12 (pF)", "depleted"
        );
        for p in &points {
            println!(
                "{:>14.4e} {:>12.5} {:>8}",
                p.zeta_cm3, p.c12_pf, p.fully_depleted
            );
        }
        println!(
            "{} densities at {} V in {seconds:.2} s",
            points.len(),
            o.voltage_v
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        let r = parse_range("1e7:1e11:5").unwrap();
        assert_eq!(r.len(), 5);
        for (a, b) in r.iter().zip([1e7, 1e8, 1e9, 1e10, 1e11]) {
            assert!((a / b - 1.0).abs() < 1e-12);
        }
        assert!(parse_range("1e7:1e11").is_err());
        assert!(
            parse_range("0:1e11:5")
                .unwrap_err()
                .contains("0 < MIN < MAX")
        );
        assert!(parse_range("1e7:1e11:1").unwrap_err().contains("2..=1000"));
        assert!(parse_range("1e7:x:5").is_err());
    }
}
