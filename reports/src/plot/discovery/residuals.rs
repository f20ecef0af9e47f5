//! The left panel: standardised residuals against the bias, windows shaded.

use hpge_inference::Discovery;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::*;
use crate::error::Result;
use crate::plot::style::{err, zero_line};

/// The residuals against U_B.
pub(super) fn residual_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    d: &Discovery,
) -> Result<()> {
    let s = &d.summary;
    let body = caption(
        area,
        "standardised posterior-predictive residuals (c_p - c_m) / sd: model - data, as every figure",
    )?;
    let order = sorted_voltages(&d.voltage_v);
    let volts: Vec<f64> = order.iter().map(|p| p.0).collect();
    let bands: Vec<[f64; 2]> = s
        .disagreement
        .iter()
        .map(|w| band_edges(&volts, w.voltages_v))
        .collect();
    let (v_lo, v_hi) = (volts[0], volts[volts.len() - 1]);
    let span = if v_hi > v_lo { v_hi - v_lo } else { 1.0 };
    let x0 = bands
        .iter()
        .map(|b| b[0])
        .fold(v_lo - 0.02 * span, f64::min);
    let x1 = bands
        .iter()
        .map(|b| b[1])
        .fold(v_hi + 0.02 * span, f64::max);

    let label_font = TextStyle::from(("sans-serif", KEY_FONT).into_font());
    let label_h = body.estimate_text_size("W1", &label_font).map_err(err)?.1 as i32 + 4;
    let rows = 2 + usize::from(d.after.is_some());
    let top_px = LEGEND_ROW_H * rows as f64 + 22.0;
    let bottom_px = if bands.is_empty() {
        0.0
    } else {
        f64::from(2 * label_h + 10)
    };
    let (_, body_h) = body.dim_in_pixel();
    let plot_h = f64::from(body_h) - f64::from(2 * MARGIN + X_LABEL_H);
    let residuals = std::iter::once(&d.before)
        .chain(&d.after)
        .flat_map(|f| f.check.residuals.iter().map(|r| -r));
    let (y0, y1) = residual_range(residuals, plot_h, top_px, bottom_px);

    let mut chart = ChartBuilder::on(&body)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_H)
        .y_label_area_size(Y_LABEL_W)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("U_B (V)")
        .y_desc("(c_p - c_m) / sd")
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .light_line_style(WHITE)
        .draw()
        .map_err(err)?;

    for (i, b) in bands.iter().enumerate() {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(b[0].max(x0), y0), (b[1].min(x1), y1)],
                window_color(i).mix(0.16).filled(),
            )))
            .map_err(err)?;
    }
    zero_line(&mut chart, (x0, x1), GUIDE)?;
    for y in [2.0, -2.0] {
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, y), (x1, y)],
                8,
                5,
                GUIDE.stroke_width(1),
            ))
            .map_err(err)?;
    }

    let mut models = vec![(&d.before, &s.before, BEFORE, "before")];
    if let Some(a) = &d.after {
        models.push((a, &s.after, AFTER, "after"));
    }
    for (k, (fit, gap, color, what)) in models.into_iter().enumerate() {
        let pts: Vec<(f64, f64)> = order
            .iter()
            // discovery.json keeps data - model; the figure shows model - data (c_p - c_m),
            // the sign convention of every figure.
            .map(|&(v, i)| (v, -fit.check.residuals[i]))
            .collect();
        // Lines between finite neighbours only.
        for run in pts.split(|p| !p.1.is_finite()).filter(|r| !r.is_empty()) {
            chart
                .draw_series(LineSeries::new(run.to_vec(), color.stroke_width(1)))
                .map_err(err)?;
        }
        let finite = pts.iter().copied().filter(|p| p.1.is_finite());
        let label = format!("{what}: {} (chi2/ndf = {:.2})", gap.model, gap.chi2_ndf);
        if k == 0 {
            chart
                .draw_series(finite.map(|p| Circle::new(p, 4, color.filled())))
                .map_err(err)?
                .label(label)
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (20, 0)], color.stroke_width(1))
                        + Circle::new((10, 0), 4, color.filled())
                });
        } else {
            let square = move |p: (f64, f64)| {
                EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], color.filled())
            };
            chart
                .draw_series(finite.map(square))
                .map_err(err)?
                .label(label)
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (20, 0)], color.stroke_width(1))
                        + Rectangle::new([(6, -4), (14, 4)], color.filled())
                });
        }
    }

    // The +-2 lines' legend entry, after the models'.
    chart
        .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
        .map_err(err)?
        .label("|r| = 2")
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (8, 0)], GUIDE.stroke_width(1))
                + PathElement::new(vec![(12, 0), (20, 0)], GUIDE.stroke_width(1))
        });

    // Window labels in the strip kept free at the bottom.
    let (px, py) = chart.plotting_area().get_pixel_range();
    let wanted: Vec<[i32; 4]> = bands
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let text = format!("W{}", i + 1);
            let w = body
                .estimate_text_size(&text, &label_font)
                .map_or(20, |s| s.0 as i32)
                + 6;
            let mid = chart
                .backend_coord(&(0.5 * (b[0].max(x0) + b[1].min(x1)), y0))
                .0;
            [mid - w / 2, py.end - 2 * label_h - 8, w, label_h]
        })
        .collect();
    for (i, b) in place_labels(&wanted, [px.start, px.end], label_h + 2)
        .into_iter()
        .enumerate()
    {
        boxed_label(root, b, &format!("W{}", i + 1), window_color(i))?;
    }

    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 16))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}
