//! The figure of a model discovery (`hpge-cv discover`): the start model's standardised
//! posterior-predictive residuals against the bias, before and after adding the chosen
//! extension, with the windows of disagreement shaded; beside them the detector's r-z
//! cross-section with the region each window probes.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use hpge_inference::Discovery;
use hpge_solver::Detector;
use hpge_solver::geometry::BoundingBox;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::plot::cross_section::{contact_color, draw_regions, passive_color};
use crate::plot::err;
use crate::plot::fit::PALETTE;

mod key;
mod region;
mod residuals;
#[cfg(test)]
mod tests;

use key::draw_key;
use region::region_panel;
use residuals::residual_panel;

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
