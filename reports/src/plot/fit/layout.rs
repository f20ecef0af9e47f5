//! What the figures of a fit share: the grid of panels, axis labels and ranges, the interval
//! colours and the legend strip above the panels.

use hpge_inference::fit::ParameterSummary;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::Result;
use crate::plot::style::err;

/// Rows and columns of a grid of `n` panels with at most `cols` columns.
pub(super) fn grid(n: usize, cols: usize) -> (usize, usize) {
    let cols = cols.min(n).max(1);
    (n.div_ceil(cols), cols)
}

/// "name [unit]", or the name alone for a dimensionless parameter (unit "1" or empty).
/// A parameter whose mode or 68.3% interval lies at a prior bound (`at_prior_bound`, issue 63)
/// says so in its label: "(at prior bound)".
pub(super) fn axis_label(p: &ParameterSummary) -> String {
    let name = match p.unit.trim() {
        "" | "1" => p.name.clone(),
        u => format!("{} [{u}]", p.name),
    };
    if p.at_prior_bound.is_empty() {
        name
    } else {
        format!("{name} (at prior bound)")
    }
}

/// Fill colours of the 68.3, 95.5 and 99.7% intervals (LEVELS order), as in BAT.jl's plots.
pub(super) const LEVEL_COLORS: [RGBColor; 3] = [
    RGBColor(77, 175, 74),
    RGBColor(255, 210, 60),
    RGBColor(235, 95, 75),
];
/// Histogram bins outside every interval.
pub(super) const OUTSIDE: RGBColor = RGBColor(200, 200, 200);
/// The prior.
pub(super) const PRIOR: RGBColor = RGBColor(31, 119, 180);
/// The truth (dashed).
pub(super) const TRUTH: RGBColor = RGBColor(118, 42, 131);

/// [lo, hi] around `values` and `extra` (padded by 5%), within `support`; the whole support when
/// the values span more than half of it.
pub(super) fn view_range(values: &[f64], extra: &[f64], support: [f64; 2]) -> (f64, f64) {
    let (mut lo, mut hi) = values
        .iter()
        .chain(extra)
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    let span = support[1] - support[0];
    if span.is_finite() && span > 0.0 && hi - lo > 0.5 * span {
        return (support[0], support[1]);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        1e-3 * lo.abs().max(1.0)
    };
    let (lo, hi) = (lo - pad, hi + pad);
    if support[0] < support[1] {
        (lo.max(support[0]), hi.min(support[1]))
    } else {
        (lo, hi)
    }
}

/// Padded [lo, hi] around finite values (an empty or flat set gets a unit or 10% span).
pub(super) fn padded(values: impl Iterator<Item = f64>, frac: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo {
        frac * (hi - lo)
    } else {
        0.1 * lo.abs().max(1e-12)
    };
    (lo - pad, hi + pad)
}

/// The axes of a fit figure's panel: what each axis shows, the spans the tick labels are
/// formatted for, how many labels (plotters' default where `None`), and the font sizes of the
/// labels and of the axis descriptions.
pub(super) struct Axes<'a> {
    /// What the x and the y axis show.
    pub desc: (&'a str, &'a str),
    /// The x and y spans, for [`ticks`].
    pub span: (f64, f64),
    /// How many labels on x and on y.
    pub labels: Option<(usize, usize)>,
    /// Font sizes of the tick labels and of the axis descriptions.
    pub font: (u32, u32),
}

/// Draws a panel's axes in the fit figures' style (no light grid lines).
pub(super) fn draw_axes<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    axes: Axes,
) -> Result<()> {
    let (x_ticks, y_ticks) = (ticks(axes.span.0), ticks(axes.span.1));
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(axes.desc.0)
        .y_desc(axes.desc.1)
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .label_style(("sans-serif", axes.font.0))
        .axis_desc_style(("sans-serif", axes.font.1))
        .light_line_style(WHITE);
    if let Some((x, y)) = axes.labels {
        mesh.x_labels(x).y_labels(y);
    }
    mesh.draw().map_err(err)?;
    Ok(())
}

/// A tick-label formatter for an axis spanning `span`: as many decimals as a step of about
/// span/6 needs (none for steps of 1 and more, at most 12), so that neighbouring labels differ
/// even on a narrow axis far from 0 (a posterior squeezed against d_Li = 0.2 mm: 0.200002,
/// 0.200004); exponent notation only for values of 1e6 and more, or below 1e-4 on such a step.
pub(super) fn ticks(span: f64) -> impl Fn(&f64) -> String {
    let step = (span / 6.0).abs();
    let decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
    move |v: &f64| {
        let a = v.abs();
        if a >= 1e6 || (a > 0.0 && a < 1e-4 && step < 1e-4) {
            format!("{v:.1e}")
        } else {
            format!("{v:.decimals$}")
        }
    }
}

/// A legend entry's symbol.
#[derive(Debug, Clone, Copy)]
pub(super) enum Key {
    /// A filled box.
    Fill(RGBColor),
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
    /// A cross.
    Cross(RGBColor),
}

const KEY_FONT: (&str, u32) = ("sans-serif", 17);
const KEY_ROW_H: i32 = 26;

/// Positions (x, row) of the entries of a legend strip `width` pixels wide.
fn key_layout<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[(Key, String)],
    width: i32,
) -> Result<Vec<(i32, i32)>> {
    let font = TextStyle::from(KEY_FONT.into_font());
    let (mut x, mut row) = (20, 0);
    let mut out = Vec::with_capacity(keys.len());
    for (_, text) in keys {
        let (tw, _) = area.estimate_text_size(text, &font).map_err(err)?;
        let w = 34 + tw as i32;
        if x > 20 && x + w > width - 10 {
            (x, row) = (20, row + 1);
        }
        out.push((x, row));
        x += w + 30;
    }
    Ok(out)
}

/// Splits a legend strip off the top of `area`, draws `keys` into it and returns the rest.
pub(super) fn key_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[(Key, String)],
) -> Result<DrawingArea<DB, Shift>> {
    let width = area.dim_in_pixel().0 as i32;
    let at = key_layout(area, keys, width)?;
    let rows = at.last().map_or(0, |p| p.1 + 1);
    let (strip, rest) = area.split_vertically(rows * KEY_ROW_H + 10);
    let font = TextStyle::from(KEY_FONT.into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for ((key, text), &(x, row)) in keys.iter().zip(&at) {
        let y = row * KEY_ROW_H + KEY_ROW_H / 2 + 4;
        match *key {
            Key::Fill(c) => strip.draw(&Rectangle::new([(x, y - 8), (x + 24, y + 8)], c.filled())),
            Key::Line(c) => strip.draw(&PathElement::new(
                vec![(x, y), (x + 24, y)],
                c.stroke_width(3),
            )),
            Key::Dashed(c) => strip
                .draw(&PathElement::new(
                    vec![(x, y), (x + 9, y)],
                    c.stroke_width(3),
                ))
                .and_then(|_| {
                    strip.draw(&PathElement::new(
                        vec![(x + 15, y), (x + 24, y)],
                        c.stroke_width(3),
                    ))
                }),
            Key::Dot(c) => strip.draw(&Circle::new((x + 12, y), 5, c.filled())),
            Key::Cross(c) => strip.draw(&Cross::new((x + 12, y), 7, c.stroke_width(3))),
        }
        .map_err(err)?;
        strip
            .draw(&Text::new(text.clone(), (x + 32, y), font.clone()))
            .map_err(err)?;
    }
    Ok(rest)
}

#[cfg(test)]
mod tick_tests {
    use super::ticks;

    #[test]
    fn narrow_axes_far_from_zero_keep_their_ticks_apart() {
        let t = ticks(1.2e-5);
        assert_eq!(t(&0.200002), "0.200002");
        assert_ne!(t(&0.200002), t(&0.200004));
        assert_eq!(ticks(3.0)(&1.5), "1.5");
        assert_eq!(ticks(600.0)(&200.0), "200");
        assert_eq!(ticks(3e6)(&2e6), "2.0e6");
        assert_eq!(ticks(6e-6)(&3e-5), "3.0e-5");
    }
}
