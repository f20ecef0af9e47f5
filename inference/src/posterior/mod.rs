//! The likelihood of a measured C-V curve (the paper's eqs. 12-15, and the variant with the
//! measured covariance) and the posterior the samplers see.

mod cholesky;
mod likelihood;
mod posterior;

pub use cholesky::Cholesky;
pub use likelihood::{Likelihood, NoiseKind, NoiseSettings};
pub use posterior::{Evaluation, Posterior};

#[cfg(test)]
mod tests;
