//! Figures against a coordinate: the posterior predictive against the bias and zeta at the
//! global mode along z and r.

use hpge_inference::fit::{LEVELS, Predictive};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::layout::{Axes, Key, LEVEL_COLORS, draw_axes, key_strip, padded};
use crate::error::Result;
use crate::plot::style::PALETTE;
use crate::plot::style::err;
use hpge_inference::fit::ZetaProfile;

/// sigma_c (dashed) and the zero line.
const SIGMA: RGBColor = RGBColor(90, 90, 90);
/// c_p - c_m at the global mode.
const MODE: RGBColor = RGBColor(31, 119, 180);

/// The posterior predictive of c_p - c_m against U_B: nested central bands, the median, the
/// difference at the global mode and +-sigma_c around zero.
pub(super) fn predictive<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pred: &Predictive,
    title: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!(
                "{title}: posterior predictive of c_p - c_m ({} draws)",
                pred.draws
            ),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let mut keys: Vec<(Key, String)> = LEVELS
        .iter()
        .zip(LEVEL_COLORS)
        .map(|(l, c)| (Key::Fill(c), format!("{:.1}% central interval", 100.0 * l)))
        .collect();
    keys.push((Key::Line(BLACK), "median".into()));
    keys.push((Key::Dot(MODE), "global mode".into()));
    keys.push((Key::Dashed(SIGMA), "\u{b1} sigma_c at the mode".into()));
    let body = key_strip(&root, &keys)?;
    // Points in order of the bias.
    let mut order: Vec<usize> = (0..pred.voltage_v.len()).collect();
    order.sort_by(|&i, &k| pred.voltage_v[i].total_cmp(&pred.voltage_v[k]));
    let v = |i: usize| pred.voltage_v[i];
    let diff = |i: usize| {
        pred.c_mode_pf
            .get(i)
            .zip(pred.c_m_pf.get(i))
            .map(|(p, m)| p - m)
    };
    let band = |i: usize, l: usize| pred.bands_pf.get(i).and_then(|b| b.get(l)).copied();
    let sigma = |i: usize| pred.sigma_pf.get(i).copied();
    let ys = order.iter().flat_map(|&i| {
        let b = (0..LEVELS.len()).filter_map(move |l| band(i, l)).flatten();
        let s = sigma(i).into_iter().flat_map(|s| [s, -s]);
        b.chain(s)
            .chain(diff(i))
            .chain(pred.median_pf.get(i).copied())
    });
    let (y0, y1) = padded(ys.chain([0.0]), 0.08);
    let (x0, x1) = padded(pred.voltage_v.iter().copied(), 0.03);
    let mut chart = curve_chart(&body, (x0, x1), (y0, y1), ("U_B [V]", "c_p - c_m [pF]"))?;
    // Widest band first, so that the narrower ones lie on top.
    for l in (0..LEVELS.len()).rev() {
        let have: Vec<(f64, [f64; 2])> = order
            .iter()
            .filter_map(|&i| band(i, l).map(|b| (v(i), b)))
            .collect();
        if have.len() < 2 {
            continue;
        }
        let outline: Vec<(f64, f64)> = have
            .iter()
            .map(|(x, b)| (*x, b[1]))
            .chain(have.iter().rev().map(|(x, b)| (*x, b[0])))
            .collect();
        chart
            .draw_series(std::iter::once(Polygon::new(
                outline,
                LEVEL_COLORS[l].filled(),
            )))
            .map_err(err)?;
    }
    chart
        .draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            SIGMA.stroke_width(1),
        ))
        .map_err(err)?;
    for sign in [1.0, -1.0] {
        let pts: Vec<(f64, f64)> = order
            .iter()
            .filter_map(|&i| sigma(i).map(|s| (v(i), sign * s)))
            .collect();
        chart
            .draw_series(DashedLineSeries::new(pts, 8, 5, SIGMA.stroke_width(2)))
            .map_err(err)?;
    }
    let median: Vec<(f64, f64)> = order
        .iter()
        .filter_map(|&i| pred.median_pf.get(i).map(|m| (v(i), *m)))
        .collect();
    chart
        .draw_series(LineSeries::new(median, BLACK.stroke_width(2)))
        .map_err(err)?;
    chart
        .draw_series(
            order
                .iter()
                .filter_map(|&i| diff(i).map(|d| Circle::new((v(i), d), 4, MODE.filled()))),
        )
        .map_err(err)?;
    Ok(())
}

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
