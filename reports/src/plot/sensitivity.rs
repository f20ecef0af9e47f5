//! The sensitivity scan: c12 at one bias against a constant impurity density.

use std::path::Path;

use hpge_solver::scan::ScanPoint;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{PALETTE, err, log_key_points};
use crate::error::Result;

/// A labelled reference line of the scan: a density (vertical, cm^-3) or a capacitance
/// (horizontal, pF).
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// The legend's text.
    pub label: String,
    /// The density (cm^-3) or capacitance (pF).
    pub value: f64,
}

/// The reference lines of a sensitivity scan.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScanMarks {
    /// Densities (vertical lines), e.g. the transform's zeta_l and zeta_u, the manufacturer's
    /// levels.
    pub densities: Vec<Mark>,
    /// Capacitances (horizontal lines), e.g. the measured c12 at the scan's bias.
    pub capacitances: Vec<Mark>,
}

impl ScanMarks {
    /// The transform's sensitive range (paper, section 6): zeta_l = 1e8 and zeta_u = 1e11 cm^-3.
    pub fn sensitive_range() -> Self {
        let t = hpge_solver::impurity::LogTransform::default();
        // x = log10(zeta / m^-3); 1 cm^-3 = 1e6 m^-3.
        let (l, u) = (10f64.powf(t.x_l - 6.0), 10f64.powf(t.x_u - 6.0));
        Self {
            densities: vec![
                Mark {
                    label: format!("zeta_l = {l:.0e} cm^-3 (transform's x_l)"),
                    value: l,
                },
                Mark {
                    label: format!("zeta_u = {u:.0e} cm^-3 (transform's x_u)"),
                    value: u,
                },
            ],
            capacitances: Vec::new(),
        }
    }
}

/// Draws c12 against zeta (both log scale) with the reference lines `marks`; filled markers:
/// fully depleted at the bias.
pub fn sensitivity(
    points: &[ScanPoint],
    voltage_v: f64,
    name: &str,
    marks: &ScanMarks,
    path: &Path,
) -> Result<()> {
    render!(path, (1000, 700), |root, _svg| draw(
        &root, points, voltage_v, name, marks
    ))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[ScanPoint],
    voltage_v: f64,
    name: &str,
    marks: &ScanMarks,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let zmin = points
        .iter()
        .map(|p| p.zeta_cm3)
        .fold(f64::INFINITY, f64::min);
    let zmax = points.iter().map(|p| p.zeta_cm3).fold(0.0, f64::max);
    let (zmin, zmax) = marks
        .densities
        .iter()
        .fold((zmin, zmax), |(a, b), m| (a.min(m.value), b.max(m.value)));
    let cs = points
        .iter()
        .map(|p| p.c12_pf)
        .chain(marks.capacitances.iter().map(|m| m.value));
    let cmin = cs.clone().fold(f64::INFINITY, f64::min).max(1e-6);
    let cmax = cs.fold(0.0, f64::max).max(cmin * 1.01);
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
    // Reference lines, dashed, one colour each (the scan's own is PALETTE[0]).
    let (y0, y1) = (cmin / 1.3, cmax * 1.3);
    let (x0, x1) = (zmin / 1.3, zmax * 1.3);
    let lines = marks
        .densities
        .iter()
        .map(|m| (m, [(m.value, y0), (m.value, y1)]))
        .chain(
            marks
                .capacitances
                .iter()
                .map(|m| (m, [(x0, m.value), (x1, m.value)])),
        );
    for (k, (m, pts)) in lines.enumerate() {
        let c = PALETTE[(k + 1) % PALETTE.len()];
        chart
            .draw_series(DashedLineSeries::new(pts, 8, 5, c.stroke_width(2)))
            .map_err(err)?
            .label(m.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
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
