//! What most figures share: the palette, the legend box, log-axis labels and plotters errors as
//! this crate's error.

use plotters::style::RGBColor;

use crate::error::Error;

/// One colour per chain, profile or parameter (tab10, then black and dark magenta for the 11th
/// and 12th series); the coverage figures use it too.
pub(crate) const PALETTE: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(139, 0, 139),
];

/// The legend most figures use: a framed, slightly transparent box at `position`.
pub(crate) fn legend<
    'a,
    DB: plotters::prelude::DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
>(
    chart: &mut plotters::prelude::ChartContext<'a, DB, CT>,
    position: plotters::prelude::SeriesLabelPosition,
) -> crate::Result<()> {
    use plotters::prelude::{BLACK, Color, WHITE};
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// A plotters drawing error as this crate's error (`Error::Drawing`).
pub(crate) fn err<E: std::fmt::Debug>(e: E) -> Error {
    Error::drawing(e)
}

/// 1, 2 and 5 times the powers of ten within [lo, hi] (log-axis labels at every scale).
pub(crate) fn log_key_points(lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut decade = 10f64.powf(lo.log10().floor());
    while decade <= hi {
        for m in [1.0, 2.0, 5.0] {
            let v = m * decade;
            if (lo..=hi).contains(&v) {
                out.push(v);
            }
        }
        decade *= 10.0;
    }
    out
}

/// The horizontal line y = 0 across [x0, x1] of a residual or pull panel, one pixel wide.
pub(crate) fn zero_line<DB: plotters::prelude::DrawingBackend>(
    chart: &mut plotters::prelude::ChartContext<
        '_,
        DB,
        plotters::prelude::Cartesian2d<
            plotters::coord::types::RangedCoordf64,
            plotters::coord::types::RangedCoordf64,
        >,
    >,
    (x0, x1): (f64, f64),
    color: RGBColor,
) -> crate::error::Result<()> {
    use plotters::prelude::{LineSeries, ShapeStyle};
    chart
        .draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            ShapeStyle::from(color).stroke_width(1),
        ))
        .map_err(err)?;
    Ok(())
}
