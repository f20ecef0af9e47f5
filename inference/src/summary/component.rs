//! One Gaussian component of a mixture: what EM fits and what a posterior's modes are reported
//! as.

/// One Gaussian component of a [`Mixture`](super::Mixture).
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Mixing weight (the weights of a mixture sum to 1).
    pub weight: f64,
    /// Mean vector, length `d`.
    pub mean: Vec<f64>,
    /// Covariance matrix, row-major `d x d`.
    pub cov: Vec<f64>,
}
