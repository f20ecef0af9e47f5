//! The likelihood of a measured C-V curve (the paper's eqs. 12-15, and the variant with the
//! measured covariance) and the posterior the samplers see.

mod density;
mod laplace;
mod likelihood;

pub use density::{Posterior, PosteriorEvaluation};
pub use laplace::{
    LaplaceFit, LaplaceSettings, VisitedCurve, fd_steps, laplace_fit, laplace_fit_guided,
};
pub use likelihood::{
    CalibrationScale, Likelihood, NoiseKind, NoiseSettings, OwnErrors, ScaleFit,
    calibration_mixture,
};

#[cfg(test)]
mod tests;
