//! Figures and reports of hpge-cv: every figure the command line draws (SVG or PNG through
//! plotters, chosen by the file's extension) and the steps of `report paper` that remake the
//! paper's figures.
//!
//! - [`plot`]: one function per figure. The detector's r-z cross-section
//!   ([`plot::cross_section`]), the potential with the undepleted region ([`plot::field_map`]),
//!   the C-V curve ([`plot::cv_curve`]), the sensitivity scan ([`plot::sensitivity`]), grid
//!   convergence ([`plot::convergence`]), the measurement's pulses, spectra and C-V curve
//!   ([`plot::measurement`]), the surrogate's learning curves and errors
//!   ([`plot::learning_curves`], [`plot::surrogate_errors`]), a fit's posteriors, predictive and
//!   densities ([`plot::fit_figures`]), a model discovery ([`plot::discovery_figures`]), a
//!   coverage study ([`plot::coverage_figures`]) and general curves against one axis
//!   ([`plot::line_figure`]: pulses, |E| along r). [`plot::check_output`] checks an output path
//!   before any work.
//! - [`paper`]: the steps of `report paper` that draw the paper's figures from shipped inputs
//!   (C-V curve, transform and example density, training samples, surrogate), the impurity
//!   models of section 9, and the README and report.json of a run.
//! - [`status`]: the README's status table, derived from the shipped results files.
//! - [`replace`]: a run refuses to replace another run's results file unless `--force`.
//!
//! Every failure is an [`Error`] naming the file at fault.
//!
//! ```
//! use hpge_reports::plot::{Corner, Curve, LineFigure, line_figure};
//!
//! let fig = LineFigure {
//!     title: "a parabola".into(),
//!     x_desc: "x (mm)".into(),
//!     y_desc: "y (mm)".into(),
//!     curves: vec![Curve {
//!         label: "y = x^2".into(),
//!         points: (0..=10).map(|i| (i as f64, Some((i * i) as f64))).collect(),
//!     }],
//!     y_from_zero: true,
//!     legend: Corner::UpperLeft,
//!     footnotes: vec!["made by the doctest of hpge-reports".into()],
//! };
//! let path = std::env::temp_dir().join(format!("hpge-reports-doctest-{}.svg", std::process::id()));
//! line_figure(&fig, &path)?;
//! assert!(path.is_file());
//! std::fs::remove_file(&path)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]
#[macro_use]
mod error;
pub mod discover;
pub mod fit;
mod json_file;
pub mod numbers;
pub mod paper;
pub mod plot;
mod provenance;
pub mod replace;
pub mod status;

pub use error::{Error, Result};
pub use plot::{Corner, Curve, Format, LineFigure, check_output, line_figure};
pub use provenance::{PROGRAM, VERSION};
