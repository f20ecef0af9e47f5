//! Figures of the surrogate (paper, Figs. "DNN_learning_curves", "DNN_training_result_2d_scatter"
//! and "DNN_training_result_1d"): learning curves, c_p over c_s, and the histograms of absolute and
//! relative errors with the Gaussian fit. Each as SVG and PNG.

use std::path::Path;

use hpge_surrogate::model::EpochRecord;
use hpge_surrogate::{Figures, ModelInfo};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{PALETTE, err, legend, log_key_points};
use crate::error::Result;

/// `learning-curves.svg/png` in `dir`.
pub fn learning_curves(curves: &[EpochRecord], info: &ModelInfo, dir: &Path) -> Result<()> {
    for ext in ["svg", "png"] {
        let p = dir.join(format!("learning-curves.{ext}"));
        let one = |f: Result<()>| f;
        one(render!(&p, (1100, 650), |root, _svg| draw_curves(
            &root, curves, info
        )))?;
    }
    Ok(())
}

fn draw_curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    curves: &[EpochRecord],
    info: &ModelInfo,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let epochs = curves.iter().map(|r| r.epoch).max().unwrap_or(1) as f64;
    let vals = curves
        .iter()
        .flat_map(|r| [r.train_loss, r.test_loss])
        .filter(|v| *v > 0.0);
    let (lo, hi) = vals.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "learning curves: recipe {} ({} training samples)",
                info.recipe_name, info.training.n
            ),
            ("sans-serif", 22),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(
            0.0..epochs + 1.0,
            ((lo * 0.8)..(hi * 1.25))
                .log_scale()
                .with_key_points(log_key_points(lo * 0.8, hi * 1.25)),
        )
        .map_err(err)?;
    let loss = info
        .recipe
        .as_ref()
        .map_or("loss".to_string(), |r| r.loss.describe());
    chart
        .configure_mesh()
        .x_desc("epoch")
        .y_desc(format!("mean loss per sample: {loss}"))
        .y_label_formatter(&|v| format!("{v}"))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(err)?;
    // Cycle boundaries (dashed).
    let mut last_cycle = 1;
    for r in curves.iter().filter(|r| r.member == 0) {
        if r.cycle != last_cycle {
            let x = r.epoch as f64 - 0.5;
            let n = 40;
            let (a, b) = ((lo * 0.8).ln(), (hi * 1.25).ln());
            chart
                .draw_series((0..n).step_by(2).map(|k| {
                    let y0 = (a + (b - a) * k as f64 / n as f64).exp();
                    let y1 = (a + (b - a) * (k + 1) as f64 / n as f64).exp();
                    PathElement::new([(x, y0), (x, y1)], BLACK.mix(0.6))
                }))
                .map_err(err)?;
            last_cycle = r.cycle;
        }
    }
    let members = curves.iter().map(|r| r.member).max().unwrap_or(0) + 1;
    for m in 0..members {
        let pts = |test: bool| -> Vec<(f64, f64)> {
            curves
                .iter()
                .filter(|r| r.member == m)
                .map(|r| {
                    (
                        r.epoch as f64,
                        if test { r.test_loss } else { r.train_loss },
                    )
                })
                .collect()
        };
        let s = chart
            .draw_series(LineSeries::new(pts(false), BLUE.stroke_width(2)))
            .map_err(err)?;
        if m == 0 {
            s.label("training set")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        }
        let s = chart
            .draw_series(LineSeries::new(pts(true), RED.stroke_width(2)))
            .map_err(err)?;
        if m == 0 {
            s.label("test set")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
        }
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// `<label>-scatter`, `<label>-errors` (.svg and .png) in `dir`.
pub fn surrogate_errors(
    pred: &[f64],
    truth: &[f64],
    info: &ModelInfo,
    label: &str,
    dir: &Path,
) -> Result<()> {
    let f = Figures::of(pred, truth);
    for ext in ["svg", "png"] {
        let p = dir.join(format!("{label}-scatter.{ext}"));
        let one = |f: Result<()>| f;
        let name = format!("{label} set");
        one(render!(&p, (800, 800), |root, _svg| scatter(
            &root,
            &[(name.as_str(), pred, truth)],
            info
        )))?;
        let p = dir.join(format!("{label}-errors.{ext}"));
        one(render!(&p, (1400, 600), |root, _svg| errors(
            &root, pred, truth, &f, label
        )))?;
    }
    Ok(())
}

/// `path` (.svg or .png): c_p over c_s of several sets on log axes, one colour each (e.g. the
/// training and test sets of a `train` run, as the paper's Fig. 18), each named (`"training
/// set"`) with the number of points drawn.
pub fn scatter_sets(sets: &[(&str, &[f64], &[f64])], info: &ModelInfo, path: &Path) -> Result<()> {
    if sets.is_empty() || sets.iter().any(|(_, p, t)| p.len() != t.len()) {
        invalid!("a scatter needs sets with one prediction per solver value");
    }
    render!(path, (800, 800), |root, _svg| scatter(&root, sets, info))
}

fn scatter<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    sets: &[(&str, &[f64], &[f64])],
    info: &ModelInfo,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    // Log axes: c12 spans two decades (a few pF at full depletion to about 1000 pF at 25 V),
    // and the relative error is what the likelihood sees.
    let all = sets
        .iter()
        .flat_map(|(_, p, t)| p.iter().chain(t.iter()))
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0);
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = if lo < hi {
        (lo / 1.1, hi * 1.1)
    } else {
        (1.0, 10.0)
    };
    let names: Vec<String> = sets
        .iter()
        .map(|(label, _, t)| format!("{label} ({} rows)", t.len()))
        .collect();
    let mut chart = ChartBuilder::on(root)
        .caption(
            // The sets by name only (the legend gives their rows), so the title fits the figure.
            format!(
                "c12 surrogate vs solver, recipe {}: {}",
                info.recipe_name,
                sets.iter()
                    .map(|(label, _, _)| label.split(',').next().unwrap_or(label))
                    .collect::<Vec<_>>()
                    .join(" / ")
            ),
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (lo..hi).log_scale().with_key_points(log_key_points(lo, hi)),
            (lo..hi).log_scale().with_key_points(log_key_points(lo, hi)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("c12 solver (pF)")
        .y_desc("c12 surrogate (pF)")
        .x_label_formatter(&|v| format!("{v}"))
        .y_label_formatter(&|v| format!("{v}"))
        .draw()
        .map_err(err)?;
    for (k, ((_, pred, truth), name)) in sets.iter().zip(&names).enumerate() {
        let c = PALETTE[k % PALETTE.len()];
        chart
            .draw_series(
                truth
                    .iter()
                    .zip(pred.iter())
                    .filter(|(t, p)| **t > 0.0 && **p > 0.0)
                    .map(|(&t, &p)| Circle::new((t, p), 1, c.mix(0.35).filled())),
            )
            .map_err(err)?
            .label(name.clone())
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
    }
    chart
        .draw_series(LineSeries::new([(lo, lo), (hi, hi)], BLACK))
        .map_err(err)?;
    if sets.len() > 1 {
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    }
    Ok(())
}

fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<f64> {
    let mut h = vec![0.0; bins];
    let w = (hi - lo) / bins as f64;
    for &v in values {
        let k = ((v - lo) / w).floor();
        if k >= 0.0 && (k as usize) < bins {
            h[k as usize] += 1.0;
        }
    }
    h
}

fn errors<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pred: &[f64],
    truth: &[f64],
    f: &Figures,
    label: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let panels = root.split_evenly((1, 2));
    let abs: Vec<f64> = pred.iter().zip(truth).map(|(p, t)| p - t).collect();
    let rel: Vec<f64> = pred
        .iter()
        .zip(truth)
        .map(|(p, t)| 100.0 * (p - t) / t)
        .collect();
    let bins = 120;
    for (k, area) in panels.iter().enumerate() {
        // The core of each distribution: +-10 Gaussian sigma of the relative error, +-the 95%
        // quantile of |c_p - c_s| for the absolute one; the caption counts what lies outside.
        let mut sorted_abs: Vec<f64> = abs.iter().map(|x| x.abs()).collect();
        sorted_abs.sort_by(f64::total_cmp);
        let q95 = hpge_foundation::quantile(&sorted_abs, 0.95).max(1e-12);
        let (values, span, xdesc, title) = if k == 0 {
            (&abs, 1.5 * q95, "c_p - c_s (pF)", "a) absolute")
        } else {
            (
                &rel,
                1000.0 * f.rel_sigma.max(1e-9),
                "(c_p - c_s)/c_s (%)",
                "b) relative",
            )
        };
        let outside = values.iter().filter(|v| v.abs() > span).count();
        let (lo, hi) = (-span, span);
        let h = histogram(values, lo, hi, bins);
        let w = (hi - lo) / bins as f64;
        let top = h.iter().copied().fold(1.0_f64, f64::max);
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!(
                    "{title} differences, {label} set (n = {}, {outside} outside)",
                    f.n
                ),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(lo..hi, (0.5_f64..top * 2.0).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(xdesc)
            .y_desc("samples per bin")
            .draw()
            .map_err(err)?;
        chart
            .draw_series(
                h.iter()
                    .enumerate()
                    .filter(|(_, c)| **c > 0.0)
                    .map(|(i, &c)| {
                        let x0 = lo + i as f64 * w;
                        Rectangle::new([(x0, 0.5), (x0 + w, c)], BLUE.mix(0.45).filled())
                    }),
            )
            .map_err(err)?;
        if k == 1 {
            let (mu, s) = (100.0 * f.rel_mean, 100.0 * f.rel_sigma);
            let norm = f.n as f64 * w / (s * (2.0 * std::f64::consts::PI).sqrt());
            let pts: Vec<(f64, f64)> = (0..=400)
                .map(|i| lo + (hi - lo) * i as f64 / 400.0)
                .map(|x| (x, norm * (-0.5 * ((x - mu) / s).powi(2)).exp()))
                .filter(|&(_, y)| y >= 0.5)
                .collect();
            chart
                .draw_series(LineSeries::new(pts, RED.stroke_width(2)))
                .map_err(err)?
                .label(format!("Gaussian fit: mean {mu:+.3}%, sigma {s:.3}%"))
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
            legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
    }
    Ok(())
}
