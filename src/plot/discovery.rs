//! The figure of a model discovery (`hpge-cv discover`): the start model's standardised
//! posterior-predictive residuals against the bias, before and after adding the chosen
//! extension, with the windows of disagreement shaded; beside them the detector's r-z
//! cross-section with the region each window probes.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use hpge_inference::Discovery;
use hpge_solver::{BoundingBox, Detector};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::cross_section::{contact_color, draw_regions, passive_color};
use super::err;
use super::fit::PALETTE;

/// Figure size in pixels.
const SIZE: (u32, u32) = (1400, 600);
/// Width of the residual panel; the cross-section gets the rest.
const LEFT_W: u32 = 810;
/// Height of a panel's caption strip.
const CAPTION_H: u32 = 30;
const MARGIN: u32 = 15;
const X_LABEL_H: u32 = 48;
const Y_LABEL_W: u32 = 62;
/// Smallest width of the key column beside the cross-section.
const KEY_MIN_W: u32 = 250;
/// Legend and key font size.
const KEY_FONT: u32 = 15;
/// Height of a legend row of plotters' series labels at 16 px (measured).
const LEGEND_ROW_H: f64 = 25.0;
/// The start model and the extended model.
const BEFORE: RGBColor = PALETTE[0];
const AFTER: RGBColor = PALETTE[1];
/// The zero line and the +-2 lines.
const GUIDE: RGBColor = RGBColor(90, 90, 90);
/// The semiconductor's interior in the cross-section.
const CRYSTAL: RGBColor = RGBColor(226, 226, 226);
/// Window colours: the palette without the two models' colours and its grey.
const WINDOW_COLORS: [RGBColor; 7] = [
    PALETTE[2], PALETTE[3], PALETTE[4], PALETTE[5], PALETTE[6], PALETTE[8], PALETTE[9],
];

fn window_color(i: usize) -> RGBColor {
    WINDOW_COLORS[i % WINDOW_COLORS.len()]
}

/// Writes `residuals.svg` and `residuals.png` into `out` (created if missing); returns their
/// paths.
///
/// Left: the standardised posterior-predictive residuals of the start model (and of the
/// extended one, when an extension was chosen) against U_B, the zero and +-2 lines, each window
/// of disagreement shaded and labelled W1, W2, ... Right: the r-z cross-section of `det` with the
/// region each window probes in its colour.
pub fn discovery_figures(d: &Discovery, det: &Detector, out: &Path) -> Result<Vec<PathBuf>> {
    let n = d.voltage_v.len();
    if n == 0 {
        bail!("the discovery has no voltages to plot");
    }
    let fits = std::iter::once(&d.before).chain(&d.after);
    for f in fits {
        if f.check.residuals.len() != n {
            bail!(
                "{}: {} residuals for {n} voltages",
                f.model,
                f.check.residuals.len()
            );
        }
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the folder {}", out.display()))?;
    let mut paths = Vec::new();
    for ext in ["svg", "png"] {
        let p = out.join(format!("residuals.{ext}"));
        let done: Result<()> = render!(&p, SIZE, |root, _svg| draw(&root, d, det));
        done?;
        paths.push(p);
    }
    Ok(paths)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &Discovery,
    det: &Detector,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let s = &d.summary;
    let title = format!(
        "start model {}: residuals before and after adding {}",
        s.before.model,
        s.chosen.as_deref().unwrap_or("nothing")
    );
    let body = root.titled(&title, ("sans-serif", 24)).map_err(err)?;
    let (left, right) = body.split_horizontally(LEFT_W);
    residual_panel(root, &left, d)?;
    region_panel(root, &right, d, det)
}

/// Draws `text` into a strip at the top of `area` and returns the rest.
fn caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
) -> Result<DrawingArea<DB, Shift>> {
    let (strip, rest) = area.split_vertically(CAPTION_H);
    strip
        .draw(&Text::new(
            text.to_string(),
            (MARGIN as i32 + 5, 4),
            ("sans-serif", 18).into_font(),
        ))
        .map_err(err)?;
    Ok(rest)
}

/// "0.0032" or "3.2e-5" (below 1e-3).
fn p_text(p: f64) -> String {
    if p.is_finite() && p > 0.0 && p < 1e-3 {
        format!("{p:.1e}")
    } else {
        format!("{p:.4}")
    }
}

/// A tick label: at most two decimals, trailing zeros dropped ("500", "2.5", "-0.25").
fn tick(v: &f64) -> String {
    let t = format!("{v:.2}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    if t == "-0" { "0".into() } else { t.into() }
}

/// "W1 (1025-1375 V)".
fn window_label(i: usize, v: [f64; 2]) -> String {
    format!("W{} ({:.0}-{:.0} V)", i + 1, v[0], v[1])
}

/// The voltages as increasing (value, index) pairs.
fn sorted_voltages(v: &[f64]) -> Vec<(f64, usize)> {
    let mut s: Vec<(f64, usize)> = v.iter().copied().zip(0..).collect();
    s.sort_by(|a, b| a.0.total_cmp(&b.0));
    s
}

/// The shaded extent of a window [lo, hi] of the increasing `voltages`: widened on each side by
/// half the gap to the next voltage outside it (half the median gap at the ends), so that its
/// points lie inside the band rather than on its edges.
fn band_edges(voltages: &[f64], window: [f64; 2]) -> [f64; 2] {
    let gaps: Vec<f64> = voltages
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|g| *g > 0.0)
        .collect();
    let half_typical = if gaps.is_empty() {
        0.0
    } else {
        let mut g = gaps.clone();
        g.sort_by(f64::total_cmp);
        0.5 * g[g.len() / 2]
    };
    let below = voltages.iter().rev().find(|&&v| v < window[0]);
    let above = voltages.iter().find(|&&v| v > window[1]);
    [
        below.map_or(window[0] - half_typical, |b| 0.5 * (b + window[0])),
        above.map_or(window[1] + half_typical, |a| 0.5 * (a + window[1])),
    ]
}

/// [lo, hi] of the residual axis: the finite `values`, 0 and +-2.5 padded by 5%, widened so that
/// `top_px` pixels at the top (for the legend) and `bottom_px` at the bottom (for the window
/// labels) of a plot `height_px` tall stay clear of them.
fn residual_range(
    values: impl Iterator<Item = f64>,
    height_px: f64,
    top_px: f64,
    bottom_px: f64,
) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((-2.5f64, 2.5f64), |(a, b), v| (a.min(v), b.max(v)));
    let pad = 0.05 * (hi - lo);
    let (lo, hi) = (lo - pad, hi + pad);
    // Never let the reserved strips take more than 60% of the height.
    let data_px = (height_px - top_px - bottom_px)
        .max(0.4 * height_px)
        .max(1.0);
    let per_px = (hi - lo) / data_px;
    (lo - bottom_px * per_px, hi + top_px * per_px)
}

/// Pixel boxes `[x, y, w, h]` moved apart: each is clamped into `[x_min, x_max]` horizontally,
/// then moved by `step` pixels vertically (down when positive) until it overlaps none placed
/// before it (at most 20 times).
fn place_labels(wanted: &[[i32; 4]], x_range: [i32; 2], step: i32) -> Vec<[i32; 4]> {
    let overlap = |a: &[i32; 4], b: &[i32; 4]| {
        a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
    };
    let mut placed: Vec<[i32; 4]> = Vec::with_capacity(wanted.len());
    for &[x, y, w, h] in wanted {
        let x = x.min(x_range[1] - w).max(x_range[0]);
        let mut b = [x, y, w, h];
        for _ in 0..20 {
            if !placed.iter().any(|p| overlap(p, &b)) {
                break;
            }
            b[1] += step;
        }
        placed.push(b);
    }
    placed
}

/// `text` cut to at most `max_w` pixels in `font`, ending in "..." when cut.
fn fit_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    font: &TextStyle,
    max_w: u32,
) -> String {
    let width = |t: &str| area.estimate_text_size(t, font).map_or(0, |s| s.0);
    if width(text) <= max_w {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    for n in (0..chars.len()).rev() {
        let t: String = chars[..n].iter().collect::<String>() + "...";
        if width(&t) <= max_w {
            return t;
        }
    }
    String::new()
}

/// `text` broken at spaces into at most `max_lines` lines of at most `max_w` pixels in `font`
/// (the last cut by [`fit_text`] when the text is longer).
fn wrap_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    font: &TextStyle,
    max_w: u32,
    max_lines: usize,
) -> Vec<String> {
    let width = |t: &str| area.estimate_text_size(t, font).map_or(0, |s| s.0);
    let mut lines: Vec<String> = Vec::new();
    let mut words = text.split(' ').peekable();
    while words.peek().is_some() {
        if lines.len() + 1 == max_lines {
            let rest: Vec<&str> = words.collect();
            lines.push(fit_text(area, &rest.join(" "), font, max_w));
            break;
        }
        let mut line = words.next().unwrap_or_default().to_string();
        while let Some(w) = words.peek() {
            let longer = format!("{line} {w}");
            if width(&longer) > max_w {
                break;
            }
            line = longer;
            words.next();
        }
        lines.push(fit_text(area, &line, font, max_w));
    }
    lines
}

/// The outline of the rectangle with corners `a` and `b` as a closed path (the SVG backend draws
/// rectangles' outlines 1 px wide whatever the style says).
fn frame<C: Copy>(a: (C, C), b: (C, C), style: ShapeStyle) -> PathElement<(C, C)> {
    PathElement::new(vec![a, (b.0, a.1), b, (a.0, b.1), a], style)
}

/// A label on a half-transparent white box at absolute pixel `[x, y, w, h]` of `root`.
fn boxed_label<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    b: [i32; 4],
    text: &str,
    color: RGBColor,
) -> Result<()> {
    root.draw(&Rectangle::new(
        [(b[0], b[1]), (b[0] + b[2], b[1] + b[3])],
        WHITE.mix(0.8).filled(),
    ))
    .map_err(err)?;
    root.draw(&Text::new(
        text.to_string(),
        (b[0] + 3, b[1] + 2),
        ("sans-serif", KEY_FONT).into_font().color(&color),
    ))
    .map_err(err)
}

/// The residuals against U_B.
fn residual_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    d: &Discovery,
) -> Result<()> {
    let s = &d.summary;
    let body = caption(
        area,
        "standardised posterior-predictive residuals (data - model) / sd",
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
        .flat_map(|f| f.check.residuals.iter().copied());
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
        .y_desc("standardised residual")
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
    chart
        .draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            GUIDE.stroke_width(1),
        ))
        .map_err(err)?;
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
            .map(|&(v, i)| (v, fit.check.residuals[i]))
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

/// The r-z box shown: the semiconductor and the contacts, padded by 6% of the larger side, r
/// from 0, within the world.
fn view_box(det: &Detector) -> BoundingBox {
    let b = det
        .contacts
        .iter()
        .fold(det.semiconductor.geometry.bbox(), |b, c| {
            b.union(&c.geometry.bbox())
        });
    let w = &det.world;
    let pad = 0.06 * (b.r_max_mm - b.r_min_mm).max(b.z_max_mm - b.z_min_mm);
    BoundingBox::new(
        0.0,
        (b.r_max_mm + pad).min(w.r_max_mm),
        (b.z_min_mm - pad).max(w.z_min_mm),
        (b.z_max_mm + pad).min(w.z_max_mm),
    )
}

/// The cross-section with the probed regions, and its key.
fn region_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    d: &Discovery,
    det: &Detector,
) -> Result<()> {
    let s = &d.summary;
    let body = caption(
        area,
        &format!("regions the windows probe: {}, r-z", det.name),
    )?;
    let (w_px, h_px) = body.dim_in_pixel();
    let v = view_box(det);
    let (dr, dz) = (v.r_max_mm - v.r_min_mm, v.z_max_mm - v.z_min_mm);
    let avail_w = w_px
        .saturating_sub(KEY_MIN_W + Y_LABEL_W + 2 * MARGIN)
        .max(50);
    let avail_h = h_px.saturating_sub(X_LABEL_H + 2 * MARGIN).max(50);
    let scale = (f64::from(avail_w) / dr).min(f64::from(avail_h) / dz);
    let plot_w = (scale * dr).round().max(20.0) as u32;
    let plot_h = (scale * dz).round().max(20.0) as u32;
    let (chart_area, key_area) = body.split_horizontally(plot_w + Y_LABEL_W + 2 * MARGIN);
    let (chart_area, _) = chart_area.split_vertically(plot_h + X_LABEL_H + 2 * MARGIN);
    let mut chart = ChartBuilder::on(&chart_area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_H)
        .y_label_area_size(Y_LABEL_W)
        .build_cartesian_2d(v.r_min_mm..v.r_max_mm, v.z_min_mm..v.z_max_mm)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("r (mm)")
        .y_desc("z (mm)")
        .x_labels(6)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    // One cell per pixel: the interior is one colour, so rows merge into few runs.
    let cells = (plot_w as usize, plot_h as usize);
    draw_regions(
        &mut chart,
        det,
        [v.r_min_mm, v.r_max_mm],
        [v.z_min_mm, v.z_max_mm],
        cells,
        |_, _| CRYSTAL,
    )?;

    let mut wanted = Vec::new();
    let mut texts = Vec::new();
    let font = TextStyle::from(("sans-serif", KEY_FONT).into_font());
    for (i, w) in s.disagreement.iter().enumerate() {
        let Some(g) = &w.region else { continue };
        let c = window_color(i);
        chart
            .draw_series([Rectangle::new(
                [(g.r_mm[0], g.z_mm[0]), (g.r_mm[1], g.z_mm[1])],
                c.mix(0.35).filled(),
            )])
            .map_err(err)?;
        chart
            .draw_series([frame(
                (g.r_mm[0], g.z_mm[0]),
                (g.r_mm[1], g.z_mm[1]),
                c.stroke_width(2),
            )])
            .map_err(err)?;
        let text = window_label(i, w.voltages_v);
        let (tw, th) = body.estimate_text_size(&text, &font).map_err(err)?;
        let (x, y) = chart.backend_coord(&(g.r_mm[0], g.z_mm[1]));
        wanted.push([x + 3, y + 3, tw as i32 + 6, th as i32 + 4]);
        texts.push((i, text));
    }
    let (px, _) = chart.plotting_area().get_pixel_range();
    let step = wanted.first().map_or(0, |b| b[3] + 2);
    for (b, (i, text)) in place_labels(&wanted, [px.start, px.end], step)
        .into_iter()
        .zip(&texts)
    {
        boxed_label(root, b, text, window_color(*i))?;
    }
    draw_key(&key_area, d, det, &v)
}

/// The key beside the cross-section: materials and contacts, then the windows.
fn draw_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    d: &Discovery,
    det: &Detector,
    view: &BoundingBox,
) -> Result<()> {
    let font = TextStyle::from(("sans-serif", KEY_FONT).into_font());
    let (w_px, h_px) = area.dim_in_pixel();
    let (x0, mut y) = (10, MARGIN as i32 + 4);
    let text_w = w_px.saturating_sub(x0 as u32 + 36 + 8);
    let row = 22;
    let mut entries: Vec<(RGBColor, String)> = vec![(
        CRYSTAL,
        format!(
            "{} ({})",
            det.semiconductor.name, det.semiconductor.material.name
        ),
    )];
    entries.extend(
        det.contacts
            .iter()
            .enumerate()
            .map(|(k, c)| (contact_color(k), format!("{} ({})", c.name, c.potential))),
    );
    let in_view = |b: BoundingBox| !view.intersection(&b).is_empty();
    entries.extend(
        det.passives
            .iter()
            .filter(|p| in_view(p.geometry.bbox()))
            .map(|p| (passive_color(p.kind), p.name.clone())),
    );
    for (color, text) in entries {
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            color.filled(),
        ))
        .map_err(err)?;
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
        let t = fit_text(area, &text, &font, text_w);
        area.draw(&Text::new(t, (x0 + 36, y), font.clone()))
            .map_err(err)?;
        y += row;
    }
    y += 14;
    let s = &d.summary;
    if s.disagreement.is_empty() {
        area.draw(&Text::new(
            "no structured disagreement",
            (x0, y),
            ("sans-serif", 18).into_font(),
        ))
        .map_err(err)?;
        area.draw(&Text::new(
            format!("(no window with p < {})", s.settings.window_p),
            (x0, y + 24),
            font.clone(),
        ))
        .map_err(err)?;
        return Ok(());
    }
    area.draw(&Text::new(
        "windows of disagreement",
        (x0, y),
        ("sans-serif", 17).into_font(),
    ))
    .map_err(err)?;
    y += 24;
    for (i, w) in s.disagreement.iter().enumerate() {
        if y + 3 * row > h_px as i32 - 4 {
            let more = s.disagreement.len() - i;
            area.draw(&Text::new(
                format!("... and {more} more (see report.md)"),
                (x0, y),
                font.clone(),
            ))
            .map_err(err)?;
            break;
        }
        let c = window_color(i);
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            c.mix(0.35).filled(),
        ))
        .map_err(err)?;
        area.draw(&frame((x0, y), (x0 + 26, y + 16), c.stroke_width(2)))
            .map_err(err)?;
        let line1 = format!(
            "{}: p = {}",
            window_label(i, w.voltages_v),
            p_text(w.p_value)
        );
        let line2 = match (&w.region, &w.region_error) {
            (Some(g), _) => format!(
                "r {:.1}-{:.1} mm, z {:.1}-{:.1} mm",
                g.r_mm[0], g.r_mm[1], g.z_mm[0], g.z_mm[1]
            ),
            (None, Some(e)) => format!("no region: {e}"),
            (None, None) => "no region".to_string(),
        };
        let lines = std::iter::once(fit_text(area, &line1, &font, text_w))
            .chain(wrap_text(area, &line2, &font, text_w, 2));
        for line in lines {
            area.draw(&Text::new(line, (x0 + 36, y), font.clone()))
                .map_err(err)?;
            y += row - 2;
        }
        y += 8;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use hpge_inference::{
        Disagreement, DiscoverSettings, DiscoverySummary, Elpd, Gap, ModelFit, Region,
        ResidualCheck, Window,
    };

    use super::*;

    #[test]
    fn bands_reach_halfway_to_the_neighbours() {
        let v = [0.0, 10.0, 20.0, 30.0, 50.0];
        assert_eq!(band_edges(&v, [10.0, 20.0]), [5.0, 25.0]);
        assert_eq!(band_edges(&v, [20.0, 30.0]), [15.0, 40.0]);
        // At the ends: half the median gap (10).
        assert_eq!(band_edges(&v, [0.0, 10.0]), [-5.0, 15.0]);
        assert_eq!(band_edges(&v, [30.0, 50.0]), [25.0, 55.0]);
        assert_eq!(band_edges(&[7.0], [7.0, 7.0]), [7.0, 7.0]);
    }

    #[test]
    fn the_residual_axis_keeps_room_for_legend_and_labels() {
        // Residuals within +-2.5: the axis covers +-2.5 plus 5% and the two strips.
        let (lo, hi) = residual_range([1.0, -1.0, f64::NAN].into_iter(), 400.0, 100.0, 50.0);
        let per_px = 5.5 / 250.0;
        assert!((lo - (-2.75 - 50.0 * per_px)).abs() < 1e-12, "{lo}");
        assert!((hi - (2.75 + 100.0 * per_px)).abs() < 1e-12, "{hi}");
        // An outlier widens the data range; the strips stay free in pixels.
        let (lo, hi) = residual_range([9.0, -1.0].into_iter(), 400.0, 100.0, 0.0);
        let top_of_data = 9.0 + 0.05 * 11.5;
        assert!(lo < -2.5 && hi > top_of_data);
        assert!(((hi - top_of_data) / (hi - lo) * 400.0 - 100.0).abs() < 1e-9);
        // Strips never take more than 60% of the plot.
        let (lo, hi) = residual_range(std::iter::empty(), 100.0, 90.0, 90.0);
        assert!(((2.75 - -2.75) / (hi - lo) - 40.0 / 220.0).abs() < 1e-12);
    }

    #[test]
    fn labels_move_apart_and_stay_inside() {
        let boxes = [
            [10, 10, 50, 20],
            [30, 15, 50, 20],
            [210, 0, 50, 20],
            [290, 0, 50, 20],
        ];
        let placed = place_labels(&boxes, [0, 300], 22);
        assert_eq!(placed[0], boxes[0]);
        assert_eq!(placed[1], [30, 37, 50, 20]);
        assert_eq!(placed[2], boxes[2]);
        // Clamped to x <= 300 - 50, where it overlaps the third: moved down once.
        assert_eq!(placed[3], [250, 22, 50, 20]);
        assert_eq!(window_label(0, [1025.0, 1374.6]), "W1 (1025-1375 V)");
        assert_eq!(p_text(0.0123), "0.0123");
        assert_eq!(p_text(3.2e-5), "3.2e-5");
        let ticks: Vec<String> = [500.0, 2.5, -0.25, 0.0, -1e-9, 70.0]
            .iter()
            .map(tick)
            .collect();
        assert_eq!(ticks, ["500", "2.5", "-0.25", "0", "0", "70"]);
    }

    fn gap(model: &str, chi2_ndf: f64) -> Gap {
        Gap {
            chi2_ndf,
            max_pull: 3.0,
            ppc_p: 0.01,
            chi2: chi2_ndf * 57.0,
            ndf: 57,
            model: model.into(),
            method: "mcmc".into(),
            converged: true,
            mode: BTreeMap::new(),
        }
    }

    fn model_fit(model: &str, residuals: Vec<f64>) -> ModelFit {
        let n = residuals.len();
        ModelFit {
            model: model.into(),
            names: vec!["d_li_mm".into()],
            mcmc: None,
            laplace: None,
            check: ResidualCheck {
                residuals,
                windows: Vec::new(),
                ppc_p: 0.01,
                replicates: 1000,
            },
            elpd: Elpd {
                blocks: vec![[0, n - 1]],
                per_block: vec![0.0],
                total: 0.0,
                max_k_hat: 0.1,
            },
            c_mode: vec![40.0; n],
            sigma_mode: vec![1.0; n],
        }
    }

    fn window(v: &[f64], lo: f64, hi: f64, p: f64, region: Option<Region>) -> Disagreement {
        let first = v.iter().position(|&x| x == lo).unwrap();
        let last = v.iter().position(|&x| x == hi).unwrap();
        Disagreement {
            voltages_v: [lo, hi],
            region_error: region
                .is_none()
                .then(|| "the depletion front does not move there".into()),
            region,
            p_value: p,
            window: Window {
                first,
                last,
                sign: 1,
                statistic: 30.0,
                p_value: p,
            },
        }
    }

    /// A B_Z-like start model with three windows of disagreement, one of them without a region,
    /// and an extension that removes them (or, `extended` false, none chosen and no windows).
    fn synthetic(extended: bool) -> Discovery {
        let v: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
        let wiggle =
            |k: usize, a: f64| a * ((k as f64 * 1.7).sin() + 0.5 * (k as f64 * 0.37).cos());
        let bump = |x: f64, c: f64, w: f64| (-((x - c) / w).powi(2)).exp();
        let before: Vec<f64> = v
            .iter()
            .enumerate()
            .map(|(k, &x)| {
                3.2 * bump(x, 1200.0, 220.0) - 2.6 * bump(x, 2400.0, 180.0)
                    + 2.4 * bump(x, 2750.0, 120.0)
                    + wiggle(k, 0.5)
            })
            .collect();
        let after: Vec<f64> = (0..v.len()).map(|k| wiggle(k, 0.7)).collect();
        let region = |r: [f64; 2], z: [f64; 2]| Region {
            r_mm: r,
            z_mm: z,
            nodes: 100,
        };
        let disagreement = if extended {
            vec![
                window(
                    &v,
                    1025.0,
                    1375.0,
                    4e-4,
                    Some(region([28.0, 33.5], [0.0, 70.0])),
                ),
                window(&v, 2275.0, 2525.0, 0.003, None),
                window(
                    &v,
                    2675.0,
                    2825.0,
                    0.008,
                    Some(region([24.0, 29.0], [0.0, 70.0])),
                ),
            ]
        } else {
            Vec::new()
        };
        let mut inputs = BTreeMap::new();
        inputs.insert("data".into(), "cv.csv".into());
        let summary = DiscoverySummary {
            start_model: "b-z".into(),
            disagreement,
            candidates: Vec::new(),
            chosen: extended.then(|| "radial".into()),
            before: gap("b-z", 3.41),
            after: gap(if extended { "b-z+radial" } else { "b-z" }, 1.02),
            delta_elpd: 12.0,
            delta_elpd_se: 3.0,
            seconds: 100.0,
            ln_bayes_factor: extended.then_some(9.0),
            elpd_method: "psis".into(),
            elpd_blocks: 10,
            elpd_max_k_hat: [0.2, 0.3],
            runs: Vec::new(),
            predictor: "exact".into(),
            surrogate_start: gap("b-z", 3.41),
            not_applicable: Vec::new(),
            verdict: "synthetic".into(),
            program_version: "0".into(),
            inputs,
            settings: DiscoverSettings::default(),
        };
        Discovery {
            summary,
            before: model_fit("b-z", before),
            after: extended.then(|| model_fit("b-z+radial", after)),
            c_m_pf: vec![40.0; v.len()],
            voltage_v: v,
            start_inputs: vec![1.0],
        }
    }

    fn detector() -> Detector {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("detectors/super-siegfried-k1.toml");
        Detector::from_file(&path, &Default::default()).unwrap()
    }

    /// Writes the figure into a fresh temporary folder and checks both files, none empty.
    /// HPGE_KEEP_FIGURES=1 keeps the folder.
    fn check(tag: &str, d: &Discovery) {
        let dir =
            std::env::temp_dir().join(format!("hpge-cv-discovery-{tag}-{}", std::process::id()));
        let paths = discovery_figures(d, &detector(), &dir).unwrap();
        assert_eq!(paths.len(), 2, "{paths:?}");
        for ext in ["svg", "png"] {
            let p = dir.join(format!("residuals.{ext}"));
            assert!(paths.contains(&p), "{} not listed", p.display());
            let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
            assert!(len > 0, "{} missing or empty", p.display());
        }
        if std::env::var_os("HPGE_KEEP_FIGURES").is_none() {
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }

    #[test]
    fn figures_of_a_synthetic_discovery() {
        check("extended", &synthetic(true));
        check("nothing", &synthetic(false));
    }

    #[test]
    fn mismatched_residuals_are_refused_before_drawing() {
        let dir = std::env::temp_dir().join("hpge-cv-discovery-never-written");
        let mut d = synthetic(true);
        d.after.as_mut().unwrap().check.residuals.pop();
        assert!(discovery_figures(&d, &detector(), &dir).is_err());
        d.voltage_v.clear();
        assert!(discovery_figures(&d, &detector(), &dir).is_err());
        assert!(!dir.exists());
    }
}
