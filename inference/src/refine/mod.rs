//! Posterior-adaptive refinement (issue 21): exact-solver curves at posterior draws teach a
//! model of the surrogate's error there ([`GpCorrection`]); the corrected surrogate
//! ([`CorrectedModel`]) carries that model's uncertainty into the likelihood, point by point.

mod corrected;
mod gp;

pub use corrected::CorrectedModel;
pub use gp::{GpCorrection, GpHyper, GpPrediction};

#[cfg(test)]
mod tests;
