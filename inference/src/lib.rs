//! # hpge-inference
//!
//! The statistics side of hpge-cv (paper, sections 4 and 8): measured data (raw pulser data to a
//! C-V curve with its covariance), priors, the likelihood with parameter-dependent uncertainties,
//! samplers and their diagnostics, posterior summaries and predictive checks, and the
//! model-discovery workflow. It sees a model only through one narrow trait, implemented by both
//! the exact solver and the surrogate. Filled in by the measurement and inference issues.

mod error;

pub use error::{Error, Result};
