//! Figures: SVG and PNG through plotters.

mod colormap;
mod cross_section;
mod cv;
mod field;

use std::path::Path;

pub use cross_section::cross_section;
pub use cv::cv_curve;
pub use field::field_map;

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
