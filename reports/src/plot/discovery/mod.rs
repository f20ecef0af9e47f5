//! The figure of a model discovery (`hpge-cv discover`): the start model's standardised
//! posterior-predictive residuals against the bias, before and after adding the chosen
//! extension, with the windows of disagreement shaded; beside them the detector's r-z
//! cross-section with the region each window probes.

use std::path::{Path, PathBuf};

use hpge_inference::Discovery;
use hpge_solver::Detector;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::{Error, Result};
use crate::plot::style::err;

mod key;
mod layout;
mod region;
mod residuals;
#[cfg(test)]
mod tests;

use layout::{LEFT_W, SIZE};
use region::region_panel;
use residuals::residual_panel;

/// Writes `residuals.svg` and `residuals.png` into `out` (created if missing); returns their
/// paths.
///
/// Left: the standardised posterior-predictive residuals of the start model (and of the
/// extended one, when an extension was chosen) against U_B, the zero and +-2 lines, each window
/// of disagreement shaded and labelled W1, W2, ... Right: the r-z cross-section of `det` with the
/// region each window probes in its colour.
pub fn discovery_figures(d: &Discovery, det: &Detector, out: &Path) -> Result<Vec<PathBuf>> {
    let n = d.voltage_v.len();
    if n == 0 {
        invalid!("the discovery has no voltages to plot");
    }
    let fits = std::iter::once(&d.before).chain(&d.after);
    for f in fits {
        if f.check.residuals.len() != n {
            invalid!(
                "{}: {} residuals for {n} voltages",
                f.model,
                f.check.residuals.len()
            );
        }
    }
    std::fs::create_dir_all(out).map_err(Error::io(out, "cannot create the folder"))?;
    let mut paths = Vec::new();
    for ext in ["svg", "png"] {
        let p = out.join(format!("residuals.{ext}"));
        let done: Result<()> = render!(&p, SIZE, |root, _svg| draw(&root, d, det));
        done?;
        paths.push(p);
    }
    Ok(paths)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &Discovery,
    det: &Detector,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let s = &d.summary;
    let title = format!(
        "start model {}: residuals before and after adding {}",
        s.before.model,
        s.chosen.as_deref().unwrap_or("nothing")
    );
    let body = root.titled(&title, ("sans-serif", 24)).map_err(err)?;
    let (left, right) = body.split_horizontally(LEFT_W);
    residual_panel(root, &left, d)?;
    region_panel(root, &right, d, det)
}
