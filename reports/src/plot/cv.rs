//! The C-V curve c12(U_B).

use std::path::Path;

use hpge_solver::{CvCurve, Detector};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{err, log_key_points};
use crate::error::Result;

/// Draws c12 (log scale) against U_B, marking the full-depletion voltage.
pub fn cv_curve(curve: &CvCurve, det: &Detector, path: &Path) -> Result<()> {
    render!(path, (1000, 700), |root, _svg| draw(&root, curve, det))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    curve: &CvCurve,
    det: &Detector,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let pts: Vec<(f64, f64)> = curve
        .points
        .iter()
        .map(|p| (p.voltage_v, p.c12_pf))
        .collect();
    let vmax = pts.iter().map(|p| p.0).fold(0.0, f64::max) * 1.05;
    let cmin = pts
        .iter()
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min)
        .max(1e-6);
    let cmax = pts.iter().map(|p| p.1).fold(0.0, f64::max).max(cmin * 1.01);
    let title = format!(
        "{}: simulated C-V curve ({}; {} {})",
        det.name,
        det.semiconductor.impurity_file().display(),
        crate::provenance::PROGRAM,
        crate::provenance::VERSION
    );
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            0.0..vmax.max(1.0),
            (cmin / 1.2..cmax * 1.2)
                .log_scale()
                .with_key_points(log_key_points(cmin / 1.2, cmax * 1.2)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("bias U_B (V)")
        .y_desc("c12 (pF)")
        .y_label_formatter(&|v| {
            if *v >= 10.0 {
                format!("{v:.0}")
            } else {
                format!("{v:.2}")
            }
        })
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    let blue = RGBColor(31, 119, 180);
    chart
        .draw_series(LineSeries::new(pts.clone(), blue.stroke_width(2)))
        .map_err(err)?
        .label("c12 (field solver)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart
        .draw_series(curve.points.iter().map(|p| {
            let style = if p.fully_depleted {
                blue.filled()
            } else {
                blue.stroke_width(1)
            };
            Circle::new((p.voltage_v, p.c12_pf), 4, style)
        }))
        .map_err(err)?;
    if let Some(vd) = curve.depletion_voltage_v {
        let red = RGBColor(214, 39, 40);
        chart
            .draw_series(DashedLineSeries::new(
                [(vd, cmin / 1.2), (vd, cmax * 1.2)],
                8,
                5,
                red.stroke_width(2),
            ))
            .map_err(err)?
            .label(format!(
                "full-depletion voltage {vd:.1} V (filled points: fully depleted)"
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
    }
    if curve.depletion_voltage_v.is_none() {
        let slope = match curve.points.as_slice() {
            [.., a, b] => (a.c12_pf - b.c12_pf) / (b.voltage_v - a.voltage_v),
            _ => f64::NAN,
        };
        root.draw(&Text::new(
            format!("not fully depleted at any listed bias; -dc12/dU at the last point: {slope:.2e} pF/V"),
            (120, 75),
            ("sans-serif", 16).into_font(),
        ))
        .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    Ok(())
}
