//! Studies that run the solver, the surrogate or the fit many times and summarise the outcome.
//!
//! - [`accuracy`]: c12 on every shipped detector type against a 4x finer reference.
//! - [`coverage`]: simulation-based calibration of the fit (rank uniformity, interval coverage).
//! - [`hidden`]: hidden-effect tests of model discovery.

pub mod accuracy;
pub mod coverage;
pub mod hidden;
