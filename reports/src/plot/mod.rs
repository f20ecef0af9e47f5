//! Figures: SVG and PNG through plotters.

/// Draws `$body` (which sees the drawing area as `$root` and whether the target is SVG as
/// `$svg`, and returns this crate's `Result<()>`) on a PNG or SVG backend chosen by the extension
/// of `$path`, then writes the file; every failure is an `Error::Draw` or `Error::UnknownFormat`
/// naming the file. Returns from the enclosing function on failure, else evaluates to `Ok(())`.
macro_rules! render {
    ($path:expr, $size:expr, |$root:ident, $svg:ident| $body:expr) => {{
        let path: &std::path::Path = $path;
        let draw = |message: String| $crate::Error::Draw {
            file: path.to_path_buf(),
            message,
        };
        match $crate::plot::Format::from_path(path) {
            Some(format) => {
                let $svg = format == $crate::plot::Format::Svg;
                if $svg {
                    let $root = plotters::prelude::SVGBackend::new(path, $size).into_drawing_area();
                    $body.map_err(|e: $crate::Error| draw(e.chain_text()))?;
                    $root.present().map_err(|e| draw(e.to_string()))?;
                } else {
                    let $root =
                        plotters::prelude::BitMapBackend::new(path, $size).into_drawing_area();
                    $body.map_err(|e: $crate::Error| draw(e.chain_text()))?;
                    $root.present().map_err(|e| draw(e.to_string()))?;
                }
            }
            None => {
                return Err($crate::Error::UnknownFormat {
                    file: path.to_path_buf(),
                    message: "unknown file type; use .svg or .png",
                });
            }
        }
        Ok(())
    }};
}

mod colormap;
mod convergence;
mod coverage;
mod cross_section;
mod cv;
mod discovery;
mod field;
mod fit;
mod lines;
mod measure;
mod sensitivity;
mod surrogate;

use std::path::Path;

use crate::{Error, Result};

pub use convergence::convergence;
pub use coverage::coverage_figures;
pub use cross_section::cross_section;
pub use cv::cv_curve;
pub use discovery::discovery_figures;
pub use field::field_map;
pub use fit::{ZetaAtMode, ZetaProfile, fit_figures};
pub use lines::{Corner, Curve, LineFigure, line_figure};
pub use measure::measurement;
pub use sensitivity::{SensitivityPoint, sensitivity};
pub use surrogate::{learning_curves, surrogate_errors};

/// Output format, chosen by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics (bitmap).
    Png,
}

impl Format {
    /// `.svg` or `.png` (case-insensitive); anything else is `None`.
    pub fn from_path(path: &Path) -> Option<Format> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "svg" => Some(Format::Svg),
            "png" => Some(Format::Png),
            _ => None,
        }
    }
}

/// Checks an output path before any work: a known extension and an existing folder. `flag` names
/// the option in the message.
pub fn check_output(path: &Path, flag: &str) -> Result<()> {
    let output = |message: String| Error::Output {
        flag: flag.to_string(),
        file: path.to_path_buf(),
        message,
    };
    if Format::from_path(path).is_none() {
        return Err(output(
            "unknown file type; use a name ending in .svg or .png".into(),
        ));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        return Err(output(format!(
            "the folder {} does not exist",
            dir.display()
        )));
    }
    Ok(())
}

/// The legend most figures use: a framed, slightly transparent box at `position`.
pub(crate) fn legend<
    'a,
    DB: plotters::prelude::DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
>(
    chart: &mut plotters::prelude::ChartContext<'a, DB, CT>,
    position: plotters::prelude::SeriesLabelPosition,
) -> Result<()> {
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
