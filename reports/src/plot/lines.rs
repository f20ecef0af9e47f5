//! Curves against one axis, with gaps: charge signals against time, |E| against r. One colour per
//! curve from the project palette; a footnote line carries the provenance.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{PALETTE, err};
use crate::error::Result;

/// One curve: points (x, y); `None` leaves a gap (e.g. undepleted volume).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend entry.
    pub label: String,
    /// The points in drawing order.
    pub points: Vec<(f64, Option<f64>)>,
}

/// A figure of several curves.
#[derive(Debug, Clone, PartialEq)]
pub struct LineFigure {
    /// Title above the plot.
    pub title: String,
    /// x-axis description with unit.
    pub x_desc: String,
    /// y-axis description with unit.
    pub y_desc: String,
    /// The curves (colours in order of the palette).
    pub curves: Vec<Curve>,
    /// Start the y axis at 0 (magnitudes).
    pub y_from_zero: bool,
    /// Which corner the legend goes in.
    pub legend: Corner,
    /// Lines of small text under the plot (provenance, notes).
    pub footnotes: Vec<String>,
}

/// A corner of the plot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    /// Top left.
    UpperLeft,
    /// Bottom right.
    LowerRight,
    /// Middle of the plot area (for curves that leave the centre empty).
    MiddleMiddle,
}

impl Corner {
    fn position(self) -> SeriesLabelPosition {
        match self {
            Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
            Corner::MiddleMiddle => SeriesLabelPosition::MiddleMiddle,
            Corner::LowerRight => SeriesLabelPosition::LowerRight,
        }
    }
}

/// Draws `fig` to `path` (.svg or .png by extension).
pub fn line_figure(fig: &LineFigure, path: &Path) -> Result<()> {
    let notes: Vec<String> = fig.footnotes.iter().flat_map(|n| wrap(n, 125)).collect();
    let size = (1000, 650 + 22 * notes.len() as u32);
    render!(path, size, |root, _svg| draw(&root, fig, &notes))
}

/// Splits `text` at spaces into lines of at most `width` characters (a longer word stays whole).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split(' ') {
        let last = lines.last_mut().expect("never empty");
        if !last.is_empty() && last.chars().count() + 1 + word.chars().count() > width {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

/// Tick labels with as many decimals as the axis span needs (and no "-0").
fn tick_label(v: f64, span: f64) -> String {
    let decimals = (1.0 - span.log10().floor()).clamp(0.0, 6.0) as usize;
    let text = format!("{v:.decimals$}");
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        text.trim_start_matches('-').to_string()
    } else {
        text
    }
}

/// The finite y range of the curves, padded by 5% (and reaching 0 when asked).
fn y_range(fig: &LineFigure) -> (f64, f64) {
    let ys = fig
        .curves
        .iter()
        .flat_map(|c| c.points.iter().filter_map(|p| p.1));
    let (mut lo, mut hi) = ys
        .filter(|y| y.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(y), b.max(y))
        });
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    if fig.y_from_zero {
        lo = lo.min(0.0);
        hi = hi.max(0.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-12 * hi.abs().max(1.0));
    let lo = if fig.y_from_zero && lo >= 0.0 {
        0.0
    } else {
        lo - pad
    };
    (lo, hi + pad)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &LineFigure,
    notes: &[String],
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let foot_h = 22 * notes.len() as u32 + if notes.is_empty() { 0 } else { 10 };
    let (plot_area, foot) = root.split_vertically(root.dim_in_pixel().1 - foot_h);
    let xs = fig
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.0))
        .filter(|x| x.is_finite());
    let (x_lo, x_hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (x_lo, x_hi) = if x_lo.is_finite() && x_hi > x_lo {
        (x_lo, x_hi)
    } else {
        (0.0, 1.0)
    };
    let (y_lo, y_hi) = y_range(fig);
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(&fig.title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(fig.x_desc.as_str())
        .y_desc(fig.y_desc.as_str())
        .x_label_formatter(&|v| tick_label(*v, x_hi - x_lo))
        .y_label_formatter(&|v| tick_label(*v, y_hi - y_lo))
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    for (k, c) in fig.curves.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let style = color.stroke_width(3);
        // Split at the gaps; the first segment carries the legend entry.
        let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &(x, y) in &c.points {
            match y {
                Some(y) if x.is_finite() && y.is_finite() => {
                    if let Some(s) = segments.last_mut() {
                        s.push((x, y));
                    }
                }
                _ => {
                    if segments.last().is_some_and(|s| !s.is_empty()) {
                        segments.push(Vec::new());
                    }
                }
            }
        }
        let mut labelled = false;
        for s in segments.into_iter().filter(|s| !s.is_empty()) {
            // A segment of one point draws no line: a dot shows it.
            if let [p] = s.as_slice() {
                chart
                    .draw_series(std::iter::once(Circle::new(*p, 5, color.filled())))
                    .map_err(err)?;
            }
            let series = chart.draw_series(LineSeries::new(s, style)).map_err(err)?;
            if !labelled {
                series.label(c.label.clone()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(3))
                });
                labelled = true;
            }
        }
    }
    chart
        .configure_series_labels()
        .position(fig.legend.position())
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let font = ("sans-serif", 14).into_font().color(&RGBColor(80, 80, 80));
    for (i, line) in notes.iter().enumerate() {
        foot.draw(&Text::new(line.as_str(), (20, 22 * i as i32), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_and_wrapping() {
        assert_eq!(tick_label(-0.0001, 2.2), "0.0");
        assert_eq!(tick_label(0.4, 2.2), "0.4");
        assert_eq!(tick_label(150.0, 300.0), "150");
        let lines = wrap("aaa bbb ccc", 7);
        assert_eq!(lines, vec!["aaa bbb", "ccc"]);
    }
}
