//! The posterior predictive figure (issue 63 item 3: "predictive figures that show the misfit"),
//! three panels against the bias, residuals always data minus model:
//!
//! 1. c12 on a log axis: the data with their error bars, the exact solver's curve at the
//!    exact-checked mode, the surrogate's curve at the mode and its posterior-predictive 95.5%
//!    band;
//! 2. (c_m - c_p) / c_p in percent: the surrogate's posterior-predictive bands and median, the
//!    exact curve at the mode, and +-sigma_c / c_p (the likelihood's sigma at the mode);
//! 3. the pulls of the data around the exact curve at the mode, each point over its own standard
//!    deviation after the run's calibration factor kappa is taken out, with the data's chi^2
//!    (measured covariance, or the paper's 3%) in the caption: sum pulls^2 + a^2 = chi^2_data.
//!
//! Without an exact check the pulls are the surrogate's mode under the likelihood's sigma, and
//! the caption says so.

use hpge_inference::Fit;
use hpge_inference::fit::LEVELS;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::{Axes, Key, LEVEL_COLORS, draw_axes, key_strip, padded};
use crate::error::Result;
use crate::plot::style::{err, log_key_points, zero_line};

/// The data.
const DATA: RGBColor = RGBColor(0, 0, 0);
/// The exact solver at the mode.
const EXACT: RGBColor = RGBColor(214, 39, 40);
/// The surrogate at the mode.
const SURROGATE: RGBColor = RGBColor(31, 119, 180);
/// sigma_c and the reference lines.
const GUIDE: RGBColor = RGBColor(110, 110, 110);

/// What the pulls panel shows, and its caption.
struct Pulls {
    points: Vec<(f64, f64)>,
    caption: String,
}

fn pulls(fit: &Fit, order: &[usize]) -> Pulls {
    let pred = &fit.predictive;
    let s = &fit.summary;
    let data_words = match s.likelihood.kind.as_str() {
        "covariance" => "measured covariance",
        _ => "the paper's 3%",
    };
    if let Some((own, check)) = s
        .exact_check
        .as_ref()
        .and_then(|c| c.own_errors_at_mode.as_ref().map(|o| (o, c)))
        .filter(|(o, _)| o.pulls.len() == pred.voltage_v.len())
    {
        let kappa = own.calibration.map_or(String::new(), |c| {
            format!(
                " after the calibration factor kappa = {:.5} \u{b1} {} (prior sd {:.1}%)",
                c.factor,
                if c.factor_sd < 1e-4 {
                    format!("{:.1e}", c.factor_sd)
                } else {
                    format!("{:.5}", c.factor_sd)
                },
                100.0 * c.prior_sd
            )
        });
        return Pulls {
            points: order
                .iter()
                .map(|&i| (pred.voltage_v[i], own.pulls[i]))
                .collect(),
            caption: format!(
                "(data - exact) / own sigma{kappa}; chi^2 = {:.1} for {} ({data_words}), p {}",
                check.chi2_data_at_mode,
                s.ndf,
                p_text(check.p_data_at_mode)
            ),
        };
    }
    Pulls {
        points: order
            .iter()
            .filter_map(|&i| {
                let sd = *pred.sigma_pf.get(i)?;
                Some((pred.voltage_v[i], (pred.c_m_pf[i] - pred.c_mode_pf[i]) / sd))
            })
            .collect(),
        caption: format!(
            "no exact check: (data - surrogate at the mode) / sigma_c; likelihood chi^2 = {:.1} for {}",
            s.chi2, s.ndf
        ),
    }
}

fn p_text(p: f64) -> String {
    if p < 1e-15 {
        "< 1e-15".into()
    } else if p < 1e-3 {
        format!("= {p:.1e}")
    } else {
        format!("= {p:.3}")
    }
}

/// The three panels of the predictive figure.
pub(super) fn predictive<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fit: &Fit,
    title: &str,
) -> Result<()> {
    let pred = &fit.predictive;
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!(
                "{title}: data against the exact solver at the mode and the posterior predictive ({} draws)",
                pred.draws
            ),
            ("sans-serif", 22),
        )
        .map_err(err)?;
    let exact: Option<&Vec<f64>> = fit
        .summary
        .exact_check
        .as_ref()
        .map(|c| &c.c_exact_at_mode_pf)
        .filter(|c| c.len() == pred.voltage_v.len());
    let mut keys = vec![(Key::Dot(DATA), "data \u{b1} its sd".to_string())];
    if exact.is_some() {
        keys.push((Key::Line(EXACT), "exact solver at the mode".into()));
    }
    keys.push((Key::Dashed(SURROGATE), "surrogate at the mode".into()));
    keys.extend(
        LEVELS
            .iter()
            .zip(LEVEL_COLORS)
            .map(|(l, c)| (Key::Fill(c), format!("{:.1}% predictive", 100.0 * l))),
    );
    keys.push((Key::Dashed(GUIDE), "\u{b1} sigma_c at the mode".into()));
    let body = key_strip(&root, &keys)?;
    let h = body.dim_in_pixel().1;
    let (top, rest) = body.split_vertically(h * 42 / 100);
    let (middle, bottom) = rest.split_vertically(h * 30 / 100);
    let mut order: Vec<usize> = (0..pred.voltage_v.len()).collect();
    order.sort_by(|&i, &k| pred.voltage_v[i].total_cmp(&pred.voltage_v[k]));
    let v = |i: usize| pred.voltage_v[i];
    let (x0, x1) = padded(pred.voltage_v.iter().copied(), 0.03);
    let own = fit
        .summary
        .exact_check
        .as_ref()
        .and_then(|c| c.own_errors_at_mode.as_ref());
    let data_sd = |i: usize| {
        own.and_then(|o| o.sigma_total_pf.get(i).copied())
            .unwrap_or(0.0)
    };

    // 1. c12 on a log axis.
    let band = |i: usize, l: usize| pred.bands_pf.get(i).and_then(|b| b.get(l)).copied();
    let cs = order.iter().flat_map(|&i| {
        let b = band(i, 1).map(|b| [pred.c_m_pf[i] + b[0], pred.c_m_pf[i] + b[1]]);
        [pred.c_m_pf[i], pred.c_mode_pf[i]]
            .into_iter()
            .chain(b.into_iter().flatten())
            .chain(exact.map(|e| e[i]))
    });
    let (cmin, cmax) = cs
        .filter(|c| *c > 0.0 && c.is_finite())
        .fold((f64::INFINITY, 0.0_f64), |(a, b), c| (a.min(c), b.max(c)));
    let (cmin, cmax) = if cmin < cmax {
        (cmin / 1.15, cmax * 1.15)
    } else {
        (1.0, 10.0)
    };
    let mut chart = ChartBuilder::on(&top)
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(
            x0..x1,
            (cmin..cmax)
                .log_scale()
                .with_key_points(log_key_points(cmin, cmax)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("U_B [V]")
        .y_desc("c12 [pF] (log)")
        .x_label_formatter(&|u| format!("{u:.0}"))
        .y_label_formatter(&|c| {
            if *c >= 10.0 {
                format!("{c:.0}")
            } else {
                format!("{c:.2}")
            }
        })
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(WHITE)
        .draw()
        .map_err(err)?;
    let outline: Vec<(f64, f64)> = order
        .iter()
        .filter_map(|&i| band(i, 1).map(|b| (v(i), pred.c_m_pf[i] + b[1])))
        .chain(
            order
                .iter()
                .rev()
                .filter_map(|&i| band(i, 1).map(|b| (v(i), pred.c_m_pf[i] + b[0]))),
        )
        .collect();
    if outline.len() >= 4 {
        chart
            .draw_series(std::iter::once(Polygon::new(
                outline,
                LEVEL_COLORS[1].mix(0.8).filled(),
            )))
            .map_err(err)?;
    }
    chart
        .draw_series(DashedLineSeries::new(
            order.iter().map(|&i| (v(i), pred.c_mode_pf[i])),
            8,
            5,
            SURROGATE.stroke_width(2),
        ))
        .map_err(err)?;
    if let Some(e) = exact {
        chart
            .draw_series(LineSeries::new(
                order.iter().map(|&i| (v(i), e[i])),
                EXACT.stroke_width(2),
            ))
            .map_err(err)?;
    }
    chart
        .draw_series(order.iter().map(|&i| {
            let (c, s) = (pred.c_m_pf[i], data_sd(i));
            ErrorBar::new_vertical(v(i), (c - s).max(cmin), c, c + s, DATA.filled(), 6)
        }))
        .map_err(err)?;
    chart
        .draw_series(
            order
                .iter()
                .map(|&i| Circle::new((v(i), pred.c_m_pf[i]), 3, DATA.filled())),
        )
        .map_err(err)?;

    // 2. (c_m - c_p) / c_p in percent.
    let rel = |i: usize, d: f64| -100.0 * d / (pred.c_m_pf[i] + d);
    let sigma_rel = |i: usize| pred.sigma_pf.get(i).map(|s| 100.0 * s / pred.c_mode_pf[i]);
    let exact_rel = |i: usize| exact.map(|e| 100.0 * (pred.c_m_pf[i] - e[i]) / e[i]);
    let ys = order.iter().flat_map(|&i| {
        let b = (0..LEVELS.len())
            .filter_map(move |l| band(i, l))
            .flat_map(move |b| [rel(i, b[0]), rel(i, b[1])]);
        b.chain(sigma_rel(i).into_iter().flat_map(|s| [s, -s]))
            .chain(exact_rel(i))
    });
    let (y0, y1) = padded(ys.chain([0.0]), 0.08);
    let mut chart = ChartBuilder::on(&middle)
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    draw_axes(
        &mut chart,
        Axes {
            desc: ("U_B [V]", "(data - model) / model [%]"),
            span: (x1 - x0, y1 - y0),
            labels: None,
            font: (15, 17),
        },
    )?;
    for l in (0..LEVELS.len()).rev() {
        let have: Vec<(f64, [f64; 2])> = order
            .iter()
            .filter_map(|&i| band(i, l).map(|b| (v(i), [rel(i, b[1]), rel(i, b[0])])))
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
    zero_line(&mut chart, (x0, x1), GUIDE)?;
    for sign in [1.0, -1.0] {
        let pts: Vec<(f64, f64)> = order
            .iter()
            .filter_map(|&i| sigma_rel(i).map(|s| (v(i), sign * s)))
            .collect();
        chart
            .draw_series(DashedLineSeries::new(pts, 8, 5, GUIDE.stroke_width(2)))
            .map_err(err)?;
    }
    chart
        .draw_series(DashedLineSeries::new(
            order.iter().map(|&i| {
                (
                    v(i),
                    100.0 * (pred.c_m_pf[i] - pred.c_mode_pf[i]) / pred.c_mode_pf[i],
                )
            }),
            8,
            5,
            SURROGATE.stroke_width(2),
        ))
        .map_err(err)?;
    if exact.is_some() {
        chart
            .draw_series(LineSeries::new(
                order
                    .iter()
                    .filter_map(|&i| exact_rel(i).map(|r| (v(i), r))),
                EXACT.stroke_width(2),
            ))
            .map_err(err)?;
    }

    // 3. Pulls.
    let p = pulls(fit, &order);
    let reach = p
        .points
        .iter()
        .map(|(_, y)| y.abs())
        .filter(|y| y.is_finite())
        .fold(3.5_f64, f64::max)
        * 1.1;
    let mut chart = ChartBuilder::on(&bottom)
        .margin(16)
        .caption(p.caption, ("sans-serif", 16))
        .x_label_area_size(46)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, -reach..reach)
        .map_err(err)?;
    draw_axes(
        &mut chart,
        Axes {
            desc: ("U_B [V]", "pull"),
            span: (x1 - x0, 2.0 * reach),
            labels: None,
            font: (15, 17),
        },
    )?;
    for y in [-3.0, -1.0, 1.0, 3.0] {
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, y), (x1, y)],
                6,
                5,
                GUIDE.stroke_width(1),
            ))
            .map_err(err)?;
    }
    zero_line(&mut chart, (x0, x1), GUIDE)?;
    chart
        .draw_series(
            p.points
                .iter()
                .filter(|(_, y)| y.is_finite())
                .map(|&q| Circle::new(q, 4, EXACT.filled())),
        )
        .map_err(err)?;
    Ok(())
}
