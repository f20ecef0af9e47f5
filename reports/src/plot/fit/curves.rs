//! Figures against a coordinate: zeta at the global mode along z and r (the posterior
//! predictive against the bias is `predictive.rs`).

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::layout::{Axes, Key, draw_axes, key_strip, padded};
use crate::error::Result;
use crate::plot::style::PALETTE;
use crate::plot::style::err;

/// The zero line.
const SIGMA: RGBColor = RGBColor(90, 90, 90);
use hpge_inference::fit::ZetaProfile;

/// zeta in 1e10 cm^-3 along `axis` ("z" or "r"), one colour per profile: the global mode (solid),
/// the posterior's 68.3% and 95.5% central bands over the draws (shaded, where computed) and the
/// truth (dashed, where known).
pub(super) fn zeta<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    profiles: &[ZetaProfile],
    band_draws: usize,
    axis: &str,
    title: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let bands = profiles.iter().any(|p| !p.band_955_cm3.is_empty());
    let truth = profiles.iter().any(|p| !p.truth_cm3.is_empty());
    let root = root
        .titled(
            &format!(
                "{title}: impurity density along {axis}, global mode{}{}",
                if bands {
                    format!(" with 68.3% / 95.5% bands ({band_draws} draws)")
                } else {
                    String::new()
                },
                if truth { ", truth dashed" } else { "" }
            ),
            ("sans-serif", 22),
        )
        .map_err(err)?;
    let mut keys: Vec<(Key, String)> = profiles
        .iter()
        .enumerate()
        .map(|(k, p)| (Key::Line(PALETTE[k % PALETTE.len()]), p.label.clone()))
        .collect();
    if truth {
        keys.push((Key::Dashed(RGBColor(90, 90, 90)), "truth".into()));
    }
    let knots = profiles.iter().any(|p| !p.knots_mm.is_empty());
    if knots {
        keys.push((
            Key::Dot(RGBColor(60, 60, 60)),
            "knot of the model, with its value at the mode (1e10 cm^-3)".into(),
        ));
    }
    let body = key_strip(&root, &keys)?;
    let (x0, x1) = padded(profiles.iter().flat_map(|p| p.x_mm.iter().copied()), 0.02);
    let ys = profiles.iter().flat_map(|p| {
        p.zeta_cm3
            .iter()
            .chain(&p.truth_cm3)
            .copied()
            .chain(p.band_955_cm3.iter().flatten().copied())
            .map(|z| z / 1e10)
    });
    let (y0, y1) = padded(ys.chain([0.0]), 0.06);
    let mut chart = curve_chart(
        &body,
        (x0, x1),
        (y0, y1),
        (&format!("{axis} [mm]"), "zeta [1e10 cm^-3]"),
    )?;
    chart
        .draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            SIGMA.stroke_width(1),
        ))
        .map_err(err)?;
    for (k, p) in profiles.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        for (band, alpha) in [(&p.band_955_cm3, 0.12), (&p.band_683_cm3, 0.25)] {
            if band.len() != p.x_mm.len() || band.is_empty() {
                continue;
            }
            let outline: Vec<(f64, f64)> = p
                .x_mm
                .iter()
                .zip(band)
                .map(|(x, b)| (*x, b[1] / 1e10))
                .chain(
                    p.x_mm
                        .iter()
                        .zip(band)
                        .rev()
                        .map(|(x, b)| (*x, b[0] / 1e10)),
                )
                .collect();
            chart
                .draw_series(std::iter::once(Polygon::new(
                    outline,
                    colour.mix(alpha).filled(),
                )))
                .map_err(err)?;
        }
    }
    for (k, p) in profiles.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let pts = p.x_mm.iter().zip(&p.zeta_cm3).map(|(x, z)| (*x, z / 1e10));
        chart
            .draw_series(LineSeries::new(pts, colour.stroke_width(3)))
            .map_err(err)?;
        // The knots: a dot on the mode's curve and its value.
        for &xk in &p.knots_mm {
            let Some(v) = interpolate(&p.x_mm, &p.zeta_cm3, xk) else {
                continue;
            };
            let v = v / 1e10;
            chart
                .draw_series([Circle::new((xk, v), 5, colour.filled())])
                .map_err(err)?;
            chart
                .draw_series([Text::new(
                    format!("{v:.2}"),
                    (xk, v),
                    ("sans-serif", 14).into_font().color(&colour),
                )])
                .map_err(err)?;
        }
        if p.truth_cm3.len() == p.x_mm.len() {
            let pts: Vec<(f64, f64)> = p
                .x_mm
                .iter()
                .zip(&p.truth_cm3)
                .map(|(x, z)| (*x, z / 1e10))
                .collect();
            chart
                .draw_series(DashedLineSeries::new(pts, 9, 6, colour.stroke_width(2)))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// y at `x` by linear interpolation of the points (xs increasing), None outside them.
fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> Option<f64> {
    let i = xs.partition_point(|t| *t < x);
    if i == 0 {
        return (xs.first() == Some(&x)).then(|| ys[0]);
    }
    let (x0, x1) = (xs[i - 1], *xs.get(i)?);
    let f = if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.0 };
    Some(ys[i - 1] + f * (ys[i] - ys[i - 1]))
}

/// A whole-figure chart of the fit's curves on [x0, x1] x [y0, y1], with its axes drawn.
fn curve_chart<'a, DB: DrawingBackend>(
    body: &'a DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    desc: (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>> {
    let mut chart = ChartBuilder::on(body)
        .margin(20)
        .x_label_area_size(52)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    draw_axes(
        &mut chart,
        Axes {
            desc,
            span: (x1 - x0, y1 - y0),
            labels: None,
            font: (16, 18),
        },
    )?;
    Ok(chart)
}
