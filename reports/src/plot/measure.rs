//! Figures of the measurement (paper, Figs. "pg_pulse_for_undepl_det", "pg_pulse_amp_hists_and_fit"
//! and "dataCVScan"): pulses with their tail fits, Q_t spectra, pulser-peak fits, the C-V curve
//! with error bars and -dc12/dU_B with the full-depletion threshold. Each as SVG and PNG.

use std::path::Path;

use hpge_measurement::slope::negative_slopes;
use hpge_measurement::synth::PC_PER_KEV;
use hpge_measurement::{Measurement, PulseSet, VoltagePoint};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{err, legend, log_key_points};
use crate::error::Result;

/// Writes `pulses`, `spectra`, `peak-fits`, `cv` and `slope` (.svg and .png) into `dir`.
pub fn measurement(m: &Measurement, sets: &[PulseSet], dir: &Path) -> Result<()> {
    for ext in ["svg", "png"] {
        let p = |name: &str| dir.join(format!("{name}.{ext}"));
        let one = |f: Result<()>| f;
        one(render!(&p("pulses"), (1500, 500), |root, _svg| pulses(
            &root, m, sets
        )))?;
        one(render!(&p("spectra"), (1150, 650), |root, _svg| spectra(
            &root, m
        )))?;
        one(render!(&p("peak-fits"), (1200, 900), |root, _svg| {
            peak_fits(&root, m)
        }))?;
        one(render!(&p("cv"), (1000, 650), |root, _svg| cv(&root, m)))?;
        one(render!(&p("slope"), (1000, 650), |root, _svg| slope(
            &root, m
        )))?;
    }
    Ok(())
}

/// Up to n points spread over the curve (first, last and evenly between).
fn spread(points: &[VoltagePoint], n: usize) -> Vec<&VoltagePoint> {
    let k = points.len();
    let mut idx: Vec<usize> = (0..n.min(k))
        .map(|i| if n <= 1 { 0 } else { i * (k - 1) / (n - 1) })
        .collect();
    idx.dedup();
    idx.into_iter().map(|i| &points[i]).collect()
}

fn pulses<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    m: &Measurement,
    sets: &[PulseSet],
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let chosen = spread(&m.points, 3);
    let panels = root.split_evenly((1, chosen.len().max(1)));
    for (area, p) in panels.iter().zip(chosen) {
        let Some(set) = sets.iter().find(|s| s.source == p.source) else {
            continue;
        };
        // The first example that is a pulser pulse (its Q_t within 5 sigma of the peak).
        let Some((idx, fit)) = p
            .examples
            .iter()
            .find(|(_, f)| (f.q_t_pc - p.peak.mean_pc).abs() < 5.0 * p.peak.sigma_pc)
            .or(p.examples.first())
        else {
            continue;
        };
        let trace = set.pulse(*idx);
        let t_us: Vec<f64> = (0..set.n_samples).map(|s| set.time_ns(s) * 1e-3).collect();
        let (lo, hi) = trace
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let pad = 0.05 * (hi - lo).max(1e-9);
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("U_B = {} V, pulse {idx}", p.bias_v),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..t_us[t_us.len() - 1], (lo - pad)..(hi + pad))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("t (us)")
            .y_desc("Q (pC)")
            .draw()
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(
                t_us.iter().copied().zip(trace.iter().copied()),
                BLUE.mix(0.6),
            ))
            .map_err(err)?
            .label("recorded")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE));
        let start = fit.start_ns * 1e-3;
        chart
            .draw_series(LineSeries::new(
                t_us.iter()
                    .copied()
                    .filter(|&t| t >= start)
                    .map(|t| (t, fit.model_pc(t * 1e3))),
                RED.stroke_width(2),
            ))
            .map_err(err)?
            .label(if fit.flat {
                format!("flat top: Q_t = {:.5} pC", fit.q_t_pc)
            } else {
                format!(
                    "Q_t - Q_u exp(-t/tau): Q_t = {:.5} pC, tau = {:.0} ns",
                    fit.q_t_pc, fit.tau_ns
                )
            })
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    }
    Ok(())
}

/// Gamma lines marked on the spectra: (label, energy in keV).
const GAMMA_LINES: [(&str, f64); 3] = [
    ("208Tl 2614.5 keV", 2614.5),
    ("40K 1460.8 keV", 1460.8),
    ("208Tl 583.2 keV", 583.2),
];

fn spectra<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, m: &Measurement) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let (root, bar) = root.split_horizontally(1000);
    let all: Vec<f64> = m
        .points
        .iter()
        .flat_map(|p| p.q_t_pc.iter().copied())
        .filter(|q| *q > 0.0)
        .collect();
    let qmax = all.iter().copied().fold(0.0, f64::max).max(1e-3) * 1.3;
    let qmin = (qmax / 1e3).max(1e-3);
    let nb = 200;
    let edge = |i: usize| qmin * (qmax / qmin).powf(i as f64 / nb as f64);
    let hist = |q: &[f64]| -> Vec<f64> {
        let mut h = vec![0.0; nb];
        for &x in q {
            if x > qmin && x < qmax {
                let k = ((x / qmin).ln() / (qmax / qmin).ln() * nb as f64) as usize;
                h[k.min(nb - 1)] += 1.0;
            }
        }
        h
    };
    let hists: Vec<Vec<f64>> = m.points.iter().map(|p| hist(&p.q_t_pc)).collect();
    let hmax = hists.iter().flatten().copied().fold(1.0, f64::max);
    // Half the spacing of neighbouring biases above and below each row.
    let u: Vec<f64> = m.points.iter().map(|p| p.bias_v).collect();
    let half = |k: usize| -> (f64, f64) {
        let d = |a: usize, b: usize| 0.5 * (u[b] - u[a]).abs();
        let below = if k > 0 {
            d(k - 1, k)
        } else if u.len() > 1 {
            d(0, 1)
        } else {
            25.0
        };
        let above = if k + 1 < u.len() { d(k, k + 1) } else { below };
        (u[k] - below, u[k] + above)
    };
    let (ylo, yhi) = (half(0).0, half(u.len() - 1).1);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Q_t of all pulses per bias: the pulser peak moves left with U_B; gamma lines dashed",
            ("sans-serif", 17),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (qmin..qmax)
                .log_scale()
                .with_key_points(log_key_points(qmin, qmax)),
            ylo..yhi,
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("Q_t (pC)")
        .y_desc("bias U_B (V)")
        .disable_mesh()
        .draw()
        .map_err(err)?;
    for (k, h) in hists.iter().enumerate() {
        let (y0, y1) = half(k);
        chart
            .draw_series((0..nb).filter(|&i| h[i] > 0.0).map(|i| {
                let t = (1.0 + h[i]).ln() / (1.0 + hmax).ln();
                let color = ViridisRGB::get_color(1.0 - t);
                Rectangle::new([(edge(i), y0), (edge(i + 1), y1)], color.filled())
            }))
            .map_err(err)?;
    }
    // The gamma lines (dashed, labelled at the top) and the pulser track (labelled at its
    // first bias).
    let label_font = ("sans-serif", 14).into_font();
    for (k, (name, kev)) in GAMMA_LINES.iter().enumerate() {
        let q = kev * PC_PER_KEV;
        if !(qmin..qmax).contains(&q) {
            continue;
        }
        chart
            .draw_series(DashedLineSeries::new(
                [(q, ylo), (q, yhi)],
                6,
                4,
                RED.mix(0.7).stroke_width(1),
            ))
            .map_err(err)?;
        let y = yhi - (0.03 + 0.04 * k as f64) * (yhi - ylo);
        chart
            .draw_series([Text::new(
                name.to_string(),
                (q * 1.03, y),
                label_font.clone().color(&RED),
            )])
            .map_err(err)?;
    }
    if let Some(p) = m.points.first() {
        let q = p.peak.mean_pc;
        if q.is_finite() && (qmin..qmax).contains(&q) {
            chart
                .draw_series([Text::new(
                    format!("pulser peak ({:.0} V)", p.bias_v),
                    (q * 0.75, p.bias_v + 0.04 * (yhi - ylo)),
                    label_font.clone(),
                )])
                .map_err(err)?;
        }
    }
    // Colour bar: counts per bin on the same log scale as the map.
    let (x0, y0, bw, bh) = (20, 60, 24, 420);
    for k in 0..bh {
        let t = 1.0 - (k as f64 + 0.5) / bh as f64;
        bar.draw(&Rectangle::new(
            [(x0, y0 + k), (x0 + bw, y0 + k + 1)],
            ViridisRGB::get_color(1.0 - t).filled(),
        ))
        .map_err(err)?;
    }
    let font = ("sans-serif", 14).into_font();
    bar.draw(&Text::new(
        "pulses per bin",
        (x0 - 10, y0 - 30),
        font.clone(),
    ))
    .map_err(err)?;
    for k in 0..=4 {
        let t = k as f64 / 4.0;
        let counts = ((1.0 + hmax).ln() * t).exp() - 1.0;
        let y = y0 + ((1.0 - t) * bh as f64) as i32;
        bar.draw(&Text::new(
            format!("{counts:.0}"),
            (x0 + bw + 6, y - 7),
            font.clone(),
        ))
        .map_err(err)?;
    }
    Ok(())
}

fn peak_fits<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, m: &Measurement) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let chosen = spread(&m.points, 4);
    for (area, p) in root.split_evenly((2, 2)).iter().zip(chosen) {
        let f = &p.peak;
        let (x0, x1) = (f.edges_pc[0], f.edges_pc[f.edges_pc.len() - 1]);
        let ymax = f.counts.iter().copied().fold(1.0, f64::max) * 1.25;
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!(
                    "U_B = {} V: mean {:.6} +- {:.1e} pC, width {:.1e} pC",
                    p.bias_v, f.mean_pc, f.mean_err_pc, f.sigma_pc
                ),
                ("sans-serif", 16),
            )
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(x0..x1, 0.0..ymax)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("Q_t (pC)")
            .y_desc("pulses")
            .x_labels(5)
            .draw()
            .map_err(err)?;
        chart
            .draw_series((0..f.counts.len()).map(|i| {
                Rectangle::new(
                    [(f.edges_pc[i], 0.0), (f.edges_pc[i + 1], f.counts[i])],
                    BLUE.mix(0.4).filled(),
                )
            }))
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(
                (0..f.counts.len())
                    .map(|i| (0.5 * (f.edges_pc[i] + f.edges_pc[i + 1]), f.expected(i))),
                RED.stroke_width(2),
            ))
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(
                [(f.mean_pc, 0.0), (f.mean_pc, ymax)],
                BLACK,
            ))
            .map_err(err)?;
    }
    Ok(())
}

fn cv<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, m: &Measurement) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let c = &m.curve;
    let lo = c
        .c12_pf
        .iter()
        .zip(&c.sigma_pf)
        .map(|(a, s)| a - s)
        .fold(f64::INFINITY, f64::min)
        .max(1e-3);
    let hi = c
        .c12_pf
        .iter()
        .zip(&c.sigma_pf)
        .map(|(a, s)| a + s)
        .fold(0.0, f64::max);
    let vmax = c.voltage_v.last().copied().unwrap_or(1.0) * 1.05;
    let mut chart = ChartBuilder::on(root)
        .caption(
            "measured C-V curve (error bars: total, highly correlated; see the covariance)",
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            0.0..vmax,
            (lo / 1.2..hi * 1.2)
                .log_scale()
                .with_key_points(log_key_points(lo / 1.2, hi * 1.2)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("bias U_B (V)")
        .y_desc("c12 (pF)")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(
            c.voltage_v
                .iter()
                .zip(&c.c12_pf)
                .zip(&c.sigma_pf)
                .map(|((&u, &y), &s)| ErrorBar::new_vertical(u, y - s, y, y + s, BLUE.filled(), 6)),
        )
        .map_err(err)?;
    if let Some(u) = m.depletion_voltage_v {
        chart
            .draw_series(LineSeries::new(
                [(u, lo / 1.2), (u, hi * 1.2)],
                RED.mix(0.6),
            ))
            .map_err(err)?
            .label(format!("full depletion {u:.0} V"))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
        legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    }
    Ok(())
}

/// -dc12/dU_B between neighbouring points on a log axis, every point shown (issue 63 item 6):
/// a point where c12 rises with the bias (-dc12/dU_B <= 0, where the log axis has no place) is
/// drawn as a cross on the axis floor with its value in the legend, so that a negative point
/// near U_fd, where the depletion voltage is read, is not lost.
fn slope<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, m: &Measurement) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let s = negative_slopes(&m.curve.voltage_v, &m.curve.c12_pf);
    let th = m.settings.depletion_slope_pf_per_v;
    let pos: Vec<(f64, f64)> = s.iter().copied().filter(|p| p.1 > 0.0).collect();
    let rising: Vec<(f64, f64)> = s
        .iter()
        .copied()
        .filter(|p| p.1 <= 0.0 || p.1.is_nan())
        .collect();
    let lo = pos.iter().map(|p| p.1).fold(th, f64::min) / 3.0;
    let hi = pos.iter().map(|p| p.1).fold(th, f64::max) * 3.0;
    let vmax = m.curve.voltage_v.last().copied().unwrap_or(1.0) * 1.05;
    let caption = if rising.is_empty() {
        "-dc12/dU_B between neighbouring points (every one positive)".to_string()
    } else {
        format!(
            "-dc12/dU_B between neighbouring points; {} where c12 rises (<= 0): crosses on the floor",
            rising.len()
        )
    };
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            0.0..vmax,
            (lo..hi).log_scale().with_key_points(log_key_points(lo, hi)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("bias U_B (V)")
        .y_desc("-dc12/dU_B (pF/V)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(
            pos.iter()
                .map(|&(u, d)| Circle::new((u, d), 4, BLUE.filled())),
        )
        .map_err(err)?;
    if !rising.is_empty() {
        let floor = lo * 1.15;
        let values: Vec<String> = rising
            .iter()
            .take(4)
            .map(|(u, d)| format!("{d:.1e} at {u:.0} V"))
            .collect();
        let more = if rising.len() > 4 { ", ..." } else { "" };
        chart
            .draw_series(
                rising
                    .iter()
                    .map(|&(u, _)| Cross::new((u, floor), 7, RED.stroke_width(3))),
            )
            .map_err(err)?
            .label(format!("<= 0 pF/V: {}{more}", values.join(", ")))
            .legend(|(x, y)| Cross::new((x + 10, y), 6, RED.stroke_width(3)));
    }
    chart
        .draw_series(LineSeries::new([(0.0, th), (vmax, th)], RED))
        .map_err(err)?
        .label(format!("{th} pF/V (full depletion)"))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
    if let Some(u) = m.depletion_voltage_v {
        chart
            .draw_series(LineSeries::new([(u, lo), (u, hi)], RED.mix(0.5)))
            .map_err(err)?
            .label(format!("U_fd = {u:.0} V"))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.mix(0.5)));
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}
