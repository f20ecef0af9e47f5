//! The sensitivity scan: c12 at one bias against a constant impurity density.

use std::path::Path;

use hpge_solver::scan::ScanPoint;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{err, log_key_points};
use crate::error::Result;

/// Draws c12 against zeta (both log scale); filled markers: fully depleted at the bias.
pub fn sensitivity(points: &[ScanPoint], voltage_v: f64, name: &str, path: &Path) -> Result<()> {
    render!(path, (1000, 700), |root, _svg| draw(
        &root, points, voltage_v, name
    ))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[ScanPoint],
    voltage_v: f64,
    name: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let zmin = points
        .iter()
        .map(|p| p.zeta_cm3)
        .fold(f64::INFINITY, f64::min);
    let zmax = points.iter().map(|p| p.zeta_cm3).fold(0.0, f64::max);
    let cmin = points
        .iter()
        .map(|p| p.c12_pf)
        .fold(f64::INFINITY, f64::min)
        .max(1e-6);
    let cmax = points
        .iter()
        .map(|p| p.c12_pf)
        .fold(0.0, f64::max)
        .max(cmin * 1.01);
    let title = format!(
        "{name}: c12 at {voltage_v} V for constant impurity densities ({} {})",
        crate::provenance::PROGRAM,
        crate::provenance::VERSION
    );
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (zmin / 1.3..zmax * 1.3).log_scale(),
            (cmin / 1.3..cmax * 1.3)
                .log_scale()
                .with_key_points(log_key_points(cmin / 1.3, cmax * 1.3)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("constant net impurity density zeta (cm^-3, n-type)")
        .y_desc(format!("c12 at {voltage_v} V (pF)"))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    let blue = RGBColor(31, 119, 180);
    let pts: Vec<(f64, f64)> = points.iter().map(|p| (p.zeta_cm3, p.c12_pf)).collect();
    chart
        .draw_series(LineSeries::new(pts, blue.stroke_width(2)))
        .map_err(err)?
        .label("c12 (field solver); filled: fully depleted")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart
        .draw_series(points.iter().map(|p| {
            let style = if p.fully_depleted {
                blue.filled()
            } else {
                blue.stroke_width(1)
            };
            Circle::new((p.zeta_cm3, p.c12_pf), 4, style)
        }))
        .map_err(err)?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    Ok(())
}
