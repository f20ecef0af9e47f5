//! Figures: SVG and PNG through plotters, the format chosen by the file's extension
//! ([`Format`]). One file (or folder) per topic, each with its public drawing function re-exported
//! here: the detector (`cross_section`), the solver (`cv`, `field`, `convergence`, `sensitivity`),
//! the measurement (`measure`), the surrogate (`surrogate`), inference (`fit/`, `discovery/`,
//! `coverage`) and curves against one axis (`lines`). `style` holds the palette, the legend box
//! and log-axis labels that most figures share, `colormap` the colours of signed densities.

#[macro_use]
pub(crate) mod render;

mod colormap;
mod convergence;
mod coverage;
mod cross_section;
mod cv;
mod depletion;
mod discovery;
mod field;
mod fit;
pub(crate) mod fonts;
mod format;
mod lines;
mod measure;
mod sensitivity;
pub(crate) mod style;
mod surrogate;

pub use convergence::convergence;
pub use coverage::{coverage_figures, coverage_title, redraw_coverage};
pub use cross_section::cross_section;
pub use cv::cv_curve;
pub use depletion::{DepletionBands, depleted_from, depletion_bands, depletion_map};
pub use discovery::discovery_figures;
pub use field::field_map;
pub use fit::{ZetaAtMode, ZetaProfile, fit_figures};
pub use format::{Format, check_output};
pub use lines::{Corner, Curve, LineFigure, line_figure};
pub use measure::measurement;
pub use sensitivity::{Mark, ScanMarks, sensitivity};
pub use surrogate::{learning_curves, scatter_sets, surrogate_errors};
