//! Grid convergence of c12 at one bias: c12 against the number of grid nodes (log), each fixed
//! grid with its estimated error as a bar, the adaptive answer as a band.

use std::path::Path;

use hpge_solver::field::ConvergenceRow;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{PALETTE, err};
use crate::error::Result;

/// Draws the rows of a convergence study (`hpge_solver::field::convergence_study`).
pub fn convergence(rows: &[ConvergenceRow], title: &str, path: &Path) -> Result<()> {
    render!(path, (1000, 700), |root, _svg| draw(&root, rows, title))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[ConvergenceRow],
    title: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let fixed: Vec<&ConvergenceRow> = rows.iter().filter(|r| !r.adaptive).collect();
    let adaptive = rows.iter().find(|r| r.adaptive);
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    let lo = rows
        .iter()
        .map(|r| r.c12_pf - finite(r.c12_err_pf))
        .fold(f64::INFINITY, f64::min);
    let hi = rows
        .iter()
        .map(|r| r.c12_pf + finite(r.c12_err_pf))
        .fold(f64::NEG_INFINITY, f64::max);
    let pad = (hi - lo).max(1e-6 * hi.abs()) * 0.1;
    let nmin = rows.iter().map(|r| r.nodes).min().unwrap_or(1) as f64;
    let nmax = rows.iter().map(|r| r.nodes).max().unwrap_or(2) as f64;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d((nmin / 1.5..nmax * 1.5).log_scale(), lo - pad..hi + pad)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("grid nodes")
        .y_desc("c12 (pF)")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.4}"))
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    let blue = PALETTE[0];
    let red = PALETTE[1];
    if let Some(a) = adaptive {
        let band = [
            (nmin / 1.5, a.c12_pf - a.c12_err_pf),
            (nmax * 1.5, a.c12_pf + a.c12_err_pf),
        ];
        chart
            .draw_series(std::iter::once(Rectangle::new(
                band,
                red.mix(0.15).filled(),
            )))
            .map_err(err)?;
        chart
            .draw_series(std::iter::once(Circle::new(
                (a.nodes as f64, a.c12_pf),
                6,
                red.filled(),
            )))
            .map_err(err)?
            .label(format!(
                "adaptive at the tolerance: {:.5} +- {:.2e} pF ({} nodes; band: its estimate)",
                a.c12_pf, a.c12_err_pf, a.nodes
            ))
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, red.filled()));
    }
    let pts: Vec<(f64, f64)> = fixed.iter().map(|r| (r.nodes as f64, r.c12_pf)).collect();
    chart
        .draw_series(LineSeries::new(pts.clone(), blue.stroke_width(2)))
        .map_err(err)?
        .label("fixed grids, spacings x 2, 1, 1/2, ... (bars: estimated error)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart
        .draw_series(fixed.iter().map(|r| {
            let e = finite(r.c12_err_pf);
            ErrorBar::new_vertical(
                r.nodes as f64,
                r.c12_pf - e,
                r.c12_pf,
                r.c12_pf + e,
                blue.stroke_width(2),
                10,
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 4, blue.filled())))
        .map_err(err)?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(err)?;
    Ok(())
}
