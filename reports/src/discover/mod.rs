//! The outputs of `discover`: the summary as JSON, the per-voltage residuals before and after
//! the chosen extension, the figures and the Markdown report.

mod report;

use std::fmt::Write as _;
use std::path::Path;

use hpge_inference::Discovery;

pub use report::write_report;

use crate::{Error, Result, plot};

/// The per-voltage table: data, both models at their modes, sigma, standardised residuals; one
/// header row, no comment lines (the provenance is in `discovery.json`: `program_version`,
/// `start_model`, `chosen`).
pub fn write_residuals(path: &Path, d: &Discovery) -> Result<()> {
    let mut f = String::new();
    let _ = writeln!(
        f,
        "voltage_V,c_m_pF,before_c_pF,before_sigma_pF,before_residual,after_c_pF,after_sigma_pF,after_residual"
    );
    let after = d.after.as_ref().unwrap_or(&d.before);
    for k in 0..d.voltage_v.len() {
        let _ = writeln!(
            f,
            "{},{},{},{},{},{},{},{}",
            d.voltage_v[k],
            d.c_m_pf[k],
            d.before.c_mode[k],
            d.before.sigma_mode[k],
            d.before.check.residuals[k],
            after.c_mode[k],
            after.sigma_mode[k],
            after.check.residuals[k]
        );
    }
    std::fs::write(path, f).map_err(Error::io(path, "cannot write"))
}

/// Writes a discovery's outputs into `out`: `discovery.json`, `residuals.csv`, `report.md` and
/// (unless `no_plots`) the figures, drawn on the start model's detector.
///
/// # Errors
/// A file that cannot be written, a figure that cannot be drawn, a detector that cannot be built.
pub fn write_outputs(
    out: &Path,
    d: &Discovery,
    exact: &hpge_surrogate::ExactSolver,
    no_plots: bool,
) -> Result<()> {
    let json = out.join("discovery.json");
    std::fs::write(&json, serde_json::to_string_pretty(&d.summary)? + "\n")
        .map_err(Error::io(&json, "cannot write"))?;
    write_residuals(&out.join("residuals.csv"), d)?;
    let figures = if no_plots {
        Vec::new()
    } else {
        let det = exact.detector(&d.start_inputs)?;
        plot::discovery_figures(d, &det, out)?
    };
    write_report(&out.join("report.md"), d, &figures)?;
    Ok(())
}
