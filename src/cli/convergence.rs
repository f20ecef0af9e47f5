//! `hpge-cv convergence`: c12 at one bias against the grid resolution, with the error estimate.

use std::path::PathBuf;

use anyhow::Result;
use hpge_reports::plot;
use hpge_solver::jobs;

use super::DetectorInput;
use super::args::load_detector;
use hpge_solver::options::{SolverOptions, WeightingOptions};

/// Arguments of `convergence`.
#[derive(Debug, clap::Args)]
pub struct ConvergenceArgs {
    #[command(flatten)]
    pub input: DetectorInput,
    /// Bias voltage in V.
    #[arg(long, value_name = "U", allow_hyphen_values = true)]
    pub voltage: f64,
    /// Fixed grids: the spacings times 2, 1, 1/2, ... (this many).
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub levels: usize,
    #[command(flatten)]
    pub solver: SolverOptions,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Draw c12 against the grid nodes with the estimates (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// Runs the study and prints (and draws) it.
pub fn run(a: &ConvergenceArgs) -> Result<()> {
    if let Some(p) = &a.plot {
        plot::check_output(p, "--plot")?;
    }
    let det = load_detector(&a.input)?;
    let options = jobs::ConvergenceOptions {
        voltage_v: a.voltage,
        levels: a.levels,
        settings: a.solver.grid.apply(
            &a.solver
                .field_settings(WeightingOptions::default().weighting),
            &det,
        )?,
    };
    let (rows, record) =
        jobs::convergence(&det, &options).map_err(|e| e.respell(super::args::flag))?;
    let settings = &options.settings;
    let finest = rows
        .iter()
        .filter(|r| !r.adaptive)
        .max_by_key(|r| r.nodes)
        .map_or(f64::NAN, |r| r.c12_pf);
    if let Some(p) = &a.plot {
        let title = format!(
            "{}: c12 at {} V against the grid ({} {})",
            det.name,
            a.voltage,
            env!("CARGO_PKG_NAME"),
            env!("CARGO_PKG_VERSION")
        );
        plot::convergence(&rows, &title, p)?;
    }
    if a.json {
        let v = serde_json::to_value(&record)?;
        outln!("{v}");
    } else {
        outln!(
            "{:>10} {:>12} {:>10} {:>14} {:>11} {:>14} {:>8}",
            "grid",
            "spacing (mm)",
            "nodes",
            "c12 (pF)",
            "+- (pF)",
            "vs finest",
            "s"
        );
        for r in &rows {
            outln!(
                "{:>10} {:>12.3} {:>10} {:>14.6} {:>11.2e} {:>13.3}% {:>8.2}",
                if r.adaptive {
                    "adaptive".to_string()
                } else {
                    format!("x{}", r.scale)
                },
                r.spacing_mm,
                r.nodes,
                r.c12_pf,
                r.c12_err_pf,
                100.0 * (r.c12_pf / finest - 1.0),
                r.seconds
            );
        }
        outln!(
            "adaptive: tolerance {:.2}% of c12; estimates are max |c12(h) - c12(2h)| over two coarsenings (an upper bound for order >= 1)",
            100.0 * settings.grid.tolerance
        );
    }
    Ok(())
}
